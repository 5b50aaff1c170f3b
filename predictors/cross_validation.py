"""Scores by group and choices made without the group they are scored on.

Each candidate (a predictor with its parameters) is scored on every recording once; its score on a
recording, per horizon, is its RMS error over constant velocity's (angular, and position where the
recording moves). A group's score is the geometric mean over its recordings, a corpus's the
geometric mean over its groups, so a person recorded four times counts once.

Choosing (`choose`) is by the mean over the horizons of the log of the corpus score, the position
and the angular parts averaged (position only where recordings have it), among the candidates that
are not worse than constant velocity on any recording at any horizon (constant velocity itself is
always such a candidate). Cross-validation (`cross_validate`) makes that choice on all groups but
one and scores the choice on the one left out, for every group: the held-out scores say how the
choosing would do on people (or scenes, or devices) it has never seen.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping, Sequence

from predictors.corpus import Recording
from predictors.evaluation import Evaluation

PARTS = ("angular", "position")  # what choosing weighs: RMS errors
REPORTED = ("angular", "angular_p95", "position", "position_p95")  # what folds report: RMS and tails
_FIELDS = {"angular": "angular_rms_deg", "angular_p95": "angular_p95_deg", "position": "position_rms_mm",
           "position_p95": "position_p95_mm"}


def geometric_mean(values: Sequence[float]) -> float:
    """The geometric mean of the finite positive values (NaN if none)."""
    kept = [v for v in values if math.isfinite(v) and v > 0.0]
    return math.exp(sum(math.log(v) for v in kept) / len(kept)) if kept else math.nan


@dataclass(frozen=True)
class CorpusScores:
    """Every candidate's evaluation on every recording, by candidate label then recording name,
    with the baseline's (constant velocity) among them, and the horizons (ms) scored."""

    evaluations: Mapping[str, Mapping[str, Evaluation]]
    baseline: str
    horizons_ms: tuple[float, ...]

    @property
    def candidates(self) -> tuple[str, ...]:
        """The candidate labels, in the order given."""
        return tuple(self.evaluations)

    def ratio(self, label: str, recording: str, part: str, horizon_ms: float) -> float:
        """One recording's error (a `REPORTED` part) over the baseline's (NaN where the baseline's is
        zero: no position)."""
        field = _FIELDS[part]
        error = getattr(self.evaluations[label][recording].at(horizon_ms), field)
        base = getattr(self.evaluations[self.baseline][recording].at(horizon_ms), field)
        return error / base if base > 0.0 else math.nan

    def group_ratio(self, label: str, recordings: Sequence[str], part: str, horizon_ms: float) -> float:
        """The geometric mean of the recordings' ratios."""
        return geometric_mean([self.ratio(label, r, part, horizon_ms) for r in recordings])

    def corpus_ratio(self, label: str, groups: Mapping[str, Sequence[str]], part: str, horizon_ms: float) -> float:
        """The geometric mean over the groups of each group's ratio."""
        return geometric_mean([self.group_ratio(label, members, part, horizon_ms) for members in groups.values()])

    def worst(self, label: str, recordings: Sequence[str], part: str, horizon_ms: float) -> float:
        """The largest ratio among the recordings (NaN if none has the part)."""
        values = [v for v in (self.ratio(label, r, part, horizon_ms) for r in recordings) if math.isfinite(v)]
        return max(values) if values else math.nan

    def loss(self, label: str, groups: Mapping[str, Sequence[str]]) -> float:
        """The choosing criterion: the mean over horizons of log corpus ratio, parts averaged."""
        parts = []
        for part in PARTS:
            logs = [math.log(r) for h in self.horizons_ms if math.isfinite(r := self.corpus_ratio(label, groups, part, h))]
            if logs:
                parts.append(sum(logs) / len(logs))
        return sum(parts) / len(parts) if parts else math.inf

    def never_worse(self, label: str, recordings: Sequence[str]) -> bool:
        """Whether no recording's ratio exceeds 1 at any horizon, in either part."""
        return all(not self.worst(label, recordings, part, h) > 1.0 for part in PARTS for h in self.horizons_ms)

    def choose(self, groups: Mapping[str, Sequence[str]]) -> str:
        """The candidate with the lowest loss on `groups` among those never worse than the
        baseline on their recordings (the module docstring says why)."""
        recordings = [r for members in groups.values() for r in members]
        allowed = [label for label in self.candidates if self.never_worse(label, recordings)]
        return min(allowed or self.candidates, key=lambda label: self.loss(label, groups))


def groups_of(recordings: Sequence[Recording], by: str) -> dict[str, list[str]]:
    """Recording names by group under `by` (see `Recording.group`), groups in first-seen order;
    recordings apart or without that label are left out."""
    groups: dict[str, list[str]] = {}
    for recording in recordings:
        key = recording.group(by)
        if key is not None:
            groups.setdefault(key, []).append(recording.name)
    return groups


@dataclass(frozen=True)
class Fold:
    """One group held out: the candidate chosen on the others, and its ratios on the group per
    `REPORTED` part and horizon (ms), with the worst recording's ratio."""

    group: str
    recordings: tuple[str, ...]
    chosen: str
    ratios: dict[str, dict[float, float]]
    worst: dict[str, dict[float, float]]


def cross_validate(scores: CorpusScores, groups: Mapping[str, Sequence[str]]) -> list[Fold]:
    """For every group: choose on all the others (`CorpusScores.choose`), score on that one."""
    folds = []
    for held, members in groups.items():
        chosen = scores.choose({g: m for g, m in groups.items() if g != held})
        folds.append(Fold(
            held, tuple(members), chosen,
            {part: {h: scores.group_ratio(chosen, members, part, h) for h in scores.horizons_ms} for part in REPORTED},
            {part: {h: scores.worst(chosen, members, part, h) for h in scores.horizons_ms} for part in REPORTED},
        ))
    return folds


def held_out_mean(folds: Sequence[Fold], part: str, horizon_ms: float) -> float:
    """The geometric mean over the folds of the held-out group's ratio: the cross-validated score."""
    return geometric_mean([fold.ratios[part][horizon_ms] for fold in folds])
