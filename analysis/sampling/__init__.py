"""The camera-display sampling bias of a measured latency, and what the video says about it.

A camera filming a sample-and-hold display sees the sphere at whatever phase of each refresh its
exposures fall, and reads the latency off by the mean of that phase's bias
(``analysis.sampling.model``), averaged over the sphere's rows, which the display's scan-out and
the camera's readout reach one after another (``analysis.sampling.rows``). ``measure_sampling``
works out which refresh rates, phases, exposures and row slopes the video allows
(``analysis.sampling.inference``, with the exposure from the LED's blur,
``analysis.sampling.exposure``, or as given), and ``SamplingBias.apply`` turns a latency
and its interval into the corrected latency and an interval that holds every bias still possible.
Where the video identifies the bias it is corrected; where it does not (the camera phase-locked to
the display, or a rate the video does not show), the interval is widened by it and a warning says
why and what to film instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from analysis.sampling.exposure import Exposure, exposure_from_blur, given_exposure
from analysis.sampling.inference import BIAS_RANGE, RefreshHypothesis, refresh_hypotheses
from analysis.sampling.model import commensurate
from analysis.sampling.rates import COMMON_REFRESH_HZ, RATE_TOLERANCE
from analysis.sampling.residuals import TimingResiduals
from analysis.sampling.rows import SphereRows
from analysis.blobs import Track
from analysis.caveat import caveat

# Residuals may be correlated over this fraction of a swing period.
CORRELATION_PERIODS = 0.1
# The bias counts as identified when its range (BIAS_RANGE) is within this fraction of its size either
# side of it; it is corrected where that is worth doing, at least this fraction of the latency's
# own 95 % half-width.
IDENTIFIED_SPREAD = 0.5
WORTH_CORRECTING = 0.5
# A widening smaller than this fraction of the half-width (or than WIDENING_NOTICE_S) goes unsaid.
WIDENING_NOTICE = 0.25
WIDENING_NOTICE_S = 0.05e-3
# A bias range is summarised by this many mixture components.
MIXTURE_COMPONENTS = 64
QUANTILE_GRID = 512
NORMAL_95 = 1.959963984540054


@dataclass(frozen=True)
class SamplingBias:
    """What the camera's sampling of the display may do to the latency.

    refresh_hz: the display's refresh rate best supported (Hz); refresh_source "given", "seen in the
    video" (its refreshes show in the sphere's timing) or "not seen"; rates_hz every rate the video
    is consistent with, worst_hz the one of them that allows the widest bias; exposure the camera's;
    correction_s the bias subtracted from the latency where identified (else 0); range_s the bias's
    range (BIAS_RANGE of its posterior) over everything still possible (s).
    """

    refresh_hz: float
    refresh_source: str
    rates_hz: tuple[float, ...]
    worst_hz: float
    exposure: Exposure
    camera_fps: float
    correction_s: float
    range_s: tuple[float, float]
    hypotheses: tuple[RefreshHypothesis, ...]

    def apply(self, latency_s: float, ci_s: tuple[float, float] | None) -> tuple[float, tuple[float, float] | None]:
        """The latency less the correction, and its 95 % interval with every possible bias: over the
        consistent rates, the hull of the 95 % quantiles of the latency's own (normal) uncertainty
        convolved with each rate's bias distribution, and of the latency less the bias's range. The
        second matters where the video cannot place the refreshes (phase-locked): the bias is then
        anywhere in its range, and a 95 % interval of it would miss the truth for one phase in
        twenty; the interval must hold every phase the video allows."""
        correction = self.correction_for(ci_s)
        corrected = latency_s - correction
        if ci_s is None:
            return corrected, None
        below, above = (latency_s - ci_s[0]) / NORMAL_95, (ci_s[1] - latency_s) / NORMAL_95
        lows, highs = [], []
        for hypothesis in self.hypotheses:
            low, high = _mixture_quantiles(*_components(latency_s - hypothesis.biases_s, hypothesis.weights), below, above)
            least, most = hypothesis.range_s(*BIAS_RANGE)
            lows.append(min(low, latency_s - most))
            highs.append(max(high, latency_s - least))
        return corrected, (min(min(lows), ci_s[0] - correction), max(max(highs), ci_s[1] - correction))

    def correction_for(self, ci_s: tuple[float, float] | None) -> float:
        """The correction applied to a latency with this 95 % interval (or none): the identified
        bias, where it is at least WORTH_CORRECTING of the interval's half-width (or, without an
        interval, at least WIDENING_NOTICE_S)."""
        least = WORTH_CORRECTING * (ci_s[1] - ci_s[0]) / 2 if ci_s is not None else WIDENING_NOTICE_S
        return self.correction_s if abs(self.correction_s) >= least else 0.0

    def warning(self, ci_s: tuple[float, float] | None, widened_s: tuple[float, float] | None) -> str | None:
        """A warning (`analysis.caveat`) naming the cause and the remedy when the bias was corrected in,
        or widened noticeably, the interval ``ci_s`` (``widened_s`` what ``apply`` made of it), else None."""
        camera = f"the {self.camera_fps:g} fps camera"
        if self.correction_for(ci_s) != 0.0:
            return caveat(
                f"the sphere's timing in the video was {self.correction_s * 1e3:+.2f} ms off, and was corrected: {camera} "
                f"samples the {self.refresh_hz:.4g} Hz display ({self.refresh_source}) {self._phases_text()}",
                self._remedy(self.refresh_hz, ()),
            )
        if ci_s is None or widened_s is None:
            return None
        half_width = (ci_s[1] - ci_s[0]) / 2
        if (widened_s[1] - widened_s[0]) / 2 - half_width <= max(WIDENING_NOTICE * half_width, WIDENING_NOTICE_S):
            return None
        low, high = self.range_s
        widened = f"the interval was widened by the sphere's timing in the video, which may be off by {low * 1e3:+.2f} to {high * 1e3:+.2f} ms"
        exposure = () if self.exposure.source == "given" else ("--exposure-ms",)
        if self.refresh_source == "not seen":
            rates = " or ".join(dict.fromkeys(f"{rate:.4g}" for rate in sorted(self.rates_hz)))
            return caveat(
                f"{widened}: the video does not show whether the display refreshes at {rates} Hz, and {camera} may sample "
                "it at a fixed phase",
                self._remedy(self.worst_hz, ("--display-hz", *exposure)),
            )
        return caveat(
            f"{widened}: {camera} samples the {self.refresh_hz:.4g} Hz display ({self.refresh_source}) {self._phases_text()}",
            self._remedy(self.worst_hz, exposure),
        )

    def _remedy(self, refresh_hz: float, options: tuple[str, ...]) -> str:
        """What a lab can do: give the options named, film at a rate that walks through the refresh,
        or (where a refresh fits in a frame interval) expose for whole refreshes."""
        ways = [f"give {' and '.join(options)}"] if options else []
        whole = [f"expose for {_whole_refreshes(refresh_hz)}"] if refresh_hz >= self.camera_fps else []
        if not walks(self.camera_fps) or not ways + whole:
            ways.append(f"film at {suggested_fps(self.camera_fps)} fps (no common display rate is a simple fraction of it)")
        ways += whole
        return ", ".join(ways[:-1]) + f" or {ways[-1]}" if len(ways) > 1 else ways[0]

    def _phases_text(self) -> str:
        ratio = commensurate(self.camera_fps / self.refresh_hz)
        if ratio is None:
            return "at a phase that walks slowly through each refresh"
        if ratio[0] == 1:
            return "at one phase of each refresh (phase-locked)"
        return f"at {ratio[0]} phases of each refresh"

    def to_dict(self) -> dict[str, object]:
        return {
            "refresh_hz": self.refresh_hz,
            "refresh_source": self.refresh_source,
            "rates_hz": [round(rate, 4) for rate in self.rates_hz],
            "worst_hz": self.worst_hz,
            "exposure": self.exposure.to_dict(),
            "correction_ms": self.correction_s * 1e3,
            "bias_range_ms": [self.range_s[0] * 1e3, self.range_s[1] * 1e3],
        }


def _whole_refreshes(refresh_hz: float) -> str:
    return f"a whole number of refreshes ({1e3 / refresh_hz:.3g} ms at {refresh_hz:.4g} Hz)"


FEW_PHASES = 10
"""A camera whose rate is p / q of a display's with q at most this samples few phases of its refresh."""


