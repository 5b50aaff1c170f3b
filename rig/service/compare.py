"""Do two systems' latencies differ? Each group of a summary (by a label) is pooled, every video
weighted by its interval, and the difference between two groups is tested against the spread the
intervals and the videos' disagreement allow.

Each video's 95 % interval gives a standard error (half-width / 1.96). A group's latency is the
inverse-variance weighted mean of its videos; its standard error is the larger of the pooled
one and the one the videos' own scatter implies (a group whose videos disagree more than their
intervals say is not believed to be more precise than they show). Two groups differ when their
difference is more than 1.96 combined standard errors from zero.
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
    """A group's pooled latency (ms), its standard error (ms) and how many videos it rests on."""

    name: str
    latency_ms: float
    se_ms: float
    videos: int


@dataclass(frozen=True)
class Difference:
    """Group b's latency less group a's (ms), its 95 % interval, and whether that excludes zero."""

    a: str
    b: str
    difference_ms: float
    ci95_ms: tuple[float, float]

    @property
    def differs(self) -> bool:
        return self.ci95_ms[0] > 0.0 or self.ci95_ms[1] < 0.0


def group_latencies(rows: Sequence[dict[str, Any]], label: str) -> list[GroupLatency]:
    """Every group of `label`'s values, from the rows with a latency and an interval."""
    groups: dict[str, list[tuple[float, float]]] = {}
    for row in rows:
        if row.get("latency_ms") is None or row.get("ci95_low_ms") is None or row.get("ci95_high_ms") is None:
            continue
        if label not in row:
            raise ConfigError(f"the summary has no label {label!r}")
        se = (float(row["ci95_high_ms"]) - float(row["ci95_low_ms"])) / (2.0 * Z95)
        groups.setdefault(str(row[label]), []).append((float(row["latency_ms"]), max(se, 1e-9)))
    result = []
    for name, values in sorted(groups.items()):
        weights = [1.0 / se**2 for _, se in values]
        mean = sum(w * v for w, (v, _) in zip(weights, values)) / sum(weights)
        se = math.sqrt(1.0 / sum(weights))
        if len(values) > 1:
            scatter = sum((v - mean) ** 2 for v, _ in values) / (len(values) - 1)
            se = max(se, math.sqrt(scatter / len(values)))
        result.append(GroupLatency(name, mean, se, len(values)))
    return result


def differences(groups: Sequence[GroupLatency]) -> list[Difference]:
    """Every pair of groups: b - a with its 95 % interval."""
    pairs = []
    for a, b in combinations(groups, 2):
        difference = b.latency_ms - a.latency_ms
        half = Z95 * math.hypot(a.se_ms, b.se_ms)
        pairs.append(Difference(a.name, b.name, difference, (difference - half, difference + half)))
    return pairs
