"""Chips as resources and costs: the profile tables, placement, exact event counts, energy."""

from __future__ import annotations

import numpy as np
import pytest

from quantize import ProfileError, available_profiles, load_profile, parse_profile
from quantize.chip_tables import CHIP_KEYS
from quantize.resources import ChipError, event_counts, resource_report, sample_cost
from spll_hw import Network, SpllParams, chips, network_frequencies, simulate
from spll_hw.config import read_network_file
from spll_hw.result import SimulationResult

from .test_quantize_profiles import LOIHI

BASE = SpllParams(
    tau_cco_syn=7.50e-3, tau_cco=0.314, tau_tde_trg=1.25e-3, tau_tde_fac=9.59e-3,
    tau_tde=4.52e-3, g_cco=9.84, g_tde_trg=0.271, g_tde_fac=6.15e2,
)  # fmt: skip

RESOURCES = """
[resources]
chips = { value = 1, source = "test" }
cores_per_chip = { value = 4, source = "test" }
neurons_per_core = { value = 3, source = "test" }
tde_compartments = { value = 1, source = "assumed: test" }
cores_per_tile = { value = 1, source = "test" }
mesh_columns = { value = 1, source = "test" }
"""
TIMING = """
[timing]
neuron_update = { value = 1e-8, source = "test" }
synaptic_event = { value = 2e-9, source = "test" }
spike = { value = 3e-9, source = "test" }
message = { value = 4e-9, source = "test" }
hop = { value = 5e-9, source = "test" }
barrier = { value = 1e-7, source = "test" }
realtime_paced = { value = false, source = "test" }
"""
ENERGY = """
[energy]
neuron_update = { value = 1e-12, source = "test" }
synaptic_event = { value = 2e-12, source = "test" }
spike = { value = 3e-12, source = "test" }
message = { value = 5e-12, source = "test" }
hop = { value = 7e-12, source = "test" }
static_power = { value = 0.01, source = "assumed: test" }
"""
CHIP = LOIHI + RESOURCES + TIMING + ENERGY


def write(tmp_path, text: str, name: str = "chip.toml"):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def vary_offset(n: int) -> Network:
    return Network.vary_offset(BASE, network_frequencies(80.0, 400.0, n))


# ----------------------------------------------------------------------------------- schema
def test_chip_tables_parse_with_sources_and_assumed_marks():
    chip = parse_profile(CHIP, "chip.toml").chip
    assert chip.resources.value("neurons_per_core") == 3
    assert chip.timing.value("realtime_paced") is False
    assert chip.energy.figure("static_power").assumed
    assert chip.assumed() == ["resources.tde_compartments", "energy.static_power"]
    assert parse_profile(LOIHI).chip is None  # the tables stay optional


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (CHIP.replace('{ value = 3, source = "test" }', "3"),
         "chip.toml [resources]: neurons_per_core must be a figure with its source"),
        (CHIP.replace('neurons_per_core = { value = 3, source = "test" }',
                      "neurons_per_core = { value = 3 }"),
         "chip.toml [resources]: neurons_per_core has no source"),
        (CHIP.replace('neurons_per_core = { value = 3, source = "test" }',
                      'neurons_per_core = { value = 3, source = " " }'),
         "[resources]: neurons_per_core has no source"),
        (CHIP.replace('neurons_per_core = { value = 3, source = "test" }',
                      'neurons_per_core = { source = "x" }'),
         "[resources]: neurons_per_core has no value"),
        (CHIP.replace('neurons_per_core = { value = 3, source = "test" }',
                      'neurons_per_core = { value = 3, source = "x", unit = "n" }'),
         "[resources]: neurons_per_core has unknown key(s) ['unit']"),
        (CHIP.replace('neurons_per_core = { value = 3, source = "test" }', ""),
         "chip.toml [resources]: missing key(s) ['neurons_per_core']"),
        (CHIP.replace('{ value = 3, source = "test" }', '{ value = 0, source = "t" }'),
         "[resources]: neurons_per_core = 0 is impossible"),
        (CHIP.replace('{ value = 3, source = "test" }', '{ value = 2.5, source = "t" }'),
         "[resources]: neurons_per_core must be an integer"),
        (CHIP + 'cores_per_rack = { value = 1, source = "t" }\n',
         "chip.toml [energy]: unknown key(s) ['cores_per_rack']"),
        (CHIP.replace("barrier = { value = 1e-7", "barrier = { value = -1e-7"),
         "chip.toml [timing]: barrier = -1e-07 must be a finite number >= 0"),
        (CHIP.replace("static_power = { value = 0.01", 'static_power = { value = "high"'),
         "[energy]: static_power must be a number"),
        (CHIP.replace("realtime_paced = { value = false", "realtime_paced = { value = 1"),
         "[timing]: realtime_paced must be true or false"),
        (CHIP.replace("[resources]", '[resources]\nconfigs_per_core = { value = 2, source = "t" }'
                      '\nconfig_shares = { value = ["decay", "colour"], source = "t" }'),
         "[resources]: config_shares must be a list of distinct groups"),
        (CHIP.replace("[resources]",
                      '[resources]\nconfig_shares = { value = ["decay"], source = "t" }'),
         "[resources]: config_shares needs configs_per_core"),
        (CHIP.replace("[resources]",
                      '[resources]\nthresholds_per_core = { value = 2, source = "t" }'),
         "config_shares must not contain 'threshold'"),
        (LOIHI + "[timing]\nbarrier = 3\n",
         "chip.toml [resources]: missing key(s) ['chips', 'cores_per_chip'"),
        (LOIHI + "timing = 3\n", "chip.toml [fixed_point]: unknown key(s) ['timing']"),
    ],
)  # fmt: skip
def test_chip_table_errors_name_file_table_and_key(text, message):
    with pytest.raises(ProfileError) as err:
        parse_profile(text, "chip.toml")
    assert message in str(err.value)


