"""How healthy a live run was, measured from what it logged, and whether its latency can be trusted.

A live run's latency is only the system's if the rig kept time while it ran. `run_health` reads a
run's folder once the run has ended and measures, over the run's span (from when its devices were
connected to when it ended):

* the display: refreshes presented (a new image swapped in) against those the measured refresh
  rate expects over the span, late swaps (landed after the refresh they were aimed at) and missed
  refreshes (the display repeated its image), how long the first image took, and the longest
  pause between new images from the first to the span's end (a run that stalls after two images
  has one long pause to its end);
* the pose's age at each swap (swap time minus the sensor time of the newest sample behind its
  image): median, 95th percentile and largest;
* the tracker: its typical sample interval and its dropouts (a gap over `DROPOUT_INTERVALS` of
  them) and longest gap in sensor time, and, as the rig received them, how long its first sample in
  the span took and its longest silence from there (a tracker, or its link, that held samples back
  and sent them late in a burst left the rig extrapolating as surely as one that measured nothing);
* the camera: frames dropped, with when (runs of consecutive drops), and its stalls.

`judge` turns those into a verdict (a status and its reasons) against the thresholds below:
`invalid` when the rig or its tracker stalled (its number would not be the system's latency),
`degraded` when it hitched, repeated images at most refreshes, swapped late or dropped camera frames
often (the number stands, with its caveats), `valid` otherwise. Times are seconds into the run.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from rig.live.files import MARKERS_FILE, PUBLISHED_FILE, SWAPS_FILE, read_columns, with_poses
from rig.session.run_record import FRAMES_FILE, TRACKER_FILE

STALL_S = 0.25
"""A pause longer than this with no new image (or no tracker sample) makes the run invalid: the
sphere froze for an eighth or more of a pendulum swing (1 to 2 s), far longer than any latency the
rig measures, so neither the video nor the log shows the system's latency there."""
WARM_UP_S = 1.0
"""The first image (and the first tracker sample) may come this long after the devices connected: a
renderer compiles its shaders on its first frames, and neither the log's latency nor a camera that
starts with the swing uses the run's first moments. Later than that, the run stalled at its start."""
HITCH_S = 0.1
"""A pause longer than this (six refreshes at 60 Hz) degrades the run: the latency it measures
includes hitches the system shows only under load."""
MIN_PRESENTED_SHARE = 0.5
"""Below this share of the expected refreshes presenting a new image, the run is degraded: the
display held most images for two refreshes or more, so the latency varies by a refresh from image
to image with the machine's load."""
MAX_LATE_SHARE = 0.05
"""More than this share of swaps landing after the refresh they were aimed at degrades the run: the
renderer's plan does not match what the machine delivers."""
MAX_CAMERA_DROP_SHARE = 0.01
"""More than this share of the camera's frames dropped degrades the run: the video misses moments
of it, and if they are the slow ones, the video's answer leans towards the fast ones."""
DROPOUT_INTERVALS = 3.0
"""A tracker gap longer than this many typical sample intervals is a dropout."""
SLOW_GAP_S = 0.05
"""A pause between new images longer than this (three refreshes at 60 Hz) is a moment the rig was
slow; camera drops within `SLOW_MARGIN_S` of one are counted as drops while the rig was slow."""
SLOW_MARGIN_S = 0.1

VALID, DEGRADED, INVALID = "valid", "degraded", "invalid"


def pauses(times: np.ndarray, t_begin: float, t_end: float) -> dict[str, float]:
    """When the first of `times` in the span came (s into it; the span's length if none did), and
    the longest pause (ms) from it to the span's end, the end included, with when it began."""
    inside = np.sort(times[(times >= t_begin) & (times <= t_end)])
    if not len(inside):
        return {"first_s": t_end - t_begin, "longest_gap_ms": 0.0, "longest_gap_at_s": 0.0}
    edges = np.concatenate([inside, [t_end]])
    steps = np.diff(edges)
    i = int(np.argmax(steps))
    return {"first_s": float(inside[0] - t_begin), "longest_gap_ms": float(steps[i]) * 1e3,
            "longest_gap_at_s": float(edges[i] - t_begin)}  # fmt: skip


