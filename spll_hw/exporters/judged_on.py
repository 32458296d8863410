"""What an export's own choices are judged on beyond the reference trains.

An exporter that picks its step by checks run from memory (the standard targets' step ladder,
:mod:`spll_hw.exporters.dt_ladder`) judges each step as the folder's check will judge the
folder: on the same extra inputs (the user's ``--check-input`` trains and the samples of the
network's own kind of signal, :mod:`.encoded`) and with the same number of sPLLs allowed to
fail (``--max-failed-splls``). ``spll-hw export`` states them for the length of one export
with :func:`judged_on`; the ladder reads them with :func:`extras`. Outside such a block the
ladder judges on the reference trains alone, with the default per-sPLL verdict.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass

from .check_inputs import CheckInput


@dataclass(frozen=True)
class Extras:
    """The extra inputs of an export's check and how many sPLLs may fail it (``None``: the
    default, :data:`~spll_hw.exporters.spll_verdict.MAX_FAILED`)."""

    inputs: tuple[CheckInput, ...] = ()
    max_failed: int | None = None


_EXTRAS: ContextVar[Extras | None] = ContextVar("spll_hw_export_extras", default=None)


@contextmanager
def judged_on(inputs: Sequence[CheckInput], max_failed: int | None = None) -> Iterator[None]:
    """Within the block, an export's own checks run ``inputs`` too and allow ``max_failed``
    failing sPLLs, as its folder's check will."""
    token = _EXTRAS.set(Extras(tuple(inputs), max_failed))
    try:
        yield
    finally:
        _EXTRAS.reset(token)


def extras() -> Extras:
    """The :class:`Extras` of the export running now (none outside :func:`judged_on`)."""
    return _EXTRAS.get() or Extras()
