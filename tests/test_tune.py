"""spll-hw tune: search space, constraints, pruning, storage errors, resume, two workers."""

from __future__ import annotations

import math
import sys
import time
from dataclasses import asdict

import numpy as np
import pytest

optuna = pytest.importorskip("optuna", reason="the tune extra (Optuna) is not installed")

from spll_hw import backends  # noqa: E402
from spll_hw.cli.main import main  # noqa: E402
from spll_hw.config import NetworkConfig, read_encoder_table  # noqa: E402
from spll_hw.datasets import make_synthetic  # noqa: E402
from spll_hw.encoders import make_encoder, settings_table  # noqa: E402
from spll_hw.pipeline import encode_samples  # noqa: E402
from spll_hw.tune.objective import Objective, ObjectiveSettings  # noqa: E402
from spll_hw.tune.space import SearchSpace, constraint_values  # noqa: E402
from spll_hw.tune.storage import open_storage, storage_url  # noqa: E402
from spll_hw.tune.study import StudySettings, prepare_study  # noqa: E402

from .figure_checks import capture_figures, legend_over_axes, ticks_in_view  # noqa: E402

#: A tiny synthetic problem: 3 classes x 6 samples of 0.5 s, 4 sPLLs, 3-fold CV, 2 noise draws.
TINY = [
    "--dataset", "synthetic", "--synthetic-classes", "3", "--synthetic-samples", "6",
    "--duration", "0.5", "--encoders", "lif", "--n-spll", "4", "--folds", "3", "--repeats", "2",
    "--startup-trials", "2", "--threads", "1", "--quiet",
]  # fmt: skip


def tiny_objective(**settings) -> Objective:
    samples = make_synthetic(3, 6, 0.5, seed=0).normalized()
    trains = encode_samples(make_encoder("lif"), samples)
    defaults = {"n_spll": 4, "folds": 3, "repeats": 2}
    return Objective(
        SearchSpace.table5(),
        trains,
        samples.labels,
        samples.class_names,
        samples.duration,
        ObjectiveSettings(**defaults | settings),
        threads=1,
    )


def load(url: str, name: str):
    return optuna.load_study(study_name=name, storage=open_storage(storage_url(url, ".")))


def finished_trials(study) -> list:
    done = (optuna.trial.TrialState.COMPLETE, optuna.trial.TrialState.PRUNED)
    return [t for t in study.trials if t.state in done]


# ------------------------------------------------------------------------------- search space
def test_table5_sample_becomes_a_network_file_every_command_reads(tmp_path):
    space = SearchSpace.table5()
    assert space.dims["tau_tde_fac"].describe() == "[0.0005, 0.02] log"
    assert space.dims["beta"].choices == (1.0, 10.0, 100.0, math.inf)
    study = optuna.create_study(sampler=optuna.samplers.RandomSampler(seed=3))
    trial = study.ask()
    params = space.suggest(trial)
    for name, dim in space.dims.items():
        value = params[name]
        assert value in dim.choices if dim.kind == "choice" else dim.low <= value <= dim.high
    objective = tiny_objective()
    config = objective.config(params)
    path = tmp_path / "net.toml"
    path.write_text(config.to_toml())
    assert NetworkConfig.load(path) == config
    assert config.build().n_spll == 4


