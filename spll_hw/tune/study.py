"""Create, validate, resume and run a tuning study in one or several processes.

A study stores, as its ``spll_hw`` user attribute, the search space and the objective's metadata
(:meth:`~spll_hw.tune.objective.Objective.metadata`: settings, dataset size, data fingerprint).
:func:`prepare_study` refuses to continue a study whose stored space or objective differs, and to
reuse an existing study without ``resume``, before anything is written.

``trials`` is the study's target of finished (complete or pruned) trials, shared by all workers:
a resumed study runs only what is missing. Each worker process samples with TPE seeded by
``seed + worker index`` (plus :data:`RESUME_SEED_STRIDE` per trial the study has already run, so
a resumed study does not replay its first random draws; constant liar on, so parallel workers
spread out), or with NSGA-II
(``sampler="nsga2"``, a population of ``startup_trials``). A study with several objectives
(accuracy and a chip cost, :mod:`spll_hw.tune.chip`) is created with one direction per objective
(TPE is then Optuna's multi-objective TPE) and runs without a pruner.

Stopping: SIGTERM (``kill``, a batch system) stops a study as Ctrl-C does, in the main process and
in every worker. A worker does not raise where the signal lands (half-way through a storage write
that could leave the database connection's locks taken) but asks its objective to stop
(:meth:`~spll_hw.tune.objective.Objective.request_stop`), which fails the running trial at its
next chunk of samples; finished trials stay, and the main process waits for its workers before
it exits. A worker whose main process died without a word (SIGKILL) notices within a second and
exits, so no orphan goes on adding trials.
"""

from __future__ import annotations

import contextlib
import json
import logging
import multiprocessing
import os
import signal
import sys
import threading
import time
from dataclasses import dataclass

from . import import_optuna
from .chip import directions
from .objective import Objective
from .storage import mask_url, open_storage, storage_error, storage_failures

ATTR = "spll_hw"
PRUNERS = ("median", "none")
SAMPLERS = ("tpe", "nsga2")


@dataclass(frozen=True)
class StudySettings:
    """Where the study lives and how it samples.

    Attributes:
        storage: SQLAlchemy URL (:func:`~spll_hw.tune.storage.storage_url`).
        name: study name.
        trials: target number of finished (complete + pruned) trials.
        seed: TPE seed (worker ``k`` uses ``seed + k``).
        pruner: ``"median"`` (Optuna's MedianPruner) or ``"none"``.
        startup_trials: random trials before TPE (and before the pruner prunes); NSGA-II's
            population size.
        sampler: ``"tpe"`` (single- or multi-objective TPE) or ``"nsga2"`` (Optuna's
            NSGAIISampler, for multi-objective studies).
    """

    storage: str
    name: str
    trials: int
    seed: int = 0
    pruner: str = "median"
    startup_trials: int = 10
    sampler: str = "tpe"

    def __post_init__(self) -> None:
        if self.trials < 0:
            raise ValueError(f"trials must be >= 0, got {self.trials}")
        if self.pruner not in PRUNERS:
            raise ValueError(f"unknown pruner {self.pruner!r}; choose from {PRUNERS}")
        if not self.name:
            raise ValueError("the study needs a name")
        if self.startup_trials < 0:
            raise ValueError(f"startup trials must be >= 0, got {self.startup_trials}")
        if self.sampler not in SAMPLERS:
            raise ValueError(f"unknown sampler {self.sampler!r}; choose from {SAMPLERS}")
        if self.sampler == "nsga2" and self.startup_trials < 2:
            raise ValueError("NSGA-II needs a population (--startup-trials) of at least 2")


def finished(study) -> int:
    """Number of complete or pruned trials."""
    optuna = import_optuna()
    states = (optuna.trial.TrialState.COMPLETE, optuna.trial.TrialState.PRUNED)
    return len(study.get_trials(deepcopy=False, states=states))


def prepare_study(settings: StudySettings, objective: Objective, resume: bool):
    """Create the study, or check that the stored one matches and may be resumed.

    Raises ``ValueError`` (nothing written) when the storage is unreachable, when the study exists
    and ``resume`` is false, when ``resume`` is asked of a study that does not exist or that
    spll-hw did not create, or when its stored search space or objective differs.
    """
    optuna = import_optuna()
    storage = open_storage(settings.storage)
    wanted = {"space": objective.space.to_dict(), "objective": objective.metadata()}
    wanted = json.loads(json.dumps(wanted))  # the form it takes once stored
    try:
        study = optuna.load_study(study_name=settings.name, storage=storage)
    except KeyError:
        study = None
    if study is not None:
        stored = study.user_attrs.get(ATTR)
        n = len(study.trials)
        if not resume:
            raise ValueError(
                f"study {settings.name!r} already exists with {n} trials; pass --resume to "
                "continue it, or choose another --study name"
            )
        if stored is None:
            raise ValueError(
                f"study {settings.name!r} was not created by spll-hw tune (no stored search "
                f"space, {n} trials); choose another --study name"
            )
        if stored is not None:
            _check_same(settings.name, objective, stored, wanted)
            return study
    elif resume:
        known = [s.study_name for s in optuna.get_all_study_summaries(storage)]
        raise ValueError(
            f"--resume: there is no study {settings.name!r} in {mask_url(settings.storage)} "
            f"(studies there: {', '.join(known) or 'none'}); drop --resume to start it"
        )
    else:
        study = optuna.create_study(
            study_name=settings.name,
            storage=storage,
            directions=directions(objective.settings.objectives),
            load_if_exists=True,
        )
        if study.user_attrs.get(ATTR) not in (None, wanted):  # another worker won the race
            _check_same(settings.name, objective, study.user_attrs[ATTR], wanted)
            return study
    study.set_user_attr(ATTR, wanted)
    return study


