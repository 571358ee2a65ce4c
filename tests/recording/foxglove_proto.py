"""Foxglove's protobuf messages read back by protobuf's own library, from the schema a file
or a server carries (a ``FileDescriptorSet``): a reader independent of foxglove-sdk."""

from __future__ import annotations

from functools import cache
from typing import Any


@cache
def _message_class(name: str, data: bytes) -> Any:
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

    files = list(descriptor_pb2.FileDescriptorSet.FromString(data).file)
    pool = descriptor_pool.DescriptorPool()
    added: set[str] = set()
    while files:  # each file after the files it imports
        ready = [f for f in files if set(f.dependency) <= added]
        assert ready, "a schema whose imports are not in it"
        for f in ready:
            pool.Add(f)
            added.add(f.name)
            files.remove(f)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(name))


def protobuf_decoder(schema: Any) -> Any:
    """A function decoding a message of ``schema`` (an MCAP schema record: ``name``, binary
    ``data``) into a protobuf message."""
    cls = _message_class(schema.name, bytes(schema.data))
    return cls.FromString
