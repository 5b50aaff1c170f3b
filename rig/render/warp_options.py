"""The warp renderer's options, as `--renderer warp:key=value,...` gives them (`rig.render.registry`).

| option | values | default | what |
| --- | --- | --- | --- |
| `views` | 1, 2 | 1 | client views; the second is drawn at the poses predicted for the end of the span the frame is warped over, and fills only the first's holes (Mark et al. 1997) |
| `recon` | point, quad, mesh, grid | point | how warped pixels are drawn (`rig.render.warp_server`) |
| `holes` | 0, 1, 2 | 0 | hole levels found against a proxy map and re-rendered (0: none, level-0 holes are only filled; `rig.render.warp_holes`) |
| `fill` | nearest, lowpass | nearest | how the holes left are filled (`rig.render.warp_fill`) |
| `border` | 0 to 1 | 0.05 | how much wider the client's view is than the display's, per side, as a share of its size |
| `untracked` | extrapolate, hold | extrapolate | the server pose of objects that move without being tracked: extrapolated from their last two client poses (section 3.2), or held at the client's |
| `spin` | degrees per second | 0 | the load turns about the view axis at this rate, untracked (a moving object for the warp to follow) |
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from rig.errors import ConfigError
from rig.render.warp_fill import FILLS
from rig.render.warp_holes import HOLE_LEVELS
from rig.render.warp_server import RECONSTRUCTIONS

UNTRACKED_MODES = ("extrapolate", "hold")
BORDER_FRACTION = 0.05


@dataclass(frozen=True)
class WarpOptions:
    """See the module docstring."""

    views: int = 1
    recon: str = "point"
    holes: int = 0
    fill: str = "nearest"
    border: float = BORDER_FRACTION
    untracked: str = "extrapolate"
    spin: float = 0.0

    def __post_init__(self) -> None:
        choices = {"views": (1, 2), "recon": RECONSTRUCTIONS, "holes": HOLE_LEVELS, "fill": FILLS, "untracked": UNTRACKED_MODES}
        for name, allowed in choices.items():
            if getattr(self, name) not in allowed:
                raise ConfigError(
                    f"warp option {name} must be one of {', '.join(map(str, allowed))}, got {getattr(self, name)!r}"
                )
        if not (isinstance(self.border, (int, float)) and math.isfinite(self.border) and 0.0 <= self.border <= 1.0):
            raise ConfigError(f"warp option border is the client's extra view per side, 0-1 of the display size, got {self.border!r}")
        if not (isinstance(self.spin, (int, float)) and math.isfinite(self.spin)):
            raise ConfigError(f"warp option spin is the load's turn in degrees per second, got {self.spin!r}")

    def spec(self) -> str:
        """The renderer spec that makes these options: 'warp' and the options that differ from the defaults."""
        changed = [f"{f.name}={getattr(self, f.name):g}" if isinstance(getattr(self, f.name), float) else f"{f.name}={getattr(self, f.name)}"
                   for f in fields(self) if getattr(self, f.name) != f.default]  # fmt: skip
        return "warp" + (":" + ",".join(changed) if changed else "")
