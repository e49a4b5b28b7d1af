"""`flask --app rover_web replay FILE`: publish a recording's messages with their original timing.

As `ros2 bag play` does: each message's CDR bytes go out unchanged (rclpy publishes bytes as a
serialized message), at its recorded log time relative to the first one, divided by --rate. It
runs its own rclpy context and node (the CLI never starts the app's), so a team can rehearse with
real data and no robot. The audit channel (/rover_web/audit) is only replayed when named in --topics:
it was never a ROS topic.

Motion and safety are left out unless --include-motion (issue 40): a recording's /cmd_vel would drive
a robot listening on the domain, and its /e_stop would release one engaged since; an uploaded file
comes from elsewhere. Left out: the app's own ROVER_WEB_CMD_VEL_TOPIC and ROVER_WEB_ESTOP_TOPIC, any
topic named cmd_vel*, e_stop or estop, any Twist or TwistStamped, and anything of an action (its
hidden `/_action/` topics, goal types). Each one left out is said on stderr.

/tf_static goes out transient local, as tf2's static broadcasters publish it (its subscribers match
nothing else).
"""

from __future__ import annotations

import time
from pathlib import Path

import click
from flask import Flask, current_app

NODE_NAME = "rover_web_replay"
AUDIT_TOPIC = "/rover_web/audit"
MOTION_TYPES = frozenset({"geometry_msgs/msg/Twist", "geometry_msgs/msg/TwistStamped", "geometry_msgs/Twist",
                          "geometry_msgs/TwistStamped"})
SAFETY_NAMES = ("e_stop", "estop", "emergency_stop")


def moves_or_stops(topic: str, type_name: str, own: tuple[str, ...] = ()) -> bool:
    """True for a topic whose replay could move a robot or change its e-stop."""
    leaf = topic.rstrip("/").rsplit("/", 1)[-1].lower()
    return (topic in own or leaf.startswith("cmd_vel") or leaf in SAFETY_NAMES or type_name in MOTION_TYPES
            or "/_action/" in topic or type_name.endswith(("_Goal", "_SendGoal_Request", "_SendGoal_Event")))


def init_cli(app: Flask) -> None:
    @app.cli.command("replay")
    @click.argument("file", type=click.Path(exists=True, dir_okay=False, path_type=Path))
    @click.option("--rate", type=click.FloatRange(0.01, 100), default=1.0, show_default=True,
                  help="speed: 2 plays twice as fast as recorded")
    @click.option("--loop", is_flag=True, help="start again from the beginning at the end, until Ctrl-C")
    @click.option("--topics", multiple=True,
                  help="only these topics (repeat the option, or separate with commas); default: all but the audit")
    @click.option("--delay", type=click.FloatRange(0, 60), default=1.0, show_default=True,
                  help="seconds between making the publishers and the first message, for subscribers to match")
    @click.option("--include-motion", is_flag=True,
                  help="also publish velocity commands, e-stop and action topics (left out by default: they "
                       "would move or release a robot on this domain)")
    def replay(file: Path, rate: float, loop: bool, topics: tuple[str, ...], delay: float, include_motion: bool):
        """Publish FILE's messages (an MCAP recording) with their original timing."""
        from rover_web.recording.reading import NotARecording

        wanted = {t.strip() for entry in topics for t in entry.replace(",", " ").split() if t.strip()}
        config = current_app.config
        own = None if include_motion else (config.get("ROVER_WEB_CMD_VEL_TOPIC") or "/cmd_vel",
                                           config.get("ROVER_WEB_ESTOP_TOPIC") or "/e_stop")
        player = _Player(config.get("ROVER_WEB_ROS_DOMAIN_ID"), rate, wanted, delay, own)
        try:
            while True:
                cut_short, sent = player.play_once(file)
                if sent == 0:
                    shown = ", ".join(sorted(wanted)) if wanted else "any topic"
                    raise click.ClickException(f"{file}: no message of {shown} to replay")
                click.echo(f"replayed {sent} messages from {file}")
                if cut_short:
                    raise click.ClickException(f"{file} was cut short (no footer): replayed up to its last "
                                               f"complete chunk")
                if not loop:
                    break
        except NotARecording as exc:  # bounds.TooCostly too: the file costs more than a read may
            raise click.ClickException(str(exc)) from None
        except KeyboardInterrupt:
            click.echo("replay stopped")
        finally:
            player.close()


STATIC_TF_DEPTH = 100


def _static_tf(type_name: str, topic: str) -> bool:
    return type_name == "tf2_msgs/msg/TFMessage" and topic.rstrip("/").endswith("tf_static")


class _Player:
    def __init__(self, domain_id: int | None, rate: float, wanted: set[str], delay: float,
                 motion_topics: tuple[str, ...] | None = None):
        from rover_web.ros.raw import RawPublisherNode

        self.motion_topics = motion_topics  # None: motion and safety included (--include-motion)
        self.rate = rate
        self.wanted = wanted
        self.delay = delay
        self.ros = RawPublisherNode(NODE_NAME, domain_id)
        self._publishers: dict[int, object] = {}
        self._skipped: set[str] = set()

    def _publisher(self, schema, channel):
        from rover_web.ros.typesupport import UnknownMessageType

        found = self._publishers.get(channel.id)
        if found is not None or channel.topic in self._skipped:
            return found
        if (self.wanted and channel.topic not in self.wanted) or (not self.wanted and channel.topic == AUDIT_TOPIC) \
                or channel.message_encoding != "cdr" or schema is None:
            self._skipped.add(channel.topic)
            return None
        if self.motion_topics is not None and moves_or_stops(channel.topic, schema.name, self.motion_topics):
            click.echo(f"skipping {channel.topic} ({schema.name}): motion or safety, replayed only with "
                       f"--include-motion", err=True)
            self._skipped.add(channel.topic)
            return None
        try:
            if _static_tf(schema.name, channel.topic):
                # tf2's listeners take /tf_static transient local only: a volatile publisher would
                # never reach them. Every static message of the file is kept for late joiners, as
                # each static broadcaster keeps its own.
                publisher = self.ros.publisher(schema.name, channel.topic, STATIC_TF_DEPTH, latched=True)
            else:
                publisher = self.ros.publisher(schema.name, channel.topic)
        except UnknownMessageType as exc:
            click.echo(f"skipping {channel.topic}: {exc}", err=True)
            self._skipped.add(channel.topic)
            return None
        self._publishers[channel.id] = publisher
        return publisher

    def play_once(self, file: Path) -> tuple[bool, int]:
        """(cut short, messages published)."""
        from rover_web.recording.reading import Outcome, read_messages

        outcome = Outcome()
        first_log = start = None
        sent = 0
        for schema, channel, message in read_messages(file, outcome):
            publisher = self._publisher(schema, channel)
            if publisher is None:
                continue
            if first_log is None:
                time.sleep(self.delay)  # publishers made so far get matched before the first message
                first_log, start = message.log_time, time.monotonic()
            due = start + (message.log_time - first_log) / 1e9 / self.rate
            wait = due - time.monotonic()
            if wait > 0:
                time.sleep(wait)
            publisher.publish(message.data)  # bytes: published as the serialized message, unchanged
            sent += 1
        return not outcome.complete, sent

    def close(self) -> None:
        self.ros.close()
