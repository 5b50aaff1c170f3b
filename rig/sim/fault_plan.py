"""The simulated tracker's faults as a plan, read from a spec such as `corrupt=0.01,disconnect=4:0.5`
(`rig.sim.tracker_faults` lists the faults and applies them): light, so that the command line reads
the spec without numpy."""

from __future__ import annotations

import math
from dataclasses import dataclass

from rig.errors import ConfigError


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
