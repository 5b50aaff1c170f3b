"""Each hint compared with what the video shows, and what the analysis then uses.

``review(tracks, options)`` runs first in ``estimate``; the display's refresh is compared in the
display-sampling step (``HintReview.sampling``), which needs the sphere's timing residuals. A hint
the options give a value for is overruled (recorded, not checked; the options' side or regions
overrule every hint of which blob is the LED). For the others:

- the camera's frame rate, against the frame times: a contradiction keeps the frame times (the file
  is what was filmed) and leaves the exposure and readout hints out, since they describe another
  camera setting;
- the readout and the exposure, against the frame interval (neither can be longer); the exposure
  also against the LED's motion blur (``analysis.sampling.exposure``): a contradiction leaves the
  hint out, so the readout is only bounded and the exposure taken from the blur;
- the LED's side or the regions, against the identity evidence (``analysis.identity``, without its
  prior for the left side) where it decides: a contradiction follows the evidence, as the analysis
  does when told nothing;
- the blobs' rows, against the rows they are filmed on: a contradiction is said (the camera or the
  bench has moved), nothing else changes;
- the display's scan-out cannot be checked; bottom-up is said, since the display-sampling model
  switches the sphere's rows from the top;
- the display's refresh, against the refreshes the sphere's timing shows when the rate is not
  given: a contradiction (the video sees another rate, or rules out the hint's where it tried it)
  uses what the video shows.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from analysis.blobs import Track
from analysis.caveat import caveat
from analysis.errors import AnalysisError
from analysis.hints.hint import AGREES, CANNOT_CHECK, CONTRADICTS, IDENTITY, OVERRULED, Hint, HintCheck, in_words
from analysis.identity import DECISION_MARGIN, identify
from analysis.options import AnalysisOptions
from analysis.readout import READOUT_TOLERANCE, weighted_row
from analysis.sampling import SamplingBias, measure_sampling
from analysis.sampling.exposure import exposure_from_blur
from analysis.sampling.rates import COMMON_REFRESH_HZ
from analysis.sampling.residuals import TimingResiduals
from analysis.timing import RATE_AGREEMENT
from analysis.tracks import Tracks

# A blob's row may differ from the hint's by this share of the frame's height.
ROW_AGREEMENT = 0.1
CAMERA_SETTING = ("exposure_ms", "readout_ms")


@dataclass
class HintReview:
    """The verdict on every hint so far, the warnings they gave, and the display's refresh hint
    still to compare with the sphere's timing."""

    checks: list[HintCheck] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    display: Hint | None = None
    order: tuple[Hint, ...] = ()

    @property
    def records(self) -> tuple[HintCheck, ...]:
        """The verdicts in the order the hints were given."""
        return tuple(sorted(self.checks, key=lambda check: self.order.index(check.hint)))

    def note(self, hint: Hint, video: str | None, verdict: str, used: str, warning: str | None = None) -> None:
        self.checks.append(HintCheck(hint, video, verdict, used))
        if warning is not None:
            self.warnings.append(warning)

    def sampling(
        self,
        residuals: TimingResiduals,
        led: Track,
        period_s: float,
        options: AnalysisOptions,
        row_time_s: tuple[float, tuple[float, float]],
    ) -> SamplingBias:
        """The camera's sampling of the display (``analysis.sampling.measure_sampling``) as the
        options say; with a refresh hint, compared with the sampling the video shows untold, which
        replaces it where the two contradict (see the module docstring)."""
        exposure_s = None if options.exposure_ms is None else options.exposure_ms / 1e3
        told = measure_sampling(residuals, led, period_s, options.display_hz, exposure_s, row_time_s)
        hint = self.display
        if hint is None:
            return told
        untold = measure_sampling(residuals, led, period_s, None, exposure_s, row_time_s)
        hz = float(hint.value)
        allowed = any(abs(rate - hz) <= RATE_AGREEMENT * hz for rate in untold.rates_hz)
        seen = untold.refresh_source == "seen in the video"
        tried = any(abs(rate - hz) <= RATE_AGREEMENT * hz for rate in COMMON_REFRESH_HZ)
        rates = ", ".join(dict.fromkeys(f"{rate:.4g}" for rate in sorted(untold.rates_hz)))
        video = f"{untold.refresh_hz:.4g} Hz seen in the sphere's timing" if seen else f"the sphere's timing allows {rates} Hz"
        if allowed:
            self.note(hint, video, AGREES if seen else CANNOT_CHECK, f"the hint's {hz:g} Hz")
            return told
        if not (seen or tried):
            self.note(hint, video, CANNOT_CHECK, f"the hint's {hz:g} Hz")
            return told
        shows = f"shows refreshes at {untold.refresh_hz:.4g} Hz" if seen else f"rules out {hz:g} Hz (it allows {rates} Hz)"
        self.note(
            hint, video, CONTRADICTS, "what the video shows",
            caveat(
                f"the display refreshes at {hz:g} Hz by the bench's description ({hint.source}), but the sphere's timing "
                f"{shows}: the analysis allowed for what the video shows instead",
                "check the display's refresh rate and correct the description",
            ),
        )  # fmt: skip
        return untold

    def no_sampling(self) -> None:
        """No sampling measured (no timing residuals): the refresh hint is used unchecked."""
        if self.display is not None:
            self.note(self.display, None, CANNOT_CHECK, f"the hint's {float(self.display.value):g} Hz")


