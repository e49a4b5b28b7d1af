"""Any topic's messages as JSON-ready dicts, for the echo."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rover_web.ros.convert import message_to_dict
from rover_web.ros.graph import deserializer


def dict_decoder(type_name: str, max_items: int) -> Callable[[bytes], dict[str, Any]]:
    """A function from a serialized message of `type_name` to its fields as a JSON-ready dict.

    Raises UnknownMessageType (from message_class) if the type cannot be imported.
    """
    deserialize = deserializer(type_name)

    def decode(serialized: bytes) -> dict[str, Any]:
        return message_to_dict(deserialize(serialized), max_items)

    return decode
