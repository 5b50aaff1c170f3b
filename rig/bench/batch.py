"""`rig bench batch` (its command line declared in `rig.bench.batch_settings`): what it measures.

* **Scale-out**: `rig analyse` of a batch of simulated videos in a fresh process, serially, then
  on a local Dask cluster of two worker processes (the cluster's start included), alternately a
  few rounds: the speed-up of the medians, and of each round. Beside them, the serial run with
  the threads a worker gets (`rig.executor.worker_environment`): `workers` times the serial run
  over that one is the most the workers could gain with nothing else to pay (the ceiling). A
  serial run decodes ahead on a thread of its own, so where the cores are too few to give each
  worker one too, the ceiling is under `workers`.
* **Dask's overhead**: the same for a batch of one video.
* **Fixed cost per video**: one longer clip analysed by `rig analyse` in a fresh process, against
  decoding it alone in a fresh process, with the compiled-fit cache empty (the first run on a
  machine) and then filled (every later run).

Every figure is wall time on this machine with whatever else runs on it; compare ratios taken in
one run. A video that cannot be simulated is left out of the batch, saying why; a part that cannot
be measured (no video, a run that fails or a worker that dies) is failed with the reason, and the
other part is still measured.
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

from rig.bench.batch_settings import BatchBenchOptions
from rig.bench.contract import Bench, Context, Log
from rig.commands.declared_options import config_from_args
from rig.errors import ConfigError, RigError
from rig.executor import worker_environment
from rig.service.simulate import simulate
from rig.sim.config import SimulationConfig
from rig.sim.pendulum import PendulumConfig

PERIODS_S = (0.7, 0.9, 1.1, 1.3)
DECODE_ONLY = "import sys; from analysis.video.sources import open_frames; sum(1 for _ in open_frames(sys.argv[1]).frames())"


def _process_seconds(arguments: list[str], environment: dict[str, str], allowed: tuple[int, ...] = (0,)) -> float:
    """Wall time of a command; RigError with its error output if it exits otherwise than `allowed`."""
    started = time.perf_counter()
    done = subprocess.run(arguments, capture_output=True, text=True, env=environment)
    if done.returncode not in allowed:
        raise RigError(f"{' '.join(arguments)} exited {done.returncode}: {done.stderr.strip()[-500:]}")
    return time.perf_counter() - started


def videos(folder: Path, count: int, duration_s: float, log: Log) -> tuple[list[Path], list[dict[str, Any]]]:
    """`count` simulated videos over a few pendulum periods, each with its own seed; and those that
    could not be simulated, each with its reason."""
    made, failed = [], []
    for index in range(count):
        config = SimulationConfig(duration_s=duration_s, seed=index, pendulum=PendulumConfig(period_s=PERIODS_S[index % len(PERIODS_S)]))
        try:
            made.append(simulate(config, folder / f"video{index:02d}", overwrite=True).video_path)
        except RigError as error:
            failed.append({"video": index, "failed": str(error)})
            log(f"video {index + 1}/{count} not simulated: {error}")
            continue
        log(f"simulated {index + 1}/{count}")
    return made, failed


def batch_seconds(videos: list[Path], workers: int | None, environment: dict[str, str] | None = None) -> float:
    """`rig analyse VIDEOS --summary` in a fresh process, serially or on a local Dask cluster of
    `workers` (its start included): what a user waits for either way, compiled fits cached alike;
    `environment` adds to this process's variables."""
    rig = str(Path(sys.executable).with_name("rig"))
    with tempfile.TemporaryDirectory(prefix="rig-bench-batch-") as folder:
        command = [rig, "analyse", *map(str, videos), "--summary", str(Path(folder) / "summary.csv")]
        return _process_seconds([*command, *(["--workers", str(workers)] if workers else [])], {**os.environ, **(environment or {})},
                                allowed=(0, 3))  # fmt: skip


