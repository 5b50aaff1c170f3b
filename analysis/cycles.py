"""Which whole number of periods the latency holds: phase alone fixes it only modulo one period.

The candidates are latency + k * period for every k that puts the latency inside the plausible
range (by default -200 to 600 ms; a lab with a slower system widens it). One candidate: done.
Several: they are told apart by something that does not repeat every period, the pendulum's chirp.
A real pendulum's frequency rises as its swing decays (by about amplitude^2 / 16), so the sphere,
showing the swing ``latency`` late, swings at the frequency the LED had ``latency`` earlier. In
the per-window phases this reads

    psi_led(t)    = alpha_led    + beta t - zeta h(t)
    psi_sphere(t) = alpha_sphere + beta t - zeta h(t - latency)

(h as in ``analysis.fit.model``; damping gamma from the LED's amplitudes). Each candidate is
fitted and the residual sums compared. A candidate wins when every other is worse by at least
DECISIVE_CHI2 in chi-square (scaled by the best fit's residual variance) and the chirp makes the
candidates differ by at least MIN_SEPARATION_S of apparent latency drift over the clip: a latency
that itself drifts by that much would be mistaken for a chirp, so a smaller difference decides
nothing. Otherwise the result is ambiguous and a warning lists the candidates. The rule assumes the
latency is constant over the clip; the motion's chirp is strong for wide swings and low Q, weak or
absent for small swings with little damping.

Stronger than the chirp are events that happen once (``analysis.onset``): the swing's start, when
the clip holds the release, and its stop. Each gives the sphere-minus-LED time of the event, good to
a few frames. When every such lag picks the same candidate (latency + k period, for any k) and
lies within EVENT_TOLERANCE_PERIODS of it, that candidate is the latency, even outside the
plausible range (a warning then says so); lags that disagree with each other or with the phase
decide nothing, and a warning says so.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from analysis.caveat import caveat
from analysis.latency_range import DEFAULT_LATENCY_RANGE_S
from analysis.windows import WindowPhases

DECISIVE_CHI2 = 25.0
MIN_SEPARATION_S = 0.002
# Passes of per-signal reweighting of the window phases.
REWEIGHTING_PASSES = 2
# An event's lag decides the whole number of periods when within this fraction of a period of a candidate.
EVENT_TOLERANCE_PERIODS = 0.25


@dataclass(frozen=True)
class CycleResolution:
    """The whole-period choice: the latency every estimate is unwrapped towards, and how it was chosen.

    how: "range" (one candidate in the plausible range), "chirp" (decided by the chirp), the names
    of the events that decided it joined by "+" (e.g. "swing start+swing stop"), or "unresolved"
    (ambiguous: reference_s is then the candidate nearest zero). events_s holds every event's
    sphere-minus-LED lag (s), whether it decided or not.
    """

    reference_s: float
    ambiguous: bool
    how: str
    candidates_s: list[float]
    separation_s: float | None
    evidence_chi2: float | None
    warning: str | None
    events_s: dict[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict[str, object]:
        return {
            "how": self.how,
            "events_ms": {name: lag * 1e3 for name, lag in self.events_s.items()},
            "candidates_ms": [round(c * 1e3, 4) for c in self.candidates_s],
            "separation_ms": None if self.separation_s is None else self.separation_s * 1e3,
            "evidence_chi2": self.evidence_chi2,
        }


def unwrap_near(latency_s: float, reference_s: float, period_s: float) -> float:
    """latency_s + k period_s for the whole k that brings it nearest to reference_s."""
    return latency_s - period_s * round((latency_s - reference_s) / period_s)


def chirp_shape(t: np.ndarray, gamma: float) -> np.ndarray:
    """h(t) = (exp(-2 gamma t) - 1 + 2 gamma t) / (2 gamma^2), t^2 in the limit gamma -> 0."""
    x = 2 * gamma * t
    small = np.abs(x) < 1e-4
    safe = np.where(small, 1.0, x)
    phi2 = np.where(small, 0.5 - x / 6, (np.expm1(-safe) + safe) / safe**2)
    return 2 * t**2 * phi2


def candidate_latencies(latency_s: float, period_s: float, latency_range_s: tuple[float, float]) -> list[float]:
    """Every latency_s + k period_s inside the range; the one nearest the range if none is."""
    low, high = latency_range_s
    first = math.ceil((low - latency_s) / period_s)
    last = math.floor((high - latency_s) / period_s)
    inside = [latency_s + k * period_s for k in range(first, last + 1)]
    if inside:
        return inside
    return [unwrap_near(latency_s, (low + high) / 2, period_s)]


def _chirp_fit(windows: WindowPhases, gamma: float, latency_s: float, weights: tuple[float, float]) -> tuple[float, float, float]:
    """(weighted RSS, LED RSS, sphere RSS) of the window-phase chirp model at one latency."""
    both = windows.both
    t = windows.t[both] - windows.t[both].mean()
    led, sphere = windows.led_phase[both], windows.sphere_phase[both]
    count = t.size
    zero, one = np.zeros(count), np.ones(count)
    basis = np.block(
        [
            [one[:, None], zero[:, None], t[:, None], -chirp_shape(t, gamma)[:, None]],
            [zero[:, None], one[:, None], t[:, None], -chirp_shape(t - latency_s, gamma)[:, None]],
        ]
    )
    data = np.concatenate([led, sphere])
    scale = np.concatenate([np.full(count, weights[0]), np.full(count, weights[1])])
    coefficients, *_ = np.linalg.lstsq(basis * scale[:, None], data * scale, rcond=None)
    residual = data - basis @ coefficients
    led_rss, sphere_rss = float(residual[:count] @ residual[:count]), float(residual[count:] @ residual[count:])
    return weights[0] ** 2 * led_rss + weights[1] ** 2 * sphere_rss, led_rss, sphere_rss


def _chirp_evidence(
    windows: WindowPhases, gamma: float, candidates: list[float]
) -> tuple[np.ndarray, float]:
    """Chi-square of each candidate relative to the best, and the chirp's latency separation (s)."""
    count = int(np.count_nonzero(windows.both))
    weights = (1.0, 1.0)
    for _ in range(REWEIGHTING_PASSES):
        best = min(candidates, key=lambda c: _chirp_fit(windows, gamma, c, weights)[0])
        _, led_rss, sphere_rss = _chirp_fit(windows, gamma, best, weights)
        dof = max(count - 2, 1)
        weights = (1.0 / math.sqrt(max(led_rss / dof, 1e-12)), 1.0 / math.sqrt(max(sphere_rss / dof, 1e-12)))
    totals = np.array([_chirp_fit(windows, gamma, c, weights)[0] for c in candidates])
    variance = totals.min() / max(2 * count - 5, 1)
    return (totals - totals.min()) / max(variance, 1e-300), _separation(windows, gamma, candidates)