@pytest.mark.parametrize(
    ("specs", "message"),
    [
        ({"tau_cco_sin": {"low": 0.1, "high": 0.2}}, "unknown parameter 'tau_cco_sin'"),
        ({"tau_cco": {"low": 0.5, "high": 0.05, "log": True}}, "reversed range"),
        ({"g_cco": {"low": 2.0, "high": 2.0}}, "empty range"),
        ({"beta": {"choices": []}}, "empty list of choices"),
        ({"g_cco": {"low": 0.0, "high": 2.0, "log": True}}, "log range needs low > 0"),
        ({"tau_tde": {"low": -1.0, "high": 0.1}}, "tau_tde = -1.0"),
        ({"f_start": {"low": 30.0, "high": 400.0}}, "must stay below f_end"),
        ({"g_cco": {"low": 1.0, "hi": 2.0}}, "unknown key"),
        ({"i_cco_offset": 3.0}, "unknown parameter 'i_cco_offset'"),
        ({"spread": {"low": -0.5, "high": 1.0}}, "spread = -0.5"),
        ({"lif.gian": {"low": 1.0, "high": 2.0}}, r"no numeric parameter 'gian'; tunable: .*gain"),
        ({"lif.normalize": 1.0}, "no numeric parameter 'normalize'"),
        ({"touch.gain": 1.0}, "unknown encoder 'touch'"),
        ({"pacinian.model": {"low": 0, "high": 3}}, "integer encoder parameter takes choices"),
        ({"pacinian.model": {"choices": [0, 1.5]}}, "not all integers"),
        ({"pacinian.model": {"choices": [0, 7]}}, "pacinian.model = 7: PC model must be 0..3"),
        ({"lif.tau": {"low": -0.001, "high": 0.002}}, "lif.tau = -0.001: LIF tau must be > 0"),
        ({"peak.duration": {"low": 1.0, "high": 4.0}}, "cannot be tuned; fix it with --set"),
    ],
)
def test_bad_search_space_is_a_clear_error(specs, message):
    with pytest.raises(ValueError, match=message):
        SearchSpace.table5().with_overrides(specs)


def test_space_file_overrides_and_fixes(tmp_path):
    path = tmp_path / "space.toml"
    path.write_text("[space]\ng_cco = 2.0\nbeta = { choices = [10, inf] }\n")
    space = SearchSpace.load(path)
    assert space.dims["g_cco"].kind == "fixed" and "g_cco" not in space.tuned
    assert space.complete({"beta": 10.0})["g_cco"] == 2.0
    assert space.differences(SearchSpace.table5().to_dict()) == [
        "beta: stored {'choices': [1.0, 10.0, 100.0, 'inf']}, now {'choices': [10, 'inf']}",
        "g_cco: stored {'low': 0.1, 'high': 10.0, 'log': True}, now {'value': 2.0}",
    ]
    (tmp_path / "bad.toml").write_text("[spll]\ng_cco = 2.0\n")
    with pytest.raises(ValueError, match=r"exactly one \[space\] table"):
        SearchSpace.load(tmp_path / "bad.toml")


def test_spread_is_an_optional_dimension_drawn_with_the_study_seed():
    assert "spread" not in SearchSpace.table5().dims  # the thesis's space: no diversity
    objective = tiny_objective(seed=5)
    params = {
        n: d.choices[0] if d.kind == "choice" else d.low for n, d in objective.space.dims.items()
    }
    assert objective.config(params).spread == 0.0
    space = SearchSpace.table5().with_overrides({"spread": {"low": 0.0, "high": 1.0}})
    assert "spread" in space.tuned
    config = Objective(
        space, objective.noisy[0], objective.labels, objective.class_names, objective.duration,
        objective.settings, threads=1,
    ).config(params | {"spread": 0.4})  # fmt: skip
    assert (config.spread, config.spread_seed) == (0.4, 5)
    np.testing.assert_array_equal(
        config.build().matrix(), objective.config(params).build().with_spread(0.4, 5).matrix()
    )


