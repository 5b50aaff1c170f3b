"""A hint (`Hint`): a value a lab's description of its bench gives, with where it came from; and what
the analysis made of it (`HintCheck`).

A hint is named for what it says. Those in APPLIED fill the analysis option of the same name; the
others are only checked against the video: the camera's frame rate ("fps": the frame times come
from the file, not from a hint), and the facts of `HintedFacts`, which no option holds (the
display's scan-out, where the blobs sit in rows). Each value is checked where it enters, against
the declaration of its name (`AnalysisOptions` checks its hints).
"""

from __future__ import annotations

from dataclasses import dataclass

from declared import Range, setting

SCANOUTS = ("top-down", "bottom-up")
"""Which way a display's scan-out, or a camera's readout, moves across the film's rows."""

APPLIED = ("display_hz", "exposure_ms", "readout_ms", "led_side", "led_roi", "sphere_roi")
"""Hints that fill the analysis option of their name where the options leave it unset."""
IDENTITY = ("led_side", "led_roi", "sphere_roi")
"""Hints that say which blob is the LED: the options' side or regions overrule them all."""

AGREES, CONTRADICTS, CANNOT_CHECK, OVERRULED = "agrees", "contradicts", "cannot check", "overruled"

_ROW = Range(0.0, 1.0, includes_low=True, includes_high=True)


@dataclass(frozen=True)
class HintedFacts:
    """What a lab may say of its bench that no analysis option holds: the analysis checks these
    against the video, and uses none of them. (A declaration: a hint of one of these names is
    checked against its field's.)"""

    scanout: str = setting("top-down", "", "which way the display's scan-out moves in the film", choices=SCANOUTS)
    led_row: float | None = setting(
        None, "", "the LED's mean row in the film, as a share of the frame's height from the top", _ROW, unset="not said",
    )  # fmt: skip
    sphere_row: float | None = setting(
        None, "", "the sphere's mean row in the film, as a share of the frame's height from the top", _ROW, unset="not said",
    )  # fmt: skip


CHECKED = ("fps", "scanout", "led_row", "sphere_row")
"""Hints the analysis only checks against the video."""

Value = float | str | tuple[int, int, int, int]


def in_words(value: Value) -> str:
    """A hint's or an option's value as a message reads it: 60, left, [0, 0, 40, 30]."""
    return f"{value:g}" if isinstance(value, float) else str(list(value)) if isinstance(value, tuple) else str(value)


@dataclass(frozen=True)
class Hint:
    """A value a lab gives for `name` (one of APPLIED or CHECKED, in the unit of the option or fact
    of that name), and where it came from, in the lab's words ("bench.toml [camera]: rig
    calibrate-camera 2026-11-28 from flash.mp4")."""

    name: str
    value: Value
    source: str


@dataclass(frozen=True)
class HintCheck:
    """What the analysis made of a hint: the value the video shows for it, in words where it shows
    one (None where it shows nothing), the verdict (AGREES, CONTRADICTS, CANNOT_CHECK, or OVERRULED
    where the options gave the value), and what the analysis used instead of or as the hint."""

    hint: Hint
    video: str | None
    verdict: str
    used: str

    def to_dict(self) -> dict[str, object]:
        value = self.hint.value
        return {
            "name": self.hint.name,
            "value": list(value) if isinstance(value, tuple) else value,
            "source": self.hint.source,
            "video": self.video,
            "verdict": self.verdict,
            "used": self.used,
        }
