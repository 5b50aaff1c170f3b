"""Tracker profiles as data: the shipped ones load and round-trip through the emulator's encoder and
the rig's decoders; a bad profile is refused with a message naming the file and the key."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from rig.devices.trackers.decoders import decoder_for
from rig.devices.trackers.profile import load_profile, parse_profile, shipped_profiles
from rig.devices.trackers.readings import euler_quaternion
from rig.emulate.encode import Emission, RecordEncoder
from rig.errors import ConfigError

GOOD = """
format = "binary"
sync = "a5 5a"
fields = ["t:u32", "qw:f32", "qx:f32", "qy:f32", "qz:f32"]
"""


def test_every_shipped_profile_loads_and_is_documented() -> None:
    names = shipped_profiles()
    assert {"csv", "polhemus-ascii", "polhemus-quat", "binary-pose", "hid-quat16"} <= set(names)
    for name in names:
        assert load_profile(name).description


@pytest.mark.parametrize("name", ["csv", "polhemus-ascii", "polhemus-quat", "binary-pose", "hid-quat16"])
def test_a_shipped_profile_round_trips_a_pose_through_encoder_and_decoder(name: str) -> None:
    profile = load_profile(name)
    turn = Rotation.from_rotvec([0.3, -0.2, 0.5]).as_quat(scalar_first=True)
    emission = Emission(17, 123.456789, (0.1, -0.25, 0.5), tuple(turn), (0.2, -0.1, 1.5))
    decoder = decoder_for(profile)
    encoded = RecordEncoder(profile).encode(emission)
    readings = decoder.feed(encoded, 1.0)
    assert decoder.corrupt == 0 and len(readings) == 1
    tolerance = 1e-4 if profile.format == "hid" else 1e-6
    q = np.array(readings.orientations[0])
    assert min(np.abs(q - turn).max(), np.abs(q + turn).max()) < tolerance
    if profile.has("px"):
        np.testing.assert_allclose(readings.positions[0], emission.position, atol=1e-6)
    if profile.has("t"):
        assert readings.device_times[0] == pytest.approx(emission.device_time, abs=1e-6)
    if profile.has("wx"):
        np.testing.assert_allclose(readings.rates[0], emission.angular_rate, atol=math.radians(0.0625))


@given(st.sampled_from(["ZYX", "XYZ", "zyx", "xyz", "ZXZ", "yxy"]), st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3))
def test_euler_angles_turn_as_scipy_reads_the_same_sequence(sequence: str, angles: list[float]) -> None:
    expected = Rotation.from_euler(sequence, angles).as_quat(scalar_first=True)
    q = np.array(euler_quaternion(sequence, angles))
    assert min(np.abs(q - expected).max(), np.abs(q + expected).max()) < 1e-12


@pytest.mark.parametrize(
    "text, key",
    [
        ('format = "text"\nfields = ["px", "py", "pz"]', "orientation"),
        ('format = "text"\nfields = ["px", "py", "qw", "qx", "qy", "qz"]', "pz"),
        ('format = "serial"\nfields = ["qw", "qx", "qy", "qz"]', "format"),
        ('format = "binary"\nfields = ["qw:f32", "qx:f32", "qy:f32", "qz:f33"]', "qz:f33"),
        ('format = "binary"\nfields = ["qw:f32", "qx:f32", "qy:f32", "qz:f32"]', "sync"),
        ('format = "binary"\nsync = "zz"\nfields = ["qw:f32", "qx:f32", "qy:f32", "qz:f32"]', "sync"),
        (GOOD + 'checksum = "md5"', "checksum"),
        ('format = "text"\nfields = ["e1", "e2", "e3"]\neuler = "ZZX"', "euler"),
        ('format = "text"\nfields = ["qw", "qx", "qy", "qz"]\n[units]\nposition = "furlong"', "units.position"),
        ('format = "text"\nfields = ["qw", "qx", "qy", "qz"]\n[scale]\npx = 2.0', "scale.px"),
        ('format = "text"\nfields = ["qw", "qx", "qy", "qz"]\nsperator = ","', "sperator"),
        ('format = "hid"\nreport_id = 300\nfields = ["qw:i16", "qx:i16", "qy:i16", "qz:i16"]', "report_id"),
        ('format = "text"\nfields = ["qw", "qx", "qy", "qz", "qw"]', "more than once"),
        ("format = [", "TOML"),
    ],
)
def test_a_bad_profile_is_refused_naming_its_key(text: str, key: str) -> None:
    with pytest.raises(ConfigError, match=f"tracker profile lab.toml.*{key}"):
        parse_profile(text, "lab.toml", "lab")


def test_a_lab_profile_is_read_from_its_path(tmp_path: Path) -> None:
    path = tmp_path / "imu.toml"
    path.write_text(GOOD)
    assert load_profile(str(path)).name == "imu"
    with pytest.raises(ConfigError, match="cannot read tracker profile"):
        load_profile(str(tmp_path / "missing.toml"))
    with pytest.raises(ConfigError, match="no tracker profile 'nosuch'; shipped profiles: binary-pose"):
        load_profile("nosuch")
