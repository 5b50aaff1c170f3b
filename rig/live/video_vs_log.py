"""The video's latency against the rig log's, over the same instants and over the whole run.

The log's latency at the instants the camera filmed weights the run as the video does: the two
measure the same thing, and the self-test checks that they agree. The log's latency over the whole
run is the run's: where the camera missed moments of it (dropped frames, a late start) and the
latency changed meanwhile, the video's answer is not the whole run's. When the whole-run figure
lies outside the video's 95 % interval, `compare` says so with both numbers, one line of cause (the
camera's drops, and how many came while the rig was slow, `rig.live.health.slow_spans`) and one
of remedy.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from rig.live.files import camera_instants
from rig.live.health import during, slow_spans, swaps_of


def compare(video: dict[str, Any], log: dict[str, Any], dropped: np.ndarray, slow: list[tuple[float, float]]) -> dict[str, Any]:
    """Video against log over the filmed instants and the whole run; `dropped` are when the camera
    dropped frames and `slow` when the rig was slow (both on the rig clock). The `warning` (cause
    and remedy) is there when the whole run's latency lies outside the video's interval."""
    ci = video.get("ci95_ms")
    whole = log["whole_run_latency_ms"]
    holds = None if not ci else bool(ci[0] <= whole <= ci[1])
    while_slow = int(np.count_nonzero(during(dropped, slow))) if len(dropped) else 0
    result: dict[str, Any] = {
        "video_ms": video["latency_ms"], "video_ci95_ms": ci, "log_filmed_ms": log["latency_ms"], "log_whole_run_ms": whole,
        "whole_run_in_interval": holds, "camera_drops": int(len(dropped)), "drops_while_rig_slow": while_slow, "warning": None,
    }  # fmt: skip
    if holds is False:
        numbers = (f"the video's latency {video['latency_ms']:.1f} ms (95% CI [{ci[0]:.1f}, {ci[1]:.1f}]) is not the whole "
                   f"run's by the rig's log, {whole:.1f} ms (over the instants filmed the log gives {log['latency_ms']:.1f} ms)")  # fmt: skip
        if len(dropped):
            why = (f"the camera dropped {len(dropped)} frames, {while_slow} of them while the rig was slow, so the video "
                   "leaves out moments when the latency was different")  # fmt: skip
        else:
            why = "the camera filmed only part of the run, and the latency changed over the run"
        result["warning"] = {
            "cause": f"{numbers}: {why}",
            "remedy": "lighten the machine's load (close other programs) so the camera keeps every frame and the rig "
            "its pace, then measure again; until then the whole-run figure is the run's",
        }
    return result


def video_against_log(out_dir: Path, video: dict[str, Any], log: dict[str, Any]) -> dict[str, Any]:
    """`compare` for a run folder: its camera's drops and its rig's slow moments from its logs."""
    swaps = swaps_of(Path(out_dir))
    slow = slow_spans(swaps["t"]) if swaps is not None else []
    return compare(video, log, camera_instants(out_dir, dropped=True), slow)