def _separation(windows: WindowPhases, gamma: float, candidates: list[float]) -> float:
    """Smallest apparent latency drift (s) over the clip that tells two candidates apart.

    For two candidate latencies the sphere's phase trends differ by zeta [h(t - l1) - h(t - l2)]
    (the slope is shared with the LED, only a constant is the sphere's own): its range over the
    clip, over omega, is the latency drift that would mimic it. zeta is the LED's chirp alone.
    """
    led = np.isfinite(windows.led_phase)
    if np.count_nonzero(led) < 4 or len(candidates) < 2:
        return 0.0
    t = windows.t[led] - windows.t[led].mean()
    basis = np.column_stack([np.ones_like(t), t, -chirp_shape(t, gamma)])
    zeta = np.linalg.lstsq(basis, windows.led_phase[led], rcond=None)[0][2]
    ordered = sorted(candidates)
    smallest = math.inf
    for first, second in zip(ordered, ordered[1:]):
        trend = zeta * (chirp_shape(t - first, gamma) - chirp_shape(t - second, gamma))
        smallest = min(smallest, float(np.ptp(trend)) / windows.omega)
    return smallest


def _event_choice(
    latency_s: float, period_s: float, event_lags_s: dict[str, float], latency_range_s: tuple[float, float]
) -> tuple[float | None, str | None]:
    """(the candidate every event picks, or None; a warning, or None)."""
    if not event_lags_s:
        return None, None
    picks = {name: unwrap_near(latency_s, lag, period_s) for name, lag in event_lags_s.items()}
    listed = ", ".join(f"the {name} {lag * 1e3:.0f} ms" for name, lag in event_lags_s.items())
    off = [name for name, lag in event_lags_s.items() if abs(lag - picks[name]) > EVENT_TOLERANCE_PERIODS * period_s]
    if off or len({round(pick / period_s) for pick in picks.values()}) > 1:
        return None, caveat(
            f"the swing's events ({listed} from LED to sphere) do not agree with each other or with the phase "
            f"(latency {latency_s * 1e3:.1f} ms modulo {period_s * 1e3:.1f} ms), and were not used",
            "check the tracks at the start and end of the clip (--plot)",
        )
    chosen = next(iter(picks.values()))
    low, high = latency_range_s
    if not low <= chosen <= high:
        return chosen, caveat(
            f"the swing's events ({listed}) put the latency at {chosen * 1e3:.1f} ms, outside the range "
            f"{low * 1e3:g} to {high * 1e3:g} ms, and it was reported",
            "widen --latency-range if such a latency is possible, or check the tracks at the start and end of the clip",
        )
    return chosen, None


