# Navtech driver: a libFuzzer target for the stream decoder, run for a bounded time by ctest.
# The tree builds with g++; libFuzzer needs clang, so the fuzzer is compiled by a custom command
# straight from the (ROS-free, dependency-free) protocol sources. Skipped when clang or its
# libFuzzer runtime (Debian: clang, libclang-rt-14-dev) is missing.
find_program(SPINRADAR_CLANGXX NAMES clang++ clang++-16 clang++-15 clang++-14)
set(SPINRADAR_FUZZ_OK OFF)
if(SPINRADAR_CLANGXX)
  set(probe_dir ${CMAKE_BINARY_DIR}/fuzz_probe)
  file(MAKE_DIRECTORY ${probe_dir})
  file(WRITE ${probe_dir}/probe.cpp
    "#include <cstdint>\n#include <cstddef>\nextern \"C\" int LLVMFuzzerTestOneInput(const uint8_t*, size_t) { return 0; }\n")
  execute_process(COMMAND ${SPINRADAR_CLANGXX} -fsanitize=fuzzer,address probe.cpp -o probe
    WORKING_DIRECTORY ${probe_dir} RESULT_VARIABLE probe_rc OUTPUT_QUIET ERROR_QUIET)
  if(probe_rc EQUAL 0)
    set(SPINRADAR_FUZZ_OK ON)
  endif()
endif()

if(SPINRADAR_FUZZ_OK)
  set(fuzz_bin ${CMAKE_BINARY_DIR}/fuzz/fuzz_navtech_stream)
  file(MAKE_DIRECTORY ${CMAKE_BINARY_DIR}/fuzz)
  set(fuzz_srcs
    ${PROJECT_SOURCE_DIR}/test/fuzz/fuzz_navtech_stream.cpp
    ${PROJECT_SOURCE_DIR}/src/driver/navtech_protocol.cpp
    ${PROJECT_SOURCE_DIR}/src/driver/navtech_time.cpp
    ${PROJECT_SOURCE_DIR}/src/driver/scan_assembler.cpp)
  set(fuzz_hdrs
    ${PROJECT_SOURCE_DIR}/include/spinradar/driver/navtech_protocol.hpp
    ${PROJECT_SOURCE_DIR}/include/spinradar/driver/navtech_time.hpp
    ${PROJECT_SOURCE_DIR}/include/spinradar/driver/scan_assembler.hpp
    ${PROJECT_SOURCE_DIR}/include/spinradar/core/polar_scan.hpp)
  add_custom_command(OUTPUT ${fuzz_bin}
    COMMAND ${SPINRADAR_CLANGXX} -std=c++17 -g -O1 -fsanitize=fuzzer,address,undefined
            -fno-sanitize-recover=undefined -I${PROJECT_SOURCE_DIR}/include ${fuzz_srcs} -o ${fuzz_bin}
    DEPENDS ${fuzz_srcs} ${fuzz_hdrs}
    COMMENT "Building the Navtech stream fuzzer with ${SPINRADAR_CLANGXX}" VERBATIM)
  add_custom_target(fuzz_navtech_stream ALL DEPENDS ${fuzz_bin})
  # New inputs go to a scratch corpus in the build tree; the committed seeds are read-only.
  set(fuzz_corpus ${CMAKE_BINARY_DIR}/fuzz_navtech_corpus)
  file(MAKE_DIRECTORY ${fuzz_corpus})
  add_test(NAME fuzz_navtech_stream
    COMMAND ${fuzz_bin} -max_total_time=20 -timeout=10 -rss_limit_mb=2048 -max_len=16384
            -print_final_stats=1 -artifact_prefix=${CMAKE_BINARY_DIR}/fuzz_navtech_ ${fuzz_corpus} ${PROJECT_SOURCE_DIR}/test/fuzz/seeds)
  set_tests_properties(fuzz_navtech_stream PROPERTIES TIMEOUT 120 LABELS fuzz)
else()
  message(STATUS "spinradar: clang with libFuzzer not found: fuzz_navtech_stream skipped")
endif()

# ROS conversions of the driver's scans (plain gtest, no roscore needed).
if(TARGET spinradar_nodelets AND EXISTS ${PROJECT_SOURCE_DIR}/test/ros/test_navtech_conversions.cpp)
  add_executable(ros_test_navtech_conversions ${PROJECT_SOURCE_DIR}/test/ros/test_navtech_conversions.cpp)
  target_link_libraries(ros_test_navtech_conversions PRIVATE spinradar_nodelets ${SPINRADAR_GTEST}
    Threads::Threads)
  add_dependencies(ros_test_navtech_conversions ${PROJECT_NAME}_generate_messages_cpp)
  gtest_discover_tests(ros_test_navtech_conversions DISCOVERY_MODE PRE_TEST DISCOVERY_TIMEOUT 60
    WORKING_DIRECTORY ${CMAKE_BINARY_DIR} PROPERTIES TIMEOUT 120)
endif()

# rostest: the DriverNodelet against `spinradar serve` on loopback (test/ros/driver.test).
if(TARGET spinradar_nodelets AND CATKIN_ENABLE_TESTING)
  find_package(rostest QUIET)
  if(rostest_FOUND)
    # A plain executable (add_rostest_gtest would leave it out of `all`, so a fresh
    # build-then-ctest would run a rostest whose node was never built).
    add_executable(ros_test_driver_nodelet test/ros/test_driver_nodelet.cpp)
    target_include_directories(ros_test_driver_nodelet PRIVATE ${PROJECT_SOURCE_DIR}/include
      ${CATKIN_DEVEL_PREFIX}/${CATKIN_GLOBAL_INCLUDE_DESTINATION} ${catkin_INCLUDE_DIRS})
    target_link_libraries(ros_test_driver_nodelet PRIVATE ${catkin_LIBRARIES} ${SPINRADAR_GTEST}
      Threads::Threads)
    add_dependencies(ros_test_driver_nodelet ${PROJECT_NAME}_generate_messages_cpp)
    add_rostest(test/ros/driver.test DEPENDENCIES ros_test_driver_nodelet spinradar_nodelets
      spinradar_cli)
  endif()
endif()