@pytest.mark.parametrize("name", ["loihi1", "loihi2", "spinnaker", "dynapse2"])
def test_bundled_chips_give_a_source_for_every_figure(name):
    chip = load_profile(name).chip
    assert chip is not None
    for table in chip.tables():
        for key, figure in table.figures:
            assert key in CHIP_KEYS[table.table]
            assert len(figure.source) > 5, f"{name} {table.table}.{key}"
    listed = chips.figures(name)
    assert listed and all(f.source for f in listed)
    assert {f"{f.table}.{f.key}" for f in listed if f.assumed} == set(chip.assumed())


def test_bundled_chip_figures_are_the_published_ones():
    loihi = load_profile("loihi1").chip
    assert loihi.energy.value("synaptic_event") == 23.6e-12  # Davies et al. 2018, Table 2
    assert loihi.energy.value("neuron_update") == 81e-12
    assert loihi.timing.value("synaptic_event") == 3.5e-9
    assert (loihi.resources.value("neurons_per_core"), loihi.resources.value("cores_per_chip"))\
        == (1024, 128)  # fmt: skip
    assert loihi.resources.value("fan_in_per_core") == loihi.resources.value(
        "fan_out_per_core"
    ) == 4096  # fmt: skip
    assert load_profile("loihi2").chip.resources.value("cores_per_chip") == 128
    spinnaker = load_profile("spinnaker")
    assert spinnaker.chip.energy.value("message") == 0.8e-9 and spinnaker.dt == 1e-4
    dynap = load_profile("dynapse2").chip.resources
    assert (dynap.value("cores_per_chip"), dynap.value("neurons_per_core")) == (4, 256)
    assert dynap.value("synapses_per_neuron") == 64 and dynap.value("configs_per_core") == 1
    # Per-event energies of Loihi 2 and DYNAP-SE2 are not public: marked assumed.
    assert "energy.synaptic_event" in load_profile("loihi2").chip.assumed()
    assert "energy.synaptic_event" in load_profile("dynapse2").chip.assumed()
    assert {"analog", "fixed16"} <= set(available_profiles())


# ---------------------------------------------------------------------------- placement
def test_profile_without_resources_is_refused_clearly():
    with pytest.raises(ChipError, match="has no \\[resources\\] table"):
        resource_report(vary_offset(2), "fixed16")
    with pytest.raises(ValueError, match="has no \\[resources\\] table"):
        chips.resources(chips.OnChip(vary_offset(2), "analog"))


