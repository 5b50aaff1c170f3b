"""`rig bench batch`: its table and plot from a report (the bench itself is a command, not a test)."""

from pathlib import Path

from rig.bench import batch

REPORT = {
    "scale_out": {
        "videos": 24, "workers": 2, "rounds": 3, "serial_s": 120.0, "dask_s": 66.0, "speed_up": 120.0 / 66.0,
        "speed_up_per_round": [1.5, 1.8, 1.9], "worker_opencv_threads": 1, "serial_as_worker_s": 140.0,
        "ceiling_speed_up": 2 * 120.0 / 140.0,
        "one_video_serial_s": 5.0, "one_video_dask_s": 7.5, "dask_overhead_s": 2.5,
    },
    "fixed_cost": {
        "clip": "clip.avi", "decode_s": 2.0, "analyse_cold_cache_s": 6.0, "analyse_warm_cache_s": 4.0,
        "ratio_cold": 3.0, "ratio_warm": 2.0,
    },
}  # fmt: skip


def test_the_table_states_the_speed_up_the_overhead_and_the_fixed_cost_ratios() -> None:
    text = batch.table(REPORT)
    assert "(median of 3 rounds)" in text and "speed-up 1.82 (rounds: 1.50, 1.80, 1.90)" in text
    assert "ceiling: serially with a worker's threads (OpenCV 1) 140.0 s, so 2 workers can be at most 1.71 times" in text
    assert "Dask overhead for one video: +2.5 s" in text
    assert "= 3.00 (empty cache), 2.00 (filled cache)" in text


def test_the_plot_is_written(tmp_path: Path) -> None:
    batch.plot(REPORT, tmp_path / "batch.png")
    assert (tmp_path / "batch.png").stat().st_size > 10_000


def test_the_scale_out_alternates_serial_and_dask_runs_and_reports_medians(monkeypatch) -> None:
    """A drifting load hits serial and Dask rounds alike when they alternate."""
    calls = []
    times = iter([1.0, 10.0, 6.0, 11.0, 1.0, 3.0, 12.0, 7.0, 15.0, 1.5, 4.0, 14.0, 9.0, 16.0, 2.0, 5.0])
    as_worker = {"OPENCV_FOR_THREADS_NUM": "1", "OPENBLAS_NUM_THREADS": "1"}
    monkeypatch.setattr(batch, "worker_environment", lambda workers: as_worker)

    def fake_batch_seconds(videos, workers, environment=None):
        calls.append((len(videos), workers, environment))
        return next(times)

    monkeypatch.setattr(batch, "batch_seconds", fake_batch_seconds)
    report = batch.scale_out([Path(f"v{i}.avi") for i in range(4)], 2, 3, lambda message: None)
    assert calls == [(1, None, None)] + [(4, None, None), (4, 2, None), (4, None, as_worker), (1, None, None), (1, 2, None)] * 3
    assert report["serial_s"] == 12.0 and report["dask_s"] == 7.0 and report["speed_up"] == 12.0 / 7.0
    assert report["speed_up_per_round"] == [10 / 6, 12 / 7, 14 / 9]
    assert report["serial_as_worker_s"] == 15.0 and report["ceiling_speed_up"] == 2 * 12.0 / 15.0
    assert report["worker_opencv_threads"] == 1
    assert report["one_video_serial_s"] == 1.5 and report["dask_overhead_s"] == 4.0 - 1.5