def test_encoder_dimensions_re_encode_every_trial_with_the_same_noise_seeds():
    from spll_hw.pipeline import jitter
    from spll_hw.tune.objective import Encoding

    base = tiny_objective(seed=2)
    samples = make_synthetic(3, 6, 0.5, seed=0).normalized()
    space = SearchSpace.table5().with_overrides(
        {"lif.gain": {"low": 1000.0, "high": 8000.0, "log": True}, "lif.tau": {"choices": [1, 2]}}
    )
    assert space.encoders == {"lif"} and space.tuned[-2:] == ["lif.gain", "lif.tau"]
    encoding = Encoding(
        make_encoder("lif", t_ref=5e-4), samples.signals, samples.fs, samples.noise_ids
    )
    objective = Objective(
        space, base.noisy[0], base.labels, base.class_names, base.duration, base.settings,
        threads=1, encoding=encoding,
    )  # fmt: skip
    params = {n: d.choices[0] if d.kind == "choice" else d.low for n, d in space.dims.items()}
    draws = objective.draws(params | {"lif.gain": 3000.0, "lif.tau": 2})
    assert len(draws) == 2
    lif = make_encoder("lif", t_ref=5e-4, gain=3000.0, tau=2)
    expected = lif.encode(samples.signals, samples.fs, ids=samples.noise_ids)
    for r, draw in enumerate(draws):  # the study's noise seeds, the trial's encoder
        for got, want in zip(draw, jitter(expected, 5e-4, 0.5, 2 + r), strict=True):
            np.testing.assert_array_equal(got, want)
    other = objective.draws(params | {"lif.gain": 6000.0, "lif.tau": 2})
    assert sum(t.size for t in other[0]) > sum(t.size for t in draws[0])  # more gain: more spikes
    network_only = {n: v for n, v in params.items() if not n.startswith("lif.")}
    assert objective.config(params) == base.config(network_only)  # encoder dims: not the network
    assert base.draws(network_only) is base.noisy  # no encoder dimension: the precomputed draws


@pytest.mark.parametrize("encoder", [None, "pacinian"])
def test_tuning_another_encoders_parameters_is_a_clear_error(encoder):
    from spll_hw.tune.objective import Encoding

    base = tiny_objective()
    space = SearchSpace.table5().with_overrides({"lif.gain": {"low": 1e3, "high": 8e3}})
    encoding = None
    if encoder:
        encoding = Encoding(make_encoder(encoder), np.zeros((18, 10)), 1000.0, np.arange(18))
    with pytest.raises(ValueError, match=r"tunes parameters of encoder\(s\) \['lif'\]"):
        Objective(
            space, base.noisy[0], base.labels, base.class_names, base.duration, base.settings,
            encoding=encoding,
        )  # fmt: skip


def test_tuned_encoder_lands_in_the_report_as_evaluate_flags(tmp_path, capsys):
    from spll_hw.cli.inputs import encoder_overrides

    space = tmp_path / "space.toml"
    space.write_text('[space]\n"lif.gain" = { low = 2000.0, high = 8000.0, log = true }\n')
    out = tmp_path / "study"
    fixed = ["--set", "lif.tau=0.003"]
    args = [*TINY, *fixed, "--space", str(space), "--trials", "3", "--out", str(out)]
    assert main(["tune", *args]) == 0
    header = (out / "best.toml").read_text().splitlines()[1]
    flags = header.removeprefix("# encoder settings: ")
    assert flags != header and flags in (out / "summary.md").read_text()
    study = load(f"sqlite:///{out / 'study.db'}", "synthetic-vary-offset-lif")
    gains = {t.params["lif.gain"] for t in finished_trials(study)}
    assert len(gains) == 3  # every trial drew its own encoder gain
    overrides = encoder_overrides(flags.removeprefix("--set ").split(" --set "), ["lif"])
    assert overrides["lif"]["gain"] in gains  # exactly a trial's value, not a rounding of it
    assert overrides["lif"]["tau"] == 0.003  # the study's fixed --set is part of the encoder
    NetworkConfig.load(out / "best.toml")  # comment and [encoder] do not stop network commands
    assert read_encoder_table(out / "best.toml") == (
        "lif",
        asdict(make_encoder("lif", **overrides["lif"])),
    )
    capsys.readouterr()
    both = ["--space", str(space), "--set", "lif.gain=3000", "--out", str(tmp_path / "b")]
    assert main(["tune", *TINY, *both]) == 2
    assert "['lif.gain'] set with --set and tuned by the search space" in capsys.readouterr().err


