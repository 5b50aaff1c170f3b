"""A lab's bench described once: the bench profile, a TOML file of its camera, display and layout,
each value with where it came from.

    [camera]
    fps = 120.0
    fps_source = "rig calibrate-camera 2026-11-28 from flash.mp4"
    exposure_ms = 2.01
    exposure_ci95_ms = [1.95, 2.08]
    exposure_source = "rig calibrate-camera 2026-11-28 from flash.mp4"
    readout_ms = 7.02
    readout_ci95_ms = [6.97, 7.08]
    readout_source = "rig calibrate-camera 2026-11-28 from flash.mp4"

    [display]
    refresh_hz = 60.0
    refresh_source = "datasheet"

    [layout]
    led_side = "left"
    source = "the LED left of the monitor"

Every key is declared once (`CameraProfile`, `DisplayProfile`, `LayoutProfile`: most as the
analysis option or fact they give, `declared.like`), read with every key, type and range checked
(`read_profile`; a bad file is one `ConfigError` line), and written back changing only the keys
set (`write_profile`: the rest of the file, comments included, stays as it was). `rig plan --bench`
and `rig calibrate-camera --bench` write it; `rig analyse`, `rig measure` and a sweep's
`[analysis] bench` read it: each value becomes a hint (`analysis.hints`) that fills the analysis
option of its name unless the command line gives it, and that the analysis checks against the
video (`with_profile`). A flashing display for `rig calibrate-camera` takes its refresh and
scan-out from it (`shutter_display`).
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import tomlkit
import tomlkit.exceptions

from analysis import AnalysisOptions
from analysis.hints import Hint
from analysis.hints.hint import HintedFacts
from analysis.options import increasing
from analysis.readout import READOUT_TOLERANCE
from declared import Range, check, from_table, like, setting
from rig.errors import ConfigError
from rig.toml_file import read_toml

ROI = tuple[int, int, int, int]


def _source(what: str, examples: str = "a datasheet, rig plan, rig calibrate-camera") -> Any:
    return setting("", "", f"where the {what} came from, in the lab's words ({examples})")


def _interval(what: str) -> Any:
    return setting(None, "ms", f"the {what}'s 95 % interval, where it was measured", Range(0.0, 1000.0, True, True), rule=increasing, unset="not measured")


@dataclass(frozen=True)
class CameraProfile:
    """The camera as it is set for filming the bench."""

    fps: float | None = like(AnalysisOptions, "fps", help="the camera's frame rate as set", unset="not said", flag=None)
    fps_source: str = _source("frame rate")
    exposure_ms: float | None = like(AnalysisOptions, "exposure_ms", help="the camera's exposure", unset="not said", flag=None)
    exposure_ci95_ms: tuple[float, float] | None = _interval("exposure")
    exposure_source: str = _source("exposure")
    readout_ms: float | None = like(
        AnalysisOptions, "readout_ms", help="the camera's rolling-shutter readout, top row to bottom row (0 for a global shutter)",
        unset="not said", flag=None,
    )  # fmt: skip
    readout_ci95_ms: tuple[float, float] | None = _interval("readout")
    readout_direction: str | None = like(
        HintedFacts, "scanout", default=None, help="which way the camera reads its rows in the film", unset="top-down",
    )  # fmt: skip
    readout_source: str = _source("readout")

    def __post_init__(self) -> None:
        check(self, ConfigError, "camera.")
        for name in ("exposure", "readout"):
            value, interval = getattr(self, f"{name}_ms"), getattr(self, f"{name}_ci95_ms")
            if value is not None and interval is not None and not interval[0] <= value <= interval[1]:
                raise ConfigError(f"camera.{name}_ms {value:g} lies outside its 95% interval {list(interval)}")
            if value is not None and self.fps is not None and value > (1 + READOUT_TOLERANCE) * 1e3 / self.fps:
                raise ConfigError(
                    f"camera.{name}_ms {value:g} is longer than a frame interval at {self.fps:g} fps ({1e3 / self.fps:.4g} ms): "
                    "one of them is for another camera setting"
                )


@dataclass(frozen=True)
class DisplayProfile:
    """The display the sphere is drawn on."""

    refresh_hz: float | None = like(AnalysisOptions, "display_hz", help="the display's refresh rate", unset="not said", flag=None)
    refresh_source: str = _source("refresh rate", "a datasheet, the display's settings, rig plan")
    scanout: str | None = like(HintedFacts, "scanout", default=None, unset="top-down")
    scanout_source: str = _source("scan-out", "a datasheet, a slow-motion film of the display")

    def __post_init__(self) -> None:
        check(self, ConfigError, "display.")


@dataclass(frozen=True)
class LayoutProfile:
    """Where the LED and the display sit in the camera's frame."""

    led_side: str | None = like(AnalysisOptions, "led_side", unset="not said", flag=None)
    led_roi: ROI | None = like(AnalysisOptions, "led_roi", unset="not said", flag=None)
    sphere_roi: ROI | None = like(AnalysisOptions, "sphere_roi", unset="not said", flag=None)
    led_row: float | None = like(HintedFacts, "led_row")
    sphere_row: float | None = like(HintedFacts, "sphere_row")
    source: str = _source("layout", "marked by hand on a first film")

    def __post_init__(self) -> None:
        check(self, ConfigError, "layout.")
        if (self.led_roi is None) != (self.sphere_roi is None):
            raise ConfigError("layout: give both regions, led_roi and sphere_roi, or neither")


