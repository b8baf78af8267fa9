"""Suite-wide settings.

Hypothesis: the ``ci`` profile (loaded when ``CI`` is set, as ``.ci/run`` does, or with
``HYPOTHESIS_PROFILE=ci``) derandomizes every property test, so a CI run is repeatable; the
``dev`` profile explores new examples on each run.  Both print the blob that reproduces a
failure (``@reproduce_failure``), and the seed is printed by hypothesis's own report.
"""

from __future__ import annotations

import os

try:
    from hypothesis import settings
except ImportError:  # the property tests skip themselves without hypothesis
    settings = None

if settings is not None:
    settings.register_profile("ci", derandomize=True, print_blob=True, deadline=None)
    settings.register_profile("dev", print_blob=True, deadline=None)
    settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE") or ("ci" if os.environ.get("CI") else "dev"))


# --------------------------------------------------------------------------------------------
# The inner loop.  `make check` runs the suite without the tests below (each takes more than a
# few seconds of CPU: benchmarks on small problems, certified tables of cornered noses, sampler
# runs, FEM studies, subprocess sweeps); `make test` (and so CI) runs everything that is not
# `slow`.  A node id here is a file, or a test function of a file (all its parameters).
LONG = {
    "tests/test_regimes_transfer.py::test_calibrate_regimes_transfer_through_the_cli",
    "tests/test_regimes_transfer.py::test_transfer_between_materials_against_the_data_file",
    "tests/test_regimes_transfer.py::test_issue22_targets",
    "tests/test_benchmarks_small.py",
    "tests/test_bad_input.py::test_bad_case_exit_status_in_a_subprocess",
    "tests/test_browser_report.py",
    "tests/test_cache.py::test_commands_write_no_cache_into_the_working_directory",
    "tests/test_calibration.py::test_calibrate_cli_files_keys_and_penetrate_posterior_other_noses",
    "tests/test_calibration.py::test_sampler_against_quadrature_of_the_same_posterior",
    "tests/test_calibration_crossval.py",
    "tests/test_calibration_eroding.py",
    "tests/test_cli_noses.py",
    "tests/test_corpus.py",
    "tests/test_fem_cli.py::test_cavity_json",
    "tests/test_fem_corners.py::test_fem_flat_nose_converges_at_the_graded_rate",
    "tests/test_fem_error_bar.py",
    "tests/test_plate_report.py",
    "tests/test_plate_coefficients.py::test_fem_agreement",
    "tests/test_plate_coefficients.py::test_fem_agreement_drag",
    "tests/test_plate_coefficients.py::test_table_interface_and_zero_beyond_exit",
    "tests/test_docs.py",
    "tests/test_perforation.py::test_part4_table3_shots_beside_the_ballistic_limit_command",
    "tests/test_perforation.py::test_run_gains_a_perforation_section",
    "tests/test_perforation.py::test_flat_nose_plug_against_recht_ipson_closed_form",
    "tests/test_user_outputs.py::test_run_csv_one_row_per_velocity_and_model",
    "tests/test_user_outputs.py::test_progress_on_a_terminal_only_and_not_with_quiet",
    "tests/test_user_outputs.py::test_penetrate_csv_and_per_shot_table",
    "tests/test_tables_speed_and_reach.py::test_near_hemisphere_costs_what_the_hemisphere_costs",
    "tests/test_calibration.py::test_penetrate_posterior_refuses_other_target_and_bad_files",
    "tests/test_plate_coefficients.py::test_energy_identity_through_the_back_face",
    "tests/test_bem_corners.py::test_more_grading_does_not_diverge",
    "tests/test_optimize_shapes.py::test_sweep_over_the_exponent_builds_a_table_per_design",
    "tests/test_guards_and_outputs.py::test_run_and_penetrate_write_no_cache_into_the_cwd",
    "tests/test_hardening_properties.py",
    "tests/test_optimize.py",
    "tests/test_penetration_cli.py::test_report_is_not_overwritten_without_force",
    "tests/test_readme_commands.py",
    "tests/test_run_report.py",
    "tests/test_separation_onset.py::test_onset_is_the_first_knot_where_eq9_turns_negative",
    "tests/test_startup_imports.py",
    "tests/test_sweep_engine.py::test_killed_sweep_process_resumes",
    "tests/test_sweep_penetration.py::test_velocity_by_material_on_an_existing_dask_cluster",
    "tests/test_sweep_vectorised.py",
    "tests/test_table_corners.py::test_certified_table_within_tolerance_off_knots_and_beside_breakpoints",
    "tests/test_tables.py::test_depth_error_estimate_bounds_a_tighter_table",
    "tests/test_tables.py::test_short_blunt_nose_reaches_its_deep_limit_with_the_defaults",
    "tests/test_tables.py::test_table_against_direct_solves_at_random_depths",
    "tests/test_tables_speed_and_reach.py::test_block_sums_of_the_rules_match_adaptive_quadrature",
    "tests/test_force_reports.py::test_force_refuses_a_users_file_and_replaces_its_own",
    # moved out of the inner loop on 2026-11-29, when make check had reached 72 s on a slower day of
    # this shared machine (2-6 s each: report regenerations, subprocess schedulers, compiles, optimisers)
    "tests/test_report_freshness.py::test_part3_nanostrength_report_regenerates_identically",
    "tests/test_report_freshness.py::test_part2_cavity_report_regenerates_identically",
    "tests/test_nanostrength_cli.py::test_report_written_and_not_overwritten",
    "tests/test_sweep_external.py::test_sweep_on_an_external_scheduler",
    "tests/test_optimize_plates.py::test_optimize_a_plate_objective",
    "tests/test_ring_kernel_c.py::test_nothing_planted_in_the_cache_is_loaded",
    "tests/test_tables_speed_and_reach.py::test_truncated_ogive_shallow_direct_solve_through_the_cli",
    "tests/test_optimize_spline.py::test_spline_case_fem_against_bem",
    "tests/test_optimize_spline.py::test_spline_optimize_vary_key_checks",
}


def pytest_collection_modifyitems(config, items):
    import pytest

    for item in items:
        test = item.nodeid.split("[", 1)[0]
        if test in LONG or test.split("::", 1)[0] in LONG:
            item.add_marker(pytest.mark.long)
