"""What `rig demo` holds its analyser to, and the scene `rig demo --compare` renders: light
constants, read by the demo (`rig.service.demo`) and by its command line's help."""

AGREEMENT_MS = 1.0
"""The most the measured latency may differ from the true one for the demo to pass."""
COMPARE_RENDERERS = ("direct", "warp")
COMPARE_TRIANGLES = 100_000
"""A scene left at the defaults becomes this many load triangles for `rig demo --compare`."""
COMPARE_APP_FRAME_MS = 100.0
"""...and this application frame cost (modelled), so that the two renderers differ."""
