"""Pareto dominance of points with several objectives, each maximised or minimised."""

from __future__ import annotations

from collections.abc import Sequence


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
