"""`rig bench analyser` (its command line declared in `rig.bench.analyser_settings`): what it measures.

The bench is a sweep (`rig.service.sweep`) with a fixed spec, `specs/analyser.toml` (three tiny
cases in `specs/analyser-quick.toml`), its points written out one by one; the impairments are the
simulated camera's (`rig.sim.impairments`). Each point is simulated and analysed as `rig sweep` does
it, giving the sweep's summary row; the bench then analyses the same film with every method and adds
its record of the case to the row ("bench"). Errors are against the simulation's true latency, in ms
and in the film's frame intervals; coverage is the fraction of cases whose 95 % interval holds the
truth (methods without intervals have none); a *confidently wrong* answer is one whose interval
misses the truth by more than max(WRONG_MS, its half-width), or, for a method without an interval,
whose number is off by more than WRONG_MS. Cases the analyser refuses (the sweep's row failed: it
cannot tell the LED from the sphere) give no number and are counted apart, as are cases flagged
ambiguous (left out of the error statistics). Accuracy is also summarised over the cases whose
camera is not phase-locked to the display (the refreshes walk through the frames), where the target
is today's.

Speed: the sweep's analysis (sinefit) runs first and is the warm-up; the film is then decoded
alone (the fastest the analyser's own reader can go, nothing else done), analysed with every method
at once, and decoded again; a method's time is the whole analysis less the other methods' own
estimation time. Sinefit's time is the faster of its two runs, and decoding's the faster of the
two decodes, one either side of the analysis, so that a burst of load from elsewhere on the
machine touches the ratio less.
"""

from __future__ import annotations

import time
from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

import analysis
from analysis import AnalysisOptions
from analysis.sampling.model import commensurate
from analysis.video.sources import open_frames
from rig.bench.analyser_settings import GROUPS
from rig.bench.contract import Bench, Context, Log, cell, every_one, new_figure
from rig.service.batch import USER_ERRORS
from rig.service.sweep import Sweep, SweepPoint, read_sweep, run_sweep, simulate_and_analyse, unsimulated_row
from rig.sim.config import SimulationConfig

TARGETS = {
    "median_frames": 0.1,
    "worst_frames": 0.5,
    "coverage": (0.90, 0.98),
    "speed_ratio": 0.8,
    "confidently_wrong": 0,
    "unlocked_median_ms": 0.05,
}
WRONG_MS = 0.5


def decode_seconds(video: Path) -> tuple[float, int]:
    """Time to decode every frame with the analyser's reader, doing nothing else; and the frame count."""
    started = time.perf_counter()
    count = sum(1 for _ in open_frames(video).frames())
    return time.perf_counter() - started, count


def confidently_wrong(truth_ms: float, latency_ms: float, ci95_ms: tuple[float, float] | list[float] | None) -> bool:
    """Whether an answer misses the truth by more than max(WRONG_MS, its interval's half-width), or
    without an interval, by more than WRONG_MS."""
    if ci95_ms is None:
        return bool(abs(latency_ms - truth_ms) > WRONG_MS)
    low, high = ci95_ms
    return bool(max(low - truth_ms, truth_ms - high, 0.0) > max(WRONG_MS, (high - low) / 2))


def phase_locked(config: SimulationConfig) -> bool:
    """Whether the film's frames sample the display at one phase of its refresh."""
    ratio = commensurate(config.camera.film_fps / config.display.refresh_hz)
    return ratio is not None and ratio[0] == 1


def _method_row(
    estimate: analysis.MethodResult, truth_ms: float, frame_ms: float, seconds: float, decode_s: float, frames: int
) -> dict[str, Any]:
    error = estimate.latency_ms - truth_ms
    ci = estimate.ci95_ms
    return {
        "latency_ms": estimate.latency_ms,
        "error_ms": error,
        "error_frames": error / frame_ms,
        "ci95_ms": list(ci) if ci is not None else None,
        "covered": None if ci is None else bool(ci[0] <= truth_ms <= ci[1]),
        "confidently_wrong": confidently_wrong(truth_ms, estimate.latency_ms, ci),
        "seconds": seconds,
        "fps": frames / seconds,
        "speed_ratio": decode_s / seconds,
        "model": estimate.model,
    }


