"""Ctrl-C stops the engine within a fraction of a second, and leaves no half-written file.

Each test starts a long simulation in a subprocess, waits until the engine's worker thread
(``spll-engine``) is running, sends SIGINT and measures how long the process takes to exit.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from spll_hw import presets
from spll_hw.files import atomic_path, write_json

ROOT = Path(__file__).resolve().parents[1]
#: Longest time from SIGINT to the interrupt's report on stderr (the engine polls for it every
#: 50 ms and stops within a few milliseconds more).
MAX_REPORT = 0.5
#: Longest time from SIGINT to the process's exit: the report plus the interpreter's teardown,
#: which alone can take most of a second on a loaded machine.
MAX_EXIT = 1.0

pytestmark = pytest.mark.skipif(
    not Path("/proc/self/task").is_dir() or os.name != "posix", reason="needs Linux /proc"
)

NETWORK = """
from spll_hw import Network, network_frequencies
from tests.conftest import VIBTAC_VARY_OFFSET_LIF, poisson_train
net = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 8))
x = poisson_train(300, 3000.0, seed=0)
"""

#: Minutes of work each, unless interrupted.
CALLS = {
    "simulate": "spll_hw.simulate(net, x, 3000.0, record_spikes=False)",
    "simulate_batch": "spll_hw.simulate_batch(net, [x, x], 3000.0, threads=2)",
    "fixed_point": "spll_hw.backends.get('golden-fixed-point').simulate_batch(net, [x], 3000.0)",
}


def engine_running(pid: int) -> bool:
    """Whether process ``pid`` has the engine's worker thread."""
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            if (task / "comm").read_text().strip() == "spll-engine":
                return True
        except OSError:
            pass
    return False


def interrupt(args: list[str], label: str) -> tuple[subprocess.CompletedProcess, float, float]:
    """Run ``args`` in the repository root and send SIGINT 0.3 s after the engine started.
    Returns the finished process and the seconds from the signal to the interrupt's first
    output on stderr and to the process's exit (printed with ``label``)."""
    # SIGINT's default action in the child even where the suite runs as a background job (which
    # starts with SIGINT ignored, and Python then installs no KeyboardInterrupt handler).
    proc = subprocess.Popen(
        args, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )  # fmt: skip
    deadline = time.monotonic() + 60
    while not engine_running(proc.pid):
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "the engine never started"
        time.sleep(0.02)
    time.sleep(0.3)
    assert proc.poll() is None, "the run ended before it was interrupted"
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    first = os.read(proc.stderr.fileno(), 1)
    reported = time.monotonic() - sent
    out, err = proc.communicate(timeout=30)
    exited = time.monotonic() - sent
    print(f"{label}: interrupt reported {reported:.3f} s, exit {exited:.3f} s after SIGINT")
    return subprocess.CompletedProcess(args, proc.returncode, out, first + err), reported, exited


@pytest.mark.parametrize("call", sorted(CALLS))
def test_ctrl_c_stops_the_engine_promptly(call):
    code = "import spll_hw, spll_hw.backends\n" + textwrap.dedent(NETWORK) + CALLS[call]
    done, reported, exited = interrupt([sys.executable, "-c", code], call)
    assert done.returncode == -signal.SIGINT, done.stderr.decode()
    assert done.stderr.decode().rstrip().endswith("KeyboardInterrupt")
    assert reported <= MAX_REPORT and exited <= MAX_EXIT


def test_ctrl_c_ends_the_cli_with_status_130_and_no_files(tmp_path):
    params = tmp_path / "net.toml"
    preset = presets.path("vibtac-vary-offset-lif").read_text()
    params.write_text(preset.replace("[network]\n", "[network]\nn = 8\n"))
    out = tmp_path / "report"
    args = [sys.executable, "-m", "spll_hw.cli.main", "simulate", "--network", str(params),
            "--duration", "3000", "--out", str(out)]  # fmt: skip
    done, reported, exited = interrupt(args, "spll-hw simulate")
    assert done.returncode == 130
    assert done.stderr.decode() == "spll-hw simulate: interrupted\n"
    assert reported <= MAX_REPORT and exited <= MAX_EXIT
    assert not out.exists() or not any(out.iterdir())


def test_an_interrupted_write_leaves_the_old_file_and_no_temporary(tmp_path):
    path = tmp_path / "results.json"
    write_json(path, {"run": 1})
    with pytest.raises(KeyboardInterrupt), atomic_path(path) as temporary:
        temporary.write_text('{"run": 2, "half')
        raise KeyboardInterrupt
    assert path.read_text() == '{\n  "run": 1\n}\n'
    assert [p.name for p in tmp_path.iterdir()] == ["results.json"]
    write_json(path, {"run": 3})
    assert path.read_text() == '{\n  "run": 3\n}\n'
