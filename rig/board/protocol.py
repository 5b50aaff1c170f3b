"""The board's serial protocol, read from its one definition: protocol.h.

The header is the firmware's (firmware/include/protocol.h); rig/board/protocol.h links to it, so
the file ships inside this package (package data, copied into a wheel) and is found with
importlib.resources, from a checkout or an installed rig alike. Nothing here is a copy of the
header: the constants and the payload layouts are parsed from it the first time `protocol()` is
called, and a test compiles the header with the C compiler to check that the parse agrees with
what the firmware sees.
"""

from __future__ import annotations

import functools
import re
import struct
from dataclasses import dataclass
from importlib import resources
from typing import Mapping

from rig.errors import RigError

HEADER_FILE = resources.files("rig.board") / "protocol.h"

_FIELD_FORMATS = {
    "uint8_t": "B",
    "int8_t": "b",
    "uint16_t": "H",
    "int16_t": "h",
    "uint32_t": "I",
    "int32_t": "i",
    "char": "s",
}
_COMMENT = re.compile(r"/\*.*?\*/|//[^\n]*", re.DOTALL)
_DEFINE = re.compile(r"^\s*#define\s+(RIG_\w+)\s+(\S.*?)\s*$", re.MULTILINE)
_INTEGER = re.compile(r"^(0[xX][0-9a-fA-F]+|[0-9]+)[uUlL]*$")
_STRING = re.compile(r'^"([^"\\]*)"$')
_STRUCT = re.compile(r"typedef\s+struct\s+RIG_PACKED\s*\{(?P<body>[^}]*)\}\s*(?P<name>rig_\w+_t)\s*;")
_FIELD = re.compile(r"^\s*(?P<type>\w+)\s+(?P<name>\w+)\s*(?:\[\s*(?P<count>\d+)\s*\])?\s*;\s*$")
_MESSAGE_PREFIXES = ("RIG_CMD_", "RIG_MSG_")


@dataclass(frozen=True)
class PayloadLayout:
    """The fields of one message type's payload, in order, and their little-endian struct format."""

    name: str
    fields: tuple[str, ...]
    format: str

    @property
    def size(self) -> int:
        return struct.calcsize(self.format)

    def unpack(self, payload: bytes) -> dict[str, int | bytes]:
        """Field values by name; raises ValueError when the payload has the wrong length."""
        if len(payload) != self.size:
            raise ValueError(f"{self.name} payload is {len(payload)} bytes, expected {self.size}")
        return dict(zip(self.fields, struct.unpack(self.format, payload)))

    def pack(self, **values: int | bytes) -> bytes:
        """The payload for these field values; every field must be given."""
        if set(values) != set(self.fields):
            raise ValueError(f"{self.name} needs the fields {', '.join(self.fields)}, got {', '.join(values)}")
        try:
            return struct.pack(self.format, *(values[field] for field in self.fields))
        except struct.error as error:
            raise ValueError(f"{self.name}: {error}") from None


@dataclass(frozen=True)
class ProtocolSpec:
    """Every RIG_ constant of the header, the message types and their payload layouts."""

    constants: Mapping[str, int]
    strings: Mapping[str, str]
    layouts: Mapping[int, PayloadLayout]
    type_names: Mapping[int, str]

    def __getitem__(self, name: str) -> int:
        return self.constants[name]

    def type_id(self, name: str) -> int:
        """The type number of RIG_CMD_<name> or RIG_MSG_<name>, given the full macro name."""
        if not name.startswith(_MESSAGE_PREFIXES):
            raise KeyError(name)
        return self.constants[name]

    def layout(self, message_type: int) -> PayloadLayout:
        return self.layouts[message_type]

    def status_name(self, status: int) -> str:
        """RIG_STATUS_* name of an acknowledgement status, for messages to people."""
        for name, value in self.constants.items():
            if name.startswith("RIG_STATUS_") and value == status:
                return name.removeprefix("RIG_STATUS_").lower().replace("_", " ")
        return f"status {status}"


def _struct_layout(name: str, body: str) -> PayloadLayout:
    fields: list[str] = []
    codes: list[str] = []
    for line in body.split(";"):
        if not line.strip():
            continue
        match = _FIELD.match(line + ";")
        if match is None or match["type"] not in _FIELD_FORMATS:
            raise RigError(f"{HEADER_FILE.name}: cannot read the field {line.strip()!r} of {name}")
        code = _FIELD_FORMATS[match["type"]]
        count = int(match["count"]) if match["count"] else None
        if (code == "s") != (count is not None):
            raise RigError(f"{HEADER_FILE.name}: {match['name']} of {name}: only char fields may be, and must be, arrays")
        fields.append(match["name"])
        codes.append(f"{count}s" if code == "s" else code)
    return PayloadLayout(name=name, fields=tuple(fields), format="<" + "".join(codes))


def parse_protocol_header(text: str) -> ProtocolSpec:
    """Reads the constants and payload structs of protocol.h source text."""
    source = _COMMENT.sub("", text)
    constants: dict[str, int] = {}
    strings: dict[str, str] = {}
    for name, value in _DEFINE.findall(source):
        if _INTEGER.match(value):
            constants[name] = int(_INTEGER.match(value).group(1), 0)
        elif _STRING.match(value):
            strings[name] = _STRING.match(value).group(1)
    type_names = {value: name for name, value in constants.items() if name.startswith(_MESSAGE_PREFIXES)}
    if len(type_names) != sum(name.startswith(_MESSAGE_PREFIXES) for name in constants):
        raise RigError(f"{HEADER_FILE.name}: two message types share a number")
    layouts = {value: PayloadLayout(name=name, fields=(), format="<") for value, name in type_names.items()}
    for match in _STRUCT.finditer(source):
        struct_name = match["name"]
        type_name = struct_name.removesuffix("_t").upper()
        if type_name not in constants or not type_name.startswith(_MESSAGE_PREFIXES):
            raise RigError(f"{HEADER_FILE.name}: {struct_name} has no message type {type_name}")
        layout = _struct_layout(struct_name, match["body"])
        if layout.size > constants["RIG_FRAME_MAX_PAYLOAD"]:
            raise RigError(f"{HEADER_FILE.name}: {struct_name} is longer than RIG_FRAME_MAX_PAYLOAD")
        layouts[constants[type_name]] = layout
    return ProtocolSpec(constants=constants, strings=strings, layouts=layouts, type_names=type_names)


@functools.cache
def protocol() -> ProtocolSpec:
    """The protocol of protocol.h, parsed on first use."""
    try:
        text = HEADER_FILE.read_text(encoding="utf-8")
    except OSError as error:
        raise RigError(
            f"cannot read the board protocol {HEADER_FILE}: {error.strerror}; reinstall latency-rig, "
            "or in a checkout restore the link rig/board/protocol.h -> ../../firmware/include/protocol.h"
        ) from None
    spec = parse_protocol_header(text)
    if "RIG_PROTOCOL_VERSION" not in spec.constants:
        raise RigError(
            f"{HEADER_FILE} defines no RIG_PROTOCOL_VERSION: it should be (a link to) firmware/include/protocol.h; "
            "a checkout made without symbolic links (git config core.symlinks) holds the link's target path instead"
        )
    return spec