def measure_point(point: SweepPoint, log: Log) -> dict[str, Any]:
    """A sweep job: the point's sweep row (simulated and analysed as `rig sweep` does), with the
    bench's record of the case under "bench": the film decoded and analysed with every method."""
    started = time.perf_counter()
    try:
        run = simulate_and_analyse(point)
    except USER_ERRORS as error:
        row = unsimulated_row(point, error)
        log(f"{_case_name(point)}: REFUSED before filming: {error}")
        return row | {"bench": _case_fields(point, None, 0) | {"refused": row["error"], "ambiguous": False, "methods": {},
                                                                "warnings": [], "decode_s": 0.0}}  # fmt: skip
    return run.row | {"bench": _case_record(point, run.options, run.row, log, started)}


def _case_name(point: SweepPoint) -> str:
    return point.labels.get("case", point.out_dir.name)


def _case_fields(point: SweepPoint, truth_ms: float | None, frames: int) -> dict[str, Any]:
    """What the case is: its settings and labels, its true latency and the frames filmed."""
    config = point.config
    return {
        "case": _case_name(point),
        "group": point.labels.get("group", "mixed"),
        "period_s": config.pendulum.period_s,
        "camera_fps": config.camera.film_fps,
        "display_hz": config.display.refresh_hz,
        "exposure_ms": config.camera.exposure * 1e3,
        "display_phase": config.display.phase,
        "phase_locked": phase_locked(config),
        "amplitude_deg": config.pendulum.amplitude_deg,
        "quality": config.pendulum.quality,
        "impairment": point.labels.get("impairment", "none"),
        "predictor": config.predictor,
        "truth_ms": truth_ms,
        "frames": frames,
    }


def _case_record(point: SweepPoint, options: AnalysisOptions, row: dict[str, Any], log: Log, started: float) -> dict[str, Any]:
    """The case's record: the film decoded, and analysed with every method and the `options` the
    sweep's analysis was given."""
    config, video, truth_ms = point.config, point.analysis.video, float(row["truth_ms"])
    name = _case_name(point)
    first_decode, frames = decode_seconds(video)
    record = _case_fields(point, truth_ms, frames)
    refused = row["error"] if row["status"] == "failed" else None
    if refused is None:
        try:
            analysed_started = time.perf_counter()
            result = analysis.analyse(video, replace(options, method="all", seed=config.seed))
            total_s = time.perf_counter() - analysed_started
            second_decode, _ = decode_seconds(video)
        except analysis.AnalysisError as error:
            refused = str(error)
    if refused is not None:
        log(f"{name}: truth {truth_ms:.2f} ms, REFUSED: {refused}")
        return {**record, "refused": refused, "ambiguous": False, "methods": {}, "warnings": [], "decode_s": first_decode}
    decode_s = min(first_decode, second_decode)
    warm_s = row["seconds"]
    estimation = sum(m.seconds for m in result.methods.values())
    methods = {}
    for method, estimate in result.methods.items():
        seconds = total_s - estimation + estimate.seconds
        if method == "sinefit":
            seconds = min(seconds, warm_s)
        if method == "bayes":
            # The posterior starts from the fit: its time includes the fit's.
            seconds += result.methods["sinefit"].seconds
        methods[method] = _method_row(estimate, truth_ms, 1e3 / config.camera.film_fps, seconds, decode_s, frames)
    record.update(
        refused=None,
        ambiguous=result.ambiguous,
        cycles=result.cycles.to_dict(),
        sampling=None if result.sampling is None else result.sampling.to_dict(),
        decode_s=decode_s,
        decode_fps=frames / decode_s,
        warm_up_s=warm_s,
        methods=methods,
        warnings=result.warnings,
    )
    sinefit = methods["sinefit"]
    flags = (" AMBIGUOUS" if result.ambiguous else "") + (" CONFIDENTLY WRONG" if sinefit["confidently_wrong"] else "")
    log(
        f"{name}: truth {truth_ms:.2f} ms, sinefit {sinefit['error_ms']:+.3f} ms "
        f"(95% {sinefit['ci95_ms'][0] - truth_ms:+.2f} to {sinefit['ci95_ms'][1] - truth_ms:+.2f} about the truth){flags}, "
        f"speed x{sinefit['speed_ratio']:.2f} of decoding ({time.perf_counter() - started:.0f} s)"
    )
    return record


