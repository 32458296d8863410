"""Where a study lives: an SQLite file by default, or any SQLAlchemy URL (PostgreSQL, MySQL).

Several processes (``--workers N``) or machines share one study through the same URL; Optuna
coordinates them through the database. Every worker sends a heartbeat, so a trial whose worker
was killed is marked failed after :data:`GRACE_PERIOD` seconds and retried once with the same
parameters. Finished trials are committed as they finish: a killed run loses none.

A database that fails while a study runs (a full disk, a server gone) ends the command with one
line that names it (:func:`storage_failures`), not with SQLAlchemy's or Optuna's traceback; a
SQLite file the command created and left without a finished trial is removed again.
"""

from __future__ import annotations

import contextlib
import sqlite3
import time
import warnings
from pathlib import Path

from . import INSTALL_HINT, import_optuna

#: Seconds between a running trial's heartbeats, and silence after which it counts as dead.
HEARTBEAT_INTERVAL = 10
GRACE_PERIOD = 60
#: Seconds to wait for a database server before calling it unreachable.
CONNECT_TIMEOUT = 10
#: Tries to open a new database whose schema another process is creating at the same moment.
SCHEMA_ATTEMPTS = 5
#: Default SQLite file name inside the ``--out`` folder.
DEFAULT_DB = "study.db"


def storage_url(spec: str | None, out_dir: str | Path) -> str:
    """An SQLAlchemy URL: ``spec`` if it has a scheme (a bare ``postgresql://`` gets the psycopg
    driver), else an SQLite file (default ``<out_dir>/study.db``)."""
    if spec and "://" in spec:
        scheme, _, rest = spec.partition("://")
        # SQLAlchemy 2.0 and 2.1 pick different default PostgreSQL drivers: name ours.
        return f"postgresql+psycopg://{rest}" if scheme in ("postgresql", "postgres") else spec
    path = Path(spec) if spec else Path(out_dir) / DEFAULT_DB
    return f"sqlite:///{path.resolve()}"


def mask_url(url: str) -> str:
    """``url`` with any password replaced by ``***`` (for messages and reports)."""
    scheme, sep, rest = url.partition("://")
    credentials, at, host = rest.rpartition("@")
    if not sep or not at or ":" not in credentials:
        return url
    return f"{scheme}://{credentials.split(':', 1)[0]}:***@{host}"


def open_storage(url: str):
    """An Optuna ``RDBStorage`` on ``url`` with heartbeats; ``ValueError`` if it cannot be reached.

    SQLite files get their folder created; a server that does not answer within
    :data:`CONNECT_TIMEOUT` seconds, a missing database driver or a malformed URL is a
    ``ValueError`` naming the (password-masked) URL.
    """
    optuna = import_optuna()
    from optuna.storages import RDBStorage, RetryHeartbeatStaleTrialCallback
    from sqlalchemy.exc import IntegrityError, OperationalError, SQLAlchemyError

    engine_kwargs: dict = {}
    if url.startswith("sqlite:///"):
        folder = Path(url.removeprefix("sqlite:///")).parent
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ValueError(f"cannot open storage {url}: cannot create {folder}: {exc}") from None
        engine_kwargs["connect_args"] = {"timeout": 60}
    elif url.startswith(("postgresql", "mysql")):
        engine_kwargs["connect_args"] = {"connect_timeout": CONNECT_TIMEOUT}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
            # Two processes opening a new database at once both create its schema; the loser gets
            # an IntegrityError (alembic_version) or "table ... already exists", and finds the
            # schema made on the next try. Other errors (an unreachable server) fail at once.
            for attempt in range(SCHEMA_ATTEMPTS):
                try:
                    return RDBStorage(
                        url,
                        engine_kwargs=engine_kwargs,
                        heartbeat_interval=HEARTBEAT_INTERVAL,
                        grace_period=GRACE_PERIOD,
                        heartbeat_stale_trial_callback=RetryHeartbeatStaleTrialCallback(
                            max_retry=1
                        ),
                    )
                except (IntegrityError, OperationalError) as exc:
                    racing = isinstance(exc, IntegrityError) or "already exists" in str(exc)
                    if not racing or attempt + 1 == SCHEMA_ATTEMPTS:
                        raise
                    time.sleep(0.2 * (attempt + 1))
    except ImportError:
        raise ValueError(
            f"storage {mask_url(url)}: its database driver is not installed; "
            f"for PostgreSQL: {INSTALL_HINT}"
        ) from None
    except (SQLAlchemyError, optuna.exceptions.StorageInternalError) as exc:
        reason = _reason(exc)
        if "full" in reason:  # SQLite's "database or disk is full"
            reason += " (free some space, or give --out or --storage elsewhere)"
        raise ValueError(f"cannot open storage {mask_url(url)}: {reason}") from None


