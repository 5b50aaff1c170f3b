"""Benchmarks behind `rig bench`: speed against error, one module per bench (`rig.bench.contract`).

SUBJECTS registers them: per subject, the light module that declares its command (`SUBJECT`, and
`MODES` where it has modes; its docstring's first paragraph is the command's description); each
bench's own module is imported only when it runs."""

SUBJECTS = (
    "analyser_settings",
    "predictors_settings",
    "renderers_settings",
    "trackers_settings",
    "batch_settings",
    "live_settings",
    "camera_calibration_settings",
)
