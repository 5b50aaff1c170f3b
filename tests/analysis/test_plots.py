"""The track plot is written and shows what it claims."""

from pathlib import Path

import matplotlib.image
import numpy as np

from analysis import analyse
from analysis.plots import plot_tracks


def test_plot_of_both_tracks_is_written(tmp_path: Path, scene, render_video) -> None:
    setup = scene(latency_s=0.05)
    result = analyse(render_video(setup), fps=setup.fps)
    path = plot_tracks(result, tmp_path / "tracks.png", title="test")
    assert path.stat().st_size > 10_000
    image = matplotlib.image.imread(path)
    assert image.shape[0] == 600 and image.shape[1] == 900
    assert np.ptp(image[..., :3]) > 0.5
