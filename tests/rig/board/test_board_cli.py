"""`rig board ...` as the command line sees it (tests/firmware/test_emulated_board.py runs it
against the emulated board)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pytest

from analysis.errors import AnalysisError
from rig.board import BoardRecorder, EncoderEdge, PhotodiodePassage
from rig.board.protocol import protocol
from rig.commands import board as board_commands
from rig.commands.board import PORT_VARIABLE, add_parser
from rig.errors import RigError


def parse(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="rig")
    add_parser(parser.add_subparsers(dest="command", required=True))
    return parser.parse_args(list(argv))


def write_recording(out: Path, recording) -> None:
    """A `rig board record` folder holding a synthetic recording."""
    hz = protocol()["RIG_TICK_HZ"]
    recorder = BoardRecorder(out)
    for t, count, step in zip(recording.edge_times, recording.counts, recording.steps):
        recorder.on_event(EncoderEdge(round(t * hz), round(t * hz) / hz, t, int(count), int(step), 1))
    for t, duration in zip(recording.centroids, recording.durations):
        tick = round(t * hz)
        recorder.on_event(PhotodiodePassage(tick, tick / hz, t, tick - round(duration * hz / 2), tick + round(duration * hz / 2), 800))
    recorder.close()


@pytest.mark.parametrize("command", ["info", "sync", "record", "blink", "latency"])
def test_every_board_command_has_a_handler(command: str) -> None:
    argv = {"record": ["--out=x", "--duration=1"], "latency": ["somewhere"]}.get(command, [])
    args = parse("board", command, *argv)
    assert args.func is getattr(board_commands, f"run_{command}")


def test_a_command_without_a_port_says_how_to_give_one(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(PORT_VARIABLE, raising=False)
    args = parse("board", "info")
    with pytest.raises(RigError, match=f"--port.*{PORT_VARIABLE}"):
        args.func(args)


def test_the_port_can_come_from_the_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(PORT_VARIABLE, "/dev/ttyACM7")
    assert parse("board", "sync").port == "/dev/ttyACM7"


def test_record_refuses_a_folder_with_a_recording_before_touching_the_board(tmp_path: Path) -> None:
    BoardRecorder(tmp_path).close()
    args = parse("board", "record", "--port=loop://", f"--out={tmp_path}", "--duration=1")
    with pytest.raises(RigError, match="already holds"):
        args.func(args)


def test_bad_option_values_are_rejected_by_the_parser() -> None:
    for argv in (["record", "--out=x", "--duration=0"], ["blink", "--bit-ms=-5"], ["sync", "--round-trips=x"]):
        with pytest.raises(SystemExit):
            parse("board", *argv)


def test_latency_of_a_recording(tmp_path: Path, synthetic_recording, capsys: pytest.CaptureFixture[str]) -> None:
    write_recording(tmp_path / "run", synthetic_recording(0.0237))
    args = parse("board", "latency", str(tmp_path / "run"))
    assert args.func(args) == 0
    assert "board latency 23.70" in capsys.readouterr().out
    args = parse("board", "latency", str(tmp_path / "run"), "--json", "--max-latency-ms=100", f"--plot={tmp_path / 'fit.png'}")
    assert args.func(args) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["latency_s"] == pytest.approx(0.0237, abs=20e-6) and result["max_latency_s"] == 0.1
    assert (tmp_path / "fit.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_latency_of_a_folder_that_is_no_recording(tmp_path: Path) -> None:
    args = parse("board", "latency", str(tmp_path))
    with pytest.raises(AnalysisError, match="encoder.csv"):
        args.func(args)