def review(tracks: Tracks, options: AnalysisOptions) -> tuple[Tracks, AnalysisOptions, HintReview]:
    """The options' hints compared with the tracks (all but the display's refresh, which
    ``HintReview.sampling`` compares): the tracks (the LED and the sphere swapped where the identity
    evidence contradicts a hint decisively), the options to estimate with (the hints put in, less
    those the video contradicts) and the review so far."""
    checks = HintReview(order=options.hints)
    used = options.hinted()
    dropped: list[str] = []
    active: dict[str, Hint] = {}
    for hint in options.hints:
        given = options.overruling(hint.name)
        if given is None:
            active[hint.name] = hint
        else:
            checks.note(hint, None, OVERRULED, f"the options' {given}")
    stale = "fps" in active and not _frame_rate(active["fps"], tracks, checks)
    tracks = _identity([active[name] for name in IDENTITY if name in active], tracks, checks)
    for name in CAMERA_SETTING:
        if name in active and not _camera_value(active[name], stale, float(np.median(np.diff(tracks.times.t))), tracks, checks):
            dropped.append(name)
    for name in ("led_row", "sphere_row"):
        if name in active:
            _row(active[name], tracks.led if name == "led_row" else tracks.sphere, tracks.frame_size[1], checks)
    if "scanout" in active:
        _scanout(active["scanout"], checks)
    checks.display = active.get("display_hz")
    return tracks, dataclasses.replace(used, **{name: None for name in dropped}), checks


def _frame_rate(hint: Hint, tracks: Tracks, checks: HintReview) -> bool:
    """Whether the camera's frame rate agrees with the frame times."""
    fps, hinted = tracks.times.fps, float(hint.value)
    video = f"{fps:.4g} fps ({tracks.times.source})"
    if abs(fps - hinted) <= RATE_AGREEMENT * hinted:
        checks.note(hint, video, AGREES, "the frame times")
        return True
    checks.note(
        hint, video, CONTRADICTS, "the frame times",
        caveat(
            f"the camera films at {hinted:g} fps by the bench's description ({hint.source}), but the video's frames are "
            f"{fps:.4g} fps apart ({tracks.times.source}): the frame times were used, and the description's exposure and "
            "readout, for another camera setting, were left out",
            f"describe this camera setting (measure it: rig calibrate-camera), or, if the file plays slow motion back "
            f"slower than it was filmed, give --fps {hinted:g}",
        ),
    )  # fmt: skip
    return False


def _camera_value(hint: Hint, stale: bool, interval: float, tracks: Tracks, checks: HintReview) -> bool:
    """Whether the exposure or readout hint holds: not for another camera setting, within the frame
    interval, and (the exposure) within what the LED's blur allows."""
    what = "exposure" if hint.name == "exposure_ms" else "readout"
    value_ms = float(hint.value)
    if stale:
        checks.note(hint, None, CANNOT_CHECK, "left out: the description's frame rate is not the video's")
        return False
    if value_ms / 1e3 > (1 + READOUT_TOLERANCE) * interval:
        checks.note(
            hint, f"at most {interval * 1e3:.4g} ms (a frame interval)", CONTRADICTS, "left out",
            caveat(
                f"the camera's {what} is {value_ms:g} ms by the bench's description ({hint.source}), longer than the "
                f"video's frame interval ({interval * 1e3:.4g} ms): the description is for another camera setting, and the "
                f"{what} was left out ({'bounded by the frame interval' if what == 'readout' else 'taken from the LED blur'})",
                "measure this camera setting (rig calibrate-camera) and describe it",
            ),
        )  # fmt: skip
        return False
    if what == "readout":
        checks.note(hint, f"at most {interval * 1e3:.4g} ms (a frame interval)", CANNOT_CHECK, f"the hint's {value_ms:g} ms")
        return True
    blur = exposure_from_blur(tracks.led, interval)
    if blur.source == "unknown":
        checks.note(hint, None, CANNOT_CHECK, f"the hint's {value_ms:g} ms")
        return True
    video = f"{blur.low_s * 1e3:.3g} to {blur.high_s * 1e3:.3g} ms by the LED's blur"
    # As the readout's, a nominal value may exceed the blur's range (capped at the frame interval) by READOUT_TOLERANCE.
    if blur.low_s / (1 + READOUT_TOLERANCE) <= value_ms / 1e3 <= blur.high_s * (1 + READOUT_TOLERANCE):
        checks.note(hint, video, AGREES, f"the hint's {value_ms:g} ms")
        return True
    checks.note(
        hint, video, CONTRADICTS, "the LED's blur",
        caveat(
            f"the camera exposes {value_ms:g} ms by the bench's description ({hint.source}), but the LED's motion blur "
            f"shows {blur.low_s * 1e3:.3g} to {blur.high_s * 1e3:.3g} ms: the exposure was taken from the blur",
            "measure the camera's exposure at this setting (rig calibrate-camera) and correct the description",
        ),
    )  # fmt: skip
    return False


