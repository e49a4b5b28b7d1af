"""The topic browser: GET /topics, GET /api/topics, the `topics` channel and a live echo of any topic.

`ros2 topic list -v`, `ros2 topic echo`, `hz` and `bw` in the app's own node. The topic list is
re-read from the ROS graph every ROVER_WEB_TOPICS_REFRESH_S and published on the `topics`
channel when it changes. GET /api/topics/echo?topic=... is an SSE stream of one topic's messages
(at most ROVER_WEB_TOPICS_ECHO_HZ a second) with its measured rate and bandwidth; viewers of the
same topic share one raw subscription, removed ROVER_WEB_TOPICS_ECHO_IDLE_TIMEOUT_S after the
last viewer leaves.
"""

from __future__ import annotations

from rover_web.core.state import Rover
from rover_web.i18n import N_

from . import routes
from .service import TopicBrowser


def init_app(app, rover: Rover) -> None:
    browser = TopicBrowser(rover)
    rover.add_feature(browser)
    rover.hub.register("topics")
    app.register_blueprint(routes.bp)
    rover.add_nav(N_("Topics"), "/topics")
    rover.every(browser.refresh_s, browser.refresh, name="topics-refresh", immediately=True)
    browser.echoes.start_reaper("topics-echo-reaper")
    rover.on_shutdown(browser.close)
