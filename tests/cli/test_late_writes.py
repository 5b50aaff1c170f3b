"""A write that fails after the work (a full disk, a folder taken away meanwhile) keeps the result
and the other outputs, and ends in one line, exit status 2; a fault of the rig's own keeps its
traceback and says to report it."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from rig.cli import EXIT_FAULT, EXIT_USER_ERROR, REPORT_A_FAULT, main
from rig.commands import outputs
from rig.errors import RigError
from rig.service.tune import TuneReport


def _no_space(*args: object, **kwargs: object) -> None:
    raise OSError(28, "No space left on device")


def _one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


def test_late_writes_go_on_past_a_failure_and_name_it(tmp_path: Path) -> None:
    writes = outputs.LateWrites()
    writes.write(tmp_path / "a.png", _no_space)
    writes.json(tmp_path / "b.json", {"kept": True})
    assert json.loads((tmp_path / "b.json").read_text()) == {"kept": True}
    with pytest.raises(RigError, match=r"cannot write .*a\.png \(No space left on device\)"):
        writes.check()


def test_late_csv_has_a_column_per_field_in_first_seen_order_and_notes_a_failure(tmp_path: Path) -> None:
    writes = outputs.LateWrites()
    writes.csv(tmp_path / "rows.csv", [{"a": 1, "b": None}, {"c": 2.5, "a": 3}])
    assert (tmp_path / "rows.csv").read_text().splitlines() == ["a,b,c", "1,,", "3,,2.5"]
    writes.csv(tmp_path / "gone" / "rows.csv", [{"a": 1}])
    with pytest.raises(RigError, match=r"cannot write .*gone/rows\.csv \(No such file or directory\)"):
        writes.check()


def test_simulate_keeps_its_run_and_prints_it_when_the_plot_fails(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr("rig.service.run_plot.plot_run", _no_space)
    code = main(["simulate", "--out", str(tmp_path / "run"), "--duration", "1", "--plot", str(tmp_path / "truth.png")])
    out, err = capsys.readouterr()
    assert code == EXIT_USER_ERROR
    assert "true latency" in out
    assert "truth.png" in _one_line(err) and "No space left" in err
    assert {"video.avi", "truth.json", "tracker.csv"} <= {path.name for path in (tmp_path / "run").iterdir()}


def test_tune_prints_its_report_when_the_parameters_cannot_be_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    trace = tmp_path / "head.csv"
    rows = "".join(f"{i / 100!r},{0.1 * math.sin(i / 50)},0,0,{math.cos(0.2 * math.sin(i / 40))!r},0,"
                   f"{math.sin(0.2 * math.sin(i / 40))!r},0\n" for i in range(1500))  # fmt: skip
    trace.write_text("t,px,py,pz,qw,qx,qy,qz\n" + rows)
    monkeypatch.setattr(TuneReport, "write", _no_space)
    out_file = tmp_path / "params.json"
    code = main(["tune", "kalman-cv", "--trace", str(trace), "--horizon-ms", "20", "--max-iterations", "3",
                 "--force", "--json", "--out", str(out_file)])  # fmt: skip
    out, err = capsys.readouterr()
    assert code == EXIT_USER_ERROR
    report = json.loads(out)
    assert report["written"] is False and "errors" in report
    assert "params.json" in err.strip().splitlines()[-1] and "Traceback" not in err
    assert not out_file.exists()


def test_a_fault_of_our_own_keeps_its_traceback_and_says_to_report_it() -> None:
    program = (
        "import sys, rig.devices.trackers.discovery as discovery\n"
        "discovery.serial_ports = lambda: 1 / 0\n"
        "sys.argv = ['rig', 'devices', '--lsl-wait', '0']\n"
        "from rig.cli import run\n"
        "run()\n"
    )
    done = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True, timeout=120)
    assert done.returncode == EXIT_FAULT
    assert "Traceback" in done.stderr and "ZeroDivisionError" in done.stderr
    assert done.stderr.strip().splitlines()[-1] == f"rig: {REPORT_A_FAULT}"
