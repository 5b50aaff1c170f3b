"""The files a live run writes beside those of any run (`rig.session.run_record`), by name."""

LIVE_FILE = "live.json"
PUBLISHED_FILE = "published_poses.csv"
SWAPS_FILE = "display_swaps.csv"
MARKERS_FILE = "renderer_markers.csv"