def slow_spans(swap_times: np.ndarray, slow_s: float = SLOW_GAP_S) -> list[tuple[float, float]]:
    """The pauses between consecutive swaps longer than `slow_s`: when the rig was slow."""
    t = np.sort(swap_times)
    long = np.flatnonzero(np.diff(t) > slow_s)
    return [(float(t[i]), float(t[i + 1])) for i in long]


def during(instants: np.ndarray, spans: list[tuple[float, float]], margin_s: float = SLOW_MARGIN_S) -> np.ndarray:
    """Which `instants` fall within `margin_s` of one of `spans`."""
    inside = np.zeros(len(instants), dtype=bool)
    for start, end in spans:
        inside |= (instants >= start - margin_s) & (instants <= end + margin_s)
    return inside


def swaps_of(out_dir: Path) -> dict[str, np.ndarray] | None:
    """Each new image's swap: `t` (rig clock), `image` (its published frame) and `late` (NaN where
    not known: an external renderer's markers do not say), from the window's swap log or an external
    renderer's markers; None where the run kept neither."""
    swaps = read_columns(out_dir / SWAPS_FILE)
    if swaps is not None:
        return {"t": swaps["t_swap"], "image": swaps["image"], "late": swaps["late"]}
    markers = read_columns(out_dir / MARKERS_FILE)
    if markers is None:
        return None
    frames = markers["frame"]
    new = (frames >= 0) & np.concatenate([[True], np.diff(frames) != 0])
    return {"t": markers["t_swap"][new], "image": frames[new], "late": np.full(int(new.sum()), np.nan)}


def display_health(swaps: dict[str, np.ndarray], refresh_hz: float, t_begin: float, t_end: float) -> dict[str, Any]:
    """Refreshes presented against expected, late swaps, missed refreshes and the longest pause."""
    expected = int(round(max(0.0, t_end - t_begin) * refresh_hz))
    presented = int(np.count_nonzero((swaps["t"] >= t_begin) & (swaps["t"] <= t_end)))
    late = swaps["late"]
    return {
        "refresh_hz": refresh_hz,
        "refreshes_expected": expected,
        "refreshes_presented": presented,
        "presented_share": presented / expected if expected else 0.0,
        "missed_refreshes": max(0, expected - presented),
        "late_swaps": None if np.all(np.isnan(late)) else int(np.count_nonzero(late > 0)),
        **pauses(swaps["t"], t_begin, t_end),
        "slow_moments": len(slow_spans(swaps["t"])),
    }


def pose_age(swaps: dict[str, np.ndarray], poses: dict[str, np.ndarray] | None) -> dict[str, float] | None:
    """The pose's age (ms) at each swap: the swap's time minus its image's newest sample's sensor time."""
    if poses is None or not len(poses.get("frame", ())):
        return None
    at, pose_at = with_poses(swaps["image"], np.ones(len(swaps["image"]), dtype=bool), poses)
    if not len(at):
        return None
    age_ms = (swaps["t"][at] - poses["t_sensor"][pose_at]) * 1e3
    return {"median_ms": float(np.median(age_ms)), "p95_ms": float(np.percentile(age_ms, 95)), "max_ms": float(age_ms.max())}


def tracker_health(tracker: dict[str, np.ndarray] | None, t_begin: float, t_end: float) -> dict[str, Any]:
    """The tracker's typical interval, dropouts and longest gap in sensor time over the span, and its
    first sample and longest silence as they arrived."""
    if tracker is None or len(tracker["t_sensor"]) < 3:
        return {"samples": 0 if tracker is None else len(tracker["t_sensor"]), "interval_ms": None, "dropouts": None,
                "longest_sensor_gap_ms": None, **pauses(np.array([]), t_begin, t_end)}  # fmt: skip
    t = np.unique(tracker["t_sensor"])
    interval = float(np.median(np.diff(t)))
    steps = np.diff(t[(t >= t_begin) & (t <= t_end)])
    return {"samples": int(len(tracker["t_sensor"])), "interval_ms": interval * 1e3,
            "dropouts": int(np.count_nonzero(steps > DROPOUT_INTERVALS * interval)),
            "longest_sensor_gap_ms": float(steps.max()) * 1e3 if len(steps) else None,
            **pauses(tracker["t_arrival"], t_begin, t_end)}  # fmt: skip


