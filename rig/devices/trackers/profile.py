"""Tracker profiles: how a serial or HID tracker lays out one record, as data a lab writes in TOML.

A profile names the record's fields in order, how to find a record in the byte stream, and the
units and scales that turn raw numbers into seconds, metres and a unit quaternion:

    format = "text"                     # text (ASCII lines), binary (fixed layout) or hid (reports)
    fields = ["station", "px", "py", "pz", "e1", "e2", "e3"]
    separator = "whitespace"            # text: "whitespace" or one character such as ","
    terminator = "\\r\\n"                 # text: what ends a record (default "\\n")
    euler = "ZYX"                       # e1 e2 e3 are angles about these axes; upper case intrinsic
    [units]
    position = "in"                     # m, cm, mm or in
    angle = "deg"                       # deg or rad: Euler angles and angular rate
    time = "s"                          # s, ms, us or ns: the device's own time `t`

Field names with a meaning: `t` the device's time, `seq` a record counter, `px py pz` the position,
`qw qx qy qz` a quaternion or `e1 e2 e3` Euler angles, `wx wy wz` the angular rate in the body
frame. Any other name is a field that is read and not used. A binary or HID field is `name:type`
with type u8, i8, u16, i16, u32, i32, u64, i64, f32, f64, or `pad` with a byte count (`_:pad3`);
binary records start with `sync` (hex bytes) and may end in a `checksum` (xor8, sum8,
crc16-ccitt, crc32) over the bytes between the sync and the checksum; HID reports start with
`report_id` where the device numbers its reports. `[scale]` multiplies a raw field before its
unit applies (a 16-bit quaternion in Q14 has scale 2^-14 = 6.103515625e-05).

Profiles ship in `rig/devices/trackers/profiles/` and are named by file stem; a path to a .toml
file names a lab's own. Every problem with a profile is a ConfigError naming the file and the key.
"""

from __future__ import annotations

import math
import struct
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

from rig.devices.trackers.checksums import CHECKSUMS
from rig.errors import ConfigError

FORMATS = ("text", "binary", "hid")
POSITION = ("px", "py", "pz")
QUATERNION = ("qw", "qx", "qy", "qz")
EULER = ("e1", "e2", "e3")
RATE = ("wx", "wy", "wz")
TIME = "t"
SEQUENCE = "seq"
METRES_PER = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254}
RADIANS_PER = {"rad": 1.0, "deg": math.pi / 180.0}
SECONDS_PER = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}
BINARY_TYPES = {
    "u8": "B", "i8": "b", "u16": "H", "i16": "h", "u32": "I", "i32": "i", "u64": "Q", "i64": "q", "f32": "f", "f64": "d",
}  # fmt: skip
DEFAULT_UNIT_TOLERANCE = 1e-3
_KEYS = {
    "name", "description", "format", "fields", "separator", "terminator", "sync", "checksum", "byte_order",
    "report_id", "euler", "units", "scale", "unit_tolerance",
}  # fmt: skip


@dataclass(frozen=True)
class Field:
    """One field of a record: its name, and for binary and HID records its struct code ("" for text)."""

    name: str
    code: str = ""

    @property
    def integer_bits(self) -> int | None:
        """How many bits an integer field holds (it wraps there); None for floats, text and padding."""
        if self.code and self.code in "BbHhIiQq":
            return 8 * struct.calcsize(self.code)
        return None


@dataclass(frozen=True)
class Profile:
    """A tracker's record format, loaded and checked by `load_profile`."""

    name: str
    source: str
    format: str
    fields: tuple[Field, ...]
    description: str = ""
    separator: str | None = None
    terminator: bytes = b"\n"
    sync: bytes = b""
    checksum: str = "none"
    byte_order: str = "little"
    report_id: int = 0
    euler: str = ""
    position_unit: str = "m"
    angle_unit: str = "rad"
    time_unit: str = "s"
    scale: dict[str, float] = field(default_factory=dict)
    unit_tolerance: float = DEFAULT_UNIT_TOLERANCE

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.fields)

    def has(self, *names: str) -> bool:
        return all(name in self.names for name in names)

    @property
    def struct_format(self) -> str:
        """The struct layout of a binary record's fields or a HID report after its id."""
        return ("<" if self.byte_order == "little" else ">") + "".join(f.code for f in self.fields)

    @property
    def sequence_bits(self) -> int | None:
        """The width of the record counter `seq` (64 for a text one); None without one."""
        seq = self.field(SEQUENCE)
        if seq is None:
            return None
        return seq.integer_bits or 64

    def field(self, name: str) -> Field | None:
        return next((f for f in self.fields if f.name == name), None)

    def unit(self, name: str) -> float:
        """One unit of field `name` in the rig's units (m, rad, rad/s, s; 1 for the rest), its scale aside."""
        if name in POSITION:
            return METRES_PER[self.position_unit]
        if name in EULER or name in RATE:
            return RADIANS_PER[self.angle_unit]
        return SECONDS_PER[self.time_unit] if name == TIME else 1.0

    def describe(self) -> dict[str, Any]:
        """The profile as the sidecar of a recording keeps it."""
        return {
            "name": self.name,
            "source": self.source,
            "format": self.format,
            "fields": [f"{f.name}:{f.code}" if f.code else f.name for f in self.fields],
            "units": {"position": self.position_unit, "angle": self.angle_unit, "time": self.time_unit},
            "scale": dict(self.scale),
            "euler": self.euler or None,
            "checksum": self.checksum,
        }


