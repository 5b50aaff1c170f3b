"""A tracker's own clock mapped onto the rig clock, online, with the board's clock maths.

Both mappings keep offsets (device time minus rig time) as `OffsetInterval`s in a `ClockModel`
(`rig.board.clock_sync`): interpolated between measurements, extrapolated with the drift measured
so far, started afresh when the device's clock restarts.

* `OneWayMapping`, for a serial or HID tracker that stamps its records: a record cannot arrive
  before it was sent, so every record bounds the offset from one side, offset >= device - arrival.
  Over each window of WINDOW_S the fastest record comes closest; the mapping takes the window's
  largest device - arrival as the low end of the interval and adds the gap to the runner-up (how
  far the fastest may still sit above the transport's floor) and the time field's resolution as
  its width. A record's rig time is then when it would have arrived over the fastest transfer
  seen: jitter is gone, but the floor itself, the tracker's constant delay, cannot be known from
  one-way stamps (the pendulum measurement includes it), so no tracker latency is reported.
* `CorrectedMapping`, for LSL: liblsl measures the offset to the sending machine by round trips
  (`time_correction`, with its uncertainty), a two-sided interval, so the tracker's latency to
  the host (arrival minus mapped time) is known and reported.
* `ArrivalTime`, for a device that sends no time: the sensor time is the arrival time.
"""

from __future__ import annotations

import math
from collections import deque
from typing import Any, Protocol, Sequence

from rig.board.clock_sync import CLOCK_RESTART_S, ClockModel, OffsetInterval
from rig.devices.trackers.profile import TIME, Profile

WINDOW_S = 0.5


class ClockMapping(Protocol):
    """Gives each record its sensor time on the rig clock."""

    latency_known: bool

    def observe_many(self, device_times: list[float] | None, arrivals: list[float]) -> None:
        """Learn from records taken together, before `sensor_times` is asked for them."""

    def sensor_times(self, device_times: Sequence[float | None], arrivals: Sequence[float]) -> list[float]:
        """The sensor times of records taken together (a consumer's batch), in one call."""

    def restart(self) -> None:
        """The link was lost and restored: the device's clock may have restarted."""

    def describe(self) -> dict[str, Any]: ...


def _model_summary(model: ClockModel) -> dict[str, Any]:
    latest = model.latest
    drift = model.drift()
    return {
        "offset_s": latest.midpoint if latest else None,
        "offset_interval_s": [latest.low, latest.high] if latest else None,
        "offset_at_s": latest.at if latest else None,
        "drift_ppm": drift.rate * 1e6 if drift else None,
        "drift_uncertainty_ppm": drift.uncertainty * 1e6 if drift else None,
        "measurements": len(model.intervals),
    }


class ArrivalTime:
    """No device time: a record was measured when it arrived, as far as anyone can tell."""

    latency_known = False

    def observe_many(self, device_times: list[float] | None, arrivals: list[float]) -> None:
        pass

    def sensor_times(self, device_times: Sequence[float | None], arrivals: Sequence[float]) -> list[float]:
        return list(arrivals)

    def restart(self) -> None:
        pass

    def describe(self) -> dict[str, Any]:
        return {"kind": "arrival", "detail": "the device sends no time of its own: sensor time is the arrival time"}


