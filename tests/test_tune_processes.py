"""Tuning across processes: storages opened at once, a killed run resumed, SIGTERM stopping a
study and its workers, two workers on one PostgreSQL study, and a report written whole on a
full disk."""

from __future__ import annotations

import signal
import subprocess
import sys
import time

import pytest

optuna = pytest.importorskip("optuna", reason="the tune extra (Optuna) is not installed")

from spll_hw.cli.main import main  # noqa: E402
from spll_hw.tune.storage import storage_url  # noqa: E402

from .postgres import Unavailable, postgres_server  # noqa: E402
from .test_tune import TINY, finished_trials, load  # noqa: E402

# ------------------------------------------------------------------------------- resume
OPEN_AT = """
import sys, time
from spll_hw.tune.storage import open_storage
while time.time() < float(sys.argv[2]):
    pass
open_storage(sys.argv[1])
"""


def test_processes_opening_a_new_storage_at_once_all_succeed(tmp_path):
    # Without retries about one process in three lost the schema-creation race (IntegrityError
    # on alembic_version or "table studies already exists"), which once failed the resume test.
    for rep in range(2):
        url = storage_url(None, tmp_path / str(rep))
        start = time.time() + 3.0  # every process has imported Optuna by then
        procs = [
            subprocess.Popen(
                [sys.executable, "-c", OPEN_AT, url, str(start)],
                stderr=subprocess.PIPE,
                text=True,
            )
            for _ in range(4)
        ]
        errors = [p.communicate(timeout=120)[1] for p in procs]
        assert [p.returncode for p in procs] == [0] * 4, errors


def test_sqlite_resume_after_a_killed_run_loses_no_finished_trial(tmp_path):
    out = tmp_path / "r"
    url = storage_url(None, out)
    cmd = [
        sys.executable,
        "-m",
        "spll_hw.cli.main",
        "tune",
        *TINY,
        "--out",
        str(out),
        "--study",
        "k",
        "--pruner",
        "none",
    ]
    # stderr goes to a file: an unread pipe fills up and stalls the worker.
    log = tmp_path / "first_run.stderr"
    with log.open("w") as err:
        proc = subprocess.Popen([*cmd, "--trials", "500"], stdout=subprocess.DEVNULL, stderr=err)
    try:
        deadline = time.time() + 180  # generous: CI machines are shared
        done: list = []
        while time.time() < deadline and len(done) < 4 and proc.poll() is None:
            time.sleep(0.3)
            if not (out / "study.db").exists():
                continue
            try:
                done = [t for t in load(url, "k").trials if t.state.is_finished()]
            except (KeyError, ValueError):
                continue  # study not created yet
        assert len(done) >= 4, (
            f"the first run finished {len(done)} trials (exit code {proc.poll()}); "
            f"its stderr ends: {log.read_text()[-2000:]}"
        )
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    assert proc.returncode == -signal.SIGKILL
    killed = {t.number: t.value for t in load(url, "k").trials if t.state.is_finished()}
    assert len(killed) < 500
    target = len(killed) + 3
    resumed = subprocess.run(
        [*cmd, "--trials", str(target), "--resume"], capture_output=True, text=True, timeout=120
    )
    assert resumed.returncode == 0, resumed.stderr
    study = load(url, "k")
    after = {t.number: t.value for t in study.trials if t.state.is_finished()}
    assert {n: after[n] for n in killed} == killed
    assert len(finished_trials(study)) == target
    assert len({t.number for t in study.trials}) == len(study.trials)


def _children(pid: int) -> list[int]:
    """Pids of the live child processes of ``pid`` (Linux /proc)."""
    from pathlib import Path

    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if int(fields[1]) == pid and fields[0] != "Z":
            out.append(int(stat.parent.name))
    return out


def _gone(pids: list[int], timeout: float) -> bool:
    """True once no pid in ``pids`` is alive (zombies count as gone) within ``timeout`` s."""
    from pathlib import Path

    deadline = time.time() + timeout
    while time.time() < deadline:
        alive = []
        for pid in pids:
            try:
                state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
            except OSError:
                continue
            if state != "Z":
                alive.append(pid)
        if not alive:
            return True
        time.sleep(0.2)
    return False


