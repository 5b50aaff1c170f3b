"""Any renderer through Lab Streaming Layer: the rig's pose and tracker outlets, the renderer's
marker stream, and the rig's side of an external renderer (see `rig.lsl.streams` for the streams)."""

from rig.lsl.external import MARKER_COLUMNS, ExternalRenderer, MarkerDisplay
from rig.lsl.publish import PUBLISHED_COLUMNS, LslPublisher, PublishingRenderer
from rig.lsl.streams import MARKER_CHANNELS, POSE_CHANNELS, StreamNames

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
