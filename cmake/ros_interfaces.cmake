# Messages, dynamic_reconfigure options and catkin_package(): must come before any target.
file(GLOB SPINRADAR_MSGS RELATIVE ${PROJECT_SOURCE_DIR}/msg CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/msg/*.msg)
if(SPINRADAR_MSGS)
  add_message_files(FILES ${SPINRADAR_MSGS})
  generate_messages(DEPENDENCIES std_msgs sensor_msgs geometry_msgs)
endif()

# cfg/*.cfg generate their entries from the X-macro lists in params.hpp (via
# cfg/spinradar_params.py), so they must re-run when either changes.
file(GLOB SPINRADAR_CFGS RELATIVE ${PROJECT_SOURCE_DIR} CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/cfg/*.cfg)
if(SPINRADAR_CFGS)
  generate_dynamic_reconfigure_options(${SPINRADAR_CFGS})
  foreach(cfg ${SPINRADAR_CFGS})
    get_filename_component(cfg_name ${cfg} NAME_WE)
    add_custom_command(OUTPUT ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_INCLUDE_DESTINATION}/${cfg_name}Config.h
      APPEND DEPENDS ${PROJECT_SOURCE_DIR}/include/spinradar/core/params.hpp
                     ${PROJECT_SOURCE_DIR}/cfg/spinradar_params.py)
  endforeach()
endif()

catkin_package(
  INCLUDE_DIRS include
  LIBRARIES ${SPINRADAR_ALL_PARTS}
  CATKIN_DEPENDS roscpp nodelet pluginlib std_msgs sensor_msgs geometry_msgs nav_msgs tf2_ros
    dynamic_reconfigure message_runtime
)
