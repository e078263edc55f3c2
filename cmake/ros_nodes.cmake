# Nodelets and ROS glue (only with catkin): src/ros/*.cpp (conversions, parameter loading) and
# nodelets/*.cpp (thin shells) in one plugin library, registered in nodelet_plugins.xml.
file(GLOB SPINRADAR_ROS_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/ros/*.cpp)
file(GLOB SPINRADAR_NODELET_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/nodelets/*.cpp)
if(SPINRADAR_ROS_SOURCES OR SPINRADAR_NODELET_SOURCES)
  add_library(spinradar_nodelets SHARED ${SPINRADAR_ROS_SOURCES} ${SPINRADAR_NODELET_SOURCES})
  target_include_directories(spinradar_nodelets PUBLIC ${PROJECT_SOURCE_DIR}/include
    ${CATKIN_DEVEL_PREFIX}/${CATKIN_GLOBAL_INCLUDE_DESTINATION} ${catkin_INCLUDE_DIRS})
  # The ROS shell sits on the driver, estimation, localization and the simulator's live input.
  target_link_libraries(spinradar_nodelets PUBLIC spinradar_driver spinradar_estimation
    spinradar_localization spinradar_sim spinradar_io spinradar_evaluation spinradar_core
    ${catkin_LIBRARIES})
  add_dependencies(spinradar_nodelets ${PROJECT_NAME}_generate_messages_cpp ${PROJECT_NAME}_gencfg)
endif()

# Every launch file must parse and resolve (ctest: roslaunch-check).
find_package(roslaunch QUIET)
if(roslaunch_FOUND AND CATKIN_ENABLE_TESTING)
  roslaunch_add_file_check(launch USE_TEST_DEPENDENCIES)
endif()
