"""`rig analyse`: one line or JSON on stdout, tracks CSV and plot files; exit status 0 for a clean
result, 3 for one with warnings, 2 on bad input."""

import csv
import json

import cv2
import pytest

from analysis import MethodResult, register_estimator, unregister_estimator
from rig.cli import main


# The clip's camera (120 fps, exposing whole frames, a global shutter) and display (60 Hz), as a lab
# that knows them says.
KNOWN = ["--display-hz", "60", "--exposure-ms", f"{1e3 / 120.0}", "--readout-ms", "0"]


@pytest.fixture
def clip_file(tmp_path, scene, render_video, mjpg_file):
    clip = scene(latency_s=0.045, period_s=0.9, duration_s=4.3, fps=120.0)
    return mjpg_file(tmp_path / "clip.avi", render_video(clip), clip.fps)


def test_one_line_summary_with_the_interval(clip_file, capsys):
    assert main(["analyse", str(clip_file), *KNOWN]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("latency 45.")
    assert "95% CI" in out[0] and "by sinefit" in out[0] and "per swing sd" in out[0]
    assert not any(line.startswith("warning:") for line in out)


def test_a_result_with_warnings_exits_3_and_prints_them(clip_file, capsys):
    # Without the camera's settings, 120 fps on 60 Hz samples each refresh at two phases that the
    # video cannot place exactly: the interval is widened, and the warning says why.
    assert main(["analyse", str(clip_file)]) == 3
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("latency 45.")
    (at,) = [i for i, line in enumerate(out) if line.startswith("warning: ") and "the 120 fps camera" in line]
    assert out[at + 1].startswith("  to avoid it: ") and "--exposure-ms" in out[at + 1]
    assert main(["analyse", str(clip_file), "--json"]) == 3
    assert json.loads(capsys.readouterr().out)["warnings"]


def test_json_csv_and_plot_for_every_method(tmp_path, clip_file, capsys):
    tracks, plot = tmp_path / "tracks.csv", tmp_path / "plot.png"
    code = main(["analyse", str(clip_file), *KNOWN, "--method", "all", "--json", "--csv", str(tracks), "--plot", str(plot)])
    assert code == 0
    report = json.loads(capsys.readouterr().out)
    assert report["method"] == "sinefit"
    assert set(report["methods"]) == {"fft", "xcorr", "sinefit", "bayes"}
    assert report["latency_ms"] == pytest.approx(45.0, abs=0.3)
    with tracks.open(newline="") as stream:
        assert len(list(csv.reader(stream))) == 517
    assert plot.stat().st_size > 10_000


def test_image_folder_needs_and_takes_a_frame_rate(tmp_path, scene, render_video, capsys):
    clip = scene(latency_s=0.03, duration_s=3.0, fps=120.0)
    folder = tmp_path / "frames"
    folder.mkdir()
    for index, frame in enumerate(render_video(clip)):
        cv2.imwrite(str(folder / f"img{index:04d}.png"), frame)
    assert main(["analyse", str(folder), "--method", "fft"]) == 2
    assert "no frame rate is known" in capsys.readouterr().err
    assert main(["analyse", str(folder), "--fps", "120", *KNOWN, "--method", "fft", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["latency_ms"] == pytest.approx(30.0, abs=0.5)


def test_bad_input_is_one_line_and_status_2_with_the_tracks_kept(tmp_path, scene, render_video, mjpg_file, capsys):
    clip = scene(period_s=1.0, duration_s=1.6, fps=120.0)
    video = mjpg_file(tmp_path / "short.avi", render_video(clip), clip.fps)
    tracks = tmp_path / "tracks.csv"
    assert main(["analyse", str(video), "--csv", str(tracks)]) == 2
    error = capsys.readouterr().err.strip()
    assert len(error.splitlines()) == 1 and "periods" in error
    with tracks.open(newline="") as stream:
        assert len(list(csv.reader(stream))) == clip.frame_count + 1


def test_latency_range_option_is_checked(clip_file, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["analyse", str(clip_file), "--latency-range", "300,-100"])
    assert exit_.value.code == 2
    assert "LOW must be below HIGH" in capsys.readouterr().err


class ChosenPeriods:
    """A lab's own estimator: the latency as the whole-period choice left it (no fit, so quick)."""

    name = "chosen-periods"
    gives_interval = False

    def estimate(self, context):
        return MethodResult(self.name, context.cycles.reference_s * 1e3, None, "sine", 0.0, {})


def test_method_choices_follow_the_estimator_registry(clip_file, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["analyse", str(clip_file), "--method", "chosen-periods"])
    assert exit_.value.code == 2 and "invalid choice" in capsys.readouterr().err
    register_estimator(ChosenPeriods())
    try:
        assert main(["analyse", str(clip_file), *KNOWN, "--method", "chosen-periods", "--json"]) == 0
    finally:
        unregister_estimator("chosen-periods")
    report = json.loads(capsys.readouterr().out)
    assert report["method"] == "chosen-periods" and list(report["methods"]) == ["chosen-periods"]
    assert report["latency_ms"] == pytest.approx(45.0, abs=0.5)
    with pytest.raises(SystemExit) as exit_:
        main(["analyse", str(clip_file), "--method", "chosen-periods"])
    assert exit_.value.code == 2
