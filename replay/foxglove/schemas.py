"""Foxglove's well-known schemas as Protobuf (``foxglove-schemas-protobuf``): the MCAP schema
record of a message class, and the class of a schema name, for writing and reading logs back.

Foxglove recognises a channel by its schema *name* (``foxglove.FrameTransforms``, ...); an MCAP
``protobuf`` schema is the serialised ``FileDescriptorSet`` of the message's file and every file
it imports (Rerun decodes the Foxglove schemas only in this encoding).
"""

from __future__ import annotations

import struct

from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
from foxglove_schemas_protobuf.JointStates_pb2 import JointStates
from foxglove_schemas_protobuf.Log_pb2 import Log
from foxglove_schemas_protobuf.RawImage_pb2 import RawImage
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from google.protobuf import json_format
from google.protobuf.descriptor_pb2 import FileDescriptorSet
from google.protobuf.message import DecodeError, Message

SCHEMA_ENCODING = "protobuf"
MESSAGE_ENCODING = "protobuf"
# the URDF's topic: ROS 2 std_msgs/msg/String in CDR (little endian), what Foxglove's URDF layer
# and Rerun's MCAP importer read
STRING_SCHEMA = "std_msgs/msg/String"
_CDR_HEADER = b"\x00\x01\x00\x00"  # CDR_LE, no options

# the classes our logs use, by schema name
CLASSES: dict[str, type[Message]] = {
    cls.DESCRIPTOR.full_name: cls
    for cls in (FrameTransforms, SceneUpdate, JointStates, Log, RawImage)
}


_SCHEMA_DATA: dict[str, bytes] = {}


def schema_data(cls: type[Message]) -> bytes:
    """The ``FileDescriptorSet`` (bytes) of ``cls``'s file and its imports, imports first."""
    name = cls.DESCRIPTOR.full_name
    if name not in _SCHEMA_DATA:
        _SCHEMA_DATA[name] = _file_descriptor_set(cls)
    return _SCHEMA_DATA[name]


def _file_descriptor_set(cls: type[Message]) -> bytes:
    fds = FileDescriptorSet()
    seen: set[str] = set()

    def add(fd) -> None:
        if fd.name in seen:
            return
        seen.add(fd.name)
        for dep in fd.dependencies:
            add(dep)
        fd.CopyToProto(fds.file.add())

    add(cls.DESCRIPTOR.file)
    return fds.SerializeToString(deterministic=True)


def decode(schema_name: str, data: bytes) -> Message:
    """A message of one of our schemas from its bytes; ValueError for an unknown schema or bytes
    that do not parse."""
    cls = CLASSES.get(schema_name)
    if cls is None:
        raise ValueError(f"unknown protobuf schema {schema_name!r}")
    msg = cls()
    try:
        msg.ParseFromString(data)
    except DecodeError as exc:
        raise ValueError(f"{schema_name}: {exc}") from None
    return msg


def encode_string(text: str) -> bytes:
    """A ``std_msgs/msg/String`` in CDR: header, uint32 length (with the NUL), UTF-8, NUL."""
    b = text.encode() + b"\x00"
    return _CDR_HEADER + struct.pack("<I", len(b)) + b


def decode_string(data: bytes) -> str:
    if data[:4] != _CDR_HEADER or len(data) < 8:
        raise ValueError(f"{STRING_SCHEMA}: not little-endian CDR")
    (n,) = struct.unpack_from("<I", data, 4)
    if n < 1 or len(data) < 8 + n:
        raise ValueError(f"{STRING_SCHEMA}: string length {n} beyond the message")
    return data[8 : 8 + n - 1].decode()


def message_dict(schema_name: str, data: bytes) -> dict:
    """A message of one of our schemas as a dict (protobuf's JSON mapping, field names as in
    the schema; bytes as base64). Scalar fields at their zero value are kept (proto3 does not
    write them): a rotation component of exactly 0 in one run and 4e-14 in another is then a
    difference of 4e-14 for the golden check, not a missing field."""
    if schema_name == STRING_SCHEMA:
        return {"data": decode_string(data)}
    return json_format.MessageToDict(
        decode(schema_name, data),
        preserving_proto_field_name=True,
        always_print_fields_with_no_presence=True,
    )
