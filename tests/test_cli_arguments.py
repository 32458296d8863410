"""One vocabulary across the sub-commands: every default in ``--help``, old flag spellings as
aliases, shared helpers below the commands, every input file read once, provenance in every
``results.json``."""

from __future__ import annotations

import ast
import json
import re
import subprocess
import sys
from datetime import UTC, datetime
from pathlib import Path

import pytest

from spll_hw import cli
from spll_hw.cli.arguments import shows_default
from spll_hw.cli.main import COMMANDS, build_parser, main

CLI = Path(cli.__file__).resolve().parent  # the installed package, source tree or wheel


def _commands() -> dict:
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    return sub.choices


def test_every_subcommands_help_states_every_default():
    commands = _commands()
    assert set(commands) == set(COMMANDS)
    checked = 0
    for name, parser in commands.items():
        formatter = parser._get_formatter()
        shown = "".join(parser.format_help().split())  # --help, wrapped lines joined
        for action in parser._actions:
            if not action.option_strings or not shows_default(action.default):
                continue
            stated = f"(default: {action.default})"
            text = formatter._expand_help(action)
            assert stated in text, f"{name} {action.option_strings[0]}: {text!r}"
            assert "".join(stated.split()) in shown
            checked += 1
    assert checked > 60  # the walk really covered the options


def test_help_shows_the_defaults_that_were_missing(capsys):
    for command, stated in (
        ("report", ("--out OUT report folder (default: reports/harness)",
                    "(default: time-scaled,vary-offset,grouped:2,grouped:4,grouped:8)")),
        ("response", ("--free-freq FREE_FREQ free-running frequency [Hz] (default: 50.0)",
                      "--f-min F_MIN lowest input frequency [Hz] (default: 0.0)",
                      "--f-max F_MAX highest input frequency [Hz] (default: 100.0)",
                      "--points POINTS number of input frequencies (default: 2000)")),
    ):  # fmt: skip
        assert main([command, "--help"]) == 0
        text = "".join(capsys.readouterr().out.split())
        for line in stated:
            assert "".join(line.split()) in text


#: (command, new spelling, old spelling, a value, other arguments the command needs): every
#: older spelling of docs/cli.md's "Vocabulary", in every command that had it
RENAMED = [
    *[
        (c, "--network", "--params", "biotac-vary-offset-peak", ())
        for c in ("report", "compare", "simulate", "response", "evaluate", "chips", "robustness")
    ],
    ("export", "--network", "--params", "vibtac-time-scaled-lif", ("--to", "nir", "--out", "x")),
    ("fit", "--network", "--params", "vibtac-time-scaled-lif", ("--profiles", "loihi2")),
    *[(c, "--network", "--multichannel", "biotac-multichannel-lif", ()) for c in ("chips", "tune")],
    ("export", "--network", "--multichannel", "biotac-multichannel-lif", ("--to", "nir")),
    *[
        (c, "--layouts", "--layout", "grouped:4", ())
        for c in ("compare", "stability", "simulate", "response", "export", "chips", "tune")
    ],
    ("fit", "--layouts", "--layout", "grouped:auto", ("--profiles", "loihi2")),
    ("report", "--layouts", "--layout", "time-scaled,grouped:4", ()),
    *[(c, "--profiles", "--profile", "loihi2", ()) for c in ("report", "chips", "export", "tune")],
    ("fit", "--profiles", "--profile", "loihi2", ()),
    ("chips", "--windows", "--window", "2", ()),
    ("evaluate", "--encoders", "--encoder", "lif,peak", ()),
    *[(c, "--encoders", "--encoder", "peak", ()) for c in ("report", "robustness", "tune")],
    ("simulate", "--phase-noise", "--noise-sigma", "0.001", ()),
    ("simulate", "--rate", "--poisson", "120", ()),
    *[
        (c, "--holdout-recordings", "--test-recordings", "33-40", ())
        for c in ("evaluate", "report", "tune", "robustness", "slide")
    ],
]


@pytest.mark.parametrize(("command", "new", "old", "value", "extra"), RENAMED)
def test_old_spellings_parse_to_the_same_namespace(command, new, old, value, extra, capsys):
    parser = build_parser()
    by_new = parser.parse_args([command, *extra, new, value])
    assert "deprecated" not in capsys.readouterr().err  # the new name says nothing
    by_old = parser.parse_args([command, *extra, old, value])
    said = capsys.readouterr().err.splitlines()
    assert said == [f"spll-hw {command}: {old} is deprecated, use {new}"]  # one line
    assert vars(by_new) == vars(by_old)
    action = next(a for a in parser._subparsers._group_actions[0].choices[command]._actions
                  if new in a.option_strings)  # fmt: skip
    assert action.option_strings[0] == new  # the new spelling first, shown first
    assert old in action.option_strings
    assert getattr(by_new, action.dest) == (action.type or str)(value)


