"""Without the compiled region decoder (analysis._jpeg_region not built) the analyser still imports,
decodes Motion-JPEG frames whole, gives the same result, and says once why it is slower."""

import json
import logging
import subprocess
import sys

import numpy as np

from analysis import AnalysisOptions, analyse
from analysis.video.decoding import REGION_DECODER_MISSING

WITHOUT_EXTENSION = """
import json, sys
sys.modules["analysis._jpeg_region"] = None  # import fails, as when the extension was never built
import analysis
from analysis.video.file import VideoFile
path = sys.argv[1]
result = analysis.analyse(path, analysis.AnalysisOptions(method="fft"))
print(json.dumps({
    "decodes_in_part": VideoFile(path).decodes_in_part,
    "latency_ms": result.latency_ms,
    "led_x": result.led_track.x.tolist(),
    "sphere_x": result.sphere_track.x.tolist(),
}))
"""


def test_without_the_region_decoder_a_motion_jpeg_file_gives_the_same_result(tmp_path, scene, render_video, mjpg_file, caplog):
    clip = scene(latency_s=0.03, duration_s=3.2, period_s=0.8)
    path = mjpg_file(tmp_path / "clip.avi", render_video(clip), clip.fps)
    with caplog.at_level(logging.WARNING):
        expected = analyse(path, AnalysisOptions(method="fft"))
    assert REGION_DECODER_MISSING not in caplog.text
    completed = subprocess.run(
        [sys.executable, "-c", WITHOUT_EXTENSION, str(path)], capture_output=True, text=True, check=True, timeout=300
    )
    without = json.loads(completed.stdout)
    assert without["decodes_in_part"]
    assert without["latency_ms"] == expected.latency_ms
    assert np.array_equal(without["led_x"], expected.led_track.x, equal_nan=True)
    assert np.array_equal(without["sphere_x"], expected.sphere_track.x, equal_nan=True)
    # One line on stderr per video opened (the analysis opens it once; the check above once more).
    assert completed.stderr.splitlines() == [REGION_DECODER_MISSING, REGION_DECODER_MISSING]