def _identity(hints: list[Hint], tracks: Tracks, checks: HintReview) -> Tracks:
    """The tracks, the LED and the sphere swapped where the identity evidence decisively names the
    other blob than the hints did (the regions, else the LED's side, named the LED for tracking);
    a side hint is also held to the side the evidence puts the LED on."""
    if not hints:
        return tracks
    try:
        identity = identify(tracks.led, tracks.sphere)
    except AnalysisError:
        identity = None
    # The log-odds that the blob tracked as the LED is the LED, without the evidence's prior for the left side.
    evidence = {name: value for name, value in (identity.evidence if identity is not None else {}).items() if name != "side"}
    margin = sum(evidence.values())
    tracked_is_led = margin > 0
    sign = 1.0 if tracked_is_led else -1.0
    listed = ", ".join(f"{name} {sign * value:+.1f}" for name, value in evidence.items() if value)
    words = f"{listed or 'no evidence'}; total {sign * margin:+.1f}"
    if abs(margin) < DECISION_MARGIN:
        for hint in hints:
            checks.note(hint, f"undecided (log-odds: {words})", CANNOT_CHECK, f"the hint's {in_words(hint.value)}")
        return tracks
    led_roi, sphere_roi = (tracks.led_roi, tracks.sphere_roi) if tracked_is_led else (tracks.sphere_roi, tracks.led_roi)
    side = "left" if led_roi.x <= sphere_roi.x else "right"
    video = f"the LED is the blob on the {side}, in {led_roi.as_list()} (log-odds that it is: {words})"
    for hint in hints:
        agrees = hint.value == side if hint.name == "led_side" else tracked_is_led
        checks.note(hint, video, AGREES if agrees else CONTRADICTS, f"the hint's {in_words(hint.value)}" if agrees else "the evidence")
        if not agrees and not (hint.name == "sphere_roi" and any(each.name == "led_roi" for each in hints)):  # one warning for both regions
            said = f"the LED is on the {hint.value}" if hint.name == "led_side" else f"the {_blob(hint.name)} is in {list(hint.value)}"
            checks.warnings.append(caveat(
                f"by the bench's description ({hint.source}) {said}, but the video's evidence says {video}: the evidence "
                "was followed",
                "correct the description, or give --led-side (or the regions) to overrule the evidence",
            ))  # fmt: skip
    if tracked_is_led:
        return tracks
    diagnostics = {
        key: {"led": value["sphere"], "sphere": value["led"]} if isinstance(value, dict) and set(value) == {"led", "sphere"} else value
        for key, value in tracks.diagnostics.items()
    }
    return dataclasses.replace(
        tracks, led=tracks.sphere, sphere=tracks.led, led_roi=tracks.sphere_roi, sphere_roi=tracks.led_roi,
        led_rule=f"auto: by physical evidence, against the bench's description (log-odds that the LED is the {side} blob: {words})",
        diagnostics=diagnostics,
    )  # fmt: skip


def _blob(name: str) -> str:
    return "LED" if name.startswith("led") else "sphere"


def _row(hint: Hint, blob: Track, height: int, checks: HintReview) -> None:
    """The blob's row in the video against the hint's (shares of the frame's height)."""
    name = _blob(hint.name)
    row = weighted_row(blob) / height
    video = f"{row:.2f} of the frame's height"
    if abs(row - float(hint.value)) <= ROW_AGREEMENT:
        checks.note(hint, video, AGREES, "the rows in the video")
        return
    checks.note(
        hint, video, CONTRADICTS, "the rows in the video",
        caveat(
            f"the {name} sits at {float(hint.value):.2f} of the frame's height by the bench's description ({hint.source}), "
            f"but at {row:.2f} in the video, so the camera or the bench has moved since: the analysis measured the rows itself",
            "correct the description (its regions too, if it gives them)",
        ),
    )  # fmt: skip


def _scanout(hint: Hint, checks: HintReview) -> None:
    """The display's scan-out, which the video cannot show: said where the model does not hold it."""
    if hint.value == "top-down":
        checks.note(hint, None, CANNOT_CHECK, "the display-sampling model's top-down scan-out")
        return
    checks.note(
        hint, None, CANNOT_CHECK, "the display-sampling model's top-down scan-out",
        caveat(
            f"the display scans bottom-up in the film by the bench's description ({hint.source}), but the display-sampling "
            "model switches the sphere's rows from the top: where the display's sampling biases the latency, the "
            "correction may be off by up to the scan-out's time across the sphere",
            "film the display the right way up",
        ),
    )  # fmt: skip