def camera_health(frames: dict[str, np.ndarray] | None, film: dict[str, Any] | None, t_begin: float) -> dict[str, Any] | None:
    """The camera's frames, its drops and when they happened (runs of consecutive stand-ins), stalls."""
    if frames is None or film is None:
        return None
    filled = frames["filled"] == 1
    drops = []
    for start, stop in _runs(filled):
        drops.append({"at_s": float(frames["t_capture"][start] - t_begin), "frames": int(stop - start)})
    total = len(filled)
    return {"frames": int(total), "dropped": int(filled.sum()), "dropped_share": float(filled.mean()) if total else 0.0,
            "drops": drops, "stalls": film.get("stalls", 0)}  # fmt: skip


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    """[start, stop) of each run of True in `flags`."""
    edges = np.diff(np.concatenate([[0], flags.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist()))


def _pauses(stream: dict[str, Any], stalled: str, hitched: str, first: str, silent: str) -> tuple[list[str], list[str]]:
    """The invalid and the degraded reasons of one stream's pauses (the display's images, the
    tracker's samples): its first item after the warm-up, and its longest silence."""
    invalid, degraded = [], []
    if stream["first_s"] > WARM_UP_S:
        invalid.append(f"{stalled}: its first {first} came {stream['first_s'] * 1e3:.0f} ms after the run began")
    gap, at = stream["longest_gap_ms"], stream["longest_gap_at_s"]
    silence = f"{silent} for {gap:.0f} ms from {at:.1f} s into the run"
    if gap > STALL_S * 1e3:
        invalid.append(f"{stalled}: {silence}")
    elif gap > HITCH_S * 1e3:
        degraded.append(f"{hitched}: {silence}")
    return invalid, degraded


def judge(health: dict[str, Any]) -> tuple[str, list[str]]:
    """The verdict on a run's health (see the module docstring and the thresholds)."""
    invalid, degraded = [], []
    display, tracker, camera = health.get("display"), health["tracker"], health.get("camera")
    if display is None or display["refreshes_presented"] == 0:
        invalid.append("the rig stalled: the display showed no image")
    else:
        stalls, hitches = _pauses(display, "the rig stalled", "the rig hitched", "image", "no new image")
        invalid += stalls
        degraded += hitches
        if display["presented_share"] < MIN_PRESENTED_SHARE:
            degraded.append(f"the display showed a new image at {display['presented_share']:.0%} of refreshes "
                            f"({display['refreshes_presented']} of {display['refreshes_expected']})")  # fmt: skip
        late = display["late_swaps"]
        if late is not None and late > MAX_LATE_SHARE * display["refreshes_presented"]:
            degraded.append(f"{late} of {display['refreshes_presented']} swaps were late")
    stalls, hitches = _pauses(tracker, "the tracker stalled", "the tracker dropped out", "sample", "no sample arrived")
    invalid += stalls
    degraded += hitches
    if camera is not None and camera["dropped_share"] > MAX_CAMERA_DROP_SHARE:
        worst = max(camera["drops"], key=lambda drop: drop["frames"])
        degraded.append(f"the camera dropped {camera['dropped']} frames ({camera['dropped_share']:.1%}), "
                        f"{worst['frames']} in a row at {worst['at_s']:.1f} s")  # fmt: skip
    if invalid:
        return INVALID, invalid
    return (DEGRADED, degraded) if degraded else (VALID, [])


def run_health(out_dir: Path, refresh_hz: float, t_begin: float, t_end: float, film: dict[str, Any] | None) -> dict[str, Any]:
    """A run folder's health over [t_begin, t_end] (rig clock) with its verdict, for `live.json`;
    `refresh_hz` is the display's measured rate, `film` the film's report (None without a camera)."""
    out_dir = Path(out_dir)
    swaps = swaps_of(out_dir)
    health: dict[str, Any] = {
        "span_s": t_end - t_begin,
        "display": display_health(swaps, refresh_hz, t_begin, t_end) if swaps is not None else None,
        "pose_age": pose_age(swaps, read_columns(out_dir / PUBLISHED_FILE)) if swaps is not None else None,
        "tracker": tracker_health(read_columns(out_dir / TRACKER_FILE), t_begin, t_end),
        "camera": camera_health(read_columns(out_dir / FRAMES_FILE), film, t_begin),
    }
    status, reasons = judge(health)
    verdict = f"{status}: {'; '.join(reasons)}" if reasons else status
    return {**health, "status": status, "reasons": reasons, "verdict": verdict}
