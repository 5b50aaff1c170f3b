"""A camera's shutter from a film of a flashing light: its readout (the rolling shutter's line time
times the frame's rows) and its exposure, each with a 95 % interval.

A rolling shutter exposes row y of a frame y L after row 0, for E. Filmed by it, a light flashing
at a known frequency draws bright and dark bands: each row records the share of its exposure the
light was on. ``measure_shutter(video, flash_hz)`` reads the film (``film``: each row's level in
each frame, within an ROI or wherever the light is), fits the bands over all rows and frames at
once (``fit``), and reads the fit as a camera (``estimate``), as ``ShutterOptions`` say: a
display flashing full-field has its own scan-out accounted for, a global shutter comes out as
readout 0 with a bound, and a film that cannot decide is refused with an AnalysisError saying what
to change.
"""

from analysis.shutter.estimate import estimate_shutter, measure_shutter, suggest_flash_hz
from analysis.shutter.film import RowFilm, film_of_frames, read_film
from analysis.shutter.options import ShutterOptions
from analysis.shutter.result import ShutterResult

__all__ = ["RowFilm", "ShutterOptions", "ShutterResult", "estimate_shutter", "film_of_frames", "measure_shutter", "read_film", "suggest_flash_hz"]
