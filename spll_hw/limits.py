"""Limits checked before long or large work starts: thread counts and memory estimates.

A request the machine cannot serve (ten thousand threads, a recording bigger than the free
memory) is a ``ValueError`` saying what it would need, raised before anything is allocated,
instead of an interpreter killed by an allocation failure or a run that crawls.
"""

from __future__ import annotations

import numbers
import os
from collections.abc import Iterator
from contextlib import contextmanager

#: Threads per core a call may ask for: more only adds scheduling overhead.
THREADS_PER_CORE = 8
#: Share of the available memory one request may plan to use.
MEMORY_SHARE = 0.25


def cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def max_threads() -> int:
    """Largest ``threads`` a simulation accepts."""
    return THREADS_PER_CORE * cores()


def check_threads(threads: int | None) -> int | None:
    """``threads`` (``None``: all cores) validated: an integer in ``1 .. max_threads()``."""
    if threads is None:
        return None
    if isinstance(threads, bool) or not isinstance(threads, numbers.Integral):
        raise ValueError(f"threads must be an integer >= 1 or None, got {threads!r}")
    threads = int(threads)
    if threads < 1:
        raise ValueError(f"threads must be >= 1, got {threads}")
    if threads > max_threads():
        raise ValueError(
            f"threads = {threads} is more than this machine can use: it has {cores()} cores, "
            f"and at most {max_threads()} threads are accepted (None uses all cores)"
        )
    return threads


def available_memory() -> int:
    """Memory [bytes] this process can still allocate without swapping (Linux: MemAvailable),
    and within its address-space limit (``ulimit -v``, :func:`address_space_left`)."""
    free = None
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    free = int(line.split()[1]) * 1024
    except OSError:  # pragma: no cover - not Linux
        pass
    if free is None:  # pragma: no cover - not Linux
        free = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_AVPHYS_PAGES")
    left = address_space_left()
    return free if left is None else min(free, left)


def address_space_left() -> int | None:
    """Bytes of address space this process may still map under its limit (``RLIMIT_AS``,
    ``ulimit -v``), ``None`` without a limit. Past it every allocation fails: the engine's
    (in Rust) aborts the process, so requests are measured against it beforehand."""
    try:
        import resource  # Unix only: the ImportError below is the other systems' answer

        limit, _ = resource.getrlimit(resource.RLIMIT_AS)
        if limit == resource.RLIM_INFINITY:
            return None
        with open("/proc/self/statm") as fh:
            mapped = int(fh.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (ImportError, OSError, ValueError):  # pragma: no cover - not Linux
        return None
    return max(0, limit - mapped)


def human_bytes(n: float) -> str:
    """``1.5e9`` → ``"1.4 GiB"``."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB"):
        if abs(n) < 1024 or unit == "TiB":
            return f"{n:.3g} {unit}" if unit != "B" else f"{int(n)} B"
        n /= 1024
    raise AssertionError("unreachable")


def check_memory(needed: float, what: str, fix: str) -> None:
    """Refuse a request whose planned memory ``needed`` [bytes] exceeds :data:`MEMORY_SHARE` of
    the available memory; the message says ``what`` needs it and how to ``fix`` it."""
    limit = MEMORY_SHARE * available_memory()
    if needed > limit:
        raise ValueError(
            f"{what} would need about {human_bytes(needed)} of memory, more than "
            f"{100 * MEMORY_SHARE:.0f} % of the {human_bytes(available_memory())} available; "
            f"{fix}"
        )


@contextmanager
def out_of_memory(what: str, needed: float, fix: str) -> Iterator[None]:
    """Give a ``MemoryError`` raised inside (often with an empty message) one that says
    ``what`` ran out, about how much it needed [bytes], what is available and how to ``fix``
    it."""
    try:
        yield
    except MemoryError as exc:
        left = address_space_left()
        limit = "" if left is None else " (the process has an address-space limit, ulimit -v)"
        raise MemoryError(
            f"out of memory {what}: it needs about {human_bytes(needed)}, and "
            f"{human_bytes(available_memory())} is available{limit}; {fix}"
        ) from exc
