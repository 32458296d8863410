"""Where a study lives: an SQLite file by default, or any SQLAlchemy URL (PostgreSQL, MySQL).

Several processes (``--workers N``) or machines share one study through the same URL; Optuna
coordinates them through the database. Every worker sends a heartbeat, so a trial whose worker
was killed is marked failed after :data:`GRACE_PERIOD` seconds and retried once with the same
parameters. Finished trials are committed as they finish: a killed run loses none.
"""

from __future__ import annotations

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
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ValueError(f"cannot open storage {mask_url(url)}: {reason}") from None
