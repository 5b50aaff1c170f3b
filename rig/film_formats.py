"""The containers and codecs a film may be written in, and which go together: light, so that a
camera's settings are checked without the film writers' libraries (`rig.film_file` writes them)."""

from __future__ import annotations

from rig.errors import ConfigError

CONTAINERS = ("avi", "mp4", "mov")
CODECS = ("mjpeg", "h264", "hevc")
STAMPED_CONTAINERS = ("mp4", "mov")


def check_film_format(container: str, codec: str, stamped: bool) -> None:
    """ConfigError unless `codec` goes in `container` here, and (`stamped`) the container stamps each
    frame with its own time."""
    if container not in CONTAINERS:
        raise ConfigError(f"a film's container is one of {', '.join(CONTAINERS)}, got {container!r}")
    if codec not in CODECS:
        raise ConfigError(f"a film's codec is one of {', '.join(CODECS)}, got {codec!r}")
    if (container == "avi") != (codec == "mjpeg"):
        raise ConfigError(
            f"{codec} in {container} is not written here: an AVI holds MJPEG, an MP4 or a MOV holds h264 or hevc"
        )
    if stamped and container not in STAMPED_CONTAINERS:
        raise ConfigError(
            "a film with variable frame timing needs a container that stamps each frame: give --container mp4 or mov"
        )


def default_codec(container: str) -> str:
    """The codec a film in `container` is written with unless another is asked for."""
    return "mjpeg" if container == "avi" else "h264"
