"""WebRTC video (WHEP) and the teleop data channel, in the app's own process.

  POST   /api/camera/whep?topic=T   an SDP offer (application/sdp) → 201, the answer, Location
  DELETE /api/camera/whep/<id>      ends that session
  GET    /api/camera/whep           the sessions, without their ids

One asyncio loop thread (loop.py) carries every peer connection of the process; each robot has a
WebRtcService (service.py). Frames come from a FrameProducer (the camera's subscription and
newest-message store) converted to pictures once per message (frames.py), each viewer's track
(track.py) encodes at its own level (adapt.py) in aiortc's pool. Host candidates and ICE servers
come from the settings only (ice.py). See docs/camera.md.
"""

from __future__ import annotations

from rover_web.core.fleet import Fleet
from rover_web.core.state import current_feature

from . import routes
from .loop import LoopThread
from .service import WebRtcService


def init_app(app, fleet: Fleet, camera_of) -> None:
    """`camera_of(rover)` is that robot's CameraStreams (its query parsing is reused)."""
    loop = LoopThread("webrtc-loop")
    loop.start()
    # On the first robot, registered before any service's close: hooks run in reverse, and the
    # first robot winds down last, so the loop outlives every session it has to close.
    fleet.first.on_shutdown(lambda: loop.stop(fleet.first.config["ROVER_WEB_SHUTDOWN_TIMEOUT_S"]))
    for rover in fleet:
        service = WebRtcService(rover, loop, camera_of(rover))
        rover.add_feature(service)
        service.start()
        rover.on_shutdown(service.close)
    app.register_blueprint(routes.bp)
    app.jinja_env.globals["webrtc_panel"] = lambda: {"enabled": current_feature(WebRtcService).max_viewers > 0}