#: Files SQLite may keep beside a database file ``study.db``.
_SQLITE_SIDE_FILES = ("-journal", "-wal", "-shm")


@contextlib.contextmanager
def storage_failures(url: str):
    """Within the block a failure of the study's database ``url`` (SQLAlchemy's or Optuna's
    storage error: a full disk, a server gone) is a ``ValueError`` that names the database and
    says what to do, and any other error leaves no trace of the block in a SQLite file: a
    database file, with the folders made for it, that did not exist before the block and holds
    no finished trial is removed. Where finished trials are kept, a failed write (the report on
    a full disk) says so and how to go on from them (``--resume``)."""
    path = Path(url.removeprefix("sqlite:///")) if url.startswith("sqlite:///") else None
    made = _missing(path) if path is not None else []
    try:
        yield
    except Exception as exc:
        failed = storage_error(exc)
        if failed is None:
            if _remove_unfinished(path, made) or not isinstance(exc, OSError):
                raise
            raise ValueError(
                f"{exc}; the study's finished trials are kept in {mask_url(url)}: continue with "
                "the same command and --resume (--trials 0 --resume only writes the report)"
            ) from None
        removed = _remove_unfinished(path, made)
        if removed:
            then = "nothing was kept: free some space or give --out or --storage elsewhere"
        else:
            then = ("its finished trials are kept: once it is fixed (free some space), continue "
                    "with the same command and --resume")  # fmt: skip
        raise ValueError(
            f"study storage {mask_url(url)} failed: {_reason(failed)}; {then}"
        ) from None


def storage_error(exc: BaseException) -> BaseException | None:
    """The database's error (SQLAlchemy's, or Optuna's storage error) that ``exc`` is or was
    raised from or while handling, if any (Optuna's trial loop, where a trial's result cannot be
    stored, raises an ``AssertionError``, "Should not reach.", while handling the error)."""
    optuna = import_optuna()
    from sqlalchemy.exc import SQLAlchemyError

    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, (SQLAlchemyError, optuna.exceptions.StorageInternalError)):
            return exc
        seen.add(id(exc))  # a message that said it already (raise ... from None) ends here
        exc = exc.__cause__ or (None if exc.__suppress_context__ else exc.__context__)
    return None


def _missing(path: Path) -> list[Path]:
    """``path``, its SQLite side files and the folders above it that do not exist (yet),
    innermost first."""
    files = [Path(f"{path}{end}") for end in ("", *_SQLITE_SIDE_FILES)]
    missing = [f for f in files if not f.exists()]
    folder = path.parent
    while not folder.exists():
        missing.append(folder)
        folder = folder.parent
    return missing


def _remove_unfinished(path: Path | None, made: list[Path]) -> bool:
    """Remove what the block made of a SQLite database ``path`` (``made``, :func:`_missing`)
    where that database is new and holds no finished trial; whether it did."""
    if path is None or path not in made or _finished_trials(path) != 0:
        return False
    for item in made:  # files, then their folders, innermost first (a folder only if empty)
        with contextlib.suppress(OSError):
            if item.is_dir():
                item.rmdir()
            else:
                item.unlink(missing_ok=True)
    return True


def _finished_trials(path: Path) -> int | None:
    """How many finished (complete or pruned) trials the SQLite file ``path`` holds: 0 for a
    file that is no database or holds no trials table yet (its schema was cut short), ``None``
    where it cannot be told."""
    if not path.exists():
        return 0
    try:
        with contextlib.closing(sqlite3.connect(f"{path.as_uri()}?mode=ro", uri=True)) as db:
            query = "SELECT COUNT(*) FROM trials WHERE state IN ('COMPLETE', 'PRUNED')"
            return int(db.execute(query).fetchone()[0])
    except sqlite3.OperationalError as exc:
        return 0 if "no such table" in str(exc) else None
    except sqlite3.DatabaseError:  # "file is not a database": never written whole
        return 0


def _reason(exc: BaseException) -> str:
    """The first line of the database's own error under ``exc`` (Optuna's storage error wraps
    SQLAlchemy's, whose first line is the driver's: "(sqlite3.OperationalError) database or
    disk is full")."""
    while exc.__cause__ is not None:
        exc = exc.__cause__
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__
