"""The only package that imports rclpy or *_msgs. Everything else talks to ROS through it."""

INSTALL_HINT = (
    "ROS 2 (rclpy) cannot be imported: install it with `pip install -e '.[ros]'` "
    "(ROS 2 Jazzy wheels from PyPI) or run `source /opt/ros/jazzy/setup.bash` first."
)


class RosUnavailable(RuntimeError):
    """rclpy is not importable in this Python."""


def require_rclpy() -> None:
    from .generators import without_generators

    without_generators()  # before any message class is imported (generators.py)
    try:
        import rclpy  # noqa: F401
    except ImportError as exc:
        raise RosUnavailable(f"{INSTALL_HINT} ({exc})") from None
