# One shared library per part of the product, each linking only the parts it uses. The
# allowed directions are written down in docs/DEVELOPING.md ("Parts and what each may use")
# and checked by test/core/test_layering.cpp; keep the `USES` lists below in step with it.
# Sources are globbed: adding src/<part>/foo.cpp adds it to spinradar_<part>.
function(spinradar_part part)
  cmake_parse_arguments(P "" "" "USES;LIBS" ${ARGN})
  file(GLOB srcs CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/${part}/*.cpp)
  add_library(spinradar_${part} SHARED ${srcs})
  target_include_directories(spinradar_${part} PUBLIC ${PROJECT_SOURCE_DIR}/include)
  foreach(u ${P_USES})
    target_link_libraries(spinradar_${part} PUBLIC spinradar_${u})
  endforeach()
  target_link_libraries(spinradar_${part} PUBLIC ${P_LIBS})
  if(NOT SPINRADAR_SANITIZE)
    target_compile_options(spinradar_${part} PRIVATE -O3 -march=x86-64-v2)
  endif()
endfunction()

# PNG files through libdeflate / libspng (src/io/png_*.cpp), not opencv_imgcodecs: linking the
# latter (GDAL and 120 more libraries) costs every process 0.3 s and 40 MB at start-up.
find_package(PkgConfig REQUIRED)
pkg_check_modules(SPINRADAR_PNG REQUIRED IMPORTED_TARGET libdeflate spng)

spinradar_part(core                       LIBS Eigen3::Eigen opencv_core)
spinradar_part(driver       USES core     LIBS Threads::Threads)
spinradar_part(io           USES core     LIBS PkgConfig::SPINRADAR_PNG)
spinradar_part(features     USES core     LIBS opencv_features2d opencv_imgproc)
spinradar_part(estimation   USES features core)
spinradar_part(evaluation   USES io core  LIBS opencv_imgproc)
if(SPINRADAR_SANITIZE)
  return()  # the sanitizer build checks the low parts only (scripts/test_sanitize.sh)
endif()
spinradar_part(localization USES estimation features evaluation io core)
spinradar_part(sim          USES driver io features evaluation core
                            LIBS nlohmann_json::nlohmann_json TBB::tbb Threads::Threads)
# Calibrated sensor files (config/sensors/<name>.json) are found by name: `--sensor oxford`.
target_compile_definitions(spinradar_sim PRIVATE
                           SPINRADAR_SENSORS_DIR="${PROJECT_SOURCE_DIR}/config/sensors")
spinradar_part(diagnose     USES sim evaluation io features core LIBS nlohmann_json::nlohmann_json)
target_include_directories(spinradar_core PUBLIC ${OpenCV_INCLUDE_DIRS})