def _start_and_wait_for_trials(tmp_path, workers: int):
    """A tune run of ``workers`` processes that has finished at least 2 trials."""
    out = tmp_path / "stop"
    cmd = [sys.executable, "-m", "spll_hw.cli.main", "tune", *TINY, "--out", str(out)]
    cmd += ["--study", "s", "--pruner", "none", "--trials", "500", "--workers", str(workers)]
    log = (tmp_path / "stop.stderr").open("w")
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=log)
    url = f"sqlite:///{out / 'study.db'}"
    deadline, done = time.time() + 180, []
    while time.time() < deadline and len(done) < 2 and proc.poll() is None:
        time.sleep(0.3)
        try:
            done = [t for t in load(url, "s").trials if t.state.is_finished()]
        except (KeyError, ValueError):
            continue  # the study is not created yet
    assert len(done) >= 2, (tmp_path / "stop.stderr").read_text()[-2000:]
    children = _children(proc.pid)
    assert len(children) >= (workers if workers > 1 else 0)
    return proc, url, children


@pytest.mark.parametrize("workers", [1, 2])
def test_sigterm_stops_a_study_and_its_workers_cleanly(tmp_path, workers):
    proc, url, pids = _start_and_wait_for_trials(tmp_path, workers)
    proc.send_signal(signal.SIGTERM)
    try:
        assert proc.wait(timeout=60) == 130  # as Ctrl-C: "interrupted ... --resume"
    finally:
        proc.kill()
    assert _gone(pids, 10), "workers outlived their study"
    states = {t.state.name for t in load(url, "s").trials}
    assert "RUNNING" not in states  # the running trials were marked failed, not left hanging
    said = (tmp_path / "stop.stderr").read_text()
    assert "interrupted: finished trials are stored" in said
    # said once, by spll-hw: not Optuna's "Trial N failed ... KeyboardInterrupt" traceback
    assert "Traceback" not in said and "KeyboardInterrupt" not in said, said[-3000:]
    assert "failed with value None" not in said, said[-3000:]


def test_workers_of_a_killed_study_exit_instead_of_running_on(tmp_path):
    proc, url, pids = _start_and_wait_for_trials(tmp_path, 2)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert _gone(pids, 15), "orphaned workers kept running trials"
    before = len(load(url, "s").trials)
    time.sleep(2)
    assert len(load(url, "s").trials) == before  # nobody adds trials any more


# ------------------------------------------------------------------------------- PostgreSQL
@pytest.fixture(scope="module")
def postgres_url():
    try:
        with postgres_server() as url:
            yield url
    except Unavailable as exc:
        pytest.skip(f"no PostgreSQL server for the multi-worker test: {exc}")


def test_two_workers_share_one_postgres_study(postgres_url, tmp_path):
    code = main(
        [
            "tune",
            *TINY,
            "--storage",
            postgres_url,
            "--study",
            "pg",
            "--workers",
            "2",
            "--trials",
            "8",
            "--out",
            str(tmp_path / "r"),
        ]
    )
    assert code == 0
    study = load(postgres_url, "pg")
    finished = finished_trials(study)
    assert 8 <= len(finished) <= 9  # both workers stop at the shared target (one may overshoot)
    assert all(t.state.is_finished() for t in study.trials)
    assert len({t.user_attrs["worker"] for t in finished}) == 2
    numbers = [t.number for t in study.trials]
    assert sorted(numbers) == list(range(len(numbers)))
    assert (tmp_path / "r" / "best.toml").exists()


def test_a_report_onto_a_full_disk_leaves_the_folder_as_it_was(full_disk):
    """A report is written whole or not at all: on a full disk the error names the folder and
    says it was left as it was, and it keeps what it held (the study's database)."""
    from spll_hw.files import write_text
    from spll_hw.tune.report import written_whole

    out = full_disk / "out"
    out.mkdir()
    (out / "study.db").write_bytes(b"x" * 1000)

    @written_whole
    def write(study, objective, stage, big=True):
        write_text(stage / "summary.md", "# a report\n")
        if big:
            (stage / "history.png").write_bytes(b"0" * 200_000)  # more than the 64 kB disk
        return stage / "summary.md"

    with pytest.raises(OSError, match=f"cannot write {out}: No space left on device") as error:
        write(None, None, out)
    assert f"{out} was left as it was" in str(error.value)
    assert sorted(p.name for p in out.iterdir()) == ["study.db"]
    assert [p.name for p in full_disk.iterdir()] == ["out"]
    assert write(None, None, out, big=False) == out / "summary.md"
    assert sorted(p.name for p in out.iterdir()) == ["study.db", "summary.md"]
