"""`rig record --camera SPEC --duration S --out DIR`: film with a camera, every frame to disk as it comes.

Writes DIR/video.avi (Motion-JPEG, what `rig analyse` reads; for a camera faster than 1000 fps,
which an AVI cannot hold, DIR/video.mp4 in H.264 with each frame's time, and DIR/frame_times.csv),
DIR/camera_frames.csv (each frame's capture time on the host's monotonic clock, the backend's own
timestamp, and the stand-ins written for dropped frames) and DIR/camera.json (the settings asked for
and what the camera reports); a camera faster than 10000 fps is refused before anything is written.
Ctrl-C or an unplugged camera stops cleanly and keeps every frame.
"""

from __future__ import annotations

import argparse
import json

from rig.commands import options, outputs
from rig.progress import ProgressBar

CAMERA_SPECS = (
    "camera:INDEX, camera:FILE or camera:URL (tcp://, rtsp://, http://), with ?fps=F&size=WxH&exposure=E&fourcc=MJPG "
    "to set what the camera must deliver"
)


def _summary(report: dict) -> str:
    lines = [f"recorded {report['frames']} frames from {report['camera']}"
             + (f" at {report['measured_fps']:.2f} fps" if report["measured_fps"] else "")]  # fmt: skip
    if report["dropped"]:
        lines.append(f"{report['dropped']} frames dropped (filled with the previous frame to keep the timing)")
    if report["refused"]:
        lines.append("settings the camera did not take: " + "; ".join(report["refused"]))
    if report["failure"]:
        lines.append(report["failure"])
    return "\n".join(lines)


def _run(args: argparse.Namespace) -> int:
    from rig.live.camera_recording import record_camera

    rois = (list(args.led_roi), list(args.sphere_roi)) if args.led_roi and args.sphere_roi else None
    report = record_camera(
        args.camera.removeprefix("camera:"), args.duration, args.out, preview=args.preview, rois=rois,
        accept_refused=args.accept_camera_settings, overwrite=args.overwrite, progress=ProgressBar("recording"),
    )  # fmt: skip
    if args.json:
        print(json.dumps(report))
    else:
        print(_summary(report))
        print(f"wrote {args.out}")
    return 0


def add_accept_camera_settings(parser: argparse.ArgumentParser) -> None:
    """--accept-camera-settings: whether a camera that refuses a setting may be used all the same."""
    parser.add_argument("--accept-camera-settings", action="store_true",
                        help="film with what the camera gives where it refuses a setting (default: refuse to run)")  # fmt: skip


def add_camera_options(parser: argparse.ArgumentParser) -> None:
    """The options every command that films takes."""
    add_accept_camera_settings(parser)
    parser.add_argument("--led-roi", type=options.roi, metavar="X,Y,W,H", help="region the LED swings in (pixels)")
    parser.add_argument("--sphere-roi", type=options.roi, metavar="X,Y,W,H", help="region the sphere moves in (pixels)")


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register `record`."""
    parser = subparsers.add_parser(
        "record",
        description=__doc__.split("\n\n")[0] + " " + __doc__.split("\n\n")[1].replace("\n", " "),
    )
    parser.add_argument("--camera", required=True, metavar="SPEC", help=f"the camera: {CAMERA_SPECS}")
    parser.add_argument("--duration", type=options.run_seconds, required=True, metavar="S", help="seconds to film")
    parser.add_argument("--out", type=outputs.output_folder, required=True, metavar="DIR", help="folder to write the video and frame table into")
    parser.add_argument("--preview", action="store_true", help="show the camera's frames with both regions of interest")
    parser.add_argument("--overwrite", action="store_true", help="replace a recording already in DIR")
    parser.add_argument("--json", action="store_true", help="print camera.json as one JSON object")
    add_camera_options(parser)
    parser.set_defaults(func=_run)
