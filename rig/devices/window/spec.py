"""`window[:MONITOR][?fullscreen=1&size=WxH&pos=X,Y&scanout=F]`: the on-screen display's spec.

    window                        a 640x480 window on the primary monitor
    window:1?fullscreen=1         full screen on the second monitor
    window?size=1280x720&pos=0,0&scanout=0.95

`scanout` is the share of a refresh the monitor takes to light its rows top to bottom (the
modelled scan-out; 1 by default).
"""

from __future__ import annotations

from urllib.parse import parse_qsl

from rig.devices.window.display import WindowDisplay
from rig.devices.window.gl_window import WindowSettings
from rig.errors import ConfigError

OPTIONS = ("fullscreen", "size", "pos", "scanout")


def _pair(text: str, separator: str, what: str, spec: str) -> tuple[int, int]:
    try:
        first, second = (int(v) for v in text.lower().split(separator))
    except ValueError:
        raise ConfigError(f"{what} in window{spec}: expected two whole numbers as A{separator}B, got {text!r}") from None
    return first, second


def parse_window_address(address: str) -> tuple[WindowSettings, float]:
    """(settings, scan-out fraction) of a window display's address."""
    spec = f":{address}" if address else ""
    monitor, _, query = address.partition("?")
    options = dict(parse_qsl(query, keep_blank_values=True))
    unknown = sorted(set(options) - set(OPTIONS))
    if unknown:
        raise ConfigError(f"window{spec}: no option {', '.join(unknown)}; the options are {', '.join(OPTIONS)}")
    if monitor and not monitor.isdigit():
        raise ConfigError(f"window{spec}: the monitor is a number (0: the primary), got {monitor!r}")
    size = _pair(options["size"], "x", "size", spec) if "size" in options else WindowSettings.size
    if min(size) < 16:
        raise ConfigError(f"window{spec}: a window is at least 16x16 pixels")
    position = _pair(options["pos"], ",", "pos", spec) if "pos" in options else None
    try:
        scanout = float(options.get("scanout", "1"))
    except ValueError:
        raise ConfigError(f"window{spec}: scanout is a share of the refresh such as 0.95") from None
    settings = WindowSettings(
        monitor=int(monitor or 0), fullscreen=options.get("fullscreen", "0") not in ("0", "", "false"), size=size, position=position
    )
    return settings, scanout


def window_display(address: str) -> WindowDisplay:
    """An unconnected window display for `address`."""
    settings, scanout = parse_window_address(address)
    return WindowDisplay(settings, scanout_fraction=scanout)
