"""How a film of a flashing light is read (`ShutterOptions`), each option declared once with its
unit, range, default and help (`declared.setting`), and checked where it enters: a value outside
its range is an AnalysisError naming it. `rig calibrate-camera`'s options are made from these
declarations. The flash frequency itself is not among them: every film needs its own."""

from __future__ import annotations

from dataclasses import dataclass

from analysis.errors import AnalysisError
from analysis.hints.hint import HintedFacts
from analysis.options import DISPLAY_RATES, PIXELS, AnalysisOptions
from declared import OPEN_UNIT, Flag, Range, check, like, setting

ROI = tuple[int, int, int, int]
SOURCES = ("light", "display")
DISPLAY_GROUP = "a flashing display (its own scan-out sweeps the rows, and is accounted for)"


@dataclass(frozen=True)
class ShutterOptions:
    """How to read a film of a flashing light (see `analysis.shutter.measure_shutter`); every field
    is checked when the options are made."""

    duty: float | None = setting(
        0.5, "", "the share of each period the light is on, or 'fit' where not known; it tells the exposure from the light's on time",
        OPEN_UNIT,
        none="fit", unset="fitted, when not known", flag=Flag("--duty", metavar="D"),
    )  # fmt: skip
    source: str = setting("light", "", "what flashes: a light, or a display whose rows scan out", choices=SOURCES, flag="--source")
    display_hz: float | None = setting(
        None, "Hz", "the flashing display's refresh rate", DISPLAY_RATES, unset="no display", flag=Flag("--display-hz", metavar="HZ", group="display"),
    )  # fmt: skip
    scanout: str = like(HintedFacts, "scanout", flag=Flag("--scanout", group="display"))
    scanout_share: float | None = setting(
        None, "", "the share of each refresh the display's scan-out takes (active lines over total lines)",
        Range(0.0, 1.0, includes_high=True), unset="0.88 to 1 allowed for", flag=Flag("--scanout-share", metavar="S", group="display"),
    )  # fmt: skip
    roi: ROI | None = setting(
        None, "pixels", "look for the flashing light only here, X,Y,W,H (a display: its whole height)", PIXELS,
        unset="the whole frame", flag=Flag("--roi", metavar="X,Y,W,H"),
    )  # fmt: skip
    fps: float | None = like(AnalysisOptions, "fps")
    max_exposure_s: float | None = setting(
        None, "seconds", "the longest the camera's exposure can be, at most a second", Range(0.0, 1.0, includes_high=True), unset="a frame interval",
        flag=Flag("--max-exposure-ms", unit="ms", factor=1e3, metavar="MS"),
    )  # fmt: skip

    def __post_init__(self) -> None:
        check(self, AnalysisError)
        if self.source == "display" and self.display_hz is None:
            raise AnalysisError("a flashing display's scan-out must be accounted for: give its refresh rate (--display-hz)")
        if self.source == "light" and self.display_hz is not None:
            raise AnalysisError("the display's refresh rate describes a flashing display: give --source display with it, or leave it out")
