"""The names of the files a run writes into its folder: light, so that the command line's help names
them without the recording's libraries (`rig.session.run_record` writes them)."""

TRACKER_FILE = "tracker.csv"
APP_FRAMES_FILE = "app_frames.csv"
DISPLAY_FRAMES_FILE = "display_frames.csv"
VIDEO_FILE = "video.avi"
FRAMES_FILE = "camera_frames.csv"
BOARD_FOLDER = "board"
RUN_FILES = (VIDEO_FILE, FRAMES_FILE, TRACKER_FILE, APP_FRAMES_FILE, DISPLAY_FRAMES_FILE)
