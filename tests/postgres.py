"""A throwaway PostgreSQL server on loopback for tests (Debian's ``postgresql`` package).

:func:`postgres_server` finds ``initdb``/``pg_ctl`` (on PATH or under /usr/lib/postgresql/*/bin),
initialises a cluster in a fresh temporary folder, starts it on a free 127.0.0.1 port with trust
authentication and yields its SQLAlchemy URL; the server is stopped and the folder removed
afterwards. PostgreSQL refuses to run as root, so under root the cluster belongs to (and runs as)
the ``postgres`` user the Debian package creates. Raises :class:`Unavailable` (the reason) when
the binaries or that user are missing.
"""

from __future__ import annotations

import contextlib
import glob
import os
import pwd
import shutil
import socket
import subprocess
import tempfile
from collections.abc import Iterator
from pathlib import Path


class Unavailable(RuntimeError):
    """PostgreSQL cannot be started here (the message says why)."""


def _binary(name: str) -> str:
    found = shutil.which(name) or next(
        iter(sorted(glob.glob(f"/usr/lib/postgresql/*/bin/{name}"), reverse=True)), None
    )
    if found is None:
        raise Unavailable(f"PostgreSQL's {name} not found (apt-get install postgresql)")
    return found


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def postgres_server() -> Iterator[str]:
    """Context manager yielding ``postgresql://spll@127.0.0.1:PORT/postgres``."""
    initdb, pg_ctl = _binary("initdb"), _binary("pg_ctl")
    prefix: list[str] = []
    owner = None
    if os.geteuid() == 0:
        try:
            owner = pwd.getpwnam("postgres")
        except KeyError:
            raise Unavailable("running as root and there is no 'postgres' user") from None
        prefix = ["runuser", "-u", "postgres", "--"]
    root = Path(tempfile.mkdtemp(prefix="spll-pg-"))
    if owner is not None:
        os.chown(root, owner.pw_uid, owner.pw_gid)
    data, log = root / "data", root / "server.log"
    port = _free_port()
    env = os.environ | {"LC_ALL": "C", "LANG": "C"}

    def run(*cmd: str) -> None:
        done = subprocess.run([*prefix, *cmd], capture_output=True, text=True, env=env)
        if done.returncode != 0:
            tail = log.read_text()[-2000:] if log.exists() else ""
            raise Unavailable(f"{cmd[0]} failed: {done.stderr.strip()} {tail}")

    try:
        run(initdb, "-D", str(data), "-U", "spll", "--auth=trust", "-E", "UTF8", "--no-sync")
        options = f"-p {port} -k {root} -c listen_addresses=127.0.0.1 -c fsync=off"
        run(pg_ctl, "-D", str(data), "-o", options, "-l", str(log), "-w", "-t", "60", "start")
        try:
            yield f"postgresql://spll@127.0.0.1:{port}/postgres"
        finally:
            subprocess.run(
                [*prefix, pg_ctl, "-D", str(data), "-m", "immediate", "stop"],
                capture_output=True,
                env=env,
            )
    finally:
        shutil.rmtree(root, ignore_errors=True)
