"""The analysis plot is written and shows what it claims."""

from pathlib import Path

import matplotlib.image
import numpy as np
import pytest

from analysis import AnalysisOptions, analyse
from analysis.plots import plot_tracks


@pytest.mark.parametrize("method", ["sinefit", "fft"])
def test_plot_of_tracks_fits_residuals_and_latency_is_written(tmp_path: Path, scene, render_video, method) -> None:
    setup = scene(latency_s=0.05, duration_s=4.2, fps=120.0)
    result = analyse(render_video(setup), AnalysisOptions(fps=setup.fps, method=method))
    path = plot_tracks(result, tmp_path / "tracks.png", title="test")
    assert path.stat().st_size > 10_000
    image = matplotlib.image.imread(path)
    assert image.shape[:2] == (1000, 1000)
    assert np.ptp(image[..., :3]) > 0.5
