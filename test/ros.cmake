# ROS tests (only with catkin): glue unit tests without a master, the config example check,
# and rostests of the live pipeline on the simulator (test/ros/*.test).
if(SPINRADAR_ROS)
  add_executable(ros_test_glue test/ros/test_ros_glue.cpp src/ros/conversions.cpp)
  target_include_directories(ros_test_glue PRIVATE ${PROJECT_SOURCE_DIR}/include
    ${CATKIN_DEVEL_PREFIX}/${CATKIN_GLOBAL_INCLUDE_DESTINATION} ${catkin_INCLUDE_DIRS})
  target_link_libraries(ros_test_glue PRIVATE spinradar_core ${catkin_LIBRARIES} ${SPINRADAR_GTEST}
    Threads::Threads)
  add_dependencies(ros_test_glue ${PROJECT_NAME}_generate_messages_cpp ${PROJECT_NAME}_gencfg)
  gtest_discover_tests(ros_test_glue DISCOVERY_MODE PRE_TEST TEST_PREFIX "ros." PROPERTIES TIMEOUT 60)

  add_test(NAME ros.config_yaml_matches_params
    COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/test/ros/check_config_yaml.py)
endif()
