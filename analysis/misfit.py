"""Whether the model fits: checks on what a latency estimate leaves, and a wider interval when one fails.

The fit's interval assumes a constant latency, a swing the model describes, and residuals
correlated over no more than a swing period. Each assumption is checked after every estimate:

- per-swing consistency: the latencies of the one-period windows (``analysis.windows``) scatter
  about their mean as their own noise allows (chi-square, at CHECK_P). That noise is worked out
  from each window's fit residuals as if they were independent; a window's own fit (fixed
  frequency, its own offsets and harmonics) is noisier than that, by up to WINDOW_NOISE_ALLOWANCE
  in standard deviation on clean simulated clips, so the allowance is granted;
- drift: they do not trend over the clip (the slope's t-statistic, at CHECK_P);
- residual harmonics: the sphere's residuals against the LED (``analysis.sampling.residuals``)
  hold no line at the swing frequency (LINE_POWER times the median power near it) large enough to
  matter: as a timing error (its amplitude over the sphere's speed) at least MATERIAL of the
  interval's half-width. A line there is a part of the swing that the estimate leaves unexplained
  (a latency that changes with the swing's phase, a blob hidden in part of its path). Lines at
  higher harmonics are common and harmless (the two paths differ a little in shape, and the fit
  allows for the second and third harmonic of each): they are reported, not held against the fit;
- residual correlation: those residuals are correlated over no more than about a period (their
  long-run variance over CORRELATION_SPANS periods is no more than CORRELATION_GROWTH times that
  over one). Each long-run variance is taken relative to what it would be for uncorrelated
  residuals of the clip's length: centring a series on its own mean takes from a Bartlett sum
  over B lags about B / n of the variance, which over three periods of a six-period clip is half
  of it and would hide even a random walk. The check has power on clips of tens of periods; on
  short clips the per-swing checks above stand in for it.

A failed check adds a warning and widens the interval to at least the spread of the per-swing
latencies: their standard error times Student's t over the swings, what resampling whole swings
would give, centred on the latency. That interval allows for whatever makes swings disagree; a
result whose checks fail exits with its own status on the command line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from analysis.caveat import caveat
from analysis.longrun import long_run_variance
from analysis.sampling.residuals import TimingResiduals
from analysis.swing import Swing
from analysis.windows import WindowedLatency

CHECK_P = 1e-3
WINDOW_NOISE_ALLOWANCE = 3.0
LINE_POWER = 25.0
HARMONICS = 6
MATERIAL = 0.5
CORRELATION_SPANS = 3
CORRELATION_GROWTH = 2.5
# Two-sided 97.5 % points of Student's t for 1..30 degrees of freedom (then the normal's).
_T975 = (
    12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160, 2.145, 2.131,
    2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042,
)  # fmt: skip


def student_t975(dof: int) -> float:
    return _T975[dof - 1] if dof <= len(_T975) else 1.96


@dataclass(frozen=True)
class Check:
    """One check: its name, whether it passed, and what it measured (for the user)."""

    name: str
    passed: bool
    detail: str

    def to_dict(self) -> dict[str, object]:
        return {"name": self.name, "passed": bool(self.passed), "detail": self.detail}


@dataclass(frozen=True)
class MisfitReport:
    """The checks, and the 95 % half-width (s) of the per-swing latencies' mean (None with fewer
    than three swings)."""

    checks: tuple[Check, ...]
    between_swings_s: float | None

    @property
    def failed(self) -> list[Check]:
        return [check for check in self.checks if not check.passed]

    def widen(self, latency_s: float, ci_s: tuple[float, float] | None) -> tuple[float, float] | None:
        """The interval, widened to the per-swing spread when a check failed."""
        if ci_s is None or not self.failed or self.between_swings_s is None:
            return ci_s
        return min(ci_s[0], latency_s - self.between_swings_s), max(ci_s[1], latency_s + self.between_swings_s)

    def warning(self) -> str | None:
        failed = self.failed
        if not failed:
            return None
        widened = (
            f", and the interval was widened to the spread of the per-swing latencies (+-{self.between_swings_s * 1e3:.2f} ms)"
            if self.between_swings_s is not None
            else ""
        )
        return caveat(
            f"the model does not fit the swing ({'; '.join(f'{c.name}: {c.detail}' for c in failed)}){widened}",
            "check the plot (--plot) for a latency that changes over the clip, a blob partly hidden or merging with "
            "another, or a display that drops or repeats frames",
        )

    def to_dict(self) -> dict[str, object]:
        return {
            "checks": [check.to_dict() for check in self.checks],
            "between_swings_ms": None if self.between_swings_s is None else self.between_swings_s * 1e3,
        }


def _window_errors(swing: Swing) -> np.ndarray:
    """Each window's latency standard error (s) from its fits' noise: sigma / (A sqrt(n / 2)) per
    signal's phase, over omega."""
    windows = swing.windows
    samples = max(swing.fps / swing.frequency_hz, 1.0)
    led = windows.led_noise / (windows.led_amplitude * math.sqrt(samples / 2))
    sphere = windows.sphere_noise / (windows.sphere_amplitude * math.sqrt(samples / 2))
    return np.sqrt(led**2 + sphere**2)[windows.both] / windows.omega


