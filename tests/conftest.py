"""Shared fixtures: the thesis's tuned parameter sets and input trains."""

from __future__ import annotations

import fnmatch
import shutil
import subprocess
import warnings

import numpy as np
import pytest

from spll_hw import SpllParams

#: Table 6, "VibTac vary offset LIF" (the benchmark's reference workload).
VIBTAC_VARY_OFFSET_LIF = SpllParams(
    tau_cco_syn=7.50e-3, tau_cco=0.314, tau_tde_trg=1.25e-3, tau_tde_fac=9.59e-3,
    tau_tde=4.52e-3, g_cco=9.84, g_tde_trg=0.271, g_tde_fac=6.15e2,
)  # fmt: skip

#: Table 6, "BioTac time-scaled TouchSim".
BIOTAC_TIME_SCALED_TOUCHSIM = SpllParams(
    tau_cco_syn=0.178, tau_cco=0.463, tau_tde_trg=2.36e-3, tau_tde_fac=7.47e-3,
    tau_tde=2.89e-3, g_cco=7.28, g_tde_trg=0.227, g_tde_fac=3.78e4,
)  # fmt: skip


def poisson_train(rate: float, duration: float, seed: int) -> np.ndarray:
    """Sorted Poisson spike times [s] at ``rate`` [Hz] on ``[0, duration)``."""
    rng = np.random.default_rng(seed)
    return np.sort(rng.uniform(0.0, duration, rng.poisson(rate * duration)))


def sparse_dense_bursty(duration: float) -> list[np.ndarray]:
    """Three input trains [s] on ``[0, duration)``: sparse Poisson (150 Hz), dense Poisson
    (900 Hz) and bursts (2 kHz Poisson gated on and off every 5 ms, as an encoded slip)."""
    bursts = poisson_train(2000.0, duration, seed=3)
    bursts = bursts[(bursts // 5e-3) % 2 == 0]
    return [poisson_train(150.0, duration, seed=1), poisson_train(900.0, duration, seed=2), bursts]


@pytest.fixture
def base_params() -> SpllParams:
    return VIBTAC_VARY_OFFSET_LIF


@pytest.fixture
def full_disk(tmp_path):
    """A real 64 kB filesystem, empty, to write onto until it is full (a tmpfs: mounting it
    needs root, so a test that uses it is skipped, with the reason, where that is not
    permitted)."""
    disk = tmp_path / "disk"
    disk.mkdir()
    if shutil.which("mount") is None:
        pytest.skip("no mount command")
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(disk)],
                          capture_output=True, text=True)  # fmt: skip
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here (needs root): {done.stderr.strip()}")
    try:
        yield disk
    finally:
        subprocess.run(["umount", str(disk)], check=True)


