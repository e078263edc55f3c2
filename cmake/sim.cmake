# spinradar_sim: the physics simulator of the spinning radar, no ROS.
file(GLOB SPINRADAR_SIM_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/sim/*.cpp)
if(SPINRADAR_SIM_SOURCES)
  add_library(spinradar_sim SHARED ${SPINRADAR_SIM_SOURCES})
  target_link_libraries(spinradar_sim PUBLIC spinradar_core)
  target_compile_options(spinradar_sim PRIVATE -O3 -march=x86-64-v2)
endif()