def test_reference_network_fits_one_loihi_core():
    fit = chips.resources(chips.OnChip(vary_offset(50), "loihi1"))
    rep = fit.detail
    assert fit.fits and fit.cores == 1 and fit.chips == 1
    assert (rep.neurons, rep.compartments, rep.synapses) == (100, 150, 150)
    assert (rep.tde_configs, rep.cco_configs, rep.thresholds) == (1, 1, 1)
    assert rep.cores[0].configs == 3  # two TDE compartments + the CCO
    assert rep.cores[0].fan_in == 101 and rep.cores[0].fan_out == 100
    assert "resources.tde_compartments" in fit.assumed
    assert "Assumed figures: resources.chips, resources.tde_compartments" in fit.markdown


def test_dynapse2_holds_a_vary_offset_network_on_one_bias_set_per_core(tmp_path):
    from pathlib import Path

    import quantize

    fit = chips.resources(chips.OnChip(vary_offset(50), "dynapse2"))
    # Mismatch is the device, not a configuration: all 50 TDEs share one bias set (one core),
    # the CCOs' offsets are snapped to the 3 DC biases of the other three cores.
    assert fit.detail.tde_configs == 1 and fit.detail.cco_configs == 3
    assert fit.fits and fit.cores == 4
    # with a fourth offset level the TDEs' core is missing
    text = (Path(quantize.__file__).parent / "profiles" / "dynapse2.toml").read_text()
    four = text.replace("offset_levels = 3 ", "offset_levels = 4 ")
    assert four != text
    fit = chips.resources(chips.OnChip(vary_offset(50), str(write(tmp_path, four))))
    assert fit.detail.cco_configs == 4 and not fit.fits and fit.cores == 5
    assert fit.problems == (
        "needs 5 cores for 5 distinct decay/threshold/refractory/offset/gain configurations "
        "(1 TDE x 1 compartment(s) + 4 CCO; 1 per core), the profile allows 4 (1 chip(s) x 4 "
        "cores)",
    )
    assert "does not fit: needs 5 cores" in fit.markdown


def test_time_scaled_network_runs_out_of_configurations(tmp_path):
    text = CHIP.replace(
        "[resources]",
        '[resources]\nconfigs_per_core = { value = 2, source = "t" }\n'
        'config_shares = { value = ["decay", "refractory", "threshold"], source = "t" }',
    ).replace("neurons_per_core = { value = 3", "neurons_per_core = { value = 100")
    net = Network.time_scaled(BASE, network_frequencies(80.0, 400.0, 6))
    fit = resource_report(net, write(tmp_path, text))
    assert (fit.tde_configs, fit.cco_configs) == (6, 6) and fit.n_cores == 6
    assert fit.problems == (
        "needs 6 cores for 12 distinct decay/refractory/threshold configurations (6 TDE x 1 "
        "compartment(s) + 6 CCO; 2 per core), the profile allows 4 (1 chip(s) x 4 cores)",
    )
    # The same network fits as vary-offset: one configuration per neuron type.
    assert resource_report(vary_offset(6), write(tmp_path, text)).fits


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"tde_compartments": 2, "neurons_per_core": 1},
         "it needs 2 compartments, the profile allows 1 (neurons_per_core)"),
        ({"tde_compartments": 2, "configs_per_core": 1},
         "it needs 2 configurations, the profile allows 1 (configs_per_core)"),
        ({"synapses_per_core": 1}, "it needs 2 synapses, the profile allows 1 (synapses_per_core)"),
    ],
)  # fmt: skip
def test_a_tde_bigger_than_a_core_is_a_problem_not_an_overfull_core(tmp_path, changes, message):
    text = CHIP
    for key, value in changes.items():
        line = f'{key} = {{ value = {value}, source = "t" }}'
        if f"{key} = " in text:
            text = "\n".join(line if x.startswith(f"{key} = ") else x for x in text.splitlines())
        else:
            text = text.replace("[resources]", f"[resources]\n{line}")
    fit = resource_report(vary_offset(3), write(tmp_path, text))
    assert not fit.fits and fit.n_cores == 0
    assert fit.problems[0].startswith("a TDE of") and message in fit.problems[0]


def test_unrealisable_network_is_a_problem_not_a_crash():
    net = Network.time_scaled(BASE, network_frequencies(80.0, 400.0, 6))
    fit = resource_report(net, "dynapse2")
    assert not fit.fits and not fit.cores and "distinct sPLL circuits" in fit.problems[0]
    with pytest.raises(ValueError, match="no placement"):
        event_counts(fit, np.zeros(6), np.zeros(6), 10, 1.0, None)