def resolve_cycles(
    latency_s: float,
    period_s: float,
    windows: WindowPhases,
    gamma: float,
    latency_range_s: tuple[float, float] = DEFAULT_LATENCY_RANGE_S,
    event_lags_s: Mapping[str, float] | None = None,
) -> CycleResolution:
    """Choose among the whole-period alternatives of a latency known modulo ``period_s``.

    event_lags_s: sphere-minus-LED times of one-off events of the swing, by name (see the module
    docstring); they decide when they agree.
    """
    events = dict(event_lags_s or {})
    candidates = candidate_latencies(latency_s, period_s, latency_range_s)
    chosen, event_warning = _event_choice(latency_s, period_s, events, latency_range_s)
    if chosen is not None:
        return CycleResolution(chosen, False, "+".join(events), candidates, None, None, event_warning, events)
    if len(candidates) == 1:
        return CycleResolution(candidates[0], False, "range", candidates, None, None, event_warning, events)
    listed = ", ".join(f"{c * 1e3:.1f}" for c in candidates)
    if np.count_nonzero(windows.both) < 4:
        evidence = np.zeros(len(candidates))
        separation = 0.0
    else:
        evidence, separation = _chirp_evidence(windows, gamma, candidates)
    order = np.argsort(evidence)
    best = candidates[int(order[0])]
    runner_up = float(evidence[order[1]])
    if runner_up >= DECISIVE_CHI2 and separation >= MIN_SEPARATION_S:
        return CycleResolution(best, False, "chirp", candidates, separation, runner_up, event_warning, events)
    reference = min(candidates, key=abs)
    low, high = latency_range_s
    unsettled = ", nor do the swing's events, which do not agree with each other" if event_warning else ""
    warning = caveat(
        f"the latency is known only modulo the swing period ({period_s * 1e3:.1f} ms): it may be any of {listed} ms "
        f"(all within {low * 1e3:g} to {high * 1e3:g} ms), the swing's chirp cannot tell them apart{unsettled}, and the "
        "one nearest zero was reported",
        "film a wider swing of a more damped pendulum, use a longer pendulum, or narrow --latency-range if the lab knows better",
    )
    return CycleResolution(reference, True, "unresolved", candidates, separation, runner_up, warning, events)
