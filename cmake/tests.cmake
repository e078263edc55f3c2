# gtest suites: every test/<module>/test_*.cpp is one executable linked to its module.
if(TARGET gtest_main)
  set(SPINRADAR_GTEST gtest_main)         # catkin builds googletest from /usr/src
else()
  find_package(GTest REQUIRED)
  set(SPINRADAR_GTEST GTest::gtest_main)
endif()
include(GoogleTest)

set(SPINRADAR_SHARED_DIR ${PROJECT_SOURCE_DIR}/../shared CACHE PATH "Folder holding shared/realdata")

function(spinradar_add_tests module)
  file(GLOB tests CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/test/${module}/test_*.cpp)
  foreach(src ${tests})
    get_filename_component(name ${src} NAME_WE)
    set(target ${module}_${name})
    add_executable(${target} ${src})
    target_link_libraries(${target} PRIVATE ${ARGN} ${SPINRADAR_GTEST} Threads::Threads)
    target_include_directories(${target} PRIVATE ${PROJECT_SOURCE_DIR}/test)
    target_compile_definitions(${target} PRIVATE
      SPINRADAR_SHARED_DIR="${SPINRADAR_SHARED_DIR}"
      SPINRADAR_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
      SPINRADAR_BIN_DIR="${SPINRADAR_BIN_DIR}")
    gtest_discover_tests(${target} DISCOVERY_MODE PRE_TEST DISCOVERY_TIMEOUT 60
      WORKING_DIRECTORY ${CMAKE_BINARY_DIR} PROPERTIES TIMEOUT 600)
  endforeach()
endfunction()

spinradar_add_tests(core spinradar_core)
if(TARGET spinradar_sim)
  spinradar_add_tests(sim spinradar_sim spinradar_core)
endif()
if(TARGET spinradar_diagnose)
  spinradar_add_tests(diagnose spinradar_diagnose spinradar_sim spinradar_core)
endif()
file(GLOB SPINRADAR_EXTRA_TEST_CMAKE CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/test/*.cmake)
foreach(f ${SPINRADAR_EXTRA_TEST_CMAKE})
  include(${f})
endforeach()