def shipped_profiles() -> list[str]:
    """The names of the profiles that ship with the rig, sorted."""
    folder = resources.files("rig.devices.trackers") / "profiles"
    return sorted(entry.name.removesuffix(".toml") for entry in folder.iterdir() if entry.name.endswith(".toml"))


def load_profile(name_or_path: str) -> Profile:
    """A shipped profile by name, or a lab's own from a .toml path; ConfigError if it is unusable."""
    if name_or_path.endswith(".toml") or "/" in name_or_path:
        path = Path(name_or_path)
        try:
            text = path.read_text(encoding="utf-8")
        except OSError as error:
            raise ConfigError(f"cannot read tracker profile {path}: {error.strerror}") from None
        return parse_profile(text, str(path), path.stem)
    if name_or_path not in shipped_profiles():
        raise ConfigError(
            f"no tracker profile {name_or_path!r}; shipped profiles: {', '.join(shipped_profiles())}, "
            "or give the path of a .toml file"
        )
    resource = resources.files("rig.devices.trackers") / "profiles" / f"{name_or_path}.toml"
    return parse_profile(resource.read_text(encoding="utf-8"), f"shipped profile {name_or_path}", name_or_path)


def parse_profile(text: str, source: str, default_name: str) -> Profile:
    """A profile from TOML text; `source` names it in messages."""
    try:
        table = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ConfigError(f"tracker profile {source} is not valid TOML: {error}") from None
    unknown = sorted(set(table) - _KEYS)
    if unknown:
        raise ConfigError(f"tracker profile {source}: unknown key(s) {', '.join(unknown)}; known: {', '.join(sorted(_KEYS))}")
    return _Checker(source, table).profile(default_name)


