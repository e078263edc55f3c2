# Messages, dynamic_reconfigure options and catkin_package(): must come before any target.
file(GLOB SPINRADAR_MSGS RELATIVE ${PROJECT_SOURCE_DIR}/msg CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/msg/*.msg)
if(SPINRADAR_MSGS)
  add_message_files(FILES ${SPINRADAR_MSGS})
  generate_messages(DEPENDENCIES std_msgs sensor_msgs geometry_msgs)
endif()
file(GLOB SPINRADAR_CFGS RELATIVE ${PROJECT_SOURCE_DIR} CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/cfg/*.cfg)
if(SPINRADAR_CFGS)
  generate_dynamic_reconfigure_options(${SPINRADAR_CFGS})
endif()
catkin_package(
  INCLUDE_DIRS include
  LIBRARIES spinradar_core
  CATKIN_DEPENDS roscpp nodelet std_msgs sensor_msgs geometry_msgs nav_msgs message_runtime
)
