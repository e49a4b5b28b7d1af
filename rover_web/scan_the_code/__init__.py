"""Scan the Code: the light tower monitor, around light_sequence.LightSequence (pure logic).

- subscribes ROVER_WEB_LIGHT_SEQUENCE_TOPIC (std_msgs/String colour names);
- `light_sequence` SSE channel (conflated): the whole state, resent on every visible change;
- `scan_code` SSE channel (events, never conflated, replayable with Last-Event-ID): one per
  confirmed code, so a client that was busy still sees every detection;
- publishes each confirmed code on ROVER_WEB_CODE_TOPIC (std_msgs/String "red,green,blue",
  transient local, so a node that starts later still gets the last one);
- GET /api/light_sequence (routes.py); the dashboard panel.
"""

from __future__ import annotations

from rover_web.core.fleet import Fleet
from rover_web.core.state import Rover, current_feature
from rover_web.i18n import N_

from . import routes
from .service import CODE_CHANNEL, STATE_CHANNEL, ScanTheCodeService, sequence_from_config


def init_app(app, fleet: Fleet) -> None:
    for rover in fleet:
        _init_robot(rover)
    app.register_blueprint(routes.bp)
    # The panel renders with the state already in it; SSE keeps it current.
    app.add_template_global(lambda: current_feature(ScanTheCodeService).snapshot(), "light_sequence_state")


def _init_robot(rover: Rover) -> None:
    # Imported here: the package is imported for light_sequence alone (simulator, unit tests),
    # which must not need std_msgs.
    from . import msgs

    config = rover.config
    sequence = sequence_from_config(config)
    rover.hub.register(STATE_CHANNEL, CODE_CHANNEL)
    code_pub = rover.runtime.publisher(msgs.STRING, config["ROVER_WEB_CODE_TOPIC"], "latched")
    service = ScanTheCodeService(sequence, rover.hub, lambda colours: code_pub.publish(msgs.code_message(colours)))
    rover.add_feature(service)
    rover.runtime.subscribe(msgs.STRING, config["ROVER_WEB_LIGHT_SEQUENCE_TOPIC"],
                            lambda msg: service.observe(msgs.text_of(msg)),
                            qos=config["ROVER_WEB_LIGHT_SEQUENCE_QOS"])
    rover.every(service.freshness_period_s, service.check_fresh, name="light-sequence-freshness")
    rover.add_panel(30, "panels/scan_the_code.html", N_("Scan the Code"), channels=(STATE_CHANNEL,))
