"""Pareto dominance of points with several objectives, each maximised or minimised, and of
points whose cost is a range (:func:`range_front`)."""

from __future__ import annotations

from collections.abc import Callable, Sequence


def dominates(a: Sequence[float], b: Sequence[float], signs: Sequence[float]) -> bool:
    """Whether point ``a`` dominates ``b``: at least as good in every objective and better in
    one; ``signs`` is +1 for an objective maximised, -1 for one minimised."""
    better = [s * (x - y) for x, y, s in zip(a, b, signs, strict=True)]
    return all(d >= 0 for d in better) and any(d > 0 for d in better)


def front(points: Sequence[Sequence[float]], signs: Sequence[float]) -> list[int]:
    """Indices, in input order, of the points no other point dominates (duplicates all kept)."""
    return [
        i
        for i, p in enumerate(points)
        if not any(dominates(q, p, signs) for j, q in enumerate(points) if j != i)
    ]


def range_front(accuracy: Sequence[float], cheaper: Callable[[int, int], bool | None]) -> list[int]:
    """Indices, in input order, of the points no other dominates when their cost is a range:
    ``j`` dominates ``i`` only where it is at least as accurate (``accuracy``, maximised) and
    cheaper at both ends of the ranges (``cheaper(j, i)`` is ``True``: e.g.
    :func:`spll_hw.chips.cheaper`). Where the ranking flips inside the ranges (``None``) both
    points stay, however their single values rank."""
    n = len(accuracy)
    return [
        i
        for i in range(n)
        if not any(accuracy[j] >= accuracy[i] and cheaper(j, i) is True for j in range(n) if j != i)
    ]
