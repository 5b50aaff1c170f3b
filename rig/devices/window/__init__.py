"""The rig's images on a real monitor: `WindowDisplay` (the `window` display spec)."""

from rig.devices.window.display import SWAP_COLUMNS, FrameClock, SwapRecord, WindowDisplay
from rig.devices.window.gl_window import WindowSettings
from rig.devices.window.refresh import RefreshModel

__all__ = ["SWAP_COLUMNS", "FrameClock", "RefreshModel", "SwapRecord", "WindowDisplay", "WindowSettings"]
