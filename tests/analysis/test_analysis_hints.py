"""Hints (what a lab says of its bench) in the analysis options: each checked where it enters
against the declaration of its name, filling only an option left unset, never the frame rate; and,
on a synthetic film, compared with what the film shows."""

from __future__ import annotations

import pytest

import analysis
from analysis import AnalysisError, AnalysisOptions
from analysis.hints import Hint


def test_a_hint_fills_only_an_option_left_unset_and_never_the_frame_rate() -> None:
    options = AnalysisOptions(
        display_hz=72.0,
        hints=(Hint("display_hz", 60.0, "a"), Hint("exposure_ms", 2.0, "b"), Hint("fps", 240.0, "c"), Hint("led_row", 0.3, "d")),
    )
    hinted = options.hinted()
    assert hinted.display_hz == 72.0 and hinted.exposure_ms == 2.0 and hinted.fps is None
    assert hinted.hints == options.hints and AnalysisOptions().hinted() == AnalysisOptions()


def test_the_options_side_overrules_every_hint_of_which_blob_is_the_led() -> None:
    regions = (Hint("led_roi", (0, 0, 40, 30), "a"), Hint("sphere_roi", (60, 0, 40, 30), "a"), Hint("led_side", "left", "a"))
    options = AnalysisOptions(led_side="right", hints=regions)
    assert options.hinted() == options
    assert [options.overruling(hint.name) for hint in regions] == ["led_side right"] * 3
    assert AnalysisOptions(hints=regions).hinted().led_roi == (0, 0, 40, 30)
    assert AnalysisOptions(exposure_ms=2.0).overruling("exposure_ms") == "exposure_ms 2" and options.overruling("fps") is None


@pytest.mark.parametrize(
    ("hint", "words"),
    [
        (Hint("display_hz", -60.0, "bench.toml"), "the hint display_hz (bench.toml) must be a positive number of Hz from 1 to 1000, got -60.0"),
        (Hint("led_side", "top", "bench.toml"), "the hint led_side (bench.toml) must be one of left, right, got 'top'"),
        (Hint("scanout", "sideways", "bench.toml"), "must be one of top-down, bottom-up"),
        (Hint("led_row", 1.5, "bench.toml"), "must be a number from 0 to 1"),
        (Hint("method", "fft", "bench.toml"), "the hint method (bench.toml) is not one a bench gives"),
    ],
)
def test_a_hint_is_checked_where_it_enters(hint: Hint, words: str) -> None:
    with pytest.raises(AnalysisError) as error:
        AnalysisOptions(hints=(hint,))
    assert words in str(error.value)


def test_a_hint_given_twice_is_refused() -> None:
    with pytest.raises(AnalysisError, match="is given twice"):
        AnalysisOptions(hints=(Hint("fps", 60.0, "a"), Hint("fps", 120.0, "b")))


def test_hints_the_film_agrees_with_change_nothing_and_are_recorded(scene, render_video) -> None:
    clip = scene(duration_s=4.0)
    video = render_video(clip)
    told = analysis.analyse(video, AnalysisOptions(fps=clip.fps, led_side="left", display_hz=clip.display_hz))
    hints = (Hint("led_side", "left", "bench.toml"), Hint("display_hz", clip.display_hz, "bench.toml"))
    hinted = analysis.analyse(video, AnalysisOptions(fps=clip.fps, hints=hints))
    assert hinted.latency_ms == told.latency_ms and hinted.ci95_ms == told.ci95_ms
    verdicts = {check.hint.name: check.verdict for check in hinted.hints}
    assert verdicts["led_side"] == "agrees" and verdicts["display_hz"] in ("agrees", "cannot check")
    assert [record["name"] for record in hinted.to_dict()["hints"]] == ["led_side", "display_hz"]


def test_a_side_the_film_contradicts_follows_the_evidence(scene, render_video) -> None:
    clip = scene(duration_s=4.0)
    hinted = analysis.analyse(render_video(clip), AnalysisOptions(fps=clip.fps, hints=(Hint("led_side", "right", "bench.toml"),)))
    assert hinted.latency_ms == pytest.approx(clip.latency_s * 1e3, abs=0.5)
    assert hinted.hints[0].verdict == "contradicts" and hinted.led_roi.x < hinted.sphere_roi.x
    (warning,) = [w for w in hinted.warnings if "the LED is on the right" in w]
    cause, remedy = warning.split("\n")
    assert "the evidence was followed" in cause and remedy.startswith("to avoid it: ") and "--led-side" in remedy
