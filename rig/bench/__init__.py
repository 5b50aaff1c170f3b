"""Benchmarks behind `rig bench`: speed against error, one module per bench (`rig.bench.contract`).

SUBJECTS registers them: per subject, the module of its bench, then those of its modes."""

SUBJECTS = (
    ("analyser",),
    ("predictors",),
    ("renderers", "seed_table", "warp_variants", "photon_residual"),
    ("trackers",),
    ("batch",),
    ("live",),
    ("camera_calibration",),
)
