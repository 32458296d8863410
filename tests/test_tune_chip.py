"""spll-hw tune for a chip: realised networks, fit pruning, mismatch draws, accuracy against
energy (Pareto front), a reference network, held-out recordings, and bad input refused first."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

optuna = pytest.importorskip("optuna", reason="the tune extra (Optuna) is not installed")

from spll_hw import backends, chips  # noqa: E402
from spll_hw.cli.main import main  # noqa: E402
from spll_hw.config import NetworkConfig  # noqa: E402
from spll_hw.tune.chip import (  # noqa: E402
    changed_parameters,
    chosen_points,
    pareto_front,
    study_backend,
)
from spll_hw.tune.storage import open_storage, storage_url  # noqa: E402

from .figure_checks import capture_figures, colliding_labels, legend_over_axes  # noqa: E402
from .pipeline_data import BIOTAC_DIR, needs_biotac  # noqa: E402
from .test_tune import TINY, finished_trials, tiny_objective  # noqa: E402


def load(out, name: str):
    return optuna.load_study(study_name=name, storage=open_storage(storage_url(None, out)))


def complete(study) -> list:
    return [t for t in study.trials if t.state == optuna.trial.TrialState.COMPLETE]


def test_pareto_front_and_its_chosen_points():
    # (accuracy, energy): #3 is dominated by #1 (less accurate and dearer)
    points = [(0.9, 10.0), (0.8, 5.0), (0.5, 1.0), (0.7, 8.0), (0.9, 10.0)]
    objectives = ("accuracy", "energy")
    assert pareto_front(points, objectives) == [0, 4, 1, 2]  # ties both kept, most accurate first
    assert chosen_points(points, objectives) == [
        (0, "best accuracy"), (1, "knee"), (2, "best energy"),
    ]  # fmt: skip
    assert chosen_points([(0.6, 3.0)], objectives) == [(0, "best accuracy + best energy + knee")]


def test_profile_sets_the_backend_to_the_realised_network_or_the_chips_arithmetic():
    assert study_backend("golden", "loihi2") == "golden:profile=loihi2"
    fixed = study_backend("golden-fixed-point", "fixed16")
    assert backends.get(fixed).options["profile"] == "fixed16"
    with pytest.raises(ValueError, match="simulates profile fixed16: give one"):
        study_backend("golden-fixed-point:profile=fixed16", "loihi2")
    with pytest.raises(ValueError, match="unknown profile 'loihi9'"):
        study_backend("golden", "loihi9")


def test_analog_study_averages_its_mismatch_draws_and_stores_them(tmp_path):
    out = tmp_path / "analog"
    args = [*TINY, "--pruner", "none", "--trials", "2", "--profiles", "analog"]
    assert main(["tune", *args, "--chip-draws", "2", "--out", str(out), "--study", "a"]) == 0
    study = load(out, "a")
    chip = study.user_attrs["spll_hw"]["objective"]["chip"]
    assert chip["chip_seeds"] == [0, 1] and chip["kind"] == "analog"
    assert chip["backends"] == [f"golden:profile=analog:chip_seed={k}" for k in (0, 1)]
    assert study.user_attrs["spll_hw"]["objective"]["settings"]["chip_draws"] == 2
    trial = complete(study)[0]
    per_chip = trial.user_attrs["chip_accuracies"]
    assert len(per_chip) == 2 and trial.value == pytest.approx(np.mean(per_chip))
    # each draw is its own chip: the same network, other mismatch, other rates
    objective = tiny_objective(backend="golden:profile=analog", chip_draws=2)
    config = objective.config(trial.params)
    everything = np.arange(objective.labels.size)
    draw = objective.draws(trial.params)[0]
    rates = [objective.rates(config, draw, everything, spec) for spec in objective.specs]
    assert not np.array_equal(rates[0], rates[1])
    accuracy = np.mean([objective.score(x, everything)[0] for x in rates])
    draw1 = objective.draws(trial.params)[1]
    accuracy1 = np.mean(
        [objective.score(objective.rates(config, draw1, everything, s), everything)[0]
         for s in objective.specs]
    )  # fmt: skip
    assert trial.value == pytest.approx((accuracy + accuracy1) / 2)
    assert "2 mismatch draws (chip_seed 0-1)" in (out / "summary.md").read_text()


def test_networks_that_do_not_fit_the_chip_are_pruned_with_the_reason(tmp_path):
    out = tmp_path / "unfit"  # 9 time-scale groups: the analog chip has 8
    args = [*TINY, "--n-spll", "9", "--layouts", "time-scaled", "--trials", "2"]
    assert main(["tune", *args, "--profiles", "analog", "--out", str(out), "--study", "u"]) == 0
    trials = finished_trials(load(out, "u"))
    assert len(trials) == 2
    for t in trials:
        assert t.state == optuna.trial.TrialState.PRUNED
        assert "needs 9 distinct sPLL circuits" in t.user_attrs["fit"]
        assert t.user_attrs["error"].startswith("does not fit analog:")
        assert "simulation_seconds" not in t.user_attrs  # never simulated
    summary = (out / "summary.md").read_text()
    assert "did not fit `analog` (pruned unsimulated): 2 of 2 pruned trials" in summary


def test_accuracy_against_energy_gives_a_front_with_files_and_a_reference(tmp_path, monkeypatch):
    figures = capture_figures(monkeypatch)
    out = tmp_path / "front"
    args = [*TINY, "--trials", "3", "--profiles", "loihi2", "--objectives", "accuracy,energy"]
    ref = tmp_path / "reference.toml"  # the thesis's network, 4 sPLLs like the study's
    thesis = NetworkConfig.preset("biotac-vary-offset-lif")
    ref.write_text(dataclasses.replace(thesis, n=4).to_toml())
    assert main(["tune", *args, "--compare", str(ref), "--out", str(out), "--study", "f"]) == 0
    study = load(out, "f")
    assert [d.name for d in study.directions] == ["MAXIMIZE", "MINIMIZE"]
    done = complete(study)
    assert len(done) == 3
    # energy: the mean dynamic chips.cost of the costed samples, simulated on the realised
    # network; static power is stored apart and never enters the objective
    objective = tiny_objective(backend="golden:profile=loihi2", objectives=("accuracy", "energy"))
    assert objective.first is None  # no pruner, so no first look
    t = done[0]
    network = objective.config(t.params).build()
    draw = objective.draws(t.params)[0]
    results = backends.get("golden:profile=loihi2").simulate_batch(
        network, [draw[i] for i in objective.costed], objective.duration
    )
    energy = np.mean(
        [chips.cost(chips.OnChip(network, "loihi2"), r).dynamic_energy for r in results]
    )
    assert objective.costed.size == 6 and t.values[1] == pytest.approx(energy)
    assert t.values[1] == t.user_attrs["energy_j"] > 0
    assert t.user_attrs["static_energy_j"] > 0
    # the chosen points are on the front and written out, most accurate first
    result = json.loads((out / "results.json").read_text())
    front = {f["trial"] for f in result["front"]}
    chosen = result["networks"]
    assert chosen and all(n["trial"] in front for n in chosen)
    for n in chosen:
        trial = study.trials[n["trial"]]
        assert NetworkConfig.load(out / n["file"]) == objective.config(trial.params)
        others = [u.values for u in done]
        assert not any(o[0] >= trial.values[0] and o[1] < trial.values[1] for o in others)
    assert chosen[0]["values"][0] == max(u.values[0] for u in done)
    best = (out / "best.toml").read_text().splitlines()[0]
    assert f"trial {chosen[0]['trial']}," in best
    # the reference, on the same objectives, placed against the front
    reference = result["reference"]
    assert reference["fits"] and reference["values"][1] > 0 and reference["cores"] >= 1
    summary = (out / "summary.md").read_text()
    assert "## Pareto front: accuracy against energy" in summary
    assert "## Reference network" in summary
    assert (out / "front.png").stat().st_size > 1000
    # Every complete trial is drawn (those left out for breaking the constraints too), the
    # chosen points and the reference are labelled without collisions, the legend beside.
    ax = figures["front.png"].axes[0]
    groups = [line for line in ax.lines if line.get_label().startswith(("meet", "break"))]
    assert sum(len(line.get_xdata()) for line in groups) == len(done)
    assert len(ax.texts) == len(chosen) + 1 and colliding_labels(ax) == []
    assert legend_over_axes(ax) == 0


def test_cores_objective_counts_the_chips_cores():
    objective = tiny_objective(backend="golden:profile=loihi2", objectives=("accuracy", "cores"))
    study = optuna.create_study(directions=["maximize", "minimize"])
    study.optimize(objective, n_trials=1)
    (t,) = study.trials
    network = objective.config(t.params).build()
    assert (
        t.values[1]
        == chips.resources(chips.OnChip(network, "loihi2")).cores
        == t.user_attrs["cores"]
    )


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--profiles", "analog", "--objectives", "accuracy,energy"], "needs a [energy] table"),
        (["--objectives", "accuracy,energy"], "tune for one with --profile"),
        (["--profiles", "analog", "--chip-draws", "0"], "--chip-draws: must be an integer > 0"),
        (["--profiles", "loihi2", "--chip-draws", "2"], "'loihi2' is fixed point"),
        (["--profiles", "loihi2", "--objectives", "accuracy,speed"], "unknown objective(s)"),
        (["--profiles", "loihi2", "--objectives", "energy"], "the first must be accuracy"),
        (["--profiles", "loihi9"], "unknown profile 'loihi9'"),
        (["--profiles", "analog", "--spread", "0:1", "--n-spll", "9"], "cannot realise such"),
        (["--holdout-recordings", "1-2"], "--holdout-recordings needs --dataset biotac"),
        (["--profiles", "loihi2", "--attribute"], "--attribute scores the reference"),
        (["--profiles", "loihi2", "--compare-profile", "loihi2"], "--compare-profile scores"),
        (["--backend", "golden-fixed-point:dt=4e-5"], "at dt = 4e-05 s, but the profile's fit"),
    ],
)
def test_bad_chip_input_is_refused_before_the_study(tmp_path, capsys, extra, message):
    out = tmp_path / "r"
    assert main(["tune", *TINY, "--trials", "1", *extra, "--out", str(out)]) == 2
    assert message in capsys.readouterr().err
    assert not (out / "study.db").exists()


@needs_biotac
def test_held_out_recordings_never_reach_the_study(tmp_path, capsys):
    from spll_hw.datasets import load_biotac
    from spll_hw.datasets.recordings import recording_numbers

    data = [
        "--dataset", "biotac", "--data", str(BIOTAC_DIR), "--classes", "mat1,mat2,mat3",
        "--encoders", "lif", "--n-spll", "4", "--folds", "3", "--repeats", "1", "--threads", "1",
        "--pruner", "none", "--per-class", "6", "--quiet",
    ]  # fmt: skip
    out = tmp_path / "held"
    held = ["--recordings", "1-8", "--holdout-recordings", "7-8", "--profiles", "loihi2"]
    ref = ["--compare", "biotac-vary-offset-lif", "--attribute", "--study", "h", "--out", str(out)]
    assert main(["tune", *data, *held, "--trials", "2", *ref]) == 0
    # the study's samples are those of a study on recordings 1-6 alone
    plain = tmp_path / "plain"
    assert main(["tune", *data, "--recordings", "1-6", "--trials", "0", "--profiles", "loihi2",
                 "--study", "p", "--out", str(plain)]) == 0  # fmt: skip
    stored = [load(o, n).user_attrs["spll_hw"]["objective"] for o, n in ((out, "h"), (plain, "p"))]
    assert stored[0]["data_fingerprint"] == stored[1]["data_fingerprint"]
    assert stored[0]["n_samples"] == 18
    samples = load_biotac(BIOTAC_DIR, "mat1,mat2,mat3", range(1, 9), 2.0, False)
    numbers = recording_numbers(samples)
    result = json.loads((out / "results.json").read_text())
    split = result["holdout"]
    assert split["tuned_on_recordings"] == [1, 2, 3, 4, 5, 6]
    assert split["tested_on_recordings"] == [7, 8]
    assert split["train_samples"] == int(np.sum(numbers <= 6))
    assert split["test_samples"] == int(np.sum(numbers >= 7))
    (best,) = result["networks"]
    scored = best["holdout"]
    assert np.array(scored["correct"]).shape == (1, split["test_samples"])
    assert scored["accuracy_ci"]["low"] <= scored["accuracy"] <= scored["accuracy_ci"]["high"]
    change = result["changes_vs_reference"]["best"]
    assert change["mean"] == pytest.approx(
        scored["accuracy"] - result["reference"]["holdout"]["accuracy"]
    )
    # a chip study also scores the reference off the chip, paired with it on the chip
    off = result["reference_off_chip"]
    assert np.array(off["correct"]).shape == (1, split["test_samples"])
    cost = result["chip_cost_of_reference"]
    assert cost["mean"] == pytest.approx(
        result["reference"]["holdout"]["accuracy"] - off["accuracy"]
    )
    fraction = result["recovered_fraction"]["best"]
    assert result["changes_vs_reference_off_chip"]["best"]["mean"] == pytest.approx(
        scored["accuracy"] - off["accuracy"]
    )
    if cost["high"] < 0:
        assert fraction == pytest.approx(change["mean"] / -cost["mean"])
    else:
        assert fraction is None
    # --attribute: the reference on the chip with each parameter the chip changes kept exact
    reference = NetworkConfig.preset("biotac-vary-offset-lif").with_n(4).build()
    attribution = result["attribution"]
    assert tuple(attribution) == changed_parameters(reference, "loihi2")
    assert "tau_tde_fac" in attribution and "c_cco" not in attribution
    formats = result["reference_on_formats"]  # golden:profile=loihi2, the study's own backend
    assert formats["accuracy"] == result["reference"]["holdout"]["accuracy"]
    assert result["formats_cost_of_reference"]["mean"] == pytest.approx(
        formats["accuracy"] - off["accuracy"]
    )
    for name, row in attribution.items():
        assert row["change_vs_reference_on_formats"]["mean"] == pytest.approx(
            row["holdout"]["accuracy"] - formats["accuracy"]
        ), name
    summary = (out / "summary.md").read_text()
    assert "## Which parameter's format costs the accuracy" in summary
    assert "| `tau_tde_fac` |" in summary
    assert "tuned on recordings 1-6" in summary and "tested on recordings 7-8" in summary
    assert "held-out accuracy [%] (95 % CI)" in summary
    assert "## What the chip costs, and what tuning for it recovers" in summary
    capsys.readouterr()
    bad = tmp_path / "bad"  # recordings 1-2 left for 3 folds
    args = ["tune", *data, "--recordings", "1-8", "--holdout-recordings", "3-8", "--out", str(bad)]
    assert main(args) == 2
    assert "fewer recordings to tune on than the 3 CV folds" in capsys.readouterr().err
    assert not (bad / "study.db").exists()


@needs_biotac
def test_a_study_for_a_chip_variant_is_measured_against_the_chip_as_published(tmp_path):
    variant = tmp_path / "loihi2-40us.toml"
    variant.write_text(
        '[profile]\nbase = "loihi2"\nname = "loihi2-40us"\ndescription = "40 us steps"\n'
        "[fixed_point]\ndt = 4e-5\n"
    )
    out = tmp_path / "v"
    args = [
        "tune", "--dataset", "biotac", "--data", str(BIOTAC_DIR), "--classes", "mat1,mat2,mat3",
        "--encoders", "lif", "--n-spll", "4", "--folds", "3", "--repeats", "1", "--threads", "1",
        "--pruner", "none", "--per-class", "6", "--quiet", "--recordings", "1-8",
        "--holdout-recordings", "7-8", "--profiles", str(variant), "--trials", "1",
        "--compare", "biotac-vary-offset-lif", "--compare-profile", "loihi2", "--out", str(out),
    ]  # fmt: skip
    assert main(args) == 0
    result = json.loads((out / "results.json").read_text())
    assert result["compare_profile"] == "loihi2"
    published = result["reference_on_compare_profile"]
    on_variant = result["reference"]["holdout"]
    off = result["reference_off_chip"]
    assert np.array(published["correct"]).shape == np.array(on_variant["correct"]).shape
    # 40 us steps realise other decays than 10 us: the two chips score different spikes
    assert published["correct"] != on_variant["correct"] or published != on_variant
    assert result["chip_cost_of_reference"]["mean"] == pytest.approx(
        published["accuracy"] - off["accuracy"]
    )
    (best,) = result["networks"]
    change = result["changes_vs_reference"]["best"]  # against the reference on the variant
    assert change["mean"] == pytest.approx(best["holdout"]["accuracy"] - on_variant["accuracy"])
    # what moving the reference to the variant wins back, and what the tuned network does,
    # both against the reference on loihi2 as published
    shares = result["recovered_fraction"]
    assert set(shares) == {"reference", "best"}
    moved = result["changes_vs_reference_off_chip"]["reference"]
    assert moved["mean"] == pytest.approx(on_variant["accuracy"] - off["accuracy"])
    quantized = result["changes_vs_quantized_reference"]
    assert quantized["reference"]["mean"] == pytest.approx(
        on_variant["accuracy"] - published["accuracy"]
    )
    assert quantized["best"]["mean"] == pytest.approx(
        best["holdout"]["accuracy"] - published["accuracy"]
    )
    summary = (out / "summary.md").read_text()
    assert f"The study tuned for `{variant}`" in summary
    assert "change vs the reference on `loihi2` [points]" in summary


def test_recovery_is_the_share_of_the_references_chip_cost_a_network_wins_back():
    from spll_hw.classify import HoldoutResult
    from spll_hw.tune.final import Final, Network, recovery_lines

    recordings = np.repeat(np.arange(10), 8)  # 80 test samples of 10 recordings

    def scored(accuracy: float) -> HoldoutResult:
        correct = np.zeros((1, recordings.size))
        correct[0, : int(accuracy * recordings.size)] = 1.0
        return HoldoutResult(correct, recordings, np.eye(2), ("a", "b"))

    def final(off: float, ref: float, best: float) -> Final:
        reference = Network("reference", "reference: x", None, None, (0.5,))
        reference.holdout = scored(ref)
        tuned = Network("best", "best trial", None, None, (0.6,))
        tuned.holdout = scored(best)
        return Final(("accuracy",), [tuned], reference=reference, reference_off_chip=scored(off))

    lossy = final(off=0.9, ref=0.5, best=0.7)  # the chip costs 40 points, tuning wins 20 back
    assert lossy.chip_cost().mean == pytest.approx(-0.4) and lossy.chip_cost().high < 0
    (won,) = lossy.recovery()
    assert won.network.label == "best" and won.on_chip.mean == pytest.approx(0.2)
    assert won.share == pytest.approx(0.5)
    assert won.against_off_chip.mean == pytest.approx(-0.2)  # 70 % on the chip against 90 % off
    text = "\n".join(recovery_lines(lossy, "loihi2"))
    assert "the chip costs it **-40.0" in text and "| best | +20.0" in text
    assert "| 50 % | -20.0" in text
    # a cost whose interval contains zero leaves nothing to recover
    tie = final(off=0.5, ref=0.5, best=0.6)
    assert tie.chip_cost().low <= 0 <= tie.chip_cost().high
    assert tie.recovery()[0].share is None
    assert "no loss is distinguishable" in "\n".join(recovery_lines(tie, "loihi2"))
    # --compare-profile: the study tuned for a variant of the chip; cost and recovery are
    # measured against the reference quantized on the chip as published
    variant = final(off=0.9, ref=0.8, best=0.7)  # the reference scores 80 % on the variant
    variant.baseline_profile, variant.reference_on_baseline = "loihi2", scored(0.5)
    assert variant.chip_cost().mean == pytest.approx(-0.4)
    moved, won = variant.recovery()  # the reference on the variant, untuned, comes first
    assert moved.network.label == "reference" and moved.share == pytest.approx(0.75)
    assert won.on_chip.mean == pytest.approx(0.2) and won.share == pytest.approx(0.5)
    text = "\n".join(recovery_lines(variant, "loihi2-40us"))
    assert "50.0 [" in text and "% on `loihi2`; the chip costs it **-40.0" in text
    assert "The study tuned for `loihi2-40us`, where the reference scores 80.0 [" in text
    assert "change vs the reference on `loihi2` [points]" in text
    assert "| reference | +30.0 [" in text and "| 75 % |" in text
    # no off-chip score (not a chip study): no section
    plain = final(0.9, 0.5, 0.7)
    plain.reference_off_chip = None
    assert plain.recovery() == [] and recovery_lines(plain, None) == []


def test_the_compare_profile_replaces_the_studys_in_every_chip_draw():
    from spll_hw.tune.chip import baseline_specs

    specs = ("golden-fixed-point:profile=loihi2:dt=4e-05",)
    assert baseline_specs(specs, "loihi1") == ("golden-fixed-point:profile=loihi1:dt=4e-05",)
    draws = ("golden:profile=analog:chip_seed=0", "golden:profile=analog:chip_seed=1")
    assert baseline_specs(draws, "dynapse2") == (
        "golden:profile=dynapse2:chip_seed=0", "golden:profile=dynapse2:chip_seed=1",
    )  # fmt: skip
    with pytest.raises(ValueError, match="unknown profile 'loihi9'"):
        baseline_specs(specs, "loihi9")
    with pytest.raises(ValueError, match="analog"):  # no integer arithmetic to run
        baseline_specs(specs, "analog")


def test_attribution_is_the_share_of_the_chip_cost_one_parameter_explains():
    from spll_hw.classify import HoldoutResult
    from spll_hw.tune.final import Final, Network, attribution_lines

    recordings = np.repeat(np.arange(10), 8)

    def scored(accuracy: float) -> HoldoutResult:
        correct = np.zeros((1, recordings.size))
        correct[0, : int(accuracy * recordings.size)] = 1.0
        return HoldoutResult(correct, recordings, np.eye(2), ("a", "b"))

    reference = Network("reference", "reference: x", None, None, (0.5,))
    reference.holdout = scored(0.45)  # on the chip's arithmetic
    final = Final(("accuracy",), [], reference=reference, reference_off_chip=scored(0.9),
                  formats_only=scored(0.5),
                  attribution=[("tau_tde_fac", scored(0.8)), ("g_cco", scored(0.5))])  # fmt: skip
    assert final.formats_cost().mean == pytest.approx(-0.4)
    fac, gain = final.attribution_changes()  # against the formats, not the arithmetic
    assert fac.parameter == "tau_tde_fac" and fac.change.mean == pytest.approx(0.3)
    assert fac.share == pytest.approx(0.75)  # 30 of the 40 points the formats cost
    assert gain.change.mean == pytest.approx(0.0) and gain.share == pytest.approx(0.0)
    text = "\n".join(attribution_lines(final))
    assert "the reference scores 50.0 [" in text and "-40.0 [" in text
    assert "| `tau_tde_fac` | 80.0" in text and "| +30.0" in text and "| 75 % |" in text
    # formats that cost nothing distinguishable have no share to explain; no attribution, no
    # section
    final.reference_off_chip = scored(0.5)
    assert all(a.share is None for a in final.attribution_changes())
    final.attribution = []
    assert attribution_lines(final) == []


def test_multi_objective_studies_run_without_a_pruner_and_may_use_nsga2():
    from spll_hw.tune.study import StudySettings, _sampler_and_pruner

    tpe = StudySettings("sqlite:///x.db", "s", 4, startup_trials=6)
    sampler, pruner = _sampler_and_pruner(tpe, 1, multi_objective=True)
    assert isinstance(sampler, optuna.samplers.TPESampler)
    assert isinstance(pruner, optuna.pruners.NopPruner)  # Optuna's pruners take one value
    assert isinstance(_sampler_and_pruner(tpe, 0)[1], optuna.pruners.MedianPruner)
    nsga = StudySettings("sqlite:///x.db", "s", 4, startup_trials=6, sampler="nsga2")
    sampler, _ = _sampler_and_pruner(nsga, 0, multi_objective=True)
    assert isinstance(sampler, optuna.samplers.NSGAIISampler)
    assert sampler._population_size == 6
    with pytest.raises(ValueError, match="population"):
        StudySettings("sqlite:///x.db", "s", 4, startup_trials=1, sampler="nsga2")


def test_a_resumed_study_does_not_replay_its_first_random_networks(tmp_path):
    out = tmp_path / "resumed"
    args = ["tune", *TINY, "--pruner", "none", "--startup-trials", "4", "--out", str(out)]
    assert main([*args, "--trials", "2", "--study", "r"]) == 0
    assert main([*args, "--trials", "4", "--study", "r", "--resume"]) == 0
    params = [tuple(sorted(t.params.items())) for t in finished_trials(load(out, "r"))]
    assert len(params) == 4 and len(set(params)) == 4  # the same seed would redraw #0 and #1