@dataclass(frozen=True)
class BenchProfile:
    """A lab's bench: its camera, display and layout, each value with where it came from."""

    camera: CameraProfile = field(default_factory=CameraProfile)
    display: DisplayProfile = field(default_factory=DisplayProfile)
    layout: LayoutProfile = field(default_factory=LayoutProfile)


# Each value the profile hints at: its table, key, the hint's name and the key of its source.
HINTED = (
    ("camera", "fps", "fps", "fps_source"),
    ("camera", "exposure_ms", "exposure_ms", "exposure_source"),
    ("camera", "readout_ms", "readout_ms", "readout_source"),
    ("display", "refresh_hz", "display_hz", "refresh_source"),
    ("display", "scanout", "scanout", "scanout_source"),
    ("layout", "led_side", "led_side", "source"),
    ("layout", "led_roi", "led_roi", "source"),
    ("layout", "sphere_roi", "sphere_roi", "source"),
    ("layout", "led_row", "led_row", "source"),
    ("layout", "sphere_row", "sphere_row", "source"),
)
HEADER = "# The bench described once: read by rig analyse --bench, rig measure --bench and a sweep's [analysis] bench.\n"


def read_profile(path: Path) -> BenchProfile:
    """The profile a TOML file holds; ConfigError (one line naming the file) on a file that cannot
    be read, is not TOML, has an unknown key, or a value of the wrong type or out of range."""
    return from_table(BenchProfile, read_toml(path, "bench profile"), ConfigError, str(path))


def hints(profile: BenchProfile, path: Path) -> tuple[Hint, ...]:
    """Every value the profile gives, as the analysis's hints, each with its source in words:
    "bench.toml [camera] readout_ms: rig calibrate-camera 2026-11-28 from flash.mp4"."""
    given = []
    for table, key, name, source_key in HINTED:
        section = getattr(profile, table)
        value = getattr(section, key)
        if value is not None:
            source = getattr(section, source_key)
            given.append(Hint(name, value, f"{path} [{table}] {key}" + (f": {source}" if source else "")))
    return tuple(given)


def with_profile(options: AnalysisOptions, profile: BenchProfile, path: Path) -> AnalysisOptions:
    """The options with the profile's values as their hints: each fills the option of its name
    where the options leave it unset, and the analysis checks it against the video (the options'
    own values win, and the result says so). ConfigError for a readout the analysis cannot take:
    one read bottom to top in the film."""
    camera = profile.camera
    if options.readout_ms is None and camera.readout_ms and camera.readout_direction == "bottom-up":
        raise ConfigError(
            f"{path}: the camera reads its rows bottom to top in the film (camera.readout_direction), and the analysis "
            "dates rows read top to bottom: film with the camera the other way up and calibrate it again "
            "(rig calibrate-camera --bench), or give the readout as 0 (--readout-ms 0) if the blobs share their rows"
        )
    return dataclasses.replace(options, hints=hints(profile, path))


def shutter_display(profile: BenchProfile) -> dict[str, Any]:
    """The flashing display's settings of `analysis.shutter.ShutterOptions` the profile gives: its
    refresh rate and scan-out (none where it does not give the refresh)."""
    display = profile.display
    if display.refresh_hz is None:
        return {}
    return {"display_hz": display.refresh_hz, **({"scanout": display.scanout} if display.scanout else {})}


def write_profile(path: Path, changes: Mapping[str, Mapping[str, Any]]) -> BenchProfile:
    """Set each table's keys in the profile at `path` (made if there is none; a value of None
    removes its key), keeping the rest of the file as it was, comments included; the profile it
    then holds. ConfigError, the file left as it was, where it cannot be read or written, or would
    not read back as a profile."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8") if path.exists() else HEADER
        document = tomlkit.parse(text)
    except OSError as error:
        raise ConfigError(f"cannot read the bench profile {path}: {error.strerror}") from None
    except tomlkit.exceptions.ParseError as error:
        raise ConfigError(f"{path} is not valid TOML: {error}") from None
    for name, values in changes.items():
        if name not in document:
            document.add(name, tomlkit.table())
        table = document[name]
        for key, value in values.items():
            if value is None:
                table.pop(key, None)
            else:
                table[key] = list(value) if isinstance(value, tuple) else value
    profile = from_table(BenchProfile, document.unwrap(), ConfigError, str(path))
    written = path.with_name(f".{path.name}.writing")
    try:
        written.write_text(tomlkit.dumps(document), encoding="utf-8")
        os.replace(written, path)
    except OSError as error:
        written.unlink(missing_ok=True)
        raise ConfigError(f"cannot write the bench profile {path}: {error.strerror}") from None
    return profile
