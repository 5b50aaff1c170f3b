"""The rig's Lab Streaming Layer interface for any renderer (Unity through LSL4Unity, Unreal, C++
with liblsl, Python with pylsl): what each stream is called, what its channels hold, and the clock
its times are on. docs/lsl.md ("Measuring your own renderer over LSL") explains it for implementers.

Every time in these streams, sample timestamps and time channels alike, is on the LSL clock of the
machine that sent it (`lsl_local_clock()`, the system's monotonic clock); a receiver on another
machine maps it with the inlet's `time_correction()`.

* `RigPose` (type "Pose", published by the rig): one sample per display frame, the pose predicted
  for that frame. Channels: `frame` (counts up; echo it in your markers), `t_photon` (the instant the
  pose is predicted for), `t_sensor` (the newest tracker sample behind it), `px py pz` (metres), `qw qx
  qy qz` (unit quaternion, w first, Hamilton, body to world). Sample timestamp: when it was published.
  Its description holds `view/world_to_clip` (16 numbers, row-major: how the rig's own renderer
  frames the pendulum, so an external renderer can draw the sphere in the same place),
  `view/sphere_radius_m` and the display's `refresh_hz`.
* `RigTracker` (type "MoCap", published by the rig): every raw tracker sample as it arrives, 7
  channels `px py pz qw qx qy qz`; timestamp: the sensor's time. The same layout `lsl:NAME` trackers read.
* `RigRendererMarkers` (type "Markers", published by the renderer): one sample per buffer swap, 2
  channels: `frame` (the RigPose frame drawn, -1 before the first) and `t_swap` (when the swap
  returned, or the driver's vertical blank time if it has one); timestamp: `t_swap` too.
"""

from __future__ import annotations

from dataclasses import dataclass

from declared import Flag, setting

POSE_CHANNELS = ("frame", "t_photon", "t_sensor", "px", "py", "pz", "qw", "qx", "qy", "qz")
POSE_UNITS = ("count", "seconds", "seconds", "metres", "metres", "metres", "normalised", "normalised", "normalised", "normalised")
MARKER_CHANNELS = ("frame", "t_swap")

LSL = "lsl"
"""The group of the streams' options among a live run's (`rig.live.config`)."""


@dataclass(frozen=True)
class StreamNames:
    """The three streams' names (change them to run several rigs on one network), each declared with
    its option."""

    pose: str = setting("RigPose", "", "LSL name of the rig's pose stream", flag=Flag("--pose-stream", group=LSL))
    tracker: str = setting("RigTracker", "", "LSL name of the rig's tracker stream",
                           flag=Flag("--tracker-stream", group=LSL))  # fmt: skip
    markers: str = setting("RigRendererMarkers", "", "LSL name of an external renderer's marker stream",
                           flag=Flag("--marker-stream", group=LSL))  # fmt: skip

