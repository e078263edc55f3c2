# CLI-level tests of the offline tools (`spinradar odometry/eval/...`, README table).
if(NOT TARGET spinradar_cli)
  return()
endif()
set(_cli $<TARGET_FILE:spinradar_cli>)
set(_tt ${PROJECT_SOURCE_DIR}/test/tools)
set(_out ${CMAKE_BINARY_DIR}/test_tools_out)
file(MAKE_DIRECTORY ${_out})

# README parameter table must match `spinradar params` (scripts/update_readme_params.sh fixes it).
add_test(NAME cli_readme_params_up_to_date
  COMMAND bash ${PROJECT_SOURCE_DIR}/scripts/update_readme_params.sh --check --bin ${_cli})

# Error paths: clean failure (no crash) with a message naming the file and line.
add_test(NAME cli_eval_bad_csv_line
  COMMAND bash ${_tt}/expect_error.sh "error: .*bad_poses.csv:3: column 'y': 'zero' is not a number"
          ${_cli} eval --est ${_tt}/data/bad_poses.csv --gt ${_tt}/data/short_gt.csv)
add_test(NAME cli_eval_bad_gt_line
  COMMAND bash ${_tt}/expect_error.sh "error: .*bad_poses.csv:3:"
          ${_cli} eval --est ${_tt}/data/short_est.csv --gt ${_tt}/data/bad_poses.csv)
add_test(NAME cli_eval_short_sequence
  COMMAND ${_cli} eval --est ${_tt}/data/short_est.csv --gt ${_tt}/data/short_gt.csv
          --plot ${_out}/short_eval.png)
set_tests_properties(cli_eval_short_sequence PROPERTIES
  PASS_REGULAR_EXPRESSION "frame-to-frame errors \\(2\\)")

# A calibrated sensor file's reference_scene: the default scene of simulate / serve / realism /
# diagnose, an explicit --scene wins, bad values named, files without it as before.
add_test(NAME cli_reference_scene
  COMMAND bash ${_tt}/reference_scene.sh ${_cli} ${_out}/reference_scene ${PROJECT_SOURCE_DIR})
set_tests_properties(cli_reference_scene PROPERTIES TIMEOUT 600)

# Every bad input of every class gives a named error and loses nothing (issue 17): one table of
# rows over all subcommands, inputs built from the simulator (test/tools/bad_inputs.sh).
add_test(NAME cli_bad_inputs COMMAND bash ${_tt}/bad_inputs.sh ${_cli} ${_out}/bad_inputs)
set_tests_properties(cli_bad_inputs PROPERTIES TIMEOUT 600)