# ------------------------------------------------------------------------ exact counts
def brute_force(net, result, train, core_of_tde, core_of_cco, position, multicast):
    """Walk every spike of ``result``: deliveries, messages, crossings and hops per type,
    routes X-then-Y between the ``(x, y)`` ``position`` of each core, the input from core 0."""
    counts = {"deliveries": 0, "messages": 0, "crossing": 0, "hops": 0}

    def route(a, b):
        (x0, y0), (x1, y1) = position(a), position(b)
        edges = [((x, y0), (x + 1, y0)) for x in range(min(x0, x1), max(x0, x1))]
        return edges + [((x1, y), (x1, y + 1)) for y in range(min(y0, y1), max(y0, y1))]

    tde_cores = sorted(set(core_of_tde))
    for _ in train:
        counts["deliveries"] += net.n_spll
        counts["messages"] += 1 if multicast else len(tde_cores)
        counts["crossing"] += 1 if multicast else len(tde_cores)
        paths = [route(0, c) for c in tde_cores]
        counts["hops"] += len({e for p in paths for e in p}) if multicast else sum(map(len, paths))
    for i in range(net.n_spll):
        for spikes, src, dst in (
            (result.cco_spikes[i], core_of_cco[i], core_of_tde[i]),
            (result.tde_spikes[i], core_of_tde[i], core_of_cco[i]),
        ):
            for _ in spikes:
                counts["deliveries"] += 1
                counts["messages"] += 1
                counts["crossing"] += int(src != dst)
                counts["hops"] += len(route(src, dst))
    return counts  # fmt: skip


