# spinradar_core: every algorithm, no ROS. Sources are picked up from src/core/.
file(GLOB SPINRADAR_CORE_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/core/*.cpp)
add_library(spinradar_core SHARED ${SPINRADAR_CORE_SOURCES})
target_include_directories(spinradar_core PUBLIC ${PROJECT_SOURCE_DIR}/include ${OpenCV_INCLUDE_DIRS})
target_link_libraries(spinradar_core PUBLIC Eigen3::Eigen ${OpenCV_LIBS} nlohmann_json::nlohmann_json
  yaml-cpp TBB::tbb Threads::Threads)
target_compile_options(spinradar_core PRIVATE -O3 -march=x86-64-v2)
