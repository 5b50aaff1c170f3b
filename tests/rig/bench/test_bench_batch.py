"""`rig bench batch`: its table and plot from a report (the bench itself is a command, not a test)."""

from pathlib import Path

from rig.bench import batch

REPORT = {
    "scale_out": {
        "videos": 24, "workers": 2, "serial_s": 120.0, "dask_s": 66.0, "speed_up": 120.0 / 66.0,
        "one_video_serial_s": 5.0, "one_video_dask_s": 7.5, "dask_overhead_s": 2.5,
    },
    "fixed_cost": {
        "clip": "clip.avi", "decode_s": 2.0, "analyse_cold_cache_s": 6.0, "analyse_warm_cache_s": 4.0,
        "ratio_cold": 3.0, "ratio_warm": 2.0,
    },
}  # fmt: skip


def test_the_table_states_the_speed_up_the_overhead_and_the_fixed_cost_ratios() -> None:
    text = batch.table(REPORT)
    assert "speed-up 1.82" in text
    assert "Dask overhead for one video: +2.5 s" in text
    assert "= 3.00 (empty cache), 2.00 (filled cache)" in text


def test_the_plot_is_written(tmp_path: Path) -> None:
    batch.plot(REPORT, tmp_path / "batch.png")
    assert (tmp_path / "batch.png").stat().st_size > 10_000