@pytest.mark.parametrize(
    "argv",
    [
        ["chips", "--network", "vibtac-time-scaled-lif", "--multichannel", "my-channels.toml"],
        ["fit", "--profiles", "loihi2", "--profile", "dynapse2"],
    ],
)
def test_an_option_given_by_two_spellings_is_refused(argv, capsys):
    """The last of two spellings would win silently (the campaign's ``chips --network A
    --multichannel B``): refused with exit status 2, naming both and the one to give."""
    with pytest.raises(SystemExit) as stop:
        build_parser().parse_args(argv)
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert f"{argv[1]} and {argv[3]} both given: both spell {argv[1]}" in err, err
    assert f"give {argv[1]} once" in err, err
    build_parser().parse_args(argv[:3] + argv[1:3])  # the same spelling twice: argparse's last


def test_every_alias_of_every_option_parses_alike():
    """Beyond the table: any option with several spellings gives one namespace."""
    seen = 0
    for name, parser in _commands().items():
        for action in parser._actions:
            if len(action.option_strings) < 2 or action.nargs == 0:
                continue
            required = []  # the other required options (given by two spellings: refused)
            for other in parser._actions:
                if other.required and other.option_strings and other is not action:
                    value = other.choices[0] if other.choices else "x"
                    required += [other.option_strings[0], str(value)]
            value = str(action.choices[0]) if action.choices else "1"
            parsed = [
                vars(build_parser().parse_args([name, *required, spelling, value]))
                for spelling in action.option_strings
            ]
            assert all(p == parsed[0] for p in parsed), (name, action.option_strings)
            seen += 1
    assert seen >= len(RENAMED)


def _relative_imports(path: Path):
    """``(level, module)`` of every relative import of the module at ``path``."""
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level:
            yield node.level, node.module or ""


def test_no_command_imports_a_sibling_command():
    """A command's parser (``cli/NAME.py``) imports only the shared arguments, no job and no
    input reader; its job (``cli/jobs/NAME.py``) imports the shared arguments and inputs, its
    own parser and its own parts (``tune_settings`` of ``tune``), no other command's."""
    shared = {"arguments", "inputs"}
    for path in CLI.glob("*.py"):
        if path.stem in ("__init__", "main"):
            continue
        for level, module in _relative_imports(path):
            if level == 1:  # the parsers and inputs import arguments alone
                assert module == "arguments" and path.stem != "arguments", f"{path.name}: .{module}"
            else:
                assert not module.startswith("cli"), f"{path.name} imports ..{module}"
    for path in (CLI / "jobs").glob("*.py"):
        command = path.stem.split("_")[0]
        for level, module in _relative_imports(path):
            own = module.split("_")[0] == command
            if level == 1:
                assert own, f"jobs/{path.name} imports .{module}"
            elif level == 2:
                assert module in shared or own, f"jobs/{path.name} imports ..{module}"


def test_help_imports_no_job():
    """``spll-hw --help`` and every ``spll-hw COMMAND --help`` build the parsers alone: no job
    module, no input reader, none of the heavy libraries a job imports at its top."""
    heavy = ("spll_hw.cli.jobs.", "spll_hw.cli.inputs", "spll_hw.pipeline", "sklearn",
             "optuna", "matplotlib")  # fmt: skip
    code = ("import sys\nfrom spll_hw.cli.main import main\nmain(sys.argv[1:])\n"
            "print(' '.join(m for m in sys.modules if m.startswith({heavy!r})))")  # fmt: skip
    for argv in (["--help"], ["tune", "--help"], ["slide", "--help"]):
        done = subprocess.run([sys.executable, "-c", code.format(heavy=heavy), *argv],
                              capture_output=True, text=True, check=True)  # fmt: skip
        assert done.stdout.splitlines()[-1].strip() == "", (argv, done.stdout.splitlines()[-1])


