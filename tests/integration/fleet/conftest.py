"""Two namespaced robots, boat (/boat) and drone (/drone), served by one app, and a ROS peer in
another process listening on both robots' velocity topics and on the un-namespaced one."""

from __future__ import annotations

import pytest

from tests.support.teleop_support import TWIST, subscribe_cmd_vel, warm_up

from .helpers import CMD_VEL, NAMES, ROBOTS, ROOT_CMD_VEL


@pytest.fixture
def fleet_server(live_server_factory):
    """make(**settings): a live server for boat and drone; `.robot[name]` is each robot's base URL."""

    def make(**settings):
        server = live_server_factory(ROVER_WEB_ROBOTS=ROBOTS, **settings)
        server.robot = {name: f"{server.url}/robots/{name}" for name in NAMES}
        return server

    return make


@pytest.fixture
def drive_rig(fleet_server, ros_peer):
    """make(**settings) -> (server, peer): the peer hears both robots' cmd_vel (warmed up, cleared)
    and /cmd_vel."""

    def make(**settings):
        server = fleet_server(**settings)
        peer = ros_peer("fleet_listener")
        for name in NAMES:
            subscribe_cmd_vel(peer, topic=CMD_VEL[name])
        peer.subscribe(ROOT_CMD_VEL, TWIST, max_items=8)
        for name in NAMES:
            warm_up(peer, server.robot[name], topic=CMD_VEL[name])
        peer.clear(ROOT_CMD_VEL)
        return server, peer

    return make
