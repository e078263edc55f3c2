# libFuzzer targets, run for a bounded time by ctest.
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

if(SPINRADAR_FUZZ_OK AND NOT SPINRADAR_SANITIZE)
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
elseif(NOT SPINRADAR_FUZZ_OK)
  message(STATUS "spinradar: clang with libFuzzer not found: fuzz_navtech_stream skipped")
endif()


# The file readers (scan PNG rows, MulRan CSV, RADIATE, pose / ground-truth CSVs, capture file):
# one fuzzer linked to the sanitizer build's instrumented io and driver libraries (the build of
# scripts/test_sanitize.sh, compiled by clang with -fsanitize=fuzzer-no-link), one bounded run
# per reader with its own seeds.
if(SPINRADAR_SANITIZE)
  add_executable(fuzz_readers ${PROJECT_SOURCE_DIR}/test/fuzz/fuzz_readers.cpp)
  target_link_libraries(fuzz_readers PRIVATE spinradar_io spinradar_driver opencv_imgcodecs)
  target_link_options(fuzz_readers PRIVATE -fsanitize=fuzzer)
  foreach(reader png mulran radiate csv capture)
    set(corpus ${CMAKE_BINARY_DIR}/fuzz_${reader}_corpus)
    file(MAKE_DIRECTORY ${corpus})
    add_test(NAME fuzz_reader_${reader}
      COMMAND fuzz_readers -max_total_time=12 -timeout=10 -rss_limit_mb=2048 -max_len=65536
              -print_final_stats=1 -artifact_prefix=${CMAKE_BINARY_DIR}/fuzz_${reader}_
              ${corpus} ${PROJECT_SOURCE_DIR}/test/fuzz/seeds_${reader})
    set_tests_properties(fuzz_reader_${reader} PROPERTIES TIMEOUT 120 LABELS fuzz
      ENVIRONMENT "SPINRADAR_FUZZ_READER=${reader};ASAN_OPTIONS=detect_leaks=0")
  endforeach()
endif()