def summarise(rows: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """Per method: error statistics over the unambiguous cases with a number, interval coverage,
    confidently wrong answers, refusals, speed."""
    summary = {}
    answered = [row for row in rows if not row.get("refused")]
    decode_total = sum(row["decode_s"] for row in answered)
    for name in analysis.methods():
        clear = [row for row in answered if not row["ambiguous"]]
        results = [row["methods"][name] for row in clear]
        errors_ms = np.abs([m["error_ms"] for m in results])
        errors_frames = np.abs([m["error_frames"] for m in results])
        unlocked = np.abs([row["methods"][name]["error_ms"] for row in clear if not row["phase_locked"]])
        covered = [m["covered"] for m in results if m["covered"] is not None]
        seconds = sum(row["methods"][name]["seconds"] for row in answered)
        summary[name] = {
            "cases": len(rows),
            "refused": len(rows) - len(answered),
            "unambiguous": len(clear),
            "median_abs_error_ms": float(np.median(errors_ms)) if results else None,
            "median_abs_error_frames": float(np.median(errors_frames)) if results else None,
            "worst_abs_error_ms": float(np.max(errors_ms)) if results else None,
            "worst_abs_error_frames": float(np.max(errors_frames)) if results else None,
            "unlocked_median_abs_error_ms": float(np.median(unlocked)) if unlocked.size else None,
            "coverage": float(np.mean(covered)) if covered else None,
            "intervals": len(covered),
            "confidently_wrong": sum(bool(m["confidently_wrong"]) for m in results),
            "analysis_fps": sum(row["frames"] for row in answered) / seconds if seconds else None,
            "speed_ratio": decode_total / seconds if seconds else None,
            "median_speed_ratio": float(np.median([m["speed_ratio"] for m in results])) if results else None,
        }
    return summary


def targets_met(summaries: dict[str, dict[str, dict[str, Any]]]) -> dict[str, bool | None]:
    """The targets for sinefit (and bayes's coverage): accuracy (over all the mixed grid's cases, and
    over those whose camera is not phase-locked to the display), the worst case and speed on the
    mixed grid, as before; coverage and no confidently wrong answer on the whole of both grids."""
    every, mixed = summaries["all"], summaries.get("mixed") or summaries["all"]
    fit, bayes = every["sinefit"], every["bayes"]
    speed = mixed["sinefit"]["speed_ratio"]
    low, high = TARGETS["coverage"]

    def within(value: float | None) -> bool | None:
        return None if value is None else low <= value <= high

    def at_most(value: float | None, limit: float) -> bool | None:
        return None if value is None else value <= limit

    return {
        "sinefit_median_le_0.1_frames": at_most(mixed["sinefit"]["median_abs_error_frames"], TARGETS["median_frames"]),
        "sinefit_worst_le_0.5_frames": at_most(mixed["sinefit"]["worst_abs_error_frames"], TARGETS["worst_frames"]),
        "sinefit_unlocked_median_lt_0.05_ms": at_most(mixed["sinefit"]["unlocked_median_abs_error_ms"], TARGETS["unlocked_median_ms"]),
        "sinefit_coverage_90_98": within(fit["coverage"]),
        "bayes_coverage_90_98": within(bayes["coverage"]),
        "sinefit_no_confidently_wrong": fit["confidently_wrong"] == TARGETS["confidently_wrong"],
        "sinefit_speed_ge_0.8_of_decoding": None if speed is None else speed >= TARGETS["speed_ratio"],
    }


def table(summary: dict[str, dict[str, Any]]) -> str:
    """A summary as a Markdown table (as docs/benchmarks.md shows them)."""

    lines = [
        "| method | median abs error (ms / frames) | worst abs error (ms / frames) | 95% coverage | confidently wrong | "
        "refused | analysis fps | speed vs decoding |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for name, s in summary.items():
        coverage = "-" if s["coverage"] is None else f"{s['coverage']:.0%} of {s['intervals']}"
        lines.append(
            f"| {name} | {cell(s['median_abs_error_ms'], '.3f')} / {cell(s['median_abs_error_frames'], '.3f')} | "
            f"{cell(s['worst_abs_error_ms'], '.3f')} / {cell(s['worst_abs_error_frames'], '.3f')} | {coverage} | "
            f"{s['confidently_wrong']} of {s['unambiguous']} | {s['refused']} | {cell(s['analysis_fps'], '.0f')} | "
            f"x{cell(s['speed_ratio'], '.2f')} |"
        )
    return "\n".join(lines)


def plot(summary: dict[str, dict[str, Any]], rows: list[dict[str, Any]], path: Path) -> None:
    """Speed against error, per method: every case faint, the method's median and worst bold."""
    figure, axes = new_figure((8, 5.5))
    for index, (name, s) in enumerate(summary.items()):
        colour = f"C{index}"
        clear = [row for row in rows if not row.get("refused") and not row["ambiguous"]]
        axes.scatter(
            [row["methods"][name]["speed_ratio"] for row in clear],
            [max(abs(row["methods"][name]["error_frames"]), 1e-4) for row in clear],
            s=10, alpha=0.3, color=colour,
        )  # fmt: skip
        if s["median_abs_error_frames"] is not None and s["speed_ratio"] is not None:
            axes.errorbar(
                [s["speed_ratio"]],
                [s["median_abs_error_frames"]],
                yerr=[[0.0], [s["worst_abs_error_frames"] - s["median_abs_error_frames"]]],
                fmt="o", color=colour, capsize=4, markersize=8,
                label=f"{name}: median {s['median_abs_error_frames']:.3f}, worst {s['worst_abs_error_frames']:.2f} frames",
            )  # fmt: skip
    axes.axhline(TARGETS["median_frames"], color="grey", linestyle=":", linewidth=1)
    axes.axhline(TARGETS["worst_frames"], color="grey", linestyle="--", linewidth=1)
    axes.axvline(TARGETS["speed_ratio"], color="grey", linestyle="-.", linewidth=1)
    axes.set_xscale("log")
    axes.set_yscale("log")
    axes.set_xlabel("analysis speed / decoding speed (same video)")
    axes.set_ylabel("|error| in camera frame intervals")
    axes.set_title(f"rig bench analyser: {len(rows)} simulated videos of known latency")
    axes.legend(loc="lower left", fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=110)


def of_groups(sweep: Sweep, grid: str) -> Sweep:
    """The sweep's points of one of GROUPS (by a point's "group" label; none is "mixed")."""
    return sweep if grid == "all" else sweep.only(lambda labels: labels.get("group", "mixed") in GROUPS[grid])


def run(sweep: Sweep, context: Context) -> dict[str, Any]:
    """The sweep's points run as a sweep into the context's folder (serially or on Dask,
    `rig.executor`), each measured by `measure_point`: the sweep's rows ("sweep", and
    folder/summary.csv), the bench's record of every case in their order ("cases"), the summaries
    per group of cases (GROUPS), the targets and the time taken. On Dask, speed ratios are taken
    with the workers sharing the cores."""
    started = time.perf_counter()
    job = partial(measure_point, log=context.log)
    progress = context.progress("analysing the cases")
    rows, _ = run_sweep(sweep, context.folder, context.workers, context.scheduler, progress, overwrite=True, job=job)
    cases = [row.pop("bench") for row in rows]
    summaries = {
        group: summarise(members)
        for group, member_groups in GROUPS.items()
        if (members := [case for case in cases if group == "all" or case["group"] in member_groups])
    }
    return {"summary": summaries["all"], "summaries": summaries, "targets_met": targets_met(summaries), "cases": cases,
            "sweep": rows, "seconds": time.perf_counter() - started}  # fmt: skip


def tables(report: dict[str, Any]) -> str:
    """Each group's summary as a table under its name and count."""
    return "\n".join(f"{group} ({summary['sinefit']['cases']} cases):\n{table(summary)}" for group, summary in report["summaries"].items())


BENCH = Bench(
    spec=lambda args: of_groups(args.spec, args.grid), read_spec=read_sweep,
    run=run, table=tables,
    targets=lambda report: report["targets_met"],
    all_failed=lambda report: every_one(report["cases"], "refused", "the analyser refused every one of the {count} cases"),
    notes=lambda report: f"{len(report['cases'])} cases in {report['seconds'] / 60:.1f} minutes",
    plot=lambda report, path: plot(report["summary"], report["cases"], path),
)  # fmt: skip
