"""Where the bench sits in the simulated camera's frame, by name or spelt out: what the command line's
`--layout` is checked against, without the simulation's numerical libraries (`rig.sim.layout` maps
the bench into pixels)."""

from __future__ import annotations

from dataclasses import dataclass

from rig.errors import ConfigError

LAYOUTS = {
    "side-by-side": "0.25,0.5,0.4/0.75,0.5,0.42",
    "led-above": "0.27,0.3,0.4/0.73,0.65,0.42",
    "led-below": "0.27,0.7,0.4/0.73,0.35,0.42",
}
DEFAULT_LAYOUT = "side-by-side"
LAYOUT_HELP = (
    f"{', '.join(LAYOUTS)} (the LED 35 % of the frame's height above or below the display), or "
    "LX,LY,LW/DX,DY,DW: the LED swing's centre and width, then the display panel's, as fractions of the "
    "frame (x and widths of its width, y of its height)"
)


@dataclass(frozen=True)
class Placement:
    """Where the bench sits in the camera's frame: the LED's swing and the display panel, each as
    (centre x, centre y, width), fractions of the frame's width (x, width) and height (y)."""

    led: tuple[float, float, float]
    display: tuple[float, float, float]


def placement(spec: str) -> Placement:
    """The placement a layout names (`LAYOUTS`) or spells out as LX,LY,LW/DX,DY,DW; ConfigError if neither."""
    text = LAYOUTS.get(spec, spec)
    parts = text.split("/")
    try:
        numbers = [tuple(float(v) for v in part.split(",")) for part in parts]
    except ValueError:
        numbers = []
    if len(numbers) != 2 or any(len(n) != 3 for n in numbers) or not all(0.0 < v < 1.0 for n in numbers for v in n):
        raise ConfigError(
            f"a bench layout is one of {', '.join(LAYOUTS)} or LX,LY,LW/DX,DY,DW with fractions of the frame in (0, 1), "
            f"got {spec!r}"
        )
    (lx, ly, lw), (dx, dy, dw) = numbers
    return Placement(led=(lx, ly, lw), display=(dx, dy, dw))