def test_enqueued_network_starts_encoder_dimensions_at_its_files_or_the_study_encoders_setting(
    tmp_path, capsys
):
    from spll_hw.cli.jobs.tune import enqueue_params

    space = SearchSpace.table5().with_overrides(
        {"lif.gain": {"low": 2000.0, "high": 8000.0}, "lif.tau": {"choices": [1e-3, 4e-3]}}
    )
    preset = "biotac-vary-offset-lif"
    params = enqueue_params(preset, space, make_encoder("lif", gain=3000.0, tau=4e-3))
    assert params["lif.gain"] == 3000.0 and params["lif.tau"] == 4e-3
    assert params["f_start"] == NetworkConfig.load(preset).f_start
    params = enqueue_params(preset, space, make_encoder("lif", gain=9000.0))
    assert "lif.gain" not in params and "lif.tau" not in params  # outside: Optuna samples it
    params = enqueue_params(preset, space, make_encoder("pacinian"))  # the Objective says no
    assert "lif.gain" not in params and "lif.tau" not in params
    tuned = tmp_path / "best.toml"  # a file tuned at gain 5000 and tau 1 ms
    tuned.write_text(
        NetworkConfig.load(preset).to_toml()
        + settings_table(make_encoder("lif", gain=5e3, tau=1e-3))
    )
    params = enqueue_params(str(tuned), space, make_encoder("lif", gain=3000.0, tau=4e-3))
    assert params["lif.gain"] == 5e3 and params["lif.tau"] == 1e-3
    capsys.readouterr()
    gain_only = SearchSpace.table5().with_overrides({"lif.gain": {"low": 2e3, "high": 8e3}})
    assert enqueue_params(str(tuned), gain_only, make_encoder("lif", tau=4e-3))["lif.gain"] == 5e3
    assert "tuned with lif.tau=0.001 (this study: 0.004)" in capsys.readouterr().err
    pacinian = enqueue_params(str(tuned), space, make_encoder("pacinian"))
    assert "lif.gain" not in pacinian
    assert "was tuned on lif spike trains" in capsys.readouterr().err
    narrow = space.with_overrides({"f_start": {"low": 30.0, "high": 31.0}})
    with pytest.raises(ValueError, match=r"f_start = .* is outside the search space \[30, 31\]"):
        enqueue_params(preset, narrow, make_encoder("lif"))


def test_rescore_ranks_the_best_trials_on_every_sample_as_evaluate_scores_them(tmp_path):
    import json

    space = tmp_path / "space.toml"
    space.write_text('[space]\n"lif.gain" = { low = 2000.0, high = 8000.0, log = true }\n')
    out = tmp_path / "study"
    six = ["--synthetic-samples", "6", "--pruner", "none", "--constraints", "off"]
    args = [*TINY, *six, "--per-class", "3", "--space", str(space), "--trials", "4"]
    assert main(["tune", *args, "--rescore", "3", "--out", str(out)]) == 0
    summary = (out / "summary.md").read_text()
    rows = [line for line in summary.splitlines() if line.startswith("| #")][:3]
    rescored = [float(row.split("|")[3].strip(" %")) for row in rows]
    assert len(rows) == 3 and rescored == sorted(rescored, reverse=True)
    header = (out / "best.toml").read_text().splitlines()
    assert header[0].split(", trial ")[1].startswith(rows[0].split("#")[1].split(" ")[0])
    evaluated = tmp_path / "evaluated"  # no --set: best.toml's [encoder] has the trial's gain
    assert main([
        "evaluate", "--synthetic-classes", "3", "--synthetic-samples", "6", "--duration", "0.5",
        "--encoders", "lif", "--features", "spll", "--network", str(out / "best.toml"),
        "--phase-noise", "5e-4", "--repeats", "2", "--folds", "3", "--quiet", "--jobs", "1",
        "--out", str(evaluated),
    ]) == 0  # fmt: skip
    (result,) = json.loads((evaluated / "results.json").read_text())["results"]
    assert f"{100 * result['accuracy']:.1f}" == f"{rescored[0]:.1f}"  # all 18 samples, not 9
    assert main(["tune", *args, "--rescore", "2", "--per-class", "0", "--out", str(out)]) == 2