def walks(camera_fps: float) -> bool:
    """Whether no common display rate is a simple fraction of the camera's: it then walks through
    every phase of any of their refreshes. A rate measured from a film counts to the hundredth of a frame."""
    return all(commensurate(round(camera_fps, 2) / rate, FEW_PHASES) is None for rate in COMMON_REFRESH_HZ)


def suggested_fps(camera_fps: float) -> int:
    """The whole frame rate nearest below the camera's (above, where none is) that `walks`."""
    start = max(round(camera_fps), 1)
    for candidate in [*range(start - 1, 0, -1), *range(start + 1, 2 * start + 2)]:
        if walks(candidate):
            return candidate
    raise AssertionError(f"no frame rate near {camera_fps:g} fps walks through the common display rates")


def _components(means: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """At most MIXTURE_COMPONENTS (mean, weight) pairs for a weighted set of means."""
    kept = weights > 1e-9 * weights.max()
    means, weights = means[kept], weights[kept]
    if means.size <= MIXTURE_COMPONENTS:
        return means, weights / weights.sum()
    least, most = float(means.min()), float(means.max())
    index = np.clip(((means - least) / max(most - least, 1e-300) * MIXTURE_COMPONENTS).astype(np.int64), 0, MIXTURE_COMPONENTS - 1)
    total = np.bincount(index, weights, MIXTURE_COMPONENTS)
    centre = np.bincount(index, weights * means, MIXTURE_COMPONENTS)
    used = total > 0
    return centre[used] / total[used], total[used] / total[used].sum()


def _normal_cdf(z: np.ndarray) -> np.ndarray:
    """The standard normal's distribution function (Abramowitz and Stegun 7.1.26, |error| < 1e-7)."""
    x = np.abs(z) / math.sqrt(2)
    t = 1.0 / (1.0 + 0.3275911 * x)
    poly = t * (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))))
    erf = 1.0 - poly * np.exp(-x * x)
    return 0.5 * (1.0 + np.sign(z) * erf)


