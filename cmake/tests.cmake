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

# Tests live with their part (test/<part>/) and link that part's library (and test helpers
# from test/support/ by include path).
if(SPINRADAR_SANITIZE)  # scripts/test_sanitize.sh: the low parts only
  foreach(part core driver io features)
    spinradar_add_tests(${part} spinradar_${part})
  endforeach()
else()
  foreach(part core driver io features estimation evaluation localization)
    spinradar_add_tests(${part} spinradar_${part})
  endforeach()
  # The simulator's and the diagnosis's tests run the whole pipeline on simulated recordings.
  spinradar_add_tests(sim ${SPINRADAR_ALL_PARTS})
  spinradar_add_tests(diagnose ${SPINRADAR_ALL_PARTS})
endif()
file(GLOB SPINRADAR_EXTRA_TEST_CMAKE CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/test/*.cmake)
foreach(f ${SPINRADAR_EXTRA_TEST_CMAKE})
  include(${f})
endforeach()
# test_keypoint_truth compiles the CLI's option parser in (pipeline_options.cpp).
if(TARGET sim_test_keypoint_truth)
  target_link_libraries(sim_test_keypoint_truth PRIVATE yaml-cpp CLI11::CLI11)
endif()
# Tests that feed one part with another's output (real scans read by io into the driver).
target_link_libraries(driver_test_navtech_realdata PRIVATE spinradar_io)
target_link_libraries(io_test_ground_truth_io PRIVATE spinradar_evaluation)
target_link_libraries(features_test_feature_extractor PRIVATE spinradar_io)
target_link_libraries(features_test_gaussian_blur PRIVATE spinradar_io)
# Tests that write or read images with OpenCV to check the project's own PNG code against it.
foreach(t io_test_scan_io io_test_bad_scans evaluation_test_plot sim_test_png_decode)
  if(TARGET ${t})
    target_link_libraries(${t} PRIVATE opencv_imgcodecs)
  endif()
endforeach()
