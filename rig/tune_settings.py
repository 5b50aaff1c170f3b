"""`rig tune`'s numbers, declared for the command line without the tuning's libraries (`rig.service.tune`
tunes with them)."""

from __future__ import annotations

from dataclasses import dataclass

from declared import Range, setting

HORIZONS = Range(0.0, 1000.0, True, True)
"""A prediction horizon: a display's photons come tens of ms after a sample, a cloud-rendered one's
a few hundred; past a second no motion is predictable."""


@dataclass(frozen=True)
class TuneSettings:
    """`rig tune`'s numbers, each declared on its field (its options are made from them and checked
    against their ranges as the command line is read)."""

    split: float = setting(0.6, "", "fraction of each trace's duration to train on when no --held-out is given",
                           Range(0.0, 1.0), flag="--split")  # fmt: skip
    horizon_ms: float | None = setting(None, "ms", "prediction horizon after each sample's arrival to tune for", HORIZONS,
                                       unset="always given", flag="--horizon-ms")  # fmt: skip
    max_iterations: int = setting(40, "", "optimiser iterations at most", Range(0.0, 10000.0, True, True), flag="--max-iterations")
