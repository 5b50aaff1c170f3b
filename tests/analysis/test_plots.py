"""The analysis plot is written and shows what it claims."""

from pathlib import Path

import matplotlib.image
import numpy as np
import pytest

from analysis import AnalysisOptions, analyse
from analysis.plots import plot_tracks, tracks_plot


@pytest.mark.parametrize("method", ["sinefit", "fft"])
def test_plot_of_tracks_fits_residuals_and_latency_is_written(tmp_path: Path, scene, render_video, method) -> None:
    setup = scene(latency_s=0.05, duration_s=4.2, fps=120.0)
    result = analyse(render_video(setup), AnalysisOptions(fps=setup.fps, method=method))
    path = plot_tracks(result, tmp_path / "tracks.png", title="test")
    assert path.stat().st_size > 10_000
    image = matplotlib.image.imread(path)
    assert image.shape[:2] == (1100, 1300)
    assert np.ptp(image[..., :3]) > 0.5


def test_the_plot_zooms_where_a_lag_of_a_millisecond_and_a_half_shows(scene, render_video, legends_clear_of_data) -> None:
    setup = scene(latency_s=0.0015, duration_s=6.0, fps=240.0)
    result = analyse(render_video(setup), AnalysisOptions(fps=setup.fps))
    figure = tracks_plot(result, title="test")
    legends_clear_of_data(figure)
    (zoom,) = [axes for axes in figure.axes if axes.get_xlabel().startswith("time from the LED's upward zero crossing")]
    low, high = zoom.get_xlim()
    arrow = next(text for text in zoom.texts if text.arrow_patch is not None)
    assert arrow.xy[0] - arrow.xyann[0] == pytest.approx(result.latency_ms)
    assert low < arrow.xyann[0] < arrow.xy[0] < high
    assert (arrow.xy[0] - arrow.xyann[0]) / (high - low) >= 1 / 15  # a visible share of the panel, not of a swing
    (led_line,) = [line for line in zoom.lines if line.get_label() == "LED's line"]
    (sphere,) = [line for line in zoom.lines if line.get_label() == "sphere, every swing"]
    (x0, x1), (y0, y1) = led_line.get_xdata(), led_line.get_ydata()
    slope = (y1 - y0) / (x1 - x0)
    below = np.mean(y0 + slope * (sphere.get_xdata() - x0) - sphere.get_ydata())
    assert below == pytest.approx(slope * 1.5, rel=0.5)  # the sphere's samples sit the lag behind the LED's
    assert f"{result.latency_ms:.2f} ms" in zoom.get_title()
