"""Property: whatever a joystick frame says, what reaches /cmd_vel is finite, within the maxima,
and only linear.x / angular.z are ever non-zero.

Frames go through the real parser and controller; the output builds the real geometry_msgs
message with the same function rover.cmd_vel uses, so every field of the Twist is checked.
"""

import json
import math

from hypothesis import given, settings
from hypothesis import strategies as st

from rover_web.ros.cmd_vel import clamp
from rover_web.ros.convert import twist_message
from rover_web.teleop.commands import Limits, Refused
from rover_web.teleop.control import TeleopController
from rover_web.teleop.protocol import Drive, FrameError, parse_frame

MAX_BYTES = 4096

numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=-1.0, max_value=1.0),
    st.integers(min_value=-10**30, max_value=10**30),
    st.sampled_from([0, 1, -1, 1.0000001, -1.0000001, 5e-324, 1e308]),
)
values = st.one_of(numbers, st.text(max_size=5), st.none(), st.booleans(), st.lists(numbers, max_size=2))


def to_text(obj) -> str:
    # Python writes NaN/Infinity as bare tokens, the way a hand-made client would send them.
    return json.dumps(obj, allow_nan=True)


frames = st.one_of(
    st.fixed_dictionaries({"linear": values, "angular": values}).map(to_text),
    st.fixed_dictionaries({"linear": numbers, "angular": numbers},
                          optional={"epoch": st.integers(0, 3),
                                    "source": st.sampled_from(["joystick", "keyboard", "x"]),
                                    "seq": st.one_of(st.integers(-1, 10), numbers), "t": numbers}
                          ).map(to_text),
    st.dictionaries(st.sampled_from(["linear", "angular", "stop", "epoch", "z"]), values, max_size=4).map(to_text),
    st.text(max_size=40),
    st.sampled_from(['{"linear": 1e400, "angular": 0}', '{"linear": -1e400, "angular": 1}',
                     '{"linear": NaN, "angular": NaN}', '{"linear": 1, "angular": Infinity}']),
)


class TwistOutput:
    """Like CmdVelOutput (clamp, then build the message), keeping every message built."""

    def __init__(self, limits: Limits, stamped: bool):
        self.limits, self.stamped, self.messages = limits, stamped, []

    def send(self, linear, angular):
        self._publish(clamp(linear, self.limits.max_linear_mps), clamp(angular, self.limits.max_angular_rps))

    def zero(self):
        self._publish(0.0, 0.0)

    def _publish(self, linear, angular):
        msg = twist_message(linear, angular, stamped=self.stamped, frame_id="base_link")
        self.messages.append(msg.twist if self.stamped else msg)


@settings(max_examples=400, deadline=None)
@given(batch=st.lists(frames, min_size=1, max_size=8),
       max_linear=st.sampled_from([0.0, 0.5, 5.0, 100.0]), max_angular=st.sampled_from([0.0, 2.0, 100.0]),
       stamped=st.booleans())
def test_published_twists_are_finite_bounded_and_planar(batch, max_linear, max_angular, stamped):
    limits = Limits(max_linear, max_angular)
    out = TwistOutput(limits, stamped)
    ctl = TeleopController(out, limits)
    session = ctl.connect()
    for text in batch:
        try:
            frame = parse_frame(text, MAX_BYTES)
        except FrameError:
            ctl.stop(session, "bad_input")
            continue
        if isinstance(frame, Drive):
            assert -1 <= frame.linear <= 1 and -1 <= frame.angular <= 1
            try:
                ctl.drive(session, frame.linear, frame.angular, epoch=frame.epoch, source=frame.source,
                          seq=frame.seq, sent_ms=frame.t)
            except Refused:
                pass
        ctl.tick()
    for twist in out.messages:
        fields = [twist.linear.x, twist.linear.y, twist.linear.z, twist.angular.x, twist.angular.y, twist.angular.z]
        assert all(math.isfinite(v) for v in fields)
        assert abs(twist.linear.x) <= max_linear and abs(twist.angular.z) <= max_angular
        assert twist.linear.y == twist.linear.z == twist.angular.x == twist.angular.y == 0.0


@settings(max_examples=300, deadline=None)
@given(linear=numbers, angular=numbers)
def test_controller_scales_any_number_into_the_maxima(linear, angular):
    limits = Limits(5.0, 2.0)
    out = TwistOutput(limits, False)
    ctl = TeleopController(out, limits)
    lin, ang = ctl.drive(ctl.connect(), linear, angular)
    assert math.isfinite(lin) and math.isfinite(ang)
    assert abs(lin) <= 5.0 and abs(ang) <= 2.0
    if isinstance(linear, float) and math.isfinite(linear) and abs(linear) <= 1:
        assert lin == linear * 5.0