def _mixture_quantiles(means: np.ndarray, weights: np.ndarray, below: float, above: float) -> tuple[float, float]:
    """The 2.5 % and 97.5 % quantiles of a mixture of split normals (sd ``below`` under each mean,
    ``above`` over it), from its distribution function on a fine grid."""
    below, above = max(below, 1e-12), max(above, 1e-12)
    grid = np.linspace(float(means.min()) - 6 * below, float(means.max()) + 6 * above, QUANTILE_GRID)
    offset = grid[:, None] - means[None, :]
    cdf = _normal_cdf(offset / np.where(offset < 0, below, above)) @ weights
    return float(np.interp(0.025, cdf, grid)), float(np.interp(0.975, cdf, grid))


def measure_sampling(
    residuals: TimingResiduals,
    led: Track,
    period_s: float,
    refresh_hz: float | None = None,
    exposure_s: float | None = None,
    row_time_s: tuple[float, tuple[float, float]] = (0.0, (0.0, 0.0)),
) -> SamplingBias:
    """What the camera's sampling of the display may do to the latency, from the sphere's timing
    residuals against the LED (``analysis.sampling.residuals``) and the LED's track (its blur);
    ``refresh_hz`` and ``exposure_s`` are the display's refresh and the camera's exposure where the
    user knows them; ``row_time_s`` the time per row the sphere's samples were dated by and the range
    the camera's true time per row lies in (``analysis.readout``). The correction is left at 0 unless the video identifies the bias: every rate it
    allows agrees, and the bias's 95 % range is narrow against its size."""
    frame_interval = residuals.frame_interval
    exposure = given_exposure(exposure_s, frame_interval) if exposure_s is not None else exposure_from_blur(led, frame_interval)
    bandwidth = max(1, round(CORRELATION_PERIODS * period_s / frame_interval))
    rows = None
    if residuals.rows is not None:
        rows = SphereRows(residuals.rows - float(np.mean(residuals.rows)), residuals.row_sd, *row_time_s)
    hypotheses = refresh_hypotheses(residuals, 1.0 / frame_interval, refresh_hz, (exposure.low_s, exposure.high_s), bandwidth, rows)
    best = hypotheses[0]
    ranges = [h.range_s(*BIAS_RANGE) for h in hypotheses]
    low, high = min(r[0] for r in ranges), max(r[1] for r in ranges)
    seen = all(abs(h.refresh_hz - best.refresh_hz) <= RATE_TOLERANCE * best.refresh_hz for h in hypotheses)
    mean = best.mean_s
    identified = seen and (high - low) / 2 <= IDENTIFIED_SPREAD * abs(mean)
    source = "given" if refresh_hz is not None else ("seen in the video" if seen else "not seen")
    return SamplingBias(
        refresh_hz=best.refresh_hz,
        refresh_source=source,
        rates_hz=tuple(h.refresh_hz for h in hypotheses),
        worst_hz=hypotheses[int(np.argmax([r[1] - r[0] for r in ranges]))].refresh_hz,
        exposure=exposure,
        camera_fps=1.0 / frame_interval,
        correction_s=mean if identified else 0.0,
        range_s=(low, high),
        hypotheses=tuple(hypotheses),
    )
