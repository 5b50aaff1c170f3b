"""Any renderer through Lab Streaming Layer: the rig's pose and tracker outlets, the renderer's
marker stream, and the rig's side of an external renderer (see `rig.lsl.streams` for the streams)."""

from declared.lazy import lazy_exports

__getattr__, __dir__ = lazy_exports(
    __name__,
    {
        "MARKER_COLUMNS": "rig.lsl.external",
        "ExternalRenderer": "rig.lsl.external",
        "MarkerDisplay": "rig.lsl.external",
        "PUBLISHED_COLUMNS": "rig.lsl.publish",
        "LslPublisher": "rig.lsl.publish",
        "PublishingRenderer": "rig.lsl.publish",
        "MARKER_CHANNELS": "rig.lsl.streams",
        "POSE_CHANNELS": "rig.lsl.streams",
        "StreamNames": "rig.lsl.streams",
    },
)

__all__ = [
    "MARKER_CHANNELS",
    "MARKER_COLUMNS",
    "POSE_CHANNELS",
    "PUBLISHED_COLUMNS",
    "ExternalRenderer",
    "LslPublisher",
    "MarkerDisplay",
    "PublishingRenderer",
    "StreamNames",
]
