# The `spinradar` command-line program (one subcommand per file in src/tools/).
file(GLOB SPINRADAR_TOOL_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/tools/*.cpp)
if(SPINRADAR_TOOL_SOURCES)
  add_executable(spinradar_cli ${SPINRADAR_TOOL_SOURCES})
  set_target_properties(spinradar_cli PROPERTIES OUTPUT_NAME spinradar
    RUNTIME_OUTPUT_DIRECTORY ${SPINRADAR_BIN_DIR})
  target_link_libraries(spinradar_cli PRIVATE spinradar_core CLI11::CLI11)
  target_include_directories(spinradar_cli PRIVATE ${PROJECT_SOURCE_DIR}/src/tools)
  foreach(lib spinradar_sim spinradar_diagnose spinradar_bag)
    if(TARGET ${lib})
      target_link_libraries(spinradar_cli PRIVATE ${lib})
    endif()
  endforeach()
endif()
