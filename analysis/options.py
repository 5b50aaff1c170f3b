"""How a video is analysed (`AnalysisOptions`), each option declared once with its unit, range,
default and help (`declared.setting`), and checked where it enters: a value outside its range is an
AnalysisError naming the range. `analyse` takes the options whole and hands `track` and `estimate`
the same object; the rig's `rig analyse` options, a sweep's [analysis] table and the docs' table
are made from these declarations, so a new option is one field here (and the code that reads it).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from analysis.errors import AnalysisError
from analysis.latency_range import DEFAULT_LATENCY_RANGE_S
from analysis.estimators.registry import ALL, DEFAULT_METHOD, methods
from analysis.hints.hint import APPLIED, CHECKED, IDENTITY, Hint, HintedFacts, in_words
from declared import Flag, Range, check, setting, setting_of
from declared.settings import hints as field_types
from declared.settings import whole_numbers

ROI = tuple[int, int, int, int]
SIDES = ("left", "right")
"""Where the LED's blob may be: the left or the right one of the two."""
CAMERA_RATES = Range(1.0, 10000.0, True, True)
"""Frames per second a camera films at: a webcam's tens to a high-speed camera's several thousand."""
DISPLAY_RATES = Range(1.0, 1000.0, True, True)
"""Refreshes per second of a display: tens (a headset, a monitor) to a few hundred (a gaming panel)."""
PIXELS = Range(0.0, 65535.0, True, True)
"""A position or size in a frame: no sensor is wider than this."""


def _methods() -> tuple[str, ...]:
    """The registered estimators (a lab may register more) and "all"."""
    return (*methods(), ALL)


def increasing(pair: tuple[float, float]) -> str | None:
    """LOW below HIGH."""
    return None if pair[0] < pair[1] else "LOW must be below HIGH"


@dataclass(frozen=True)
class AnalysisOptions:
    """How to analyse a video (see `analysis.analyse`); every field is checked when the options are made."""

    fps: float | None = setting(
        None, "frames per second", "camera frame rate, overriding the file's; needed for image folders", CAMERA_RATES,
        unset="the file's", flag="--fps",
    )  # fmt: skip
    led_roi: ROI | None = setting(
        None, "pixels", "region the LED swings in, X,Y,W,H; give both regions or neither", PIXELS,
        unset="found in the video", flag=Flag("--led-roi", metavar="X,Y,W,H"),
    )  # fmt: skip
    sphere_roi: ROI | None = setting(
        None, "pixels", "region the sphere moves in, X,Y,W,H", PIXELS, unset="found in the video",
        flag=Flag("--sphere-roi", metavar="X,Y,W,H"),
    )  # fmt: skip
    led_side: str | None = setting(
        None, "", "the LED is the blob on this side", choices=SIDES,
        unset="told apart by refresh steps, saturation, size and side", flag="--led-side",
    )  # fmt: skip
    method: str = setting(DEFAULT_METHOD, "", "estimator, as listed below", choices=_methods, flag="--method")
    latency_range_ms: tuple[float, float] = setting(
        tuple(v * 1e3 for v in DEFAULT_LATENCY_RANGE_S), "ms", "latencies considered, to fix the whole number of swing periods (a "
        "display's tens of ms to a streamed one's seconds)", Range(-10000.0, 10000.0, True, True), rule=increasing, flag=Flag("--latency-range", metavar="LOW,HIGH"),
    )  # fmt: skip
    seed: int = setting(0, "", "random seed of the bayes sampler", Range(0.0, 1e9, True, True), flag="--seed")
    display_hz: float | None = setting(
        None, "Hz", "the display's refresh rate, if known; it fixes how the camera samples it", DISPLAY_RATES,
        unset="looked for in the video", flag="--display-hz",
    )  # fmt: skip
    exposure_ms: float | None = setting(
        None, "ms", "the camera's exposure, if known (at most a second)", Range(0.0, 1000.0, includes_high=True), unset="estimated from the LED's motion blur",
        flag="--exposure-ms",
    )  # fmt: skip
    readout_ms: float | None = setting(
        None, "ms", "the camera's rolling-shutter readout, top row to bottom row (0 for a global shutter), if known: "
        "each blob is then timed by its rows", Range(0.0, 1000.0, True, True), unset="any readout up to the frame interval is allowed for",
        flag="--readout-ms",
    )  # fmt: skip

    hints: tuple[Hint, ...] = ()
    """What the lab says of its bench (`analysis.hints`): each fills the option of its name where it
    is unset here, and is checked against the video."""

    def __post_init__(self) -> None:
        check(self, AnalysisError)
        names = [hint.name for hint in self.hints]
        for hint in self.hints:
            problem = _hint_problem(hint) or ("is given twice" if names.count(hint.name) > 1 else None)
            if problem is not None:
                raise AnalysisError(f"the hint {hint.name} ({hint.source}) {problem}, got {hint.value!r}")

    def hinted(self) -> AnalysisOptions:
        """These options with each hint that fills an option (`analysis.hints.APPLIED`) put in where
        the option is unset (the side and the regions only where the options give neither: they
        answer one question); analyse with the options as given, which keep the hints apart."""
        values = {hint.name: hint.value for hint in self.hints if self.overruling(hint.name) is None and hint.name in APPLIED}
        return dataclasses.replace(self, **values) if values else self

    def overruling(self, name: str) -> str | None:
        """What these options give that overrules a hint of this name, in words (None: nothing)."""
        if name in IDENTITY:
            given = [f"{option} {in_words(getattr(self, option))}" for option in IDENTITY if getattr(self, option) is not None]
            return " and ".join(given) or None
        value = getattr(self, name) if name in (*APPLIED, "fps") else None
        return None if value is None else f"{name} {in_words(value)}"

    @property
    def latency_range_s(self) -> tuple[float, float]:
        """The latencies considered, in seconds."""
        low, high = self.latency_range_ms
        return low / 1e3, high / 1e3


def _hint_problem(hint: Hint) -> str | None:
    """What is wrong with a hint's name or value ("must ..."), by the declaration of its name: the
    option's, or the fact's (`analysis.hints.HintedFacts`)."""
    if hint.name not in (*APPLIED, *CHECKED):
        return f"is not one a bench gives ({', '.join((*APPLIED, *CHECKED))})"
    for kind in (AnalysisOptions, HintedFacts):
        field = next((field for field in dataclasses.fields(kind) if field.name == hint.name), None)
        declared = setting_of(field) if field is not None else None
        if declared is not None:
            return declared.problem(hint.value, whole_numbers(field_types(kind)[hint.name]))
    return None
