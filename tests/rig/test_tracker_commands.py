"""`rig record-tracker`, `rig devices` and `rig emulate-tracker` from the command line: bad input is one
line and exit status 2; a recording feeds `rig bench predictors --trace` and `rig tune` unchanged."""

from __future__ import annotations

import json
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from rig.cli import main
from rig.devices.trackers.serial_tracker import DEFAULT_PROFILE
from rig.service.tracker_recording import record_tracker


@pytest.mark.parametrize(
    "spec, message",
    [
        ("nosuch:x", "unknown tracker 'nosuch'"),
        ("serial:/dev/no-such-tracker", "no serial port /dev/no-such-tracker"),
        ("serial:loop://?profile=missing", "no tracker profile 'missing'"),
        ("serial:loop://?baud=fast", "baud='fast'"),
        ("hid:zz:1", "hex"),
        ("lsl:", "stream's name"),
        ("sim", "only in a simulated run"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str], spec: str, message: str) -> None:
    assert main(["record-tracker", "--tracker", spec, "--duration", "1", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0] and err[0].startswith("rig record-tracker: error:")


def test_a_bad_profile_file_is_one_line_and_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    profile = tmp_path / "lab.toml"
    profile.write_text('format = "text"\nfields = ["px", "py", "pz"]\n')
    assert main(["record-tracker", "--tracker", f"serial:loop://?profile={profile}", "--out", str(tmp_path / "out")]) == 2
    assert "need an orientation" in capsys.readouterr().err


def test_a_tracker_that_sends_nothing_is_a_failed_recording_that_leaves_nothing(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    assert main(["record-tracker", "--tracker", "serial:loop://", "--duration", "0.3", "--out", str(out)]) == 2
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert len(err.splitlines()) == 1 and "no sample arrived from serial:loop://" in err
    assert "received 0" in captured.out and "wrote" not in captured.out
    assert not out.exists()


def test_a_recording_ends_when_told_to_before_its_duration(tmp_path: Path) -> None:
    recording = record_tracker("serial:loop://", 600.0, tmp_path / "out", until=lambda: True)
    assert recording.samples == 0 and recording.sidecar["partial"] is False


def test_emulator_faults_are_checked(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit:
        main(["emulate-tracker", "serial", "--tcp", "0", "--faults", "corrupt=2"])
    assert exit.value.code == 2 and "probability" in capsys.readouterr().err


def test_an_emulator_with_no_reader_ends_after_its_idle_timeout() -> None:
    done = subprocess.run([sys.executable, "-m", "rig.cli", "emulate-tracker", "serial", "--tcp", "0", "--idle-timeout", "0.2",
                           "--rate", "10", "--duration", "1"], capture_output=True, text=True, timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "no reader came in 0.2 s; nothing sent" in done.stderr and "sent 0," in done.stdout


@pytest.mark.slow
def test_a_recording_with_the_default_profiles_feeds_the_predictor_bench_and_tuning(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    link = tmp_path / "tracker"
    emulator = threading.Thread(
        target=main,
        args=(["emulate-tracker", "serial", "--pty", str(link), "--rate", "200", "--duration", "3", "--log", str(tmp_path / "sent.csv")],),
    )
    emulator.start()
    try:
        while not link.exists():
            threading.Event().wait(0.01)
        out = tmp_path / "recording"
        assert main(["record-tracker", "--tracker", f"serial:{link}", "--duration", "5", "--out", str(out), "--json"]) == 0
    finally:
        emulator.join()
    sidecar = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert sidecar["samples"] == 600 and sidecar["counters"]["corrupt"] == 0
    assert sidecar["profile"]["name"] == DEFAULT_PROFILE and sidecar["clock_mapping"]["kind"] == "one-way"
    assert json.loads((out / "tracker.json").read_text())["samples"] == 600
    assert main(["bench", "predictors", "--trace", str(out / "tracker.csv"), "--predictor", "hold", "--horizons-ms", "0,10",
                 "--plot-horizon-ms", "10", "--timing-repeats", "0"]) == 0  # fmt: skip
    assert main(["tune", "desp", "--trace", str(out / "tracker.csv"), "--horizon-ms", "10", "--max-iterations", "2",
                 "--out", str(tmp_path / "desp.json")]) == 0  # fmt: skip


def test_devices_lists_what_it_sees_as_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["devices", "--json", "--lsl-wait", "0.2"]) == 0
    found = json.loads(capsys.readouterr().out)
    assert set(found) == {"serial", "hid", "lsl"}
    assert all(device["spec"].startswith(kind + ":") for kind, devices in found.items() for device in devices)
