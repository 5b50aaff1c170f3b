"""Frame times: trusted container stamps, dropped and repeated frames, variable rates, lying metadata."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from analysis import AnalysisError, AnalysisOptions, analyse
from analysis.timing import check_count, frame_times, implausible_period_warning, recorder_repeats


def test_constant_rate_stamps_give_uniform_times_without_warnings():
    stamps = 12.5 + np.arange(300) / 240.0
    times = frame_times(stamps, None, 240.0, "container")
    assert times.t == pytest.approx(np.arange(300) / 240.0, abs=1e-12)
    assert (times.fps, times.dropped, times.variable, times.warnings) == (pytest.approx(240.0), 0, False, [])


def test_millisecond_rounded_stamps_are_a_constant_rate():
    # Matroska stores milliseconds: at 480 fps the stamps stray up to half an interval's quarter.
    stamps = np.round(np.arange(500) / 480.0 * 1e3) / 1e3
    times = frame_times(stamps, None, 480.0, "container")
    assert not times.variable
    assert times.t == pytest.approx(np.arange(500) / 480.0, rel=1e-6)


def test_gaps_in_the_stamps_are_dropped_frames_at_their_true_times():
    slots = np.delete(np.arange(200), [50, 51, 120])
    times = frame_times(slots / 120.0, None, 120.0, "container")
    assert times.dropped == 3
    assert times.t == pytest.approx(slots / 120.0)
    assert any("3 frame(s) were dropped" in w for w in times.warnings)


def test_variable_frame_rate_uses_the_stamps_and_says_so():
    intervals = np.where(np.arange(299) % 2 == 0, 1 / 100.0, 1 / 140.0)
    stamps = np.concatenate([[0.0], np.cumsum(intervals)])
    times = frame_times(stamps, None, 120.0, "container")
    assert times.variable
    assert times.t == pytest.approx(stamps)
    assert any("frame rate varies" in w for w in times.warnings)


def test_slow_motion_file_rescaled_by_the_given_rate():
    # A phone stores a 240 fps capture as 30 fps playback: the user's rate rescales the stamps.
    stamps = np.arange(100) / 30.0
    times = frame_times(stamps, 240.0, 30.0, "container")
    assert times.t == pytest.approx(np.arange(100) / 240.0)
    assert times.fps == 240.0
    assert "rescaled to 240 fps" in times.source


def test_stated_rate_that_disagrees_with_the_stamps_is_reported():
    times = frame_times(np.arange(100) / 60.0, None, 30.0, "container")
    assert times.fps == pytest.approx(60.0)
    assert any("states 30 fps" in w for w in times.warnings)


def test_unusable_stamps_fall_back_to_the_frame_rate():
    stamps = np.array([0.0, 0.01, 0.005, 0.02, 0.03])
    times = frame_times(stamps, None, 100.0, "container")
    assert times.t == pytest.approx(np.arange(5) / 100.0)
    assert any("do not increase" in w for w in times.warnings)


def test_no_frame_rate_at_all_raises():
    with pytest.raises(AnalysisError, match="no frame rate is known"):
        frame_times(np.full(10, np.nan), None, None, "container")


@settings(max_examples=40, deadline=None)
@given(fps=st.floats(10.0, 2000.0), count=st.integers(3, 400), start=st.floats(0.0, 1e4))
def test_constant_rate_is_recovered_whatever_the_start(fps, count, start):
    times = frame_times(start + np.arange(count) / fps, None, None, "container")
    assert times.fps == pytest.approx(fps, rel=1e-6)
    assert times.t[0] == 0.0
    assert not times.variable and times.dropped == 0


def test_a_whole_repeat_at_a_constant_rate_is_the_recorders():
    whole = np.array([False, False, True, False, False, False])
    times = frame_times(np.arange(6) / 30.0, None, 30.0, "container")
    assert recorder_repeats(whole, times).tolist() == whole.tolist()


def test_a_whole_repeat_among_varying_timestamps_is_a_capture_of_its_own():
    """A phone's film stamps each capture: a recorder missing one leaves a gap, not a copy."""
    stamps = np.arange(8) / 30.0 + np.array([0.0, 4e-3, -3e-3, 5e-3, 0.0, -4e-3, 3e-3, 0.0]) * 3
    times = frame_times(stamps, None, 30.0, "container")
    assert times.variable
    assert not recorder_repeats(np.array([False, False, True, False, False, False, False, False]), times).any()


def test_implausible_period_and_frame_count_warnings():
    times = frame_times(np.arange(10) / 30.0, None, 30.0, "container")
    assert implausible_period_warning(1.0, times) is None
    assert "slow motion" in implausible_period_warning(8.0, times)
    assert check_count(1000, 1000, "v.mp4") is None
    assert "states 1200 frames" in check_count(1000, 1200, "v.mp4")


def test_duplicated_frames_in_a_video_are_left_out(scene, render_video):
    clip = scene(latency_s=0.04, duration_s=4.1, fps=120.0)
    frames = render_video(clip).copy()
    # The recorder lost three frames and repeated the one before in their place.
    copies = [200, 350, 420]
    frames[[c + 1 for c in copies]] = frames[copies]
    result = analyse(frames, AnalysisOptions(fps=clip.fps, method="fft"))
    assert result.diagnostics["repeated_frames"] == 3
    assert not result.led_track.valid[[201, 351, 421]].any()
    assert result.latency_ms == pytest.approx(40.0, abs=0.3)
    assert any("repeat the one before" in w for w in result.warnings)


@pytest.mark.parametrize(
    "stamps, stated_fps, says",
    [
        (np.zeros(50), 120.0, "timestamps do not increase"),
        (np.arange(100) / 240.0, 120.0, "240 fps apart"),
        (np.delete(np.arange(200), [50, 51]) / 120.0, 120.0, "2 frame(s) were dropped"),
        (np.concatenate([[0.0], np.cumsum(np.where(np.arange(299) % 2 == 0, 1 / 100.0, 1 / 140.0))]), 120.0, "frame rate varies"),
    ],
)
def test_each_timing_warning_is_a_cause_and_a_remedy(stamps, stated_fps, says):
    (warning,) = [w for w in frame_times(stamps, None, stated_fps, "container").warnings if says in w]
    cause, remedy = warning.split("\n")
    assert says in cause and remedy.startswith("to avoid it: ")