@pytest.mark.parametrize(("text", "spec"), [("0.5", 0.5), ("0:1", {"low": 0.0, "high": 1.0})])
def test_spread_flag(text, spec):
    from spll_hw.cli.jobs.tune import spread_spec

    assert spread_spec(text) == spec


def test_bad_spread_flag_is_a_clear_error(tmp_path, capsys):
    code = main(["tune", *TINY, "--trials", "1", "--spread", "1:0", "--out", str(tmp_path)])
    assert code == 2 and "spread: reversed range" in capsys.readouterr().err
    assert not (tmp_path / "study.db").exists()
    code = main(["tune", *TINY, "--trials", "1", "--spread", "a:b:c", "--out", str(tmp_path)])
    assert code == 2 and "--spread 'a:b:c'" in capsys.readouterr().err


def test_constraints_per_layout():
    thesis = NetworkConfig.preset("biotac-vary-offset-lif")  # tau_fac 12.5 ms at up to 669 Hz
    fac_f, trg_f, fac_tde, trg_tde = constraint_values(thesis)
    assert fac_f == pytest.approx(0.0125 * 669.0 - 1)
    assert trg_f == pytest.approx(0.000966 * 669.0 - 1)
    assert fac_tde == pytest.approx(0.0125 / 0.00731 - 1)
    assert trg_tde < 0
    # time-scaled: sPLL i runs f_i / 50 Hz faster, so the bound is 1/50 s on the base sPLL
    scaled = thesis.with_layout("time-scaled")
    assert constraint_values(scaled)[0] == pytest.approx(0.0125 * 50.0 - 1)


def test_best_trial_respects_constraints_unless_they_are_off():
    from spll_hw.tune.report import best_trial

    study = optuna.create_study(direction="maximize")
    for value, violation in ((0.1, -0.5), (0.4, 0.2)):
        study.add_trial(
            optuna.trial.create_trial(value=value, user_attrs={"constraints": [violation]})
        )
    assert best_trial(study, "penalise").value == 0.1
    assert best_trial(study, "enforce").value == 0.1
    assert best_trial(study, "off").value == 0.4


def studied(trials) -> optuna.Study:
    """A single-objective study of ``(accuracy, constraint violation)`` trials over two
    parameters drawn at random."""
    rng = np.random.default_rng(0)
    space = {name: optuna.distributions.FloatDistribution(0.1, 10.0) for name in ("g_cco", "beta")}
    study = optuna.create_study(direction="maximize", study_name="s")
    for value, violation in trials:
        params = {name: float(rng.uniform(0.1, 10.0)) for name in space}
        study.add_trial(optuna.trial.create_trial(
            params=params, distributions=space, value=value,
            user_attrs={"constraints": [violation]},
        ))  # fmt: skip
    return study


def test_report_history_marks_the_trials_left_out_and_counts_trials_in_whole_numbers(
    tmp_path, monkeypatch
):
    from spll_hw.tune.report import left_out_lines, plot_history

    figures = capture_figures(monkeypatch)
    study = studied([(0.5, -0.1), (0.7, 0.3), (0.6, -0.2)])
    plot_history(study, tmp_path / "history.png", "penalise")
    ax = figures["history.png"].axes[0]
    ticks = ticks_in_view(ax.xaxis)
    assert len(ticks) and np.all(ticks == np.round(ticks))  # no trial 0.5
    assert legend_over_axes(ax) == 0
    lines = {line.get_label(): line for line in ax.lines}
    crosses = lines["breaks the constraints:\nnot eligible"]
    assert list(crosses.get_xdata()) == [1]  # the most accurate trial, but infeasible
    assert max(lines["best so far"].get_ydata()) == pytest.approx(60.0)
    (line,) = left_out_lines(study, "penalise")
    assert "1 of 3 complete trials break the thesis's constraints" in line
    assert left_out_lines(study, "off") == []  # nothing is dropped with constraints off
    assert left_out_lines(studied([(0.5, 0.1), (0.7, 0.3)]), "penalise") == []  # none feasible


