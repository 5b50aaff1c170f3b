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

from declared.lazy import lazy_exports

__getattr__, __dir__ = lazy_exports(
    __name__,
    {
        "estimate_shutter": "analysis.shutter.estimate",
        "measure_shutter": "analysis.shutter.estimate",
        "suggest_flash_hz": "analysis.shutter.estimate",
        "RowFilm": "analysis.shutter.film",
        "film_of_frames": "analysis.shutter.film",
        "read_film": "analysis.shutter.film",
        "ShutterOptions": "analysis.shutter.options",
        "ShutterResult": "analysis.shutter.result",
    },
)

__all__ = ["RowFilm", "ShutterOptions", "ShutterResult", "estimate_shutter", "film_of_frames", "measure_shutter", "read_film", "suggest_flash_hz"]