def _check_same(name: str, objective: Objective, stored: dict, wanted: dict) -> None:
    problems = objective.space.differences(stored.get("space", {}))
    if problems:
        raise ValueError(
            f"study {name!r} was created with a different search space ("
            + "; ".join(problems)
            + "); use the same space or another --study name"
        )
    old, new = stored.get("objective", {}), wanted["objective"]
    changed = sorted(k for k in set(old) | set(new) if old.get(k) != new.get(k))
    if changed:
        detail = "; ".join(f"{k}: stored {old.get(k)}, now {new.get(k)}" for k in changed)
        hint = (
            " (different spike trains: check the encoder's --set flags against the [encoder] "
            "table of the study's best.toml, or its header in files from before that table)"
            if "data_fingerprint" in changed
            else ""
        )
        raise ValueError(
            f"study {name!r} was created for a different objective ({detail}){hint}; use the "
            "same dataset, encoder and settings or another --study name"
        )


def _sampler_and_pruner(settings: StudySettings, worker: int, multi_objective: bool = False):
    optuna = import_optuna()
    if settings.sampler == "nsga2":
        sampler = optuna.samplers.NSGAIISampler(
            population_size=settings.startup_trials, seed=settings.seed + worker
        )
    else:
        sampler = optuna.samplers.TPESampler(
            seed=settings.seed + worker, n_startup_trials=settings.startup_trials
        )
    if settings.pruner == "none" or multi_objective:
        return sampler, optuna.pruners.NopPruner()
    startup = max(1, settings.startup_trials // 2)
    return sampler, optuna.pruners.MedianPruner(n_startup_trials=startup)


def run_worker(
    settings: StudySettings, objective: Objective, worker: int = 0, verbosity: int | None = None
) -> None:
    """Run trials until the study has ``settings.trials`` finished ones (none if it has);
    ``verbosity`` is an Optuna logging level for this process."""
    optuna = import_optuna()
    if verbosity is not None:
        optuna.logging.set_verbosity(verbosity)
    _quiet_interrupts()
    study = optuna.load_study(study_name=settings.name, storage=open_storage(settings.storage))
    if finished(study) >= settings.trials:
        return
    # A resumed study seeds its sampler past the trials it has run: the same seed would replay
    # the first run's random start-up draws (the same networks again).
    ran = sum(1 for t in study.get_trials(deepcopy=False) if t.state.is_finished())
    study.sampler, study.pruner = _sampler_and_pruner(
        settings, worker + RESUME_SEED_STRIDE * ran, objective.settings.multi_objective
    )
    states = (optuna.trial.TrialState.COMPLETE, optuna.trial.TrialState.PRUNED)
    stop = optuna.study.MaxTrialsCallback(settings.trials, states=states)
    objective.stop_requested = False
    with _handlers(lambda signum, frame: objective.request_stop(), signal.SIGTERM, signal.SIGINT):
        study.optimize(objective, callbacks=[stop], gc_after_trial=False)
    if objective.stop_requested:  # the signal came after the last trial
        raise KeyboardInterrupt("stopped by a signal")


class _NoInterruptLog(logging.Filter):
    """Drops Optuna's "Trial N failed ... KeyboardInterrupt" warning with its traceback, and
    the "Trial N failed with value None." that follows it for the same trial: a stop by
    Ctrl-C or SIGTERM is said once, by ``spll-hw tune`` (where the trials are, how to go on),
    and so is a database that failed under a trial (:func:`~spll_hw.tune.storage.
    storage_failures`)."""

    def __init__(self) -> None:
        super().__init__()
        self.stopped: set[str] = set()  # the trials whose failure was a stop

    def filter(self, record: logging.LogRecord) -> bool:
        error = record.exc_info[1] if record.exc_info else None
        message = record.getMessage()
        trial = message.split(" failed ", 1)[0] if message.startswith("Trial ") else ""
        if isinstance(error, KeyboardInterrupt) or (error and storage_error(error)):
            self.stopped.add(trial)  # a stop, or a database that failed: said once, by spll-hw
            return False
        return not (trial in self.stopped and "failed with value None" in message)


def _quiet_interrupts() -> None:
    """Install :class:`_NoInterruptLog` on the logger of Optuna's trial loop (once)."""
    logger = logging.getLogger(OPTUNA_TRIAL_LOGGER)
    if not any(isinstance(f, _NoInterruptLog) for f in logger.filters):
        logger.addFilter(_NoInterruptLog())


#: The logger that reports a failed trial (``optuna.study._optimize``, Optuna 4 and 5).
OPTUNA_TRIAL_LOGGER = "optuna.study._optimize"

#: Seed offset per finished trial of a resumed study (beyond any worker index).
RESUME_SEED_STRIDE = 1000

#: Seconds a stopped worker gets to mark its running trial failed before it is killed.
STOP_GRACE = 30.0

#: Exit status of a worker process whose study database failed (it said so in one line).
WORKER_ERROR = 2


@contextlib.contextmanager
def _handlers(handler, *signums: int):
    """Within the block ``handler`` answers ``signums`` (main thread only: elsewhere nothing
    changes); an ignored SIGINT (a background job's) stays ignored. Restored afterwards."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {n: signal.getsignal(n) for n in signums}
    for n in signums:
        if not (n == signal.SIGINT and previous[n] == signal.SIG_IGN):
            signal.signal(n, handler)
    try:
        yield
    finally:
        for n, h in previous.items():
            signal.signal(n, h)


def _interrupt(signum, frame) -> None:
    raise KeyboardInterrupt(f"signal {signum}")


def sigterm_interrupts():
    """Context manager: within it SIGTERM raises ``KeyboardInterrupt``, like Ctrl-C."""
    return _handlers(_interrupt, signal.SIGTERM)


def _exit_with_parent(parent: int, period: float = 1.0) -> None:
    """Start a daemon thread that ends this process once its parent ``parent`` (a pid) is gone."""

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(period)
        os._exit(1)

    threading.Thread(target=watch, name="tune-parent-watch", daemon=True).start()


def _worker_process(
    settings: StudySettings, objective: Objective, worker: int, verbosity: int, parent: int
) -> None:
    """Entry point of a worker process: :func:`run_worker` until done, stopped or orphaned."""
    _exit_with_parent(parent)
    try:
        with storage_failures(settings.storage):
            run_worker(settings, objective, worker, verbosity)
    except KeyboardInterrupt:
        raise SystemExit(130) from None
    except ValueError as exc:  # its database failed: one line, as the main process says it
        print(f"spll-hw tune: worker {worker}: error: {exc}", file=sys.stderr)
        raise SystemExit(WORKER_ERROR) from None


def _stop(procs) -> None:
    """SIGTERM every live worker, give it :data:`STOP_GRACE` seconds, then SIGKILL."""
    for p in procs:
        if p.is_alive():
            p.terminate()
    deadline = time.monotonic() + STOP_GRACE
    for p in procs:
        p.join(max(0.0, deadline - time.monotonic()))
        if p.is_alive():
            p.kill()
            p.join()


def run_study(
    settings: StudySettings,
    objective: Objective,
    workers: int = 1,
    resume: bool = False,
    enqueue: dict[str, float] | None = None,
):
    """Prepare the study, queue ``enqueue`` (parameters to try first, once per study), then run
    ``workers`` processes on it (in this process when 1).

    Returns the study, reloaded after every worker has stopped. Ctrl-C or SIGTERM raise
    ``KeyboardInterrupt`` here after the workers have stopped (module docstring).
    """
    optuna = import_optuna()
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    study = prepare_study(settings, objective, resume)
    if enqueue:
        study.enqueue_trial(enqueue, skip_if_exists=True)
    with sigterm_interrupts():
        if workers == 1:
            run_worker(settings, objective)
        else:
            _run_processes(settings, objective, workers, optuna.logging.get_verbosity())
    return optuna.load_study(study_name=settings.name, storage=open_storage(settings.storage))


def _run_processes(
    settings: StudySettings, objective: Objective, workers: int, verbosity: int
) -> None:
    ctx = multiprocessing.get_context("spawn")
    procs = [
        ctx.Process(
            target=_worker_process,
            args=(settings, objective, k, verbosity, os.getpid()),
            name=f"tune-worker-{k}",
        )
        for k in range(workers)
    ]
    try:
        for p in procs:
            p.start()
        for p in procs:
            p.join()
    except BaseException:
        _stop([p for p in procs if p.pid is not None])
        raise
    failed = [p.name for p in procs if p.exitcode != 0]
    if failed and all(p.exitcode == WORKER_ERROR for p in procs if p.exitcode != 0):
        raise ValueError(f"tuning worker(s) {', '.join(failed)} stopped: see their error above")
    if failed:
        raise RuntimeError(f"tuning worker(s) {failed} failed; see their error output above")
