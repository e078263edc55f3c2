# The `spinradar` command-line program (one subcommand per file in src/tools/), the rosbag
# library it uses for `spinradar bag` when catkin is present, and the `bench` target.

# spinradar_bag: scan folders <-> rosbags of spinradar/RadarScan (needs rosbag and the
# generated message; msg <-> core conversions come from spinradar_ros).
set(SPINRADAR_BAG_CONVERSIONS ${PROJECT_SOURCE_DIR}/include/spinradar_ros/polar_scan_conversions.hpp)
file(GLOB SPINRADAR_BAG_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/bag/*.cpp)
if(SPINRADAR_ROS AND SPINRADAR_BAG_SOURCES AND EXISTS ${SPINRADAR_BAG_CONVERSIONS})
  add_library(spinradar_bag SHARED ${SPINRADAR_BAG_SOURCES})
  target_include_directories(spinradar_bag PUBLIC ${PROJECT_SOURCE_DIR}/src/bag
    ${CATKIN_DEVEL_PREFIX}/include ${catkin_INCLUDE_DIRS})
  target_link_libraries(spinradar_bag PUBLIC spinradar_io spinradar_core ${catkin_LIBRARIES})
  # Conversions implemented in src/ros/ are part of the nodelet library (defined later; CMake
  # resolves the name at generation time).
  file(GLOB SPINRADAR_BAG_CONV_SRC CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/ros/*conversions*.cpp)
  if(SPINRADAR_BAG_CONV_SRC)
    target_link_libraries(spinradar_bag PUBLIC spinradar_nodelets)
  endif()
  add_dependencies(spinradar_bag ${PROJECT_NAME}_generate_messages_cpp)
  message(STATUS "spinradar: rosbag support for `spinradar bag` ON")
else()
  message(STATUS "spinradar: rosbag support for `spinradar bag` OFF (needs catkin and "
                 "include/spinradar_ros/polar_scan_conversions.hpp)")
endif()

file(GLOB SPINRADAR_TOOL_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/tools/*.cpp)
if(SPINRADAR_TOOL_SOURCES)
  add_executable(spinradar_cli ${SPINRADAR_TOOL_SOURCES})
  set_target_properties(spinradar_cli PROPERTIES OUTPUT_NAME spinradar
    RUNTIME_OUTPUT_DIRECTORY ${SPINRADAR_BIN_DIR})
  target_link_libraries(spinradar_cli PRIVATE ${SPINRADAR_ALL_PARTS} CLI11::CLI11 yaml-cpp)
  target_include_directories(spinradar_cli PRIVATE ${PROJECT_SOURCE_DIR}/src/tools
    ${PROJECT_SOURCE_DIR}/src/bag)
  # `bench` compares with OpenCV's PNG decoder, loaded at run time: linking opencv_imgcodecs
  # would cost every run 0.3 s of start-up (include/spinradar/io/png_io.hpp).
  get_target_property(_imgcodecs_so opencv_imgcodecs IMPORTED_SONAME_RELEASE)
  if(NOT _imgcodecs_so)
    set(_imgcodecs_so "libopencv_imgcodecs.so")
  endif()
  target_compile_definitions(spinradar_cli PRIVATE SPINRADAR_IMGCODECS_SO="${_imgcodecs_so}")
  target_link_libraries(spinradar_cli PRIVATE ${CMAKE_DL_LIBS})
  # spinradar_bag (and ROS with it) is loaded with dlopen by the commands that use a bag, not
  # linked: src/tools/bag_loader.cpp. Built with the CLI; the CLI sees its header only.
  if(TARGET spinradar_bag)
    add_dependencies(spinradar_cli spinradar_bag)
    target_compile_definitions(spinradar_cli PRIVATE SPINRADAR_HAVE_BAG=1
      SPINRADAR_BAG_SO_NAME="$<TARGET_FILE_NAME:spinradar_bag>"
      SPINRADAR_BAG_SO_PATH="$<TARGET_FILE:spinradar_bag>")
  endif()
  if(TARGET spinradar_sim)
    target_compile_definitions(spinradar_cli PRIVATE SPINRADAR_HAVE_SIM=1)
  endif()

  # `make bench` / `cmake --build . --target bench`: per-stage timings on a full-size scan pair.
  add_custom_target(bench
    COMMAND spinradar_cli bench
    DEPENDS spinradar_cli
    COMMENT "spinradar bench: per-stage timings (median of repeated runs) and peak memory"
    USES_TERMINAL)
endif()
