"""`rig plan`'s accuracy, declared for the command line without the planner's libraries
(`rig.service.plan` plans with it)."""

from __future__ import annotations

from dataclasses import dataclass

from declared import Range, setting


@dataclass(frozen=True)
class PlanAccuracy:
    """The accuracy a plan must reach."""

    accuracy_ms: float = setting(
        1.0, "ms", "the 95% half-width of the latency wanted, from 10 us to 100 ms",
        Range(0.01, 100.0, True, True), flag="--accuracy-ms",
    )  # fmt: skip
