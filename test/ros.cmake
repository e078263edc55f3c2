# ROS tests (only with catkin): glue unit tests without a master, the config example check,
# and rostests of the live pipeline on the simulator (test/ros/*.test).
if(SPINRADAR_ROS)
  add_executable(ros_test_glue test/ros/test_ros_glue.cpp src/ros/conversions.cpp)
  target_include_directories(ros_test_glue PRIVATE ${PROJECT_SOURCE_DIR}/include
    ${CATKIN_DEVEL_PREFIX}/${CATKIN_GLOBAL_INCLUDE_DESTINATION} ${catkin_INCLUDE_DIRS})
  target_link_libraries(ros_test_glue PRIVATE ${SPINRADAR_ALL_PARTS} ${catkin_LIBRARIES} ${SPINRADAR_GTEST}
    Threads::Threads)
  add_dependencies(ros_test_glue ${PROJECT_NAME}_generate_messages_cpp ${PROJECT_NAME}_gencfg)
  gtest_discover_tests(ros_test_glue DISCOVERY_MODE PRE_TEST TEST_PREFIX "ros." PROPERTIES TIMEOUT 60)

  # The localizer nodelet's map -> odom path on the simulator (no master).
  if(TARGET spinradar_sim)
    add_executable(ros_test_map_localization test/ros/test_map_localization.cpp)
    target_include_directories(ros_test_map_localization PRIVATE ${PROJECT_SOURCE_DIR}/include)
    target_link_libraries(ros_test_map_localization PRIVATE ${SPINRADAR_ALL_PARTS}
      ${SPINRADAR_GTEST} Threads::Threads)
    gtest_discover_tests(ros_test_map_localization DISCOVERY_MODE PRE_TEST TEST_PREFIX "ros."
      PROPERTIES TIMEOUT 60)
  endif()

  add_test(NAME ros.config_yaml_matches_params
    COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/test/ros/check_config_yaml.py)
endif()

# rostests: live pipeline on the simulator, then playback of the bag it recorded. The test
# nodes are built with everything else (add_rostest_gtest would leave them out of `all`).
find_package(rostest QUIET)
if(SPINRADAR_ROS AND rostest_FOUND AND CATKIN_ENABLE_TESTING AND TARGET spinradar_sim)
  set(SPINRADAR_ROSTEST_DIR ${CMAKE_BINARY_DIR}/rostest_data)
  file(MAKE_DIRECTORY ${SPINRADAR_ROSTEST_DIR})
  foreach(t live_sim bag_playback)
    add_executable(ros_test_${t} test/ros/test_${t}.cpp)
    target_include_directories(ros_test_${t} PRIVATE ${PROJECT_SOURCE_DIR}/include
      ${CATKIN_DEVEL_PREFIX}/${CATKIN_GLOBAL_INCLUDE_DESTINATION} ${catkin_INCLUDE_DIRS})
    target_link_libraries(ros_test_${t} PRIVATE ${SPINRADAR_ALL_PARTS} ${catkin_LIBRARIES}
      ${SPINRADAR_GTEST} Threads::Threads)
    add_dependencies(ros_test_${t} ${PROJECT_NAME}_generate_messages_cpp)
  endforeach()
  # Playback must reproduce the live odometry exactly: run both with a frame-to-frame estimator
  # (the keyframe estimator's odometry depends on the scan the run starts from, which a live run
  # and a bag need not share). The default (keyframe) pipeline gets its own live run.
  add_rostest(test/ros/live_sim.test DEPENDENCIES ros_test_live_sim spinradar_nodelets spinradar_cli
    ARGS estimator:=mc_doppler bag:=${SPINRADAR_ROSTEST_DIR}/live.bag
         odom_csv:=${SPINRADAR_ROSTEST_DIR}/live_odom.csv)
  add_rostest(test/ros/bag_playback.test DEPENDENCIES ros_test_bag_playback spinradar_nodelets
    ARGS estimator:=mc_doppler bag:=${SPINRADAR_ROSTEST_DIR}/live.bag
         live_csv:=${SPINRADAR_ROSTEST_DIR}/live_odom.csv)
  add_rostest(test/ros/live_sim.test DEPENDENCIES ros_test_live_sim spinradar_nodelets spinradar_cli
    ARGS port:=26517)
  # ctest: the playback needs the live run's bag and CSV.
  get_property(spinradar_all_tests DIRECTORY PROPERTY TESTS)
  foreach(t ${spinradar_all_tests})
    if(t MATCHES "rostest.*live_sim")
      set_tests_properties(${t} PROPERTIES FIXTURES_SETUP spinradar_live_run TIMEOUT 200)
    elseif(t MATCHES "rostest.*bag_playback")
      set_tests_properties(${t} PROPERTIES FIXTURES_REQUIRED spinradar_live_run TIMEOUT 200)
    endif()
  endforeach()
endif()
