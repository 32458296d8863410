"""``spll-hw tune --network FILE``: a multichannel file's tables tuned with the single
network's objective, study and storage, the whole file written back."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("optuna")

from spll_hw.cli.main import main  # noqa: E402
from spll_hw.datasets.biotac_channels import load_biotac_channels  # noqa: E402
from spll_hw.multichannel.config import MultichannelConfig  # noqa: E402
from spll_hw.multichannel.features import channel_features, input_levels  # noqa: E402
from spll_hw.tune.multichannel import (  # noqa: E402
    SEP,
    MultichannelObjective,
    TableSpaces,
    first_params,
    start_params,
    table_numbers,
    table_space,
)
from spll_hw.tune.objective import ObjectiveSettings  # noqa: E402
from spll_hw.tune.space import SearchSpace, constraint_values  # noqa: E402

from .test_multichannel_data import ROW_TABLE, write_recording  # noqa: E402

ROWS = ROW_TABLE

#: pac through a preset by name, the temperatures and the electrodes each through a small
#: network; the electrodes' space leaves out the file's f_end (45 Hz), so every trial of a
#: study on them differs from the file.
FILE = f"""
[[channel]]
channels = ["pac"]
network = "biotac-tuned-time-scaled-lif"

[[channel]]
channels = ["tac", "tdc"]
{ROWS}
[[channel]]
channels = ["ele1", "ele2"]
{ROWS}
[channel.space]
f_start = {{ low = 0.5, high = 5.0 }}
f_end = {{ low = 15.0, high = 30.0 }}
beta = {{ choices = [1, inf] }}
"""

CLASSES = ["mat1", "mat2", "mat20"]


@pytest.fixture
def fake_root(tmp_path):
    for folder in CLASSES:
        for n in (1, 2, 3, 4):
            write_recording(tmp_path, folder, n, rows=120 + 7 * n)
    return tmp_path


@pytest.fixture
def file(tmp_path):
    path = tmp_path / "mc.toml"
    path.write_text(FILE)
    return path


def tune_args(file, root, out, *extra) -> list[str]:
    return [
        "tune", "--network", str(file), "--data", str(root), "--classes", ",".join(CLASSES),
        "--recordings", "1-4", "--duration", "1", "--folds", "2", "--phase-noise", "0",
        "--quiet", "--out", str(out), *extra,
    ]  # fmt: skip


def test_tiny_study_writes_the_whole_file_with_only_the_tuned_table_changed(
    file, fake_root, tmp_path, capsys
):
    out = tmp_path / "study"
    args = tune_args(file, fake_root, out, "--groups", "ele2", "--trials", "2")
    assert main([*args, "--holdout-recordings", "4"]) == 0
    assert "note: " in capsys.readouterr().err  # the file's f_end lies outside the space
    given = MultichannelConfig.load(file)
    tuned = MultichannelConfig.load(out / "best.toml")
    assert [g.channels for g in tuned.groups] == [g.channels for g in given.groups]
    for old, new in zip(given.groups[:2], tuned.groups[:2], strict=True):
        assert (new.network, new.encoder, new.input_level, new.space) == (
            old.network, old.encoder, old.input_level, old.space,
        )  # fmt: skip
    assert tuned.groups[0].source == "biotac-tuned-time-scaled-lif"  # still named
    old, new = given.groups[2], tuned.groups[2]
    assert new.network != old.network and 15.0 <= new.network.f_end <= 30.0
    assert (new.network.layout, new.network.n) == (old.network.layout, old.network.n)
    assert (new.encoder, new.space) == (old.encoder, old.space)
    results = json.loads((out / "results.json").read_text())
    assert results["tuned_tables"] == [3]
    assert results["holdout"]["tested_on_recordings"] == [4]
    best, reference = results["networks"][0], results["reference"]
    assert best["holdout"]["test_recordings"] == reference["holdout"]["test_recordings"] == 3
    assert "best" in results["changes_vs_reference"]
    summary = (out / "summary.md").read_text()
    assert "tuned: table 3 (ele1, ele2, 2 channels): 2 x 4 sPLLs" in summary
    assert "| 3:f_end |" in summary and "## Held-out recordings" in summary
    # the same study resumed with its target reached only rewrites the report
    assert main([*args, "--holdout-recordings", "4", "--resume"]) == 0
    assert MultichannelConfig.load(out / "best.toml") == tuned


def test_study_features_are_the_slide_features(file, fake_root):
    config = MultichannelConfig.load(file)
    samples = load_biotac_channels(fake_root, config.channels, CLASSES, duration=1.0).openings()
    settings = ObjectiveSettings(phase_noise=0.0, folds=2)
    objective = MultichannelObjective(config, [2, 3], samples, settings)
    everything = np.arange(len(samples))
    x = objective.rates(config, objective.draws({})[0], everything)
    levels = input_levels(config, samples)
    expected = np.concatenate(
        [channel_features(samples, c, g, levels[c]) for g in config.groups for c in g.channels],
        axis=1,
    )
    np.testing.assert_array_equal(x, expected)
    assert x.shape == (len(samples), config.n_spll) == (12, 50 + 2 * 4 + 2 * 4)
    # a trial's network: only the tuned tables change; constraints are the worst table's
    params, outside = start_params(config, objective.space)
    assert outside == [  # table 2 has no [channel.space]: Table 5's frequencies
        f"2{SEP}f_start = 2 ([30, 100] linear)",
        f"2{SEP}f_end = 45 ([300, 700] linear)",
        f"3{SEP}f_end = 45 ([15, 30] linear)",
    ]
    given = {f"2{SEP}f_start": 2.0, f"2{SEP}f_end": 45.0}  # table 2 as the file has it
    trial = objective.config(params | given | {f"3{SEP}f_end": 20.0})
    assert trial.groups[0] == config.groups[0]
    assert trial.groups[1].network == config.groups[1].network
    assert trial.groups[2].network.f_end == 20.0
    each = [constraint_values(trial.groups[k].network) for k in (1, 2)]
    assert objective.constraints(trial) == tuple(np.max(each, axis=0))


def test_table_spaces_join_the_tables_parameters(file):
    config = MultichannelConfig.load(file)
    spaces = TableSpaces({2: table_space(config, 2), 3: table_space(config, 3)})
    assert f"2{SEP}tau_cco" in spaces.dims and f"3{SEP}beta" in spaces.dims
    assert spaces.dims[f"3{SEP}f_end"].high == 30.0
    assert spaces.dims[f"2{SEP}f_end"] == SearchSpace.table5().dims["f_end"]
    assert spaces.of({f"3{SEP}g_cco": 2.0, f"2{SEP}g_cco": 3.0}, 3) == {"g_cco": 2.0}
    assert table_numbers(config, ["ele2", "1", "tdc"], "--groups") == [1, 2, 3]


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--groups", "4"], r"--groups: '4' is neither .* has table 1 \(pac\); table 2"),
        (["--groups", "ele5"], "'ele5' is neither a"),
        (["--groups", ","], "--groups: name at least one table"),
        (["--space", "s.toml"], "--space: not with a multichannel --network"),
        (["--layouts", "time-scaled", "--n-spll", "8"], "--layouts, --n-spll: not with"),
        (["--profiles", "loihi2"], "--profiles: not with a multichannel --network"),
        (["--backend", "golden:profile=loihi2"], "simulates chip profile loihi2"),
    ],
)
def test_bad_options_are_refused_before_any_work(file, tmp_path, capsys, extra, message):
    out = tmp_path / "o"
    assert main(tune_args(file, tmp_path / "nowhere", out, *extra)) == 2
    assert __import__("re").search(message, capsys.readouterr().err)
    assert not out.exists()


@pytest.mark.parametrize("flag", [["--groups", "2"], ["--per-channel"]])
def test_groups_and_per_channel_need_a_multichannel_file(capsys, flag):
    assert main(["tune", *flag, "--quiet"]) == 2
    assert f"{flag[0]} tunes tables of a multichannel file" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("space", "message"),
    [
        ("f_start = 2.0\nf_end = 45.0\nbeta = 1.0\ntau_cco_syn = 0.05\ntau_cco = 0.06\n"
         "tau_tde_trg = 0.001\ntau_tde_fac = 0.02\ntau_tde = 0.02\ng_cco = 9.8\n"
         "g_tde_trg = 0.35\ng_tde_fac = 3450.0", "fixes every parameter, so there is nothing"),
        ('"lif.gain" = { low = 100.0, high = 1000.0, log = true }', "tunes encoder parameter"),
    ],
)  # fmt: skip
def test_a_table_without_anything_to_tune_is_named(tmp_path, capsys, space, message):
    path = tmp_path / "mc.toml"
    path.write_text(f'[[channel]]\nchannels = ["ele1"]\n{ROWS}\n[channel.space]\n{space}\n')
    assert main(tune_args(path, tmp_path, tmp_path / "o")) == 2
    err = capsys.readouterr().err
    assert message in err and f"{path} table 1 (ele1)" in err


def test_a_bad_space_table_is_refused_when_the_file_is_read(tmp_path):
    path = tmp_path / "mc.toml"
    reversed_range = "tau_cco = { low = 0.5, high = 0.05 }"
    path.write_text(
        f'[[channel]]\nchannels = ["ele1"]\n{ROWS}\n[channel.space]\n{reversed_range}\n'
    )
    with pytest.raises(
        ValueError, match=r"1 \[channel.space\]: search space: tau_cco: reversed range"
    ):
        MultichannelConfig.load(path)


def test_to_toml_reads_back_equal_groups(tmp_path):
    given = MultichannelConfig.load("biotac-multichannel-lif")
    path = tmp_path / "again.toml"
    path.write_text(given.to_toml("# a header\n"))
    again = MultichannelConfig.load(path)
    assert again.groups == given.groups
    assert given.groups[1].space == {"f_start": {"low": 0.5, "high": 5.0},
                                     "f_end": {"low": 15.0, "high": 50.0}}  # fmt: skip


def test_split_gives_one_table_per_channel_and_the_same_features(file, fake_root):
    config = MultichannelConfig.load(file)
    split, numbers = config.split([3, 2])
    assert numbers == [2, 3, 4, 5]
    assert [g.channels for g in split.groups] == [("pac",), ("tac",), ("tdc",), ("ele1",),
                                                  ("ele2",)]  # fmt: skip
    assert split.groups[3].network == split.groups[4].network == config.groups[2].network
    assert split.groups[4].space == config.groups[2].space
    assert split.channels == config.channels and split.n_spll == config.n_spll
    samples = load_biotac_channels(fake_root, config.channels, CLASSES, duration=1.0).openings()
    settings = ObjectiveSettings(phase_noise=0.0, folds=2)
    everything = np.arange(len(samples))
    whole = MultichannelObjective(config, [3], samples, settings)
    each = MultichannelObjective(split, [4], samples, settings, retunable=[5])
    np.testing.assert_array_equal(
        each.rates(split, each.draws({})[0], everything),
        whole.rates(config, whole.draws({})[0], everything),
    )


def test_focus_moves_the_tuned_table_and_simulates_only_changed_networks(file, fake_root):
    split, (ele1, ele2) = MultichannelConfig.load(file).split([3])
    samples = load_biotac_channels(fake_root, split.channels, CLASSES, duration=1.0).openings()
    settings = ObjectiveSettings(phase_noise=0.0, folds=2)
    objective = MultichannelObjective(split, [ele1], samples, settings, retunable=[ele2])
    draw = objective.draws({})[0]
    assert set(draw.trains) == {ele1, ele2} and set(draw.fixed) == {1, 2, ele2}
    tuned = objective.config({f"{ele1}{SEP}f_end": 20.0} | first_params(objective)[0])
    assert tuned.groups[ele1 - 1].network.f_end == 20.0
    cached = {k: draw.fixed[k] for k in (1, 2)}
    objective.focus(ele2, tuned)
    assert objective.tuned == (ele2,) and set(objective.space.tables) == {ele2}
    assert set(draw.fixed) == {1, 2, ele1} and draw.networks[ele1] == tuned.groups[ele1 - 1].network
    assert all(draw.fixed[k] is cached[k] for k in (1, 2))  # not simulated again
    fresh = MultichannelObjective(tuned, [ele2], samples, settings)
    everything = np.arange(len(samples))
    expected = fresh.rates(tuned, fresh.draws({})[0], everything)
    np.testing.assert_array_equal(objective.rates(tuned, draw, everything), expected)
    # a file whose kept table differs from the cache is simulated, not read from the cache
    given = MultichannelObjective(split, [ele1, ele2], samples, settings)
    np.testing.assert_array_equal(
        objective.rates(split, draw, everything),
        given.rates(split, given.draws({})[0], everything),
    )
    # ... and one whose trains are not kept is refused, not read from a stale cache
    with pytest.raises(ValueError, match=f"table {ele1} .ele1. has another network"):
        fresh.rates(split, fresh.draws({})[0], everything)
    with pytest.raises(ValueError, match="table 2 is not among the tables"):
        objective.focus(2, tuned)


def test_per_channel_tunes_each_channel_in_turn_and_never_loses_cv(fake_root, tmp_path):
    path = tmp_path / "mc.toml"
    path.write_text(FILE.replace("high = 30.0", "high = 50.0"))  # the file's f_end inside
    out = tmp_path / "each"
    args = tune_args(path, fake_root, out, "--groups", "ele1", "--per-channel", "--trials", "2",
                     "--constraints", "off", "--holdout-recordings", "4")  # fmt: skip
    assert main(args) == 0
    given = MultichannelConfig.load(path)
    tuned = MultichannelConfig.load(out / "best.toml")
    assert [g.channels for g in tuned.groups] == [("pac",), ("tac", "tdc"), ("ele1",), ("ele2",)]
    assert tuned.groups[:2] == given.groups[:2]
    results = json.loads((out / "results.json").read_text())
    first, second = results["per_channel"]
    assert (first["channel"], second["channel"]) == ("ele1", "ele2")
    assert first["trials"] == second["trials"] == 2
    assert first["study"].endswith("-ele1") and second["study"].endswith("-ele2")
    assert first["start"] <= first["best"] == second["start"] <= second["best"]
    assert results["reference"]["values"][0] == pytest.approx(first["start"])
    assert results["networks"][0]["values"][0] == pytest.approx(second["best"])
    assert results["holdout"]["tested_on_recordings"] == [4]
    summary = (out / "summary.md").read_text()
    assert "## Channel by channel" in summary and "| ele2 | 4 |" in summary
    assert "## Best file: CV accuracy" in summary
    assert (out / "best.toml").read_text().startswith("# spll-hw tune --network --per-channel")
    # the channels' studies are seeded apart: their first sampled trials differ
    optuna = pytest.importorskip("optuna")
    storage = f"sqlite:///{out / 'study.db'}"
    sampled = [
        optuna.load_study(study_name=row["study"], storage=storage).trials[1].params
        for row in (first, second)
    ]
    assert list(sampled[0].values()) != list(sampled[1].values())