@pytest.mark.parametrize("n_trials", [5, 20])
def test_report_importances_say_when_too_few_trials_make_them_unreliable(
    tmp_path, monkeypatch, n_trials
):
    from spll_hw.tune.report import FANOVA_RELIABLE_TRIALS, importance_lines

    figures = capture_figures(monkeypatch)
    study = studied([(0.3 + 0.02 * k, -0.1) for k in range(n_trials)])
    text = "\n".join(importance_lines(study, tmp_path))
    title = figures["importances.png"].axes[0].get_title()
    assert f"from {n_trials} complete trials" in title
    few = n_trials < FANOVA_RELIABLE_TRIALS
    assert ("UNRELIABLE" in title) == few
    assert (f"**Unreliable: these rest on {n_trials} complete trials**" in text) == few
    assert "| g_cco |" in text and "| beta |" in text


def test_enforced_constraints_prune_without_simulating():
    objective = tiny_objective(constraints="enforce")
    study = optuna.create_study(direction="maximize")
    study.enqueue_trial({"tau_tde_fac": 0.02, "tau_tde": 0.001, "f_end": 700.0})
    study.optimize(objective, n_trials=1)
    trial = study.trials[0]
    assert trial.state == optuna.trial.TrialState.PRUNED
    assert trial.user_attrs["error"] == "violates the sPLL constraints"
    assert "simulation_seconds" not in trial.user_attrs and not trial.intermediate_values


def test_pruner_sees_the_subset_first_and_full_runs_report_every_draw():
    objective = tiny_objective(prune_fraction=0.5)
    assert objective.first.size == 9  # 3 of 6 per class
    always = optuna.create_study(
        direction="maximize", pruner=optuna.pruners.ThresholdPruner(lower=1.1)
    )
    always.optimize(objective, n_trials=1)
    pruned = always.trials[0]
    assert pruned.state == optuna.trial.TrialState.PRUNED
    assert list(pruned.intermediate_values) == [0]
    never = optuna.create_study(direction="maximize", sampler=optuna.samplers.RandomSampler(0))
    never.optimize(objective, n_trials=1)
    done = never.trials[0]
    assert list(done.intermediate_values) == [0, 1, 2]
    draws = done.user_attrs["repeat_accuracies"]
    assert done.value == pytest.approx(np.mean(draws)) and 0 <= done.value <= 1


def test_missing_optuna_names_the_extra(monkeypatch):
    from spll_hw.tune import import_optuna

    monkeypatch.setitem(sys.modules, "optuna", None)
    with pytest.raises(ImportError, match=r"\.\[tune\]"):
        import_optuna()


