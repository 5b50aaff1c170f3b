"""Do two systems' latencies differ? Each group of a summary (by a label) is pooled, every video
weighted by its interval, and the difference between two groups is tested against the spread the
intervals and the videos' disagreement allow.

Each video's 95 % interval gives a standard error (half-width / 1.96). A group's latency is the
inverse-variance weighted mean of its videos; its standard error is the larger of the pooled
one and the one the videos' own scatter implies (a group whose videos disagree more than their
intervals say is not believed to be more precise than they show). Two groups differ when their
difference is more than 1.96 combined standard errors from zero.

Only videos filmed under the same conditions are pooled: a group is one value of the label compared
and one value of each other label (`conditions`), and only groups whose conditions match are
compared. Where the rows know the truth (a sweep's simulated runs), a group carries its mean.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import combinations
from typing import Any, Sequence

from rig.errors import ConfigError

Z95 = 1.959963984540054


@dataclass(frozen=True)
class GroupLatency:
    """A group's pooled latency (ms), its standard error (ms) and how many videos it rests on; the
    other labels' values it was filmed under, and the mean true latency (ms) where every video
    knows its own."""

    name: str
    latency_ms: float
    se_ms: float
    videos: int
    conditions: tuple[tuple[str, str], ...] = ()
    truth_ms: float | None = None

    @property
    def error_ms(self) -> float | None:
        return None if self.truth_ms is None else self.latency_ms - self.truth_ms


@dataclass(frozen=True)
class Difference:
    """Group b's latency less group a's (ms), its 95 % interval, and whether that excludes zero,
    under the conditions both were filmed under."""

    a: str
    b: str
    difference_ms: float
    ci95_ms: tuple[float, float]
    conditions: tuple[tuple[str, str], ...] = ()

    @property
    def differs(self) -> bool:
        return self.ci95_ms[0] > 0.0 or self.ci95_ms[1] < 0.0


def group_latencies(rows: Sequence[dict[str, Any]], label: str, conditions: Sequence[str] = ()) -> list[GroupLatency]:
    """Every group of `label`'s values under each combination of the `conditions` labels' values,
    from the rows with a latency and an interval."""
    groups: dict[tuple[str, tuple[tuple[str, str], ...]], list[dict[str, Any]]] = {}
    for row in rows:
        if row.get("latency_ms") is None or row.get("ci95_low_ms") is None or row.get("ci95_high_ms") is None:
            continue
        missing = [name for name in (label, *conditions) if name not in row]
        if missing:
            raise ConfigError(f"the summary has no label {missing[0]!r}")
        key = (str(row[label]), tuple((name, str(row[name])) for name in conditions))
        groups.setdefault(key, []).append(row)
    return [_pooled(name, condition, members) for (name, condition), members in sorted(groups.items())]


def _pooled(name: str, conditions: tuple[tuple[str, str], ...], rows: Sequence[dict[str, Any]]) -> GroupLatency:
    values = [(float(row["latency_ms"]), max((float(row["ci95_high_ms"]) - float(row["ci95_low_ms"])) / (2.0 * Z95), 1e-9)) for row in rows]
    weights = [1.0 / se**2 for _, se in values]
    mean = sum(w * v for w, (v, _) in zip(weights, values)) / sum(weights)
    se = math.sqrt(1.0 / sum(weights))
    if len(values) > 1:
        scatter = sum((v - mean) ** 2 for v, _ in values) / (len(values) - 1)
        se = max(se, math.sqrt(scatter / len(values)))
    truths = [row.get("truth_ms") for row in rows]
    truth = sum(map(float, truths)) / len(truths) if all(t not in (None, "") for t in truths) else None  # type: ignore[arg-type]
    return GroupLatency(name, mean, se, len(values), conditions, truth)


def differences(groups: Sequence[GroupLatency]) -> list[Difference]:
    """Every pair of groups filmed under the same conditions: b - a with its 95 % interval."""
    pairs = []
    for a, b in combinations(groups, 2):
        if a.conditions != b.conditions:
            continue
        difference = b.latency_ms - a.latency_ms
        half = Z95 * math.hypot(a.se_ms, b.se_ms)
        pairs.append(Difference(a.name, b.name, difference, (difference - half, difference + half), a.conditions))
    return pairs
