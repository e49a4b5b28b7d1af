"""The echo of /parameter_events hides secret-named values, as /ros does for roles below admin."""

from rcl_interfaces.msg import Parameter, ParameterEvent, ParameterType, ParameterValue
from rclpy.serialization import serialize_message

from rover_web.topics.msgs import PARAMETER_EVENT, dict_decoder


def _string_parameter(name: str, value: str) -> Parameter:
    return Parameter(name=name, value=ParameterValue(type=ParameterType.PARAMETER_STRING, string_value=value))


def test_secret_values_are_hidden_and_others_kept():
    event = ParameterEvent(node="/gnss/ntrip_client",
                           new_parameters=[_string_parameter("ntrip_password", "hunter2")],
                           changed_parameters=[_string_parameter("caster_host", "rtk.example"),
                                               _string_parameter("api_key", "sk-123")])
    decoded = dict_decoder(PARAMETER_EVENT, 100)(serialize_message(event))
    assert "hunter2" not in repr(decoded) and "sk-123" not in repr(decoded)
    assert decoded["new_parameters"][0] == {"name": "ntrip_password", "value": None, "hidden": True}
    assert decoded["changed_parameters"][0]["value"]["string_value"] == "rtk.example"
    assert decoded["changed_parameters"][1]["hidden"] is True