# ------------------------------------------------------------------------------- storage
def test_unreachable_storage_is_a_clear_error(tmp_path, capsys):
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]  # nothing listens there once closed
    url = f"postgresql://someone:secret@127.0.0.1:{port}/spll"
    start = time.perf_counter()
    code = main(["tune", *TINY, "--storage", url, "--out", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert code == 2 and "cannot open storage" in err and "someone:***@" in err
    assert "secret" not in err and time.perf_counter() - start < 20
    assert not (tmp_path / "r" / "summary.md").exists()


def test_tuning_on_the_chips_own_arithmetic(tmp_path):
    """--backend scores every trial on that backend and is stored with the study."""
    spec = "golden-fixed-point:profile=fixed16"
    out = tmp_path / "chip"
    args = ["tune", *TINY, "--pruner", "none", "--trials", "2", "--backend", spec]
    assert main([*args, "--out", str(out), "--study", "chip"]) == 0
    study = load(storage_url(None, out), "chip")
    assert study.user_attrs["spll_hw"]["objective"]["settings"]["backend"] == spec
    trial = finished_trials(study)[0]
    chip, golden = tiny_objective(backend=spec), tiny_objective()
    config = chip.config(trial.params)
    draws = chip.draws(trial.params)
    everything = np.arange(chip.labels.size)
    rates = chip.rates(config, draws[0], everything)
    expected = backends.get(spec).rates(config.build(), list(draws[0]), chip.duration)
    np.testing.assert_array_equal(rates, expected)
    assert not np.array_equal(rates, golden.rates(config, draws[0], everything))
    with pytest.raises(ValueError, match="unknown backend 'nest'"):
        tiny_objective(backend="nest")


def test_study_reuse_needs_resume_and_the_same_space_and_objective(tmp_path, capsys):
    out = tmp_path / "r"
    args = ["tune", *TINY, "--pruner", "none", "--trials", "3", "--out", str(out), "--study", "s"]
    assert main(args) == 0
    url = storage_url(None, out)
    before = load(url, "s")
    numbers = [t.number for t in before.trials]
    assert len(finished_trials(before)) >= 3
    config = NetworkConfig.load(out / "best.toml")  # what every --params accepts
    assert config.n == 4 and config.build().n_spll == 4
    for png in ("history.png", "importances.png", "features.png", "response_mid.png"):
        assert (out / png).stat().st_size > 1000
    assert "## Best trial" in (out / "summary.md").read_text()

    space = tmp_path / "space.toml"
    space.write_text("[space]\ng_cco = { low = 0.5, high = 10.0, log = true }\n")
    for extra, message in [
        ([], "already exists with"),
        (["--resume", "--space", str(space)], "different search space (g_cco: stored"),
        (["--resume", "--phase-noise", "1e-3"], "different objective (settings: stored"),
        (["--resume", "--set", "lif.gain=3000"], "different spike trains: check the encoder"),
    ]:
        assert main(args + extra) == 2
        assert message in capsys.readouterr().err
        after = load(url, "s")
        assert [t.number for t in after.trials] == numbers  # nothing written
        assert after.user_attrs == before.user_attrs
    chip = ["--resume", "--backend", "golden-fixed-point:profile=loihi2"]
    assert main(args + chip) == 2  # another backend is another objective (and a chip study)
    err = capsys.readouterr().err
    assert "different objective (" in err and "settings: stored" in err
    # the same command with --resume and a larger target runs only the missing trials
    assert main([*args[:-4], "--trials", "5", "--out", str(out), "--study", "s", "--resume"]) == 0
    resumed = load(url, "s")
    assert len(finished_trials(resumed)) == 5


def test_prepare_refuses_a_foreign_study(tmp_path):
    url = storage_url(str(tmp_path / "db.sqlite"), tmp_path)
    foreign = optuna.create_study(study_name="x", storage=url)
    foreign.optimize(lambda t: t.suggest_float("a", 0, 1), n_trials=1)
    with pytest.raises(ValueError, match="not created by spll-hw tune"):
        prepare_study(StudySettings(url, "x", 2), tiny_objective(), resume=True)
    optuna.create_study(study_name="empty", storage=url)
    with pytest.raises(ValueError, match="not created by spll-hw tune .*0 trials"):
        prepare_study(StudySettings(url, "empty", 2), tiny_objective(), resume=True)


def test_resume_of_a_missing_study_is_refused_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "r"
    args = ["tune", *TINY, "--trials", "1", "--out", str(out), "--study", "typo", "--resume"]
    assert main(args) == 2
    assert "--resume: there is no study 'typo'" in capsys.readouterr().err
    url = storage_url(None, out)
    assert optuna.get_all_study_summaries(open_storage(url)) == []