class _Checker:
    """Reads and checks one profile's table, each message naming the file and the key."""

    def __init__(self, source: str, table: dict[str, Any]) -> None:
        self.source = source
        self.table = table

    def fail(self, message: str) -> ConfigError:
        return ConfigError(f"tracker profile {self.source}: {message}")

    def choice(self, key: str, options: Any, default: str) -> str:
        value = self.table.get(key, default)
        if value not in options:
            raise self.fail(f"{key} = {value!r}; expected one of {', '.join(map(repr, options))}")
        return value

    def profile(self, default_name: str) -> Profile:
        kind = self.choice("format", FORMATS, "")
        fields = self.fields(kind)
        names = [f.name for f in fields]
        self.check_pose(names)
        units = self.table.get("units", {})
        scale = self.table.get("scale", {})
        if not isinstance(units, dict) or not isinstance(scale, dict):
            raise self.fail("[units] and [scale] must be tables")
        for name, value in scale.items():
            if name not in names or not isinstance(value, (int, float)) or not math.isfinite(value) or value == 0:
                raise self.fail(f"scale.{name} = {value!r}: scale only fields of the record, by a non-zero number")
        tolerance = self.table.get("unit_tolerance", DEFAULT_UNIT_TOLERANCE)
        if not isinstance(tolerance, (int, float)) or not 0.0 < tolerance < 0.5:
            raise self.fail(f"unit_tolerance = {tolerance!r}; expected a number between 0 and 0.5")
        return Profile(
            name=str(self.table.get("name", default_name)),
            source=self.source,
            format=kind,
            fields=tuple(fields),
            description=str(self.table.get("description", "")),
            separator=self.separator() if kind == "text" else None,
            terminator=self.terminator() if kind == "text" else b"\n",
            sync=self.sync() if kind == "binary" else b"",
            checksum=self.choice("checksum", CHECKSUMS, "none") if kind == "binary" else "none",
            byte_order=self.choice("byte_order", ("little", "big"), "little"),
            report_id=self.report_id() if kind == "hid" else 0,
            euler=self.euler(names),
            position_unit=self.unit(units, "position", METRES_PER, "m"),
            angle_unit=self.unit(units, "angle", RADIANS_PER, "rad"),
            time_unit=self.unit(units, "time", SECONDS_PER, "s"),
            scale={name: float(value) for name, value in scale.items()},
            unit_tolerance=float(tolerance),
        )

    def fields(self, kind: str) -> list[Field]:
        raw = self.table.get("fields")
        if not isinstance(raw, list) or not raw or not all(isinstance(item, str) for item in raw):
            raise self.fail('fields must be a list of field names, such as ["t", "px", "py", "pz", "qw", "qx", "qy", "qz"]')
        fields = [self.binary_field(item) if kind != "text" else Field(item) for item in raw]
        named = [f.name for f in fields if f.code[-1:] != "x"]
        repeated = sorted({name for name in named if named.count(name) > 1})
        if repeated:
            raise self.fail(f"field(s) {', '.join(repeated)} named more than once")
        return fields

    def binary_field(self, item: str) -> Field:
        name, _, kind = item.partition(":")
        if kind.startswith("pad") and kind[3:].isdigit() and int(kind[3:]) > 0:
            return Field(name, f"{int(kind[3:])}x")
        if not name or kind not in BINARY_TYPES:
            raise self.fail(f"field {item!r} must be name:type, type one of {', '.join(BINARY_TYPES)} or padN")
        return Field(name, BINARY_TYPES[kind])

    def check_pose(self, names: list[str]) -> None:
        has_quaternion = any(n in names for n in QUATERNION)
        has_euler = any(n in names for n in EULER)
        for group in (POSITION, QUATERNION, EULER, RATE):
            present = [n for n in group if n in names]
            if present and len(present) != len(group):
                raise self.fail(f"fields hold {', '.join(present)} but not all of {', '.join(group)}")
        if has_quaternion == has_euler:
            raise self.fail("fields need an orientation: either qw qx qy qz (a quaternion) or e1 e2 e3 (Euler angles)")

    def euler(self, names: list[str]) -> str:
        sequence = self.table.get("euler", "")
        if "e1" not in names:
            if sequence:
                raise self.fail("euler is set but the fields hold no e1 e2 e3")
            return ""
        valid = isinstance(sequence, str) and len(sequence) == 3 and (sequence.isupper() or sequence.islower())
        if not valid or set(sequence.lower()) - set("xyz") or sequence[0] == sequence[1] or sequence[1] == sequence[2]:
            raise self.fail(
                f"euler = {sequence!r}; expected three axes such as \"ZYX\" (upper case: intrinsic, about the turning "
                "body's axes) or \"xyz\" (lower case: extrinsic, about fixed axes), no axis twice in a row"
            )
        return sequence

    def unit(self, units: dict[str, Any], key: str, table: dict[str, float], default: str) -> str:
        value = units.get(key, default)
        if value not in table:
            raise self.fail(f"units.{key} = {value!r}; expected one of {', '.join(table)}")
        return value

    def separator(self) -> str | None:
        value = self.table.get("separator", "whitespace")
        if value == "whitespace":
            return None
        if not isinstance(value, str) or len(value) != 1 or value in "\r\n":
            raise self.fail(f'separator = {value!r}; expected "whitespace" or one character such as ","')
        return value

    def terminator(self) -> bytes:
        value = self.table.get("terminator", "\n")
        if not isinstance(value, str) or not value or not value.isascii():
            raise self.fail(f"terminator = {value!r}; expected one or more ASCII characters, such as \"\\r\\n\"")
        return value.encode("ascii")

    def sync(self) -> bytes:
        value = self.table.get("sync", "")
        try:
            sync = bytes.fromhex(value)
        except (TypeError, ValueError):
            raise self.fail(f"sync = {value!r}; expected hex bytes such as \"a5 5a\"") from None
        if len(sync) < 1:
            raise self.fail("a binary record needs sync, the hex bytes that start every record (such as \"a5 5a\")")
        return sync

    def report_id(self) -> int:
        value = self.table.get("report_id", 0)
        if not isinstance(value, int) or not 0 <= value <= 255:
            raise self.fail(f"report_id = {value!r}; expected 1 to 255, or 0 for a device without report ids")
        return value
