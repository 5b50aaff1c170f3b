"""Records as a tracker with a given profile would send them: the inverse of the rig's decoders.

Values go in in the rig's units (s, m, unit quaternion, rad/s) and come out as the profile's
bytes: a text line, a binary record with its sync and check, or a HID report with its id. Integer
fields are rounded and wrap at their width, as a device's counters do.
"""

from __future__ import annotations

import struct
import warnings
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from rig.devices.trackers.checksums import CHECKSUMS
from rig.devices.trackers.profile import EULER, POSITION, QUATERNION, RATE, SEQUENCE, TIME, Profile


@dataclass(frozen=True)
class Emission:
    """One record the emulated device sends: its counter, its own time (s), the pose and angular rate."""

    seq: int
    device_time: float
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]
    angular_rate: tuple[float, float, float] = (0.0, 0.0, 0.0)


class RecordEncoder:
    """Encodes emissions in `profile`'s format."""

    def __init__(self, profile: Profile) -> None:
        self.profile = profile
        self._struct = struct.Struct(profile.struct_format) if profile.format != "text" else None
        self._check = CHECKSUMS[profile.checksum]

    def _physical(self, emission: Emission) -> dict[str, float]:
        """The record's values by field name, in the rig's units."""
        profile = self.profile
        values: dict[str, float] = {SEQUENCE: float(emission.seq), TIME: emission.device_time}
        values.update(zip(POSITION, emission.position))
        values.update(zip(QUATERNION, emission.orientation))
        values.update(zip(RATE, emission.angular_rate))
        if profile.euler:
            w, x, y, z = emission.orientation
            with warnings.catch_warnings():
                # At gimbal lock (the middle angle at +-90 degrees) scipy warns and sets the third
                # angle to zero; the three it gives still make the same rotation, as a device sends it.
                warnings.filterwarnings("ignore", "Gimbal lock detected", UserWarning)
                angles = Rotation.from_quat([x, y, z, w]).as_euler(profile.euler)
            values.update(zip(EULER, angles.tolist()))
        return values

    def raw_values(self, emission: Emission) -> list[float | int]:
        """The record's fields in profile order, scaled, integers rounded and wrapped."""
        profile, values = self.profile, self._physical(emission)
        raw: list[float | int] = []
        for field in profile.fields:
            if field.code.endswith("x"):
                continue
            value = values.get(field.name, 0.0) / profile.unit(field.name) / profile.scale.get(field.name, 1.0)
            bits = field.integer_bits
            if bits is not None:
                signed = field.code.islower()
                whole = int(np.rint(value)) % (1 << bits)
                if signed and whole >= 1 << (bits - 1):
                    whole -= 1 << bits
                raw.append(whole)
            else:
                raw.append(value)
        return raw

    def encode(self, emission: Emission) -> bytes:
        profile = self.profile
        raw = self.raw_values(emission)
        if profile.format == "text":
            separator = profile.separator or " "
            return separator.join(f"{v:.9g}" for v in raw).encode("ascii") + profile.terminator
        body = self._struct.pack(*raw)
        if profile.format == "hid":
            return (bytes([profile.report_id]) if profile.report_id else b"") + body
        return profile.sync + body + self._check(body, profile.byte_order)