def test_a_network_file_is_read_once_per_run(tmp_path, monkeypatch, capsys):
    import spll_hw.config as config
    from spll_hw.encoders import make_encoder, settings_table

    path = tmp_path / "net.toml"
    network = config.NetworkConfig.preset("vibtac-vary-offset-lif").with_n(4).to_toml()
    path.write_text(network + settings_table(make_encoder("lif", gain=3000.0)))
    reads = []
    real = config.read_toml

    def counted(p, what):
        reads.append(Path(p))
        return real(p, what)

    monkeypatch.setattr(config, "read_toml", counted)
    assert main(["fit", "--network", str(path), "--profiles", "analog", "--layouts",
                 "grouped:auto"]) == 0  # fmt: skip
    assert reads == [path]
    reads.clear()
    out = tmp_path / "evaluated"
    assert main([
        "evaluate", "--network", str(path), "--encoders", "lif,peak", "--features", "spll",
        "--synthetic-classes", "2", "--synthetic-samples", "4", "--duration", "0.3", "--folds",
        "2", "--quiet", "--jobs", "1", "--out", str(out),
    ]) == 0  # fmt: skip
    assert reads == [path]  # one file for both encoders, read once
    assert "lif: encoder settings from" in capsys.readouterr().err
    results = json.loads((out / "results.json").read_text())
    assert results["encoders"]["lif"]["params"]["gain"] == 3000.0


def test_a_folder_of_a_presets_name_does_not_hide_it(tmp_path, monkeypatch):
    """An export's --out named after its preset, in the working folder, is not a network file:
    the preset is still read (it was "no such parameter file")."""
    from spll_hw.config import NetworkConfig

    monkeypatch.chdir(tmp_path)
    (tmp_path / "vibtac-vary-offset-lif").mkdir()
    config = NetworkConfig.load("vibtac-vary-offset-lif")
    assert config == NetworkConfig.preset("vibtac-vary-offset-lif")
    (tmp_path / "vibtac-vary-offset-peak").write_text("not toml [")
    with pytest.raises(ValueError, match="vibtac-vary-offset-peak"):  # a file is a file
        NetworkConfig.load("vibtac-vary-offset-peak")


def test_results_json_records_version_commit_and_time(tmp_path):
    from spll_hw.provenance import version

    out = tmp_path / "sim"
    before = datetime.now(UTC).replace(microsecond=0)
    assert main(["simulate", "--duration", "0.2", "--out", str(out)]) == 0
    stamp = json.loads((out / "results.json").read_text())["provenance"]
    assert stamp["version"] == version()
    assert before <= datetime.fromisoformat(stamp["utc_time"]) <= datetime.now(UTC)
    done = subprocess.run(["git", "rev-parse", "HEAD"], cwd=CLI, capture_output=True, text=True)
    if done.returncode == 0:
        assert stamp["git_commit"] == done.stdout.strip()
        assert re.fullmatch(r"[0-9a-f]{40}", stamp["git_commit"])
    else:
        assert stamp["git_commit"] is None


def test_no_git_checkout_records_no_commit(monkeypatch):
    from spll_hw import provenance

    def not_a_checkout(*args, **kwargs):
        return subprocess.CompletedProcess(args, 128, "", "fatal: not a git repository")

    monkeypatch.setattr(provenance.subprocess, "run", not_a_checkout)
    assert provenance.provenance()["git_commit"] is None

    def no_git(*args, **kwargs):
        raise FileNotFoundError("git")

    monkeypatch.setattr(provenance.subprocess, "run", no_git)
    assert provenance.git_commit() is None


def test_a_chips_clamped_parameters_are_said_on_the_console():
    from spll_hw import chips
    from spll_hw.config import NetworkConfig
    from spll_hw.report.constraints import clamped_lines

    network = NetworkConfig.preset("biotac-time-scaled-lif").build()
    realisation = chips.realise(network, "loihi2")
    lines = clamped_lines("time-scaled", "loihi2", realisation)
    saturated = {r.name for r in realisation.detail.report.saturated()}
    assert saturated and len(lines) == len(saturated)  # one line per clamped parameter
    tau = next(line for line in lines if ": tau_cco clamped" in line)
    count = sum(r.name == "tau_cco" for r in realisation.detail.report.saturated())
    assert tau.startswith(f"loihi2, time-scaled: tau_cco clamped in {count}/50 sPLLs (worst -")
    exact = chips.realise(NetworkConfig.preset("vibtac-time-scaled-lif").build(), "loihi2")
    assert not exact.detail.report.saturated()
    assert clamped_lines("time-scaled", "loihi2", exact) == []


def test_the_cli_reference_page_is_what_help_prints():
    """docs/cli.md quotes every command's --help; scripts/cli_reference.py rewrites it."""
    root = Path(__file__).resolve().parents[1]
    done = subprocess.run([sys.executable, str(root / "scripts" / "cli_reference.py"), "--check"],
                          capture_output=True, text=True, timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr + " (run scripts/cli_reference.py)"