def scale_out(paths: list[Path], workers: int, rounds: int, log: Log) -> dict[str, Any]:
    """The batch serially and on Dask, alternately `rounds` times (a shared machine's load drifts
    between runs), and the one-video batch likewise; medians, and the speed-up of each round.
    RigError where there is no video or a run fails."""
    if not paths:
        raise RigError("no video of the batch could be simulated")
    batch_seconds(paths[:1], None)  # fills the compiled-fit cache, as any earlier run on the machine has
    as_worker = worker_environment(workers)
    serial, parallel, serial_as_worker, one_serial, one_dask = [], [], [], [], []
    for round_number in range(1, rounds + 1):
        serial.append(batch_seconds(paths, None))
        parallel.append(batch_seconds(paths, workers))
        serial_as_worker.append(batch_seconds(paths, None, as_worker))
        log(f"round {round_number}/{rounds}: {len(paths)} videos serially {serial[-1]:.1f} s, on {workers} Dask workers {parallel[-1]:.1f} s, "
            f"serially with a worker's threads {serial_as_worker[-1]:.1f} s")  # fmt: skip
        one_serial.append(batch_seconds(paths[:1], None))
        one_dask.append(batch_seconds(paths[:1], workers))
        log(f"round {round_number}/{rounds}: one video {one_serial[-1]:.1f} s serially, {one_dask[-1]:.1f} s on Dask")
    median = statistics.median
    return {
        "videos": len(paths),
        "workers": workers,
        "rounds": rounds,
        "serial_s": median(serial),
        "dask_s": median(parallel),
        "speed_up": median(serial) / median(parallel),
        "speed_up_per_round": [a / b for a, b in zip(serial, parallel)],
        "worker_opencv_threads": int(as_worker.get("OPENCV_FOR_THREADS_NUM", 0)) or None,
        "serial_as_worker_s": median(serial_as_worker),
        "ceiling_speed_up": workers * median(serial) / median(serial_as_worker),
        "one_video_serial_s": median(one_serial),
        "one_video_dask_s": median(one_dask),
        "dask_overhead_s": median(one_dask) - median(one_serial),
    }


def clip_cost(folder: Path, duration_s: float, log: Log) -> dict[str, Any]:
    """A clip simulated into `folder`, then `rig analyse` of it in a fresh process against decoding
    it alone, with an empty then a filled cache."""
    clip = simulate(replace(SimulationConfig(duration_s=duration_s), seed=99), folder, overwrite=True).video_path
    rig = str(Path(sys.executable).with_name("rig"))
    with tempfile.TemporaryDirectory(prefix="rig-bench-cache-") as cache:
        environment = {**os.environ, "JAX_COMPILATION_CACHE_DIR": cache}
        decode = min(_process_seconds([sys.executable, "-c", DECODE_ONLY, str(clip)], environment) for _ in range(2))
        cold = _process_seconds([rig, "analyse", str(clip), "--json"], environment, allowed=(0, 3))
        warm = min(_process_seconds([rig, "analyse", str(clip), "--json"], environment, allowed=(0, 3)) for _ in range(2))
    log(f"fixed cost: decode alone {decode:.1f} s, analyse {cold:.1f} s (empty cache), {warm:.1f} s (filled)")
    return {
        "clip": str(clip),
        "decode_s": decode,
        "analyse_cold_cache_s": cold,
        "analyse_warm_cache_s": warm,
        "ratio_cold": cold / decode,
        "ratio_warm": warm / decode,
    }


def run(spec: BatchBenchOptions, context: Context) -> dict[str, Any]:
    """The batch's scale-out and a clip's fixed cost (see the module docstring); a part that cannot
    be measured is `{"failed": reason}` in its place, the videos left out under "unsimulated"."""
    paths, unsimulated = videos(context.folder / "batch", spec.videos, spec.duration_s, context.log)
    report: dict[str, Any] = {"unsimulated": unsimulated}
    for part, measure in (("scale_out", lambda: scale_out(paths, spec.workers, spec.rounds, context.log)),
                          ("fixed_cost", lambda: clip_cost(context.folder / "clip", spec.clip_duration_s, context.log))):  # fmt: skip
        try:
            report[part] = measure()
        except RigError as error:
            context.log(f"{part.replace('_', ' ')} failed: {error}")
            report[part] = {"failed": str(error)}
    return report