class OneWayMapping:
    """Device time to rig time from one-way stamps (see the module docstring); `resolution_s` is the
    time field's step (a microsecond counter: 1e-6)."""

    latency_known = False

    def __init__(self, resolution_s: float) -> None:
        self.model = ClockModel()
        self._resolution = resolution_s
        self._window_end = -math.inf
        self._best = self._second = -math.inf
        self._best_at = 0.0
        self._fresh = True

    def observe_many(self, device_times: list[float] | None, arrivals: list[float]) -> None:
        """Each record bounds the offset from below; its window keeps the largest bound, when it came,
        and the largest of the rest."""
        window_end, best, second, best_at = self._window_end, self._best, self._second, self._best_at
        for device_time, t_arrival in zip(device_times, arrivals):  # type: ignore[arg-type]
            if t_arrival >= window_end and best > -math.inf:
                self._close_window(best, second, best_at)
                window_end = best = second = -math.inf
            if window_end == -math.inf:
                window_end = t_arrival + WINDOW_S
            bound = device_time - t_arrival
            if bound > best:
                best, second, best_at = bound, best, t_arrival
            elif bound > second:
                second = bound
        self._window_end, self._best, self._second, self._best_at = window_end, best, second, best_at

    def sensor_times(self, device_times: Sequence[float | None], arrivals: Sequence[float]) -> list[float]:
        """Each record's device time less the modelled offset at its arrival (the current window's
        best bound while the model is empty, or while a restarted clock is far from it), never
        after its arrival."""
        best = self._best
        if self.model.latest is None:
            return [min(d - best, t) for d, t in zip(device_times, arrivals)]  # type: ignore[operator]
        times = []
        restarted = self._fresh
        for d, t, modelled in zip(device_times, arrivals, self.model.offsets_at(arrivals)):
            # Conditional expressions rather than min and max: this runs once per record.
            if restarted and abs(best - modelled) > CLOCK_RESTART_S:
                offset = best
            else:
                bound = d - t  # type: ignore[operator]
                offset = modelled if modelled > bound else bound
            mapped = d - offset  # type: ignore[operator]
            times.append(mapped if mapped < t else t)
        return times

    def _close_window(self, best: float, second: float, best_at: float) -> None:
        gap = best - second if second > -math.inf else 0.0
        self.model.add(OffsetInterval(best, best + gap + self._resolution, best_at))
        self._fresh = False

    def restart(self) -> None:
        self._best = self._second = -math.inf
        self._window_end = -math.inf
        self._fresh = True

    def describe(self) -> dict[str, Any]:
        return {
            "kind": "one-way",
            "detail": "offset = device time - rig time of the fastest transfer, per "
            f"{WINDOW_S:g} s window; the transport's constant delay is unknown, so no latency is reported",
            **_model_summary(self.model),
        }


class CorrectedMapping:
    """Device time to rig time from round-trip corrections such as LSL's: a correction (c, u, at) says
    local = remote + c within +-u, where local is a host clock that read `origin_s` at the rig
    clock's zero (set before the first correction). The transport measures them on its own thread
    and `queue`s them; the consumer's `observe_many`, before it maps a batch, takes them in."""

    latency_known = True

    def __init__(self) -> None:
        self.model = ClockModel()
        self.origin_s: float | None = None
        self._last: tuple[float, float] | None = None
        self._queued: deque[tuple[float, float, float]] = deque()

    def queue(self, correction: float, uncertainty: float, at: float) -> None:
        """A measurement, from any thread, for the consumer to take in."""
        self._queued.append((correction, uncertainty, at))

    def add_correction(self, correction: float, uncertainty: float, at: float) -> None:
        """A new measurement (repeats of the last one are ignored)."""
        if (correction, uncertainty) == self._last:
            return
        self._last = (correction, uncertainty)
        offset = self.origin_s - correction
        self.model.add(OffsetInterval(offset - uncertainty, offset + uncertainty, at))

    def observe_many(self, device_times: list[float] | None, arrivals: list[float]) -> None:
        """Takes in the corrections queued since the last batch."""
        queued, add = self._queued, self.add_correction
        while queued:
            add(*queued.popleft())

    def sensor_times(self, device_times: Sequence[float | None], arrivals: Sequence[float]) -> list[float]:
        return self.model.to_rig_times(device_times)  # type: ignore[arg-type]

    def restart(self) -> None:
        self._last = None

    def describe(self) -> dict[str, Any]:
        return {
            "kind": "round-trip",
            "detail": "offset measured by round trips (LSL time_correction); tracker latency = arrival - mapped time",
            **_model_summary(self.model),
        }


def mapping_for(profile: Profile) -> ClockMapping:
    """A one-way mapping for a profile whose records carry the device's time, arrival time otherwise;
    an integer time field's step is the mapping's resolution."""
    time_field = profile.field(TIME)
    if time_field is None:
        return ArrivalTime()
    step = profile.scale.get(TIME, 1.0) * profile.unit(TIME)
    return OneWayMapping(abs(step) if time_field.integer_bits else 0.0)