# Odometry (registered once the subcommand is in the tree).
if(EXISTS ${PROJECT_SOURCE_DIR}/src/tools/cmd_odometry.cpp)
  add_test(NAME cli_odometry_missing_folder
    COMMAND bash ${_tt}/expect_error.sh "error: /nonexistent/spinradar_scans: no such folder"
            ${_cli} odometry --input /nonexistent/spinradar_scans --out ${_out}/never.csv)
  add_test(NAME cli_odometry_empty_folder
    COMMAND bash ${_tt}/expect_error.sh "error: .*(no scans|no .*scan files|empty)"
            ${_cli} odometry --input ${_tt} --out ${_out}/never.csv --format oxford)
  add_test(NAME cli_odometry_bad_parameter
    COMMAND bash ${_tt}/expect_error.sh "zq"
            ${_cli} odometry --input ${_tt} --out ${_out}/never.csv --zq -3)
  add_test(NAME cli_odometry_bad_config_key
    COMMAND bash ${_tt}/expect_error.sh "error: .*bad_config.yaml:2: unknown parameter 'not_a_param'"
            ${_cli} odometry --input ${_tt} --out ${_out}/never.csv --config ${_tt}/data/bad_config.yaml)
  add_test(NAME cli_odometry_bad_option_value
    COMMAND bash ${_tt}/expect_error.sh "error: option --ransac_iterations: parameter 'ransac_iterations': 'many' is not an integer"
            ${_cli} odometry --input ${_tt} --out ${_out}/never.csv --ransac-iterations many)
  # Real data: the Oxford sample's consecutive-scan motion against the dataset's ground truth.
  add_test(NAME cli_odometry_oxford_sample
    COMMAND bash ${_tt}/oxford_odometry.sh ${_cli} ${SPINRADAR_SHARED_DIR} ${_out}/oxford)
  set_tests_properties(cli_odometry_oxford_sample PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 300)
  # Background decoding (--threads 2) writes byte-identical outputs, in scan order.
  add_test(NAME cli_odometry_threads_identical
    COMMAND bash ${_tt}/odometry_threads_identical.sh ${_cli} ${_out}/threads)
  set_tests_properties(cli_odometry_threads_identical PROPERTIES TIMEOUT 300)
  # A recording is read at the range bin size its sensor.json states (--range-resolution wins).
  add_test(NAME cli_odometry_recorded_sensor
    COMMAND bash ${_tt}/odometry_recorded_sensor.sh ${_cli} ${_out}/recorded_sensor)
  # The grouped YAML form is accepted and overrides the defaults (estimator rigid -> log line).
  add_test(NAME cli_odometry_grouped_config
    COMMAND bash ${_tt}/with_realdata.sh ${SPINRADAR_SHARED_DIR} ${_cli} odometry --input ${SPINRADAR_SHARED_DIR}/realdata/oxford_2019-01-10-14-36-48
            --out ${_out}/grouped.csv --quiet --config ${_tt}/data/grouped_config.yaml)
  set_tests_properties(cli_odometry_grouped_config PROPERTIES
    PASS_REGULAR_EXPRESSION "estimator rigid" SKIP_RETURN_CODE 77)
  # Alternating-chirp Doppler (Boreas-RT): the sample frame was recorded standing still.
  if(EXISTS ${PROJECT_SOURCE_DIR}/src/tools/cmd_chirp_doppler.cpp)
    add_test(NAME cli_chirp_doppler_boreas_rt
      COMMAND bash ${_tt}/with_realdata.sh ${SPINRADAR_SHARED_DIR} ${_cli} chirp-doppler
              --input ${SPINRADAR_SHARED_DIR}/realdata/boreas_rt/test_frame.png --beta 0.0502)
    set_tests_properties(cli_chirp_doppler_boreas_rt PROPERTIES
      PASS_REGULAR_EXPRESSION "test_frame.png: no alternating-chirp Doppler" SKIP_RETURN_CODE 77)
    add_test(NAME cli_chirp_doppler_missing_file
      COMMAND bash ${_tt}/expect_error.sh "error: /nonexistent/frame.png: no such file or folder"
              ${_cli} chirp-doppler --input /nonexistent/frame.png --beta 0.05)
  endif()
  if(TARGET spinradar_bag)
    add_test(NAME cli_bag_roundtrip
      COMMAND bash ${_tt}/bag_roundtrip.sh ${_cli} ${SPINRADAR_SHARED_DIR} ${_out}/bag)
    set_tests_properties(cli_bag_roundtrip PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 300)
    if(TARGET spinradar_diagnose)
      add_test(NAME cli_diagnose_from_bag
        COMMAND bash ${_tt}/diagnose_bag.sh ${_cli} ${_out}/diagnose_bag)
      set_tests_properties(cli_diagnose_from_bag PROPERTIES TIMEOUT 300)
    endif()
  endif()
endif()

# diagnose guesses a recording's scan format as odometry does: the RADIATE sample (no row
# stamps or encoder columns) is read without --format (it once defaulted to oxford and failed).
if(TARGET spinradar_diagnose)
  add_test(NAME cli_diagnose_radiate_sample_format
    COMMAND bash ${_tt}/with_realdata.sh ${SPINRADAR_SHARED_DIR} ${_cli} diagnose --timing-only
            --recording ${SPINRADAR_SHARED_DIR}/realdata/radiate_fog_6_0 --out ${_out}/diagnose_radiate)
  set_tests_properties(cli_diagnose_radiate_sample_format PROPERTIES
    PASS_REGULAR_EXPRESSION "report in [^\n]*diagnose_radiate" SKIP_RETURN_CODE 77)
endif()

# The evaluation matrix's list of the default's losses (per seed; bootstrap over real pairs)
# against figures with a known answer (test/tools/matrix_table_losses.py).
add_test(NAME cli_matrix_table_losses
  COMMAND /usr/bin/python3 ${_tt}/matrix_table_losses.py
          ${PROJECT_SOURCE_DIR}/scripts/evaluation_matrix_table.py)
