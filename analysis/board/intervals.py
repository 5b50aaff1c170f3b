"""Intervals that must all hold one true value (a clock offset), some of which may be wrong."""

from __future__ import annotations

from typing import Sequence


def consistent_intersection(lows: Sequence[float], highs: Sequence[float]) -> tuple[float, float, list[int]]:
    """The intersection of the largest set of intervals [lows[i], highs[i]] that share a point,
    and the indices of that set. An interval that misses the others (a round trip during which
    an emulated clock stalled, a misread frame) is left out instead of emptying the intersection."""
    if not lows or len(lows) != len(highs):
        raise ValueError("need as many lows as highs, and at least one")
    best: list[int] = []
    for point in (*lows, *highs):
        members = [i for i, (low, high) in enumerate(zip(lows, highs)) if low <= point <= high]
        if len(members) > len(best):
            best = members
    if not best:
        raise ValueError("every interval is empty (low above high)")
    return max(lows[i] for i in best), min(highs[i] for i in best), best