def every_part_failed(report: dict[str, Any]) -> str | None:
    """A sentence where neither the scale-out nor the fixed cost could be measured, else None."""
    if "failed" not in report["scale_out"] or "failed" not in report["fixed_cost"]:
        return None
    return f"every part failed (the batch: {report['scale_out']['failed']}; the clip: {report['fixed_cost']['failed']})"


def table(report: dict[str, Any]) -> str:
    s, f = report["scale_out"], report["fixed_cost"]
    left_out = [f"video {v['video']} not simulated: {v['failed']}" for v in report.get("unsimulated", ())]
    batch_lines = [f"batch: failed: {s['failed']}"] if "failed" in s else [
        f"batch of {s['videos']} videos (median of {s['rounds']} rounds): serial {s['serial_s']:.1f} s, "
        f"{s['workers']} Dask workers {s['dask_s']:.1f} s, speed-up {s['speed_up']:.2f} "
        f"(rounds: {', '.join(f'{r:.2f}' for r in s['speed_up_per_round'])})",
        f"ceiling: serially with a worker's threads (OpenCV {s['worker_opencv_threads']}) {s['serial_as_worker_s']:.1f} s, so "
        f"{s['workers']} workers can be at most {s['ceiling_speed_up']:.2f} times as fast as serially, before the cluster's start",
        f"Dask overhead for one video: {s['dask_overhead_s']:+.1f} s ({s['one_video_dask_s']:.1f} s against {s['one_video_serial_s']:.1f} s)",
    ]
    clip_lines = [f"fixed cost of a clip: failed: {f['failed']}"] if "failed" in f else [
        f"fixed cost of a clip in a fresh process: analyse / decode alone = {f['ratio_cold']:.2f} (empty cache), "
        f"{f['ratio_warm']:.2f} (filled cache); decode alone {f['decode_s']:.1f} s",
    ]
    return "\n".join(batch_lines + clip_lines + left_out)


def plot(report: dict[str, Any], path: Path) -> None:
    """Wall times side by side: the batch serially and on Dask; a clip decoded, then analysed."""
    from matplotlib.figure import Figure

    s, f = report["scale_out"], report["fixed_cost"]
    figure = Figure(figsize=(10, 3.8), layout="constrained")
    batch, clip = figure.subplots(1, 2)
    for axis, part, draw in ((batch, s, _draw_batch), (clip, f, _draw_clip)):
        if "failed" in part:
            axis.set_axis_off()
            axis.text(0.5, 0.5, "failed (the table says why)", ha="center", va="center", transform=axis.transAxes)
        else:
            draw(axis, part)
    figure.savefig(path, dpi=100)


def _draw_batch(batch: Any, s: dict[str, Any]) -> None:
    batch.bar(["serial", "serial with\na worker's threads", f"{s['workers']} Dask workers"],
              [s["serial_s"], s["serial_as_worker_s"], s["dask_s"]], color=["C0", "grey", "C1"])  # fmt: skip
    batch.set_ylabel("wall time (s)")
    batch.set_xlabel(f"batch of {s['videos']} videos")
    batch.set_title(f"speed-up {s['speed_up']:.2f}, ceiling {s['ceiling_speed_up']:.2f}")


def _draw_clip(clip: Any, f: dict[str, Any]) -> None:
    clip.bar(["decode alone", "analyse,\nempty cache", "analyse,\nfilled cache"],
             [f["decode_s"], f["analyse_cold_cache_s"], f["analyse_warm_cache_s"]], color=["grey", "C3", "C2"])  # fmt: skip
    clip.set_ylabel("wall time in a fresh process (s)")
    clip.set_xlabel("one clip")
    clip.set_title(f"fixed cost: {f['ratio_warm']:.2f} x decoding (filled cache)")


BENCH = Bench(
    run=run, table=table, plot=plot, spec=lambda args: config_from_args(BatchBenchOptions, args, ConfigError), all_failed=every_part_failed,
)
