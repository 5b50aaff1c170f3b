"""`rig simulate --release-s S --board`: a lab's run from the command line, and its bad options."""

import json
from pathlib import Path

import numpy as np
import pytest

from analysis.board.recording import load_table
from rig.cli import main


def test_a_held_release_and_a_board_from_the_command_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["simulate", "--out", str(tmp_path), "--duration", "4", "--camera-fps", "60", "--release-s", "2.5", "--board", "--json"])
    assert code == 0
    assert json.loads(capsys.readouterr().out)["frames"] == 239
    truth = json.loads((tmp_path / "truth.json").read_text())
    assert truth["board"]["release_s"] == 2.5
    assert truth["board"]["blink"]["bits"] == 64
    assert truth["config"]["pendulum"]["release_s"] == 2.5
    encoder = load_table(tmp_path / "board", "encoder.csv")
    assert encoder["rig_time_s"].min() > 2.5
    led = load_table(tmp_path / "board", "led.csv")
    np.testing.assert_allclose(led["board_time_s"] - led["rig_time_s"], truth["board"]["offset_s"], atol=1e-6)
    assert (tmp_path / "board" / "recording.json").exists()


def test_help_explains_the_lab_options(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["simulate", "--help"])
    text = capsys.readouterr().out
    assert "--release-s S" in text and "--board" in text and "blink" in text


@pytest.mark.parametrize(
    "arguments, message",
    [
        (["--duration", "3", "--release-s", "2.5"], "release at 2.5 s must fall within the filmed span"),
        (["--duration", "2", "--board"], "must fall within the filmed span"),
    ],
)
def test_a_release_or_blink_the_film_cannot_hold_is_a_one_line_error(
    arguments: list[str], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["simulate", "--out", str(tmp_path / "x"), *arguments]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert message in err
    assert not (tmp_path / "x").exists()


def test_a_negative_release_is_rejected_by_the_parser(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["simulate", "--out", str(tmp_path / "x"), "--release-s", "-1"])
    assert exit_.value.code == 2
    assert "--release-s" in capsys.readouterr().err
