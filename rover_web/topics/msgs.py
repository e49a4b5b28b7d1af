"""Any topic's messages as JSON-ready dicts, for the echo."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rover_web.ros.convert import message_to_dict
from rover_web.ros.graph import deserializer
from rover_web.ros_admin.secret_params import is_secret

# Every node announces its parameter changes here, new values included: without this, echoing the
# topic would show any viewer the ntrip_password that /ros hides from everyone below admin.
PARAMETER_EVENT = "rcl_interfaces/msg/ParameterEvent"


def dict_decoder(type_name: str, max_items: int) -> Callable[[bytes], dict[str, Any]]:
    """A function from a serialized message of `type_name` to its fields as a JSON-ready dict.

    Raises UnknownMessageType (from message_class) if the type cannot be imported.
    """
    deserialize = deserializer(type_name)

    def decode(serialized: bytes) -> dict[str, Any]:
        return message_to_dict(deserialize(serialized), max_items)

    if type_name == PARAMETER_EVENT:
        return lambda serialized: hide_secret_parameters(decode(serialized))
    return decode


def hide_secret_parameters(event: dict[str, Any]) -> dict[str, Any]:
    """A ParameterEvent with the value of every secret-named parameter replaced by null."""
    for key in ("new_parameters", "changed_parameters"):
        parameters = event.get(key)
        if isinstance(parameters, list):
            event[key] = [{**p, "value": None, "hidden": True}
                          if isinstance(p, dict) and is_secret(str(p.get("name", ""))) else p
                          for p in parameters]
    return event