@pytest.mark.parametrize(
    ("per_core", "columns", "multicast"),
    [(3, 1, "false"), (2, 1, "false"), (2, 2, "true"), (4, 2, "false")],
)
def test_event_counts_equal_a_brute_force_walk_over_the_spikes(
    tmp_path, per_core, columns, multicast
):
    text = (
        CHIP.replace("neurons_per_core = { value = 3", f"neurons_per_core = {{ value = {per_core}")
        .replace("mesh_columns = { value = 1", f"mesh_columns = {{ value = {columns}")
        .replace("[timing]", f'multicast = {{ value = {multicast}, source = "t" }}\n\n[timing]')
    )
    net = vary_offset(4)
    rng = np.random.default_rng(1)
    train = np.sort(rng.uniform(0, 0.3, 90))
    result = simulate(net, train, 0.3, record_spikes=True)
    rep = resource_report(net, write(tmp_path, text))
    counts = event_counts(rep, result.tde_counts, result.cco_counts, train.size, 0.3, 1e-5)
    expect = brute_force(
        net, result, train, rep.tde_core, rep.cco_core,
        lambda c: (c % columns, c // columns), multicast == "true",
    )  # fmt: skip
    assert counts.synaptic_events == expect["deliveries"]
    assert counts.total("messages") == expect["messages"]
    assert sum(counts.crossing.values()) == expect["crossing"]
    assert counts.total("hops") == expect["hops"]
    assert counts.spikes == sum(map(len, result.tde_spikes)) + sum(map(len, result.cco_spikes))
    assert counts.neuron_updates == rep.compartments * 30_000 and counts.steps == 30_000
    if per_core == 2:  # one sPLL per core: TDE and CCO together, nothing crosses but the input
        assert counts.crossing["trigger"] == counts.crossing["feedback"] == 0
    if per_core == 3:  # sPLL 1 is split over cores 0 and 1
        assert list(rep.tde_core) == [0, 0, 1, 2] and list(rep.cco_core) == [0, 1, 1, 2]
        assert counts.crossing["trigger"] == result.cco_counts[1]


# ------------------------------------------------------------------------------- energy
def test_energy_and_latency_equal_the_hand_computed_values(tmp_path):
    profile = write(tmp_path, CHIP)
    rep = resource_report(vary_offset(1), profile)
    assert rep.n_cores == 1 and rep.compartments == 2
    cost = sample_cost(rep, profile, np.array([3]), np.array([5]), 7, 1e-3)  # dt = 10 us
    steps, updates = 100, 200
    events = 7 + 5 + 3  # input, trigger, feedback deliveries
    assert cost.energy["input deliveries"] == pytest.approx(7 * 2e-12)
    assert cost.energy["trigger deliveries"] == pytest.approx(5 * 2e-12)
    assert cost.energy["feedback deliveries"] == pytest.approx(3 * 2e-12)
    assert cost.energy["spikes"] == pytest.approx(8 * 3e-12)
    assert cost.energy["messages"] == pytest.approx(15 * 5e-12)
    assert cost.energy["hops"] == 0 and cost.energy["chip hops"] is None
    assert cost.energy["neuron updates"] == pytest.approx(updates * 1e-12)
    step = 2 * 1e-8 + (events * 2e-9 + 8 * (3e-9 + 4e-9)) / steps + 1e-7
    assert cost.step_latency == pytest.approx(step)
    assert cost.real_time_factor == pytest.approx(step / 1e-5) and cost.keeps_up
    assert cost.time_on_chip == pytest.approx(steps * step)
    # One static rule for every chip: powered for the whole window (it keeps up: 1 ms).
    assert cost.window == 1e-3 and cost.energy["static"] == pytest.approx(0.01 * 1e-3)
    assert cost.energy["cores"] is None
    dynamic = (events * 2 + 8 * 3 + 15 * 5 + updates * 1) * 1e-12
    assert cost.total_energy == pytest.approx(dynamic + 0.01 * 1e-3)
    # The same energy as figure counts x figures.
    assert cost.figure_counts == {"synaptic_event": events, "spike": 8, "message": 15, "hop": 0,
                                  "neuron_update": updates}  # fmt: skip
    assert cost.assumed == ("resources.tde_compartments", "energy.static_power")
    assert "not modelled" in cost.markdown() and "energy.static_power" in cost.markdown()
    # Only the static power is assumed: the dynamic energy rests on sourced figures alone.
    assert cost.assumed_categories == ("static",)


def test_dynamic_energy_is_apart_from_static_power_with_its_assumed_share():
    net = vary_offset(2)
    result = simulate(net, np.linspace(0.01, 0.09, 9), 0.1)
    loihi1, loihi2 = (chips.cost(chips.OnChip(net, name), result) for name in ("loihi1", "loihi2"))
    for cost in (loihi1, loihi2):
        assert cost.dynamic_energy + cost.static_energy == pytest.approx(cost.total_energy)
    # Loihi 1: per-event costs from Davies et al. 2018, static power assumed; Loihi 2: every
    # per-event cost is Loihi 1's, marked assumed, beside its measured per-step energy.
    assert loihi1.assumed_dynamic_energy == 0 < loihi1.dynamic_energy
    assert loihi1.assumed_static_energy == loihi1.static_energy > 0
    steps = loihi2.energy["steps"]
    assert steps == pytest.approx(10_000 * 26.7e-9)  # 0.1 s at 10 us, measured on a board
    assert loihi2.assumed_dynamic_energy == pytest.approx(loihi2.dynamic_energy - steps)
    assert loihi2.assumed_static_energy == 0 < loihi2.static_energy
    # SpiNNaker's static and core power are sourced, and the chip is timer-paced and keeps
    # up: it spends the window on chip, whatever its (assumed) timing figures say.
    spinnaker = chips.cost(chips.OnChip(net, "spinnaker"), result)
    assert spinnaker.assumed_static_energy == 0 < spinnaker.static_energy


def test_timer_paced_chip_spends_the_duration_on_chip(tmp_path):
    text = CHIP.replace("realtime_paced = { value = false", "realtime_paced = { value = true")
    profile = write(tmp_path, text)
    rep = resource_report(vary_offset(1), profile)
    cost = sample_cost(rep, profile, np.array([3]), np.array([5]), 7, 1e-3)
    assert cost.time_on_chip == 1e-3 and cost.energy["static"] == pytest.approx(1e-5)


def test_analog_chip_is_event_driven_and_real_time():
    net = vary_offset(8)
    rep = resource_report(net, "dynapse2")
    cost = sample_cost(rep, "dynapse2", np.full(8, 2), np.full(8, 4), 10, 0.5)
    assert cost.counts.steps is None and cost.counts.neuron_updates == 10 * 8 + 32 + 16
    assert cost.step_latency is None and cost.real_time_factor == 1.0
    assert cost.energy["static"] == pytest.approx(1e-3 * rep.n_chips * 0.5)
    assert "energy.static_power" in cost.assumed


def test_cost_through_the_core_needs_the_input_count():
    net = vary_offset(2)
    result = simulate(net, np.linspace(0.01, 0.09, 9), 0.1)
    cost = chips.cost(chips.OnChip(net, "loihi1"), result)
    assert cost.detail.counts.input_deliveries == 18
    assert cost.total_energy == pytest.approx(sum(v for v in cost.energy.values() if v))
    bare = SimulationResult(result.tde_counts, result.cco_counts, 0.1, backend="board")
    with pytest.raises(ValueError, match="n_input_spikes"):
        chips.cost(chips.OnChip(net, "loihi1"), bare)


# ---------------------------------------------------------------------------------- CLI
def test_cli_lists_profiles_with_sources_and_assumed_marks(capsys):
    from spll_hw.cli.main import main

    assert main(["chips", "--profiles", "loihi1,fixed16"]) == 0
    out = capsys.readouterr().out
    assert "| energy | synaptic_event | 23.6 pJ [21.4, 35.5] | Davies et al." in out
    assert "; low: SANA-FE arch/loihi.yaml (9ff59f8, 2023): synapse energy_spike;" in out
    assert "| resources | tde_compartments | 2 * | assumed:" in out
    assert "No [resources], [timing] or [energy] tables" in out


def test_cli_reports_fit_and_cost_per_profile(tmp_path, capsys):
    import json

    from spll_hw.cli.main import main

    out = tmp_path / "chips"
    argv = ["chips", "--network", "vibtac-vary-offset-lif", "--duration", "0.2", "--out", str(out),
            "--profiles", "loihi1,dynapse2,analog"]  # fmt: skip
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "| loihi1 | yes | 1 | 1 |" in text and "| dynapse2 | yes | 4 | 1 |" in text
    assert "energy.static_power" in text and "Skipped (no [resources] table): analog" in text
    data = json.loads((out / "results.json").read_text())
    loihi = data["profiles"][0]
    assert loihi["backend"] == "golden:profile=loihi1" and loihi["resources"]["fits"]
    counts = loihi["cost"]["counts"]
    assert counts["input_deliveries"] == data["n_input_spikes"] * 50
    assert counts["neuron_updates"] == 150 * 20_000
    # dynamic energy from Davies et al.'s sourced costs; static power assumed, apart
    assert loihi["energy_j"]["dynamic_assumed"] == 0 < loihi["energy_j"]["dynamic"]
    assert loihi["energy_j"]["static_assumed"] == loihi["energy_j"]["static"] > 0
    bench = loihi["neurobench"]
    assert bench["effective_acs"] == counts["input_deliveries"] + counts["feedback_deliveries"]
    assert bench["gate_macs"] == counts["trigger_deliveries"]
    assert bench["widths"] == "loihi1" and data["neurobench_exact"]["widths"] == "float32"
    assert "| none | `golden` | 4400 (float32) | 0.9703 |" in text
    # the chip's own integer arithmetic against golden, said where the network is designed;
    # an analog chip has none
    network = read_network_file("vibtac-vary-offset-lif").config.build()
    error, _, spec = chips.arithmetic_error(network, "loihi1")
    assert spec == "golden-fixed-point:profile=loihi1" and 0 < error < 1
    assert loihi["arithmetic_error"] == pytest.approx(error, rel=1e-12)
    assert f"| loihi1 | yes | 1 | 1 | {100 * error:.1f} % |" in text
    assert data["profiles"][1]["arithmetic_error"] is None
    assert "| dynapse2 | yes | 4 | 1 | - |" in text
    assert main(["chips", "--layouts", "vary-offset"]) == 2  # --layout without --params
    assert main(["chips", "--profiles", "nosuchchip"]) == 2


def test_sanafe_replay_charges_the_same_events():
    """SANA-FE's Loihi model, replaying a short sample's traffic, counts exactly the synaptic
    events, messages and updates of the placement (benchmarks/sanafe_crosscheck.py)."""
    pytest.importorskip("sanafe", reason="SANA-FE is in the [test] extra: pip install sanafe")
    from benchmarks.sanafe_crosscheck import crosscheck

    rows = crosscheck(duration=0.05, n_spll=5)["rows"]
    assert rows["synaptic events"][2] == rows["messages"][2] == 1.0
    assert rows["network energy [J]"][2] == pytest.approx(1.0)
    # 150 % : a Loihi-1 TDE takes two compartments, SANA-FE's stand-in one.
    assert rows["sink neuron updates (SANA-FE) / compartment updates (toolkit)"][2] == 1.5
