"""A bench whose every case failed writes what it has (its JSON, its table) and exits with status 2,
its last line on stderr saying so; a case that cannot run is a row with its reason, never the end of
the bench. Commands run in this process through `rig.cli.main`."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Callable

import pytest

from rig.bench import camera_calibration, trackers
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
    failed = trackers.failed_case(trackers.cases(1.0)[0], 1000.0, 2.0, RigError("no pty"))
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
