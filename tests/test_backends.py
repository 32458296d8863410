"""The backend registry: one protocol for every simulator, found through entry points."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest

from spll_hw import backends, simulate
from spll_hw.backends.base import Backend
from spll_hw.cli.main import main
from spll_hw.config import NetworkConfig

from .conftest import poisson_train

ROOT = Path(__file__).resolve().parents[1]


def test_golden_through_the_registry_equals_the_api():
    net = NetworkConfig.preset("biotac-vary-offset-lif").with_layout("vary-offset").build()
    x = poisson_train(300, 0.5, seed=3)
    a = backends.run("golden", net, x, 0.5)
    b = simulate(net, x, 0.5)
    np.testing.assert_array_equal(a.tde_counts, b.tde_counts)
    assert a.backend == "golden"


def test_every_declared_backend_is_registered_and_loads():
    """The registry users see (the installed entry points) is exactly what pyproject.toml
    declares, and every entry loads."""
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["entry-points"]
    shipped = set(declared[backends.GROUP])
    assert set(backends.names()) == shipped, (
        "the installed entry points differ from pyproject.toml: reinstall (pip install -e .)"
    )
    assert backends.names()[0] == "golden"
    for name in shipped:
        cls = backends.backend_class(name)
        assert issubclass(cls, Backend) and cls.name == name and cls.description
    listed = {e.name: e for e in backends.listing()}
    assert listed["golden"].unavailable is None and listed["golden"].capabilities.exact
    assert listed["golden-fixed-point"].capabilities.arithmetic == "fixed"
    assert "golden" in backends.available()


def test_spec_parsing_and_canonical_specs():
    assert backends.parse_spec("brian2-cpp_standalone:dt=1e-5:method=exact") == (
        "brian2-cpp_standalone", {"dt": 1e-5, "method": "exact"},
    )  # fmt: skip
    assert backends.parse_spec("golden") == ("golden", {})
    assert backends.parse_specs("golden, golden-fixed-point") == ["golden", "golden-fixed-point"]
    fixed = backends.get("golden-fixed-point:profile=fixed16:dt=5e-5")
    assert fixed.spec == "golden-fixed-point:profile=fixed16:dt=5e-05"
    assert fixed.capabilities.dt == 5e-5
    assert backends.get(fixed, dt=1e-4).spec == "golden-fixed-point:profile=fixed16:dt=0.0001"
    assert backends.get("golden:profile=none").spec == "golden"


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("golden,nest", "unknown backend 'nest'"),
        ("brian2-numpy:dt", "key=value"),
        ("golden:dt=1e-5", "has no option"),
        ("golden-fixed-point:profile=loihi3", "unknown profile 'loihi3'"),
        ("golden-fixed-point:profile=analog", "analog, not fixed point"),
        ("golden-fixed-point:dt=-1", "dt must be a finite number > 0"),
        ("golden:profile=loihi3", "unknown profile 'loihi3'"),
        ("golden:exact=tau_tde", "name the chip too"),
        ("golden:profile=loihi2:exact=tau_tde+tau_fac", r"\['tau_fac'\]: give sPLL parameter"),
    ],
)
def test_bad_specs_are_value_errors_before_any_work(spec, message):
    with pytest.raises(ValueError, match=message):
        backends.parse_specs(spec)


def test_exact_keeps_named_parameters_at_their_requested_values_on_a_chip():
    from spll_hw import chips
    from spll_hw.params import PARAM_NAMES

    net = NetworkConfig.preset("biotac-tuned-vary-offset-lif").build()
    on_chip = backends.get("golden:profile=loihi2").realised(net)
    one = backends.get("golden:profile=loihi2:exact=tau_tde_fac")
    assert one.spec == "golden:profile=loihi2:exact=tau_tde_fac"
    kept = one.realised(net)
    for chip, asked, got in zip(on_chip.spll, net.spll, kept.spll, strict=True):
        assert got.tau_tde_fac == asked.tau_tde_fac
        assert got.tau_tde == chip.tau_tde and got.i_cco_offset == chip.i_cco_offset
    assert any(c.tau_tde_fac != a.tau_tde_fac for c, a in zip(on_chip.spll, net.spll, strict=True))
    # a CCO parameter kept exact re-solves the offset for the frequency the chip realised
    cco = chips.keep_exact(on_chip, net, ("tau_cco",))
    for chip, got in zip(on_chip.spll, cco.spll, strict=True):
        assert got.tau_cco != chip.tau_cco or got.i_cco_offset == chip.i_cco_offset
        assert got.free_frequency() == pytest.approx(chip.free_frequency(), rel=1e-12)
    # every parameter exact is the requested network: the same spikes as golden
    everything = backends.get(f"golden:profile=loihi2:exact={'+'.join(PARAM_NAMES)}")
    assert everything.realised(net).spll == net.spll
    x = poisson_train(300, 0.3, seed=5)
    np.testing.assert_array_equal(
        everything.simulate(net, x, 0.3).tde_counts, simulate(net, x, 0.3).tde_counts
    )
    with pytest.raises(ValueError, match="50 sPLLs, the requested one 3"):
        chips.keep_exact(on_chip, NetworkConfig.preset("biotac-vary-offset-lif").with_n(3).build(),
                         ("tau_tde",))  # fmt: skip


def test_an_unavailable_backend_says_why():
    entry = {e.name: e for e in backends.listing()}["usb"]
    if entry.unavailable is None:
        pytest.skip("a USB board is attached")
    assert "usb-emulator" in entry.unavailable
    with pytest.raises(ValueError, match="not available here"):
        backends.get("usb")


def test_options_a_backend_cannot_honour_are_refused():
    net = NetworkConfig.preset("vibtac-vary-offset-lif").with_n(2).build()
    fixed = backends.get("golden-fixed-point")
    with pytest.raises(ValueError, match="cannot resume"):
        fixed.simulate(net, [0.1], 0.2, state=object())
    with pytest.raises(ValueError, match="has no probes"):
        fixed.simulate(net, [0.1], 0.2, probe_times=[0.1])


def test_backends_command_lists_capabilities(capsys):
    assert main(["backends", "--options"]) == 0
    out = capsys.readouterr().out
    assert "| golden | yes | exact, float, resume, probes, threads |" in out
    assert "| golden-fixed-point | yes | dt = 1e-05 s, fixed point, threads |" in out
    assert "profile (default loihi2)" in out
    # the NIR consumers need torch, which no extra installs: the listing says how, not "core"
    row = next(line for line in out.splitlines() if line.startswith("| nir-snntorch |"))
    assert "| none: pip install torch snntorch nirtorch |" in row and "| core |" not in row


def test_compare_command_reports_golden_as_exact(tmp_path):
    from spll_hw.cli.inputs import expand_specs

    assert expand_specs(["golden", "brian2-numpy", "brian2-numpy:dt=1e-6"], [1e-4, 1e-5]) == [
        "golden", "brian2-numpy:dt=0.0001", "brian2-numpy:dt=1e-05", "brian2-numpy:dt=1e-6",
    ]  # fmt: skip
    # Every clocked backend gets a dt sweep: its work-precision curve.
    assert expand_specs(["golden-fixed-point:profile=fixed16"], [1e-4]) == [
        "golden-fixed-point:profile=fixed16:dt=0.0001"
    ]
    args = ["compare", "--backends", "golden,golden-fixed-point,nir-numpy:dt=1e-4", "--samples",
            "2", "--duration", "0.5", "--out", str(tmp_path)]  # fmt: skip
    assert main(args) == 0
    text = (tmp_path / "summary.md").read_text()
    assert "| `golden` |" in text and "0.000 %" in text
    # Each row names its backend with its options: the chip that ran it (its default profile,
    # which the spec leaves out) and the dt, also where it is the backend's default.
    assert "| `golden-fixed-point:profile=loihi2:dt=1e-05` |" in text
    assert "| `nir-numpy:dt=1e-4` |" in text
    rows = json.loads((tmp_path / "results.json").read_text())["rows"]
    assert {row["spec"]: row["name"] for row in rows} == {
        "golden": "golden",
        "golden-fixed-point:dt=0.0001": "golden-fixed-point:profile=loihi2:dt=0.0001",
        "golden-fixed-point:dt=1e-05": "golden-fixed-point:profile=loihi2:dt=1e-05",
        "golden-fixed-point:dt=1e-06": "golden-fixed-point:profile=loihi2:dt=1e-06",
        "nir-numpy:dt=1e-4": "nir-numpy:dt=1e-4",
    }  # the spec as given, which the dt sweep's curves read
    assert (tmp_path / "work_precision.png").stat().st_size > 0
    assert main(["compare", "--backends", "golden,nest", "--out", str(tmp_path)]) == 2


def test_a_spec_is_parsed_once_and_checked_whole():
    from spll_hw import backends

    with pytest.raises(ValueError, match="'profile' is given twice"):
        backends.get("golden:profile=analog:profile=loihi2")
    # an option's range is checked where the spec is parsed, before any simulation
    with pytest.raises(ValueError, match="levels must be an integer in 1..256, got 100000"):
        backends.parse_specs("golden,standard-exact:levels=100000")
    assert backends.get("golden-fixed-point:profile=loihi2") is backends.get(
        " golden-fixed-point:profile=loihi2"
    )


def test_prepare_runs_once_per_network(monkeypatch):
    from spll_hw import backends
    from spll_hw.config import NetworkConfig

    sim = backends.get("golden-fixed-point:profile=fixed16")
    network = NetworkConfig.preset("vibtac-vary-offset-lif").with_n(3).build()
    other = NetworkConfig.preset("vibtac-vary-offset-lif").with_n(4).build()
    calls = []
    prepare = type(sim).prepare
    monkeypatch.setattr(type(sim), "prepare", lambda self, net: calls.append(net.n_spll) or
                        prepare(self, net))  # fmt: skip
    train = np.sort(np.random.default_rng(0).uniform(0, 0.1, 30))
    for _ in range(3):  # chunks of one workload
        sim.simulate_batch(network, [train], 0.1)
    sim.simulate_batch(other, [train], 0.1)
    sim.simulate_batch(network, [train], 0.1)
    assert calls.count(3) == 1 and calls.count(4) == 1
