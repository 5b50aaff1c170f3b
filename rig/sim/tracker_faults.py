"""The one fault model of the simulated tracker (`rig.sim.tracker`), from a spec such as
`corrupt=0.01,disconnect=4:0.5`:

    corrupt=P         each byte replaced by another with probability P (serial)
    drop=P            each byte left out with probability P (serial)
    garbage=R         R times a second on average, 1 to 32 random bytes between records (serial)
    burst=N           records sent N at a time, as a buffering USB bridge does
    stall=AT:S        at AT s nothing is sent for S s; then what was held goes at once
    disconnect=AT:S   at AT s the port (or LSL outlet) goes away for S s; records meanwhile are lost

Times are on the tracker's time line (the stream's start for `rig emulate-tracker`, the rig clock
in a simulated run). `delivered` applies the faults in time (burst, stall, disconnect) to when
records reach the host, for the in-process tracker and the emulator alike; `ByteFaults` damages the
bytes the emulator sends, so corrupt, drop and garbage exist only where there are bytes (a serial
stream). All randomness comes from one seeded generator, so a seed fixes every fault.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rig.errors import ConfigError

_GARBAGE_MAX = 32


@dataclass(frozen=True)
class FaultPlan:
    corrupt: float = 0.0
    drop: float = 0.0
    garbage: float = 0.0
    burst: int = 1
    stall: tuple[float, float] | None = None
    disconnect: tuple[float, float] | None = None

    @property
    def label(self) -> str:
        """The spec that gives this plan ("none" for a clean one)."""
        parts = [f"{name}={getattr(self, name):g}" for name in ("corrupt", "drop", "garbage") if getattr(self, name)]
        if self.burst > 1:
            parts.append(f"burst={self.burst}")
        parts += [f"{name}={at:g}:{s:g}" for name in ("stall", "disconnect") if (value := getattr(self, name)) for at, s in [value]]
        return ",".join(parts) or "none"

    @property
    def damages_bytes(self) -> bool:
        return bool(self.corrupt or self.drop or self.garbage)


def _probability(name: str, text: str) -> float:
    value = _number(name, text)
    if not 0.0 <= value < 1.0:
        raise ConfigError(f"fault {name}={text}: expected a probability in [0, 1)")
    return value


def _number(name: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ConfigError(f"fault {name}={text}: expected a number") from None
    if not math.isfinite(value) or value < 0.0:
        raise ConfigError(f"fault {name}={text}: expected a number >= 0")
    return value


def _period(name: str, text: str) -> tuple[float, float]:
    at, sep, seconds = text.partition(":")
    if not sep:
        raise ConfigError(f"fault {name}={text}: expected AT:SECONDS, such as {name}=4:0.5")
    return _number(name, at), _number(name, seconds)


def parse_faults(spec: str) -> FaultPlan:
    """A plan from `name=value,...` ("none" or "" for no faults); ConfigError naming a bad part."""
    values: dict[str, object] = {}
    for part in filter(None, spec.split(",")) if spec != "none" else []:
        name, sep, text = part.partition("=")
        if not sep:
            raise ConfigError(f"fault {part!r}: expected name=value (corrupt, drop, garbage, burst, stall, disconnect)")
        if name in ("corrupt", "drop"):
            values[name] = _probability(name, text)
        elif name == "garbage":
            values[name] = _number(name, text)
        elif name == "burst":
            if not text.isdigit() or int(text) < 1:
                raise ConfigError(f"fault burst={text}: expected a whole number of records >= 1")
            values[name] = int(text)
        elif name in ("stall", "disconnect"):
            values[name] = _period(name, text)
        else:
            raise ConfigError(f"unknown fault {name!r}; faults: corrupt, drop, garbage, burst, stall, disconnect")
    return FaultPlan(**values)  # type: ignore[arg-type]


def delivered(plan: FaultPlan, t_arrival: np.ndarray, lost: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """When each record reaches the host under the plan's disconnect, stall and burst, and which are
    lost, from when each would arrive (in order) and which were lost already: a disconnect loses
    what would arrive while the link is away, a stall holds what would arrive during it until its
    end, and a burst holds records until the last of each N sent has come."""
    t, lost = t_arrival.copy(), lost.copy()
    if plan.disconnect:
        at, seconds = plan.disconnect
        lost |= (t >= at) & (t < at + seconds)
    if plan.stall:
        at, seconds = plan.stall
        t[(t >= at) & (t < at + seconds)] = at + seconds
    if plan.burst > 1:
        sent = np.flatnonzero(~lost)
        last_of_group = np.minimum((np.arange(sent.size) // plan.burst + 1) * plan.burst, sent.size) - 1
        t[sent] = t[sent[last_of_group]]
    return t, lost


class ByteFaults:
    """Damages records' bytes as the plan says: `apply(record, rate_hz)` gives (bytes to send, damaged)."""

    def __init__(self, plan: FaultPlan, seed: int) -> None:
        self.plan = plan
        self._rng = np.random.default_rng(seed)

    def apply(self, record: bytes, rate_hz: float) -> tuple[bytes, bool]:
        plan, rng = self.plan, self._rng
        prefix = b""
        if plan.garbage and rng.random() < plan.garbage / rate_hz:
            prefix = rng.integers(0, 256, int(rng.integers(1, _GARBAGE_MAX + 1)), dtype=np.uint8).tobytes()
        data = np.frombuffer(record, dtype=np.uint8).copy()
        damaged = False
        if plan.corrupt:
            hit = rng.random(data.size) < plan.corrupt
            if hit.any():
                data[hit] = (data[hit] + rng.integers(1, 256, int(hit.sum()))) % 256
                damaged = True
        if plan.drop:
            keep = rng.random(data.size) >= plan.drop
            if not keep.all():
                data = data[keep]
                damaged = True
        return prefix + data.tobytes(), damaged
