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

# Navtech's own Python SDK example (../shared/navtech-iasdk) reads a full rotation from
# `spinradar serve`; skipped with a message when ../shared is absent.
if(TARGET spinradar_cli)
  add_test(NAME driver_navtech_sdk_example
    COMMAND bash ${PROJECT_SOURCE_DIR}/test/driver/navtech_sdk_example.sh
            $<TARGET_FILE:spinradar_cli> ${SPINRADAR_SHARED_DIR} ${CMAKE_BINARY_DIR}/test_navtech_sdk)
  set_tests_properties(driver_navtech_sdk_example PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 180)
endif()
