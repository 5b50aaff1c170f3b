"""The camera-calibration bench's parts on small cases: a row's error is the answer against the
simulated camera, and the summary and targets count what the rows say."""

from __future__ import annotations

from pathlib import Path

import pytest

from rig.bench import camera_calibration as bench

SMALL = bench.CalibrationGrid(width=160, height=120)


def test_a_light_case_scores_the_answer_against_the_simulated_camera(tmp_path: Path) -> None:
    row = bench.case_row(SMALL, 120.0, 6e-3, 2e-3, "light-25", 3, tmp_path)
    assert row["refused"] is None and row["duty"] == 0.25
    assert row["readout_error_ms"] == pytest.approx(row["measured_readout_ms"] - 6.0)
    assert abs(row["readout_error_pct"]) < 5 and abs(row["exposure_error_pct"]) < 10
    assert row["readout_within"] and row["exposure_within"] and row["readout_covered"] and row["exposure_covered"]


def test_a_global_shutter_is_within_when_it_reads_zero(tmp_path: Path) -> None:
    row = bench.case_row(SMALL, 120.0, 0.0, 2e-3, "light", 4, tmp_path)
    assert row["global_shutter"] and row["readout_within"] and row["readout_error_pct"] is None


def rows_of(*kinds: str) -> list[dict]:
    answered = {"refused": None, "readout_error_pct": 1.0, "exposure_error_pct": -2.0, "readout_within": True,
                "exposure_within": True, "readout_covered": True, "exposure_covered": True, "estimate_s": 0.5}  # fmt: skip
    made = {"good": answered, "wide": answered | {"readout_error_pct": 8.0, "readout_within": False},
            "missed": answered | {"exposure_covered": False}, "refused": {"refused": "no", "estimate_s": 0.1}}  # fmt: skip
    return [{"source": "light", **made[kind]} for kind in kinds]


def test_the_summary_and_the_targets_count_the_rows(tmp_path: Path) -> None:
    found = rows_of("good", "wide", "missed", "refused")
    light = bench.summary(found)["light"]
    assert (light["cases"], light["refused"], light["within_targets"], light["covered"]) == (4, 1, 2, 2)
    assert light["readout_error_pct_max"] == 8.0 and light["exposure_error_pct_median"] == 2.0
    assert bench.targets_met(rows_of("good", "refused")) == dict.fromkeys(bench.targets_met([]), True)
    assert not any(bench.targets_met(rows_of("wide", "missed")).values())
    assert "light" in bench.table({"rows": found})
    bench.plot({"rows": found}, tmp_path / "camera.png")
    assert (tmp_path / "camera.png").stat().st_size > 0