def _swing_checks(swing: Swing, windowed: WindowedLatency | None) -> tuple[list[Check], float | None]:
    if windowed is None or windowed.count < 3:
        return [], None
    latency, t = windowed.latency_s, windowed.t
    errors = _window_errors(swing)
    count = latency.size
    between = student_t975(count - 1) * float(np.std(latency, ddof=1)) / math.sqrt(count)
    weights = 1.0 / np.maximum(WINDOW_NOISE_ALLOWANCE * errors, 1e-12) ** 2
    mean = float(weights @ latency / weights.sum())
    chi2 = float(weights @ (latency - mean) ** 2)
    limit = _chi2_quantile(count - 1, 1 - CHECK_P)
    consistency = Check(
        "per-swing consistency",
        chi2 <= limit,
        f"the {count} swings' latencies scatter by {np.std(latency, ddof=1) * 1e3:.2f} ms, "
        f"{math.sqrt(chi2 / (count - 1)):.1f} times what their noise allows",
    )
    centred = t - float(weights @ t / weights.sum())
    slope = float(weights @ (centred * (latency - mean)) / (weights @ centred**2))
    # The slope's error from the scatter about the line (no less than the noise allows).
    about_line = float(weights @ (latency - mean - slope * centred) ** 2) / max(count - 2, 1)
    slope_error = math.sqrt(max(about_line, 1.0) / float(weights @ centred**2))
    statistic = abs(slope) / slope_error
    drift = Check(
        "drift",
        statistic <= _normal_quantile(1 - CHECK_P / 2),
        f"the latency changes by {slope * float(np.ptp(t)) * 1e3:+.2f} ms over the clip ({statistic:.1f} standard errors)",
    )
    return [consistency, drift], between


def _residual_checks(residuals: TimingResiduals | None, swing: Swing, half_width_s: float) -> list[Check]:
    if residuals is None:
        return []
    frequency = swing.frequency_hz
    series = np.zeros(int(residuals.index[-1]) + 1)
    series[residuals.index] = residuals.r
    fps = 1.0 / residuals.frame_interval
    size = 1 << math.ceil(math.log2(series.size))
    power = np.abs(np.fft.rfft(series - series.mean(), size)) ** 2
    frequencies = np.fft.rfftfreq(size, residuals.frame_interval)
    width = 1.5 * fps / size
    elsewhere = (frequencies >= 0.5 * frequency) & (frequencies <= (HARMONICS + 1) * frequency)
    peaks = {}
    for order in range(1, HARMONICS + 1):
        at = np.abs(frequencies - order * frequency) <= width
        elsewhere &= ~at
        if np.any(at):
            peaks[order] = float(power[at].max())
    floor = float(np.median(power[elsewhere])) if np.any(elsewhere) else math.inf
    amplitude = float(np.nanstd(swing.signals.sphere)) * math.sqrt(2)
    timings = {}
    for order, value in peaks.items():
        if value > LINE_POWER * floor:
            line = 2 * abs(np.sum(residuals.r * np.exp(-2j * math.pi * order * frequency * residuals.t))) / residuals.r.size
            timings[order] = line / (2 * math.pi * order * frequency * max(amplitude, 1e-12))
    fundamental = timings.get(1, 0.0)
    harmonics = Check(
        "residual harmonics",
        fundamental == 0.0 or fundamental < MATERIAL * half_width_s,
        (
            f"the residuals keep the swing frequency itself ({fundamental * 1e3:.2f} ms as timing)"
            if fundamental
            else "none at the swing frequency"
        )
        + "".join(f"; {order} x the swing frequency: {t * 1e3:.2f} ms as timing" for order, t in timings.items() if order > 1),
    )
    period_frames = max(1, round(fps / frequency))
    centred = series - series.mean()
    one = long_run_variance(centred, period_frames) / _white_share(centred.size, period_frames)
    spans = CORRELATION_SPANS * period_frames
    longer = long_run_variance(centred, spans) / _white_share(centred.size, spans)
    growth = longer / one if one > 0 else 1.0
    correlation = Check(
        "residual correlation",
        growth <= CORRELATION_GROWTH,
        f"the residuals' variance over {CORRELATION_SPANS} periods is {growth:.1f} times that over one",
    )
    return [harmonics, correlation]


def _white_share(count: int, bandwidth: int) -> float:
    """The share of an uncorrelated series' variance that ``long_run_variance`` keeps, in
    expectation, once the series is centred on its own mean: 1 - (n + 2 sum_k (1 - k / (B + 1))
    (n - k)) / n^2 over lags k = 1..B (B clamped as there)."""
    lags = np.arange(1, min(bandwidth, count - 1) + 1, dtype=np.float64)
    kept = 1.0 - (count + 2.0 * float(np.sum((1.0 - lags / (lags.size + 1)) * (count - lags)))) / count**2
    return max(kept, 1e-12)


def check_fit(
    swing: Swing, windowed: WindowedLatency | None, residuals: TimingResiduals | None, half_width_s: float
) -> MisfitReport:
    """Every check on an estimate whose 95 % interval is +-``half_width_s`` (see the module docstring)."""
    swing_checks, between = _swing_checks(swing, windowed)
    return MisfitReport(tuple(swing_checks + _residual_checks(residuals, swing, half_width_s)), between)


def _normal_quantile(p: float) -> float:
    """The standard normal's p quantile."""
    return math.sqrt(2) * _erfinv(2 * p - 1)


def _erfinv(y: float) -> float:
    """Inverse error function by Newton steps from a closed-form start."""
    a = 0.147
    log = math.log(max(1 - y * y, 1e-300))
    first = 2 / (math.pi * a) + log / 2
    x = math.copysign(math.sqrt(math.sqrt(first * first - log / a) - first), y)
    for _ in range(3):
        x -= (math.erf(x) - y) / (2 / math.sqrt(math.pi) * math.exp(-x * x))
    return x


def _chi2_quantile(dof: int, p: float) -> float:
    """The chi-square quantile by the Wilson-Hilferty approximation (good to a few per cent at
    1 degree of freedom, better above)."""
    z = _normal_quantile(p)
    return dof * (1 - 2 / (9 * dof) + z * math.sqrt(2 / (9 * dof))) ** 3
