"""Camera streaming in the app's own process: GET /stream (MJPEG), GET /snapshot, the camera panel.

Replaces web_video_server. One FrameProducer per distinct (topic, type, QoS, width, height,
quality): made by the first viewer, shared by the others and destroyed
ROVER_WEB_CAMERA_IDLE_TIMEOUT_S after the last one leaves; the producers of one topic share one
ROS subscription (FrameSource). Frames are encoded in request threads, once each (see stream.py),
never on the ROS executor. Each MJPEG viewer's rate, quality and size follow its link (rate.py).
GET /api/camera/streams tells who watches what, GET /api/camera/viewers what each viewer gets.
"""

from __future__ import annotations

from rover_web.core.fleet import Fleet
from rover_web.core.state import Rover, current_feature
from rover_web.i18n import N_

from . import routes, webrtc
from .service import CameraStreams


def init_app(app, fleet: Fleet) -> None:
    for rover in fleet:
        _init_robot(rover)
    app.register_blueprint(routes.bp)
    webrtc.init_app(app, fleet, lambda rover: rover.feature(CameraStreams))
    app.jinja_env.globals["camera_panel"] = lambda: current_feature(CameraStreams).panel()


def _init_robot(rover: Rover) -> None:
    streams = CameraStreams(rover)
    rover.add_feature(streams)
    streams.producers.start_reaper("camera-reaper")
    rover.on_shutdown(streams.close)
    rover.add_panel(20, "panels/camera.html", N_("Camera"))