#: The slow tier: tests that take about 10 s or more on the 2-core development machine (found
#: with ``pytest --durations``; CI lists the slowest of every run). Each is marked ``slow`` (a
#: node id, or the start of one for every case of a parametrised test; ``*`` stands for any
#: text); ``python3 -m pytest -m "not slow"`` (``scripts/test.sh --quick``) is the quick tier,
#: which still runs a test of every module (docs/testing.md). A test that grows slow is added
#: here, not dropped.
SLOW = (
    # the compiled Brian2 targets compile every run (53-195 s a check); Lava runs its processes
    "tests/test_backend_conformance.py::test_conformance[*-brian2-cpp_standalone]",
    "tests/test_backend_conformance.py::test_conformance[*-brian2-cython]",
    "tests/test_backend_conformance.py::test_conformance[*-brian2-numpy]",
    "tests/test_backend_conformance.py::test_conformance[*-lava-fixed]",
    "tests/test_backend_conformance.py::test_conformance[*-lava-float]",
    "tests/test_bad_input_campaign.py::test_an_export_onto_a_full_disk_names_the_file_and_leaves_",
    "tests/test_bad_input_campaign.py::test_the_ladder_stops_where_finer_steps_stop_helping",
    "tests/test_brian2_mapping.py::test_cpp_standalone_matches_numpy",
    "tests/test_brian2_mapping.py::test_error_shrinks_with_dt",  # its 1-us run
    "tests/test_consumer_check.py::test_below_norses_finest_step_no_torch_consumer_is_named",
    "tests/test_consumer_check.py::test_lava_run_py_check_gives_check_json_counts_without_spll_",
    "tests/test_exporter_conformance.py::test_conformance[checks_itself-lava-standard]",
    "tests/test_exporter_conformance.py::test_conformance[fails_cleanly-lava-standard]",
    "tests/test_exporter_conformance.py::test_conformance[fails_cleanly-nir-standard]",
    "tests/test_exporter_conformance.py::test_conformance[round_trip-lava-standard]",
    "tests/test_exporter_conformance.py::test_conformance[round_trip-nir-standard]",
    "tests/test_graded_current.py::test_run_py_runs_graded_currents_spike_for_spike",
    "tests/test_graded_current.py::test_the_ladder_tries_graded_currents_after_the_clock_per_spll",
    "tests/test_lava_backend.py::test_fixed_point_matches_the_rust_reference_spike_for_spike",
    "tests/test_lava_backend.py::test_fixed_point_with_several_weight_exponents",
    "tests/test_lava_backend.py::test_float_model_against_golden_within_the_time_grid",
    "tests/test_lava_backend.py::test_float_model_is_the_algorithm_in_real_numbers",
    "tests/test_lava_backend.py::test_processes_run_in_lavas_multi_process_runtime",
    "tests/test_lava_clocks.py::test_run_py_runs_each_clock_at_its_own_step_spike_for_spike",
    "tests/test_lava_clocks.py::test_the_export_writes_a_clock_per_spll_where_no_step_passes",
    "tests/test_lava_dt_choice.py::test_the_export_command_refuses_a_network_no_step_represents",
    "tests/test_multichannel_network.py::test_slide_on_a_few_real_recordings_writes_the_report",
    "tests/test_reference_integrator.py::test_random_parameters_agree_with_solve_ivp",
    "tests/test_reference_integrator.py::test_the_k_level_gate_agrees_with_solve_ivp",
    "tests/test_report_cli.py::test_report_costs_every_layout_on_chips_with_tables",
    "tests/test_report_cli.py::test_report_prices_a_construction_against_the_exact_cells",
    "tests/test_report_construction_costs.py::test_report_costs_each_construction_cell_as_its_",
    "tests/test_report_construction_costs.py::test_report_on_few_samples_says_so_next_to_the_",
    "tests/test_standard_construction.py::test_export_gate_resolves_a_slow_spll_at_the_networks_",
    "tests/test_standard_construction.py::test_the_compensated_hold_shortens_a_free_cco_by_one_",
    "tests/test_standard_lava.py::test_a_free_running_cco_keeps_goldens_period_where_its_decay_",
    "tests/test_standard_lava.py::test_every_set_of_decays_gets_its_own_processes_and_threshold",
    "tests/test_standard_lava.py::test_lava_standard_backend_equals_the_reference_backend",
    "tests/test_standard_lava.py::test_refractory_units_hold_exactly_their_steps[biotac-tuned-",
    "tests/test_standard_lava.py::test_run_py_on_lava_matches_the_bit_accurate_reference_spike_",
    "tests/test_standard_lava.py::test_run_py_runs_a_trigger_split_over_exponents_spike_for_spike",
    "tests/test_standard_lava.py::test_run_py_runs_the_dithered_hold_spike_for_spike",
    "tests/test_standard_lava.py::test_run_py_splits_the_network_into_sets_that_count_as_the_whole",
    "tests/test_standard_nir.py::test_the_numpy_consumer_steps_in_the_memory_of_its_spikes",
    "tests/test_standard_presets.py::test_default_preset_nir_standard_export_passes_its_own_check",
    "tests/test_standard_presets.py::test_lava_standard_on_a_hard_driven_preset_passes_its_check",
    "tests/test_standard_registry.py::test_export_command_writes_the_standard_targets",
    "tests/test_stats.py::test_a_planted_loss_is_inside_the_paired_interval_at_the_nominal_rate",
    "tests/test_tune.py::test_rescore_ranks_the_best_trials_on_every_sample_as_evaluate_scores_",
    "tests/test_tune.py::test_study_reuse_needs_resume_and_the_same_space_and_objective",
    "tests/test_tune.py::test_tuned_encoder_lands_in_the_report_as_evaluate_flags",
    "tests/test_tune_chip.py::test_a_resumed_study_does_not_replay_its_first_random_networks",
    "tests/test_tune_chip.py::test_a_study_for_a_chip_variant_is_measured_against_the_chip_as_",
    "tests/test_tune_chip.py::test_held_out_recordings_never_reach_the_study",
    "tests/test_tune_multichannel.py::test_tiny_study_writes_the_whole_file_with_only_the_tuned_",
    "tests/test_tune_processes.py::test_processes_opening_a_new_storage_at_once_all_succeed",
    "tests/test_tune_processes.py::test_sigterm_stops_a_study_and_its_workers_cleanly",
    "tests/test_tune_processes.py::test_sqlite_resume_after_a_killed_run_loses_no_finished_trial",
    "tests/test_tune_processes.py::test_two_workers_share_one_postgres_study",
    "tests/test_tune_processes.py::test_workers_of_a_killed_study_exit_instead_of_running_on",
)
#: The conformance suites' cases (backends, exporters, profiles): CI's environment 2 runs them
#: in full beside the quick tier, so every backend's figures are checked on NumPy 2 too.
CONFORMANCE = (
    "tests/test_backend_conformance.py::",
    "tests/test_exporter_conformance.py::",
    "tests/test_profile_conformance.py::",
)


@pytest.hookimpl(tryfirst=True)  # before -m deselects by these marks
def pytest_collection_modifyitems(config, items):
    """Mark :data:`SLOW` tests ``slow`` and :data:`CONFORMANCE` cases ``conformance``; warn of
    an entry of :data:`SLOW` that names no test of a file that was collected (renamed)."""
    for item in items:
        if _slow(item.nodeid):
            item.add_marker(pytest.mark.slow)
        if item.nodeid.startswith(CONFORMANCE):
            item.add_marker(pytest.mark.conformance)
    ids = [item.nodeid for item in items]
    for entry in SLOW:
        file = entry.partition("::")[0] + "::"
        if any(i.startswith(file) for i in ids) and not any(_matches(i, entry) for i in ids):
            warnings.warn(f"tests/conftest.py SLOW names no test: {entry}", stacklevel=1)


def _matches(nodeid: str, entry: str) -> bool:
    """Whether ``nodeid`` starts with ``entry`` of :data:`SLOW` (``*``: any text)."""
    return fnmatch.fnmatchcase(nodeid, entry.replace("[", "[[]") + "*")


def _slow(nodeid: str) -> bool:
    return any(_matches(nodeid, entry) for entry in SLOW)
