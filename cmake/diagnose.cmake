# spinradar_diagnose: sim-vs-real diagnosis, no ROS.
file(GLOB SPINRADAR_DIAGNOSE_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/diagnose/*.cpp)
if(SPINRADAR_DIAGNOSE_SOURCES)
  add_library(spinradar_diagnose SHARED ${SPINRADAR_DIAGNOSE_SOURCES})
  target_link_libraries(spinradar_diagnose PUBLIC spinradar_sim spinradar_core)
endif()
