"""A bench whose every case failed writes what it has (its JSON, its table) and exits with status 2,
its last line on stderr saying so; a case that cannot run is a row with its reason, never the end of
the bench. Commands run in this process through `rig.cli.main`."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace
from typing import Any, Callable

import numpy as np
import pytest

from predictors import PredictorError, Trace, write_trace
from predictors import quaternion as quat
from rig.bench import predictors as predictors_bench
from rig.bench import (
    batch, camera_calibration, live, predictor_scores, renderer_latency, renderer_rows, renderers, seed_table, trackers, warp_variants,
)
from rig.cli import EXIT_USER_ERROR
from rig.errors import RigError


def _assert_exits_2_saying(code: int, err: str, words: str) -> None:
    assert "Traceback" not in err
    assert code == EXIT_USER_ERROR, err
    assert words in err.strip().splitlines()[-1], err


def test_a_tracker_bench_whose_every_emulator_failed_writes_its_rows_and_exits_2(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
) -> None:
    def no_emulator(case: trackers.Case, *_: Any) -> dict[str, Any]:
        raise RigError(f"the tracker emulator did not start ({case.transport})")

    monkeypatch.setattr(trackers, "run_case", no_emulator)
    monkeypatch.setattr(trackers, "wake_floor", lambda *_: 1.0)
    out = tmp_path / "trackers.json"
    code, printed, err = run_rig(["bench", "trackers", "--duration", "0.5", "--json", str(out)], capsys)
    _assert_exits_2_saying(code, err, "every one of the 6 cases failed or recorded nothing (the first: the tracker emulator did not start (pty))")
    rows = json.loads(out.read_text())
    assert [row["failed"] for row in rows] == [f"the tracker emulator did not start ({case.transport})" for case in trackers.cases(0.25)]
    assert "failed: the tracker emulator did not start (lsl)" in printed and ": n/a" in printed


def test_a_tracker_case_that_failed_is_a_row_beside_those_that_ran() -> None:
    ran = {"failed": None, "recorded": 10}
    failed = trackers.case_fields(trackers.cases(1.0)[0], 1000.0, 2.0, "no pty")
    assert trackers.every_case_failed([failed, ran]) is None
    assert trackers.every_case_failed([failed, {"failed": None, "recorded": 0}]) is not None
    assert {name for name, met in trackers.targets([failed]).items() if met is not None} == {"every case ran"}


def test_a_calibration_bench_whose_every_film_was_refused_writes_its_record_and_exits_2(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
) -> None:
    def refused(grid: Any, fps: float, readout_s: float, exposure_s: float, source: str, *_: Any) -> dict[str, Any]:
        return {"source": source, "fps": fps, "readout_ms": readout_s * 1e3, "exposure_ms": exposure_s * 1e3, "duty": 0.5,
                "flash_hz": 30.0, "simulate_s": 0.0, "estimate_s": 0.0, "refused": "no flashing light"}  # fmt: skip

    monkeypatch.setattr(camera_calibration, "case_row", refused)
    out = tmp_path / "calibration.json"
    code, _, err = run_rig(["bench", "camera-calibration", "--quick", "--json", str(out)], capsys)
    _assert_exits_2_saying(code, err, "refused every one of the 4 films (the first: no flashing light)")
    assert [row["refused"] for row in json.loads(out.read_text())["rows"]] == ["no flashing light"] * 4


def test_an_analyser_bench_case_that_cannot_be_filmed_is_refused_and_the_bench_exits_2(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str],
) -> None:
    spec = tmp_path / "unfilmable.toml"
    spec.write_text(
        "[base]\nduration_s = 0.5\ncamera.fps = 60.0\ncamera.impairments.every_nth = 2\n"
        '[[points]]\nlabels = { case = "half the frames", group = "mixed", impairment = "none" }\nseed = 1\n'
    )
    out = tmp_path / "analyser.json"
    code, _, err = run_rig(["bench", "analyser", "--spec", str(spec), "--json", str(out)], capsys)
    _assert_exits_2_saying(code, err, "refused every one of the 1 cases (the first: not simulated: the film would hold 15 frames")
    (case,) = json.loads(out.read_text())["cases"]
    assert (case["case"], case["truth_ms"], case["frames"]) == ("half the frames", None, 0)


def _tiny_trace(folder: Path) -> Path:
    t = np.arange(120) / 60.0
    path = folder / "tiny.csv"
    write_trace(path, Trace.from_samples("tiny", t, np.outer(t, [0.2, 0.0, 0.0]), quat.from_rotation_vector(np.outer(t, [0, 1.0, 0]))))
    return path


def test_a_predictor_bench_whose_every_evaluation_raised_writes_the_failures_and_exits_2(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
) -> None:
    def refuses(name: str, trace: Trace, *_: Any) -> None:
        raise PredictorError(f"{name} cannot score {trace.name}")

    monkeypatch.setattr(predictor_scores, "evaluate", refuses)
    out = tmp_path / "predictors.json"
    trace = _tiny_trace(tmp_path)
    code, printed, err = run_rig(["bench", "predictors", "--trace", str(trace), "--predictor", "hold", "--horizons-ms", "0,50",
                                  "--json", str(out), "--plot", str(tmp_path / "predictors.png")], capsys)  # fmt: skip
    _assert_exits_2_saying(code, err, "every one of the 2 evaluations failed (the first: hold on tiny: hold cannot score tiny)")
    assert json.loads(out.read_text())["failed"] == [
        {"trace": "tiny", "predictor": name, "failed": f"{name} cannot score tiny"} for name in ("hold", "slerp")
    ]
    assert "| tiny | slerp | failed: slerp cannot score tiny |" in printed
    assert (tmp_path / "predictors.png").stat().st_size > 0


def test_a_predictor_bench_refuses_a_parameter_out_of_range_before_any_evaluation(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
) -> None:
    evaluated: list[str] = []
    monkeypatch.setattr(predictor_scores, "evaluate", lambda name, *_: evaluated.append(name))
    code, _, err = run_rig(["bench", "predictors", "--trace", str(_tiny_trace(tmp_path)), "--predictor", "desp:position_alpha=7"], capsys)
    _assert_exits_2_saying(code, err, "desp: position_alpha must be a positive number below 1, got 7")
    assert evaluated == []


def test_a_predictor_that_fails_on_a_trace_is_a_row_beside_the_scores_of_the_others(tmp_path: Path) -> None:
    t = np.arange(120) / 60.0
    trace = Trace.from_samples("tiny", t, np.outer(t, [0.2, 0.0, 0.0]), quat.from_rotation_vector(np.outer(t, [0, 1.0, 0])))
    failures: list[predictor_scores.FailedEvaluation] = []
    results = predictor_scores.evaluate_all([trace], [("slerp", {}), ("desp", {"position_alpha": 7.0})], [50.0], 0, failures=failures)
    assert [r.predictor for r in results] == ["slerp"]
    ((failure),) = failures
    assert (failure.predictor, failure.trace) == ("desp:position_alpha=7", "tiny") and "position_alpha" in failure.failed
    with pytest.raises(PredictorError):
        predictor_scores.evaluate_all([trace], [("desp", {"position_alpha": 7.0})], [50.0], 0)


def test_a_renderer_bench_whose_every_load_cannot_be_drawn_writes_failed_rows_and_exits_2(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
) -> None:
    def undrawable(width: int, height: int, triangles: int, *_: Any) -> None:
        raise RigError(f"{triangles} triangles are more than this GPU draws")

    monkeypatch.setattr(renderers, "scene_setup", undrawable)
    out, plot = tmp_path / "renderers.json", tmp_path / "renderers.png"
    code, printed, err = run_rig(["bench", "renderers", "--quick", "--json", str(out), "--plot", str(plot)], capsys)
    _assert_exits_2_saying(code, err, "every one of the 6 rows failed (the first: direct on 1000 triangles: 1000 triangles are more than")
    rows = json.loads(out.read_text())
    assert [(r["renderer"], r["rate_ratio"], r["failed"]) for r in rows] == [
        (renderer, ratio, f"{n} triangles are more than this GPU draws") for n in (1000, 8000)
        for renderer, ratio in (("direct", None), ("warp", 1), ("warp", 3))
    ]  # fmt: skip
    assert all(r["frames_timed"] is None and r["latency_measured_ms"] is None for r in rows)
    assert "warp          8000 160x120    1:3 failed: 8000 triangles are more than this GPU draws" in printed
    assert plot.stat().st_size > 0


def test_a_renderer_bench_whose_every_latency_film_failed_keeps_its_timings_and_exits_2(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
) -> None:
    def unfilmable(point: Any) -> None:
        raise RigError(f"no film at {point.config.scene_triangles} triangles")

    monkeypatch.setattr(renderer_latency, "simulate_and_analyse", unfilmable)
    out = tmp_path / "renderers.json"
    code, printed, err = run_rig(["bench", "renderers", "--quick", "--triangles", "1000", "--json", str(out)], capsys)
    _assert_exits_2_saying(code, err, "every one of the 3 rows failed (the first: direct on 1000 triangles: not simulated: no film at 1000")
    rows = json.loads(out.read_text())
    assert [r["failed"] for r in rows] == ["not simulated: no film at 1000 triangles"] * 3
    assert all(r["frame_ms_median"] > 0 and r["latency_measured_ms"] is None for r in rows)
    assert "failed: the latency film of warp on 1000 triangles: not simulated: no film at 1000 triangles" in printed


def test_a_renderer_bench_with_one_film_failed_exits_0_with_that_row_failed() -> None:
    rows = [{"renderer": "direct", "triangles": 10, "failed": "the analyser failed: no swing"}, {"renderer": "warp", "triangles": 10, "failed": None}]
    assert renderer_rows.every_row_failed(rows) is None
    assert renderer_rows.every_row_failed(rows[:1]) == "every one of the 1 rows failed (the first: direct on 10 triangles: the analyser failed: no swing)"


def test_a_live_bench_that_could_make_neither_measurement_writes_both_reasons_and_exits_2(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
) -> None:
    def no_window(*_: Any) -> None:
        raise RigError("cannot open a window (no display)")

    def no_tracker(*_: Any) -> None:
        raise RigError("no tracker sample arrived")

    monkeypatch.setattr(live, "live_run", no_tracker)
    monkeypatch.setattr(live, "swap_to_log", no_window)
    out, plot = tmp_path / "live.json", tmp_path / "live.png"
    code, printed, err = run_rig(["bench", "live", "--duration", "1", "--json", str(out), "--plot", str(plot)], capsys)
    _assert_exits_2_saying(code, err, "every measurement failed (the live run: no tracker sample arrived; the swaps: cannot open a window")
    report = json.loads(out.read_text())
    assert [report[key]["failed"] for key, _ in live.MEASURED] == ["no tracker sample arrived"] * 2 + ["cannot open a window (no display)"]
    assert "swap to logged              failed: cannot open a window (no display)" in printed
    assert plot.stat().st_size > 0


def test_a_live_bench_that_failed_alike_twice_says_why_once() -> None:
    reason = {"failed": "cannot open a window (no display)"}
    report = {"arrival_to_pose": reason, "frame_start_to_pose": reason, "swap_to_log": reason}
    assert live.every_measurement_failed(report) == "every measurement failed: cannot open a window (no display)"


def test_a_live_bench_whose_swaps_failed_keeps_the_live_run_and_exits_0(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
) -> None:
    figures = {"count": 60, "median_us": 9000.0, "p95_us": 16000.0, "max_us": 17500.0}

    def no_swaps(*_: Any) -> None:
        raise RigError("no swap was recorded")

    monkeypatch.setattr(live, "live_run", lambda *_: {"arrival_to_pose": figures, "frame_start_to_pose": figures})
    monkeypatch.setattr(live, "swap_to_log", no_swaps)
    code, printed, err = run_rig(["bench", "live", "--duration", "1", "--plot", str(tmp_path / "live.png")], capsys)
    assert code == 0, err
    assert "swap to logged              failed: no swap was recorded" in printed and "9000" in printed


def test_a_live_run_that_timed_nothing_is_refused_with_what_was_missing(tmp_path: Path) -> None:
    (tmp_path / "tracker.csv").write_text("t_sensor,t_arrival\n")
    (tmp_path / "published_poses.csv").write_text("frame,t_pose,t_sensor\n")
    (tmp_path / "app_frames.csv").write_text("index,t_start\n")
    with pytest.raises(RigError, match="no pose with its sample's arrival was recorded"):
        live.arrival_to_pose(tmp_path)


def test_a_batch_bench_whose_runs_all_failed_writes_both_reasons_and_exits_2(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
) -> None:
    def simulated(config: Any, folder: Path, **_: Any) -> Any:
        return SimpleNamespace(video_path=folder / "video.avi")

    def worker_died(arguments: list[str], *_: Any, **__: Any) -> float:
        raise RigError(f"{Path(arguments[0]).name} exited -9: a worker died")

    monkeypatch.setattr(batch, "simulate", simulated)
    monkeypatch.setattr(batch, "_process_seconds", worker_died)
    out, plot = tmp_path / "batch.json", tmp_path / "batch.png"
    code, printed, err = run_rig(["bench", "batch", "--videos", "2", "--json", str(out), "--plot", str(plot)], capsys)
    _assert_exits_2_saying(code, err, "every part failed (the batch: rig exited -9: a worker died; the clip: ")
    report = json.loads(out.read_text())
    assert report["scale_out"] == {"failed": "rig exited -9: a worker died"} and "exited -9" in report["fixed_cost"]["failed"]
    assert report["unsimulated"] == []
    assert "batch: failed: rig exited -9: a worker died" in printed and plot.stat().st_size > 0


def test_a_batch_bench_whose_videos_cannot_be_simulated_says_why_each_was_left_out_and_exits_2(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
) -> None:
    def unsimulable(config: Any, folder: Path, **_: Any) -> None:
        raise RigError(f"cannot write {folder.name}")

    monkeypatch.setattr(batch, "simulate", unsimulable)
    out = tmp_path / "batch.json"
    code, printed, err = run_rig(["bench", "batch", "--videos", "2", "--json", str(out)], capsys)
    _assert_exits_2_saying(code, err, "every part failed (the batch: no video of the batch could be simulated; the clip: cannot write clip)")
    assert json.loads(out.read_text())["unsimulated"] == [{"video": 0, "failed": "cannot write video00"}, {"video": 1, "failed": "cannot write video01"}]
    assert "video 1 not simulated: cannot write video01" in printed


def test_a_batch_bench_with_one_part_failed_exits_0_and_shows_the_other(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
) -> None:
    clip = {"clip": "clip.avi", "decode_s": 1.0, "analyse_cold_cache_s": 3.0, "analyse_warm_cache_s": 2.0, "ratio_cold": 3.0, "ratio_warm": 2.0}
    monkeypatch.setattr(batch, "videos", lambda *_: ([], []))
    monkeypatch.setattr(batch, "clip_cost", lambda *_: clip)
    code, printed, err = run_rig(["bench", "batch", "--videos", "2", "--plot", str(tmp_path / "batch.png")], capsys)
    assert code == 0, err
    assert "batch: failed: no video of the batch could be simulated" in printed and "analyse / decode alone = 3.00" in printed


@pytest.mark.parametrize(("mode", "rows"), [(["--photon-residual", "--residual-predictor", "hold"], 2), (["--variants"], 2), (["--seed-table"], 2)])
def test_a_renderer_mode_whose_every_film_failed_writes_its_rows_and_exits_2(
    mode: list[str], rows: int,
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
) -> None:  # fmt: skip
    def unfilmable(point: Any) -> None:
        raise RigError("the film would hold too few frames")

    monkeypatch.setattr(renderer_latency, "simulate_and_analyse", unfilmable)
    monkeypatch.setattr(seed_table.SeedTableSpec, "sizes", lambda self: [1000])
    out, plot = tmp_path / "mode.json", tmp_path / "mode.png"
    code, printed, err = run_rig(["bench", "renderers", "--quick", *mode, "--json", str(out), "--plot", str(plot)], capsys)
    _assert_exits_2_saying(code, err, f"every one of the {rows} rows failed (the first: ")
    mine = [r for r in json.loads(out.read_text()) if r.get("source", "this machine") == "this machine"]
    assert [r["failed"] for r in mine] == ["not simulated: the film would hold too few frames"] * rows
    assert "failed: " in printed and "not simulated: the film would hold too few frames" in printed


@pytest.mark.parametrize(("mode", "refusal"), [
    (["--warp", "warp:bogus=1"], "renderer 'warp' has no option 'bogus'"),
    (["--variants", "--variant", "warp", "--variant", "warp:bogus=1"], "renderer 'warp' has no option 'bogus'"),
    (["--predictor", "bogus"], "unknown predictor 'bogus'"),
    (["--direct-predictor", "bogus"], "unknown predictor 'bogus'"),
    (["--seed-table", "--predictor", "bogus"], "unknown predictor 'bogus'"),
    (["--variants", "--predictor", "bogus"], "unknown predictor 'bogus'"),
    (["--photon-residual", "--residual-predictor", "bogus"], "unknown predictor 'bogus'"),
])  # fmt: skip
def test_a_renderer_bench_refuses_a_warp_or_predictor_it_cannot_make_before_any_timing(
    mode: list[str], refusal: str, run_rig: Callable[..., tuple[int, str, str]], capsys: pytest.CaptureFixture[str],
) -> None:
    code, _, err = run_rig(["bench", "renderers", "--quick", *mode], capsys)
    _assert_exits_2_saying(code, err, refusal)
    assert err.strip().count("\n") == 0, err


def test_a_seed_table_whose_first_load_cannot_be_drawn_stops_there_with_failed_rows_and_exits_2(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
) -> None:
    def undrawable(width: int, height: int, triangles: int, *_: Any) -> None:
        raise RigError(f"{triangles} triangles are more than this GPU draws")

    monkeypatch.setattr(seed_table, "scene_setup", undrawable)
    out, plot = tmp_path / "seed.json", tmp_path / "seed.png"
    code, printed, err = run_rig(["bench", "renderers", "--quick", "--seed-table", "--json", str(out), "--plot", str(plot)], capsys)
    _assert_exits_2_saying(code, err, "every one of the 2 rows failed (the first: direct on 1000 triangles: not timed: 1000 triangles are more")
    mine = [r for r in json.loads(out.read_text()) if r["source"] == "this machine"]
    assert [(r["renderer"], r["triangles"], r["failed"]) for r in mine] == [
        (renderer, 1000, "not timed: 1000 triangles are more than this GPU draws") for renderer in ("direct", "warp")
    ]
    assert "failed: warp on 1000 triangles: not timed: 1000 triangles are more than this GPU draws" in printed
    assert plot.stat().st_size > 0


def test_a_warp_variant_that_cannot_be_opened_is_a_failed_row_beside_the_others(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
) -> None:
    opened = warp_variants.open_warp

    def two_views_refused(variant: str, *args: Any) -> Any:
        if "views=2" in variant:
            raise RigError("two views need more texture memory than this GPU has")
        return opened(variant, *args)

    monkeypatch.setattr(warp_variants, "open_warp", two_views_refused)
    monkeypatch.setattr(warp_variants, "film_latency", lambda run, *_: renderer_latency.failed_figures(run.config, "not filmed here"))
    out, plot = tmp_path / "variants.json", tmp_path / "variants.png"
    code, printed, err = run_rig(["bench", "renderers", "--quick", "--variants", "--json", str(out), "--plot", str(plot)], capsys)
    _assert_exits_2_saying(code, err, "every one of the 2 rows failed")
    warp, two_views = json.loads(out.read_text())
    assert (warp["failed"], warp["ssim"] > 0.9) == ("not filmed here", True)
    assert (two_views["failed"], two_views["ssim"]) == ("not timed: two views need more texture memory than this GPU has", None)
    assert "warp:views=2,recon=grid,holes=1" in printed and "failed: not timed: two views need more texture memory" in printed
    assert plot.stat().st_size > 0


def test_a_leave_one_out_fold_that_raises_is_a_failed_row_beside_the_others(monkeypatch: pytest.MonkeyPatch) -> None:
    def fold(name: str, trace: Trace, *_: Any) -> predictor_scores.HeldOut:
        if trace.name == "b":
            raise PredictorError("the fit diverged")
        return predictor_scores.HeldOut(name, trace.name, 50.0, {"position_alpha": 0.5}, 0.9, 0.8, 1.0, 1.0)

    monkeypatch.setattr(predictor_scores, "_held_out", fold)
    t = np.arange(120) / 60.0
    traces = [Trace.from_samples(name, t, np.outer(t, [0.2, 0.0, 0.0]), quat.from_rotation_vector(np.outer(t, [0, 1.0, 0]))) for name in "abc"]
    held = predictor_scores.leave_one_out("desp", traces, 50.0, 5)
    assert [(h.trace, h.failed) for h in held] == [("a", None), ("b", "the fit diverged"), ("c", None)]
    assert held[1].to_dict()["angular"] is None
    table = predictors_bench.held_out_table(held).splitlines()
    assert table[3] == "| desp | b | 50 ms | failed: the fit diverged | |" and table[2].startswith("| desp | a | 50 ms | 0.900, 0.800 |")
