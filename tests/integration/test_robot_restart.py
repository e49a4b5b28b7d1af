"""A robot process that dies and comes back (issue 21): SIGKILL of the simulator shows the link lost
within the stale time and stops the motion rover_web was sending; restarted, everything recovers
without restarting rover_web: the link, the camera stream, the drone panel's status, the LiveMap pose
and driving."""

import signal
import time

import pytest
import requests

from tests.support.mjpeg import MjpegClient
from tests.support.panels_support import display
from tests.support.teleop_support import Stick, is_zero, subscribe_cmd_vel, warm_up
from tests.support.waiting import wait_until

STALE_S = 1.0


def status(url):
    return requests.get(url + "/api/status", timeout=5).json()


def live_pose(url):
    default = requests.get(url + "/api/maps", timeout=5).json()["default"]
    return requests.get(f"{url}/api/maps/{default}", timeout=5).json()["map_parameters"]["current_pose"]


@pytest.mark.ros
def test_a_killed_robot_process_stops_motion_and_everything_recovers_when_it_returns(
        server_process, sim_process, ros_peer):
    server = server_process(env={"ROVER_WEB_STALE_AFTER_S": str(STALE_S), "ROVER_WEB_STATUS_PERIOD_S": "0.25",
                                 "ROVER_WEB_TELEOP_DEADMAN_S": "5"}).start()
    url = server.url
    sim = sim_process()
    peer = ros_peer("restart_listener")
    subscribe_cmd_vel(peer)
    warm_up(peer, url)
    wait_until(lambda: status(url)["robot_link"] == "ok", 30, "link ok with the simulator up")
    # The type named: the camera may be discovered after the link is ok, and the stream then waits
    # for it instead of answering 404 (a loaded machine's discovery took that long once).
    camera = MjpegClient(f"{url}/stream?topic=/camera/image_raw&msg_type=sensor_msgs/msg/Image&width=160",
                         keep_frames=False)
    stick = Stick(url)
    try:
        camera.wait_frames(3, timeout=20)
        wait_until(lambda: display(url, "drone", "status")["fresh"], 20, "the drone's status is fresh")
        wait_until(lambda: (p := live_pose(url)) and not p["stale"], 20, "the LiveMap pose is fresh")
        peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] > 0, timeout=5)

        sim.proc.send_signal(signal.SIGKILL)
        sim.proc.wait(10)
        killed = time.monotonic()
        wait_until(lambda: status(url)["robot_link"] == "stale", STALE_S + 3, "link shown lost")
        lost_after = time.monotonic() - killed
        peer.wait_for("/cmd_vel", is_zero, timeout=5)
        peer.clear("/cmd_vel")
        time.sleep(1.0)  # the stick is still held: nothing but zero goes out (a deadman of 5 s is not why)
        assert all(is_zero(e["msg"]) for e in peer.received("/cmd_vel")), "motion resumed after the link was lost"
        assert lost_after <= STALE_S + 1.5, lost_after

        frames_before = camera.count
        sim_process()  # the robot comes back; rover_web is not restarted
        wait_until(lambda: status(url)["robot_link"] == "ok", 30, "link ok again")
        camera.wait_frames(frames_before + 3, timeout=20)  # the same stream: its subscription matched the new camera
        wait_until(lambda: display(url, "drone", "status")["fresh"], 20, "the drone's status is fresh again")
        wait_until(lambda: (p := live_pose(url)) and not p["stale"], 20, "the LiveMap pose is fresh again")
        assert all(is_zero(e["msg"]) for e in peer.received("/cmd_vel")), "the held stick drove the new robot"
        stick.value = 0.0  # the operator lets go ...
        time.sleep(0.2)
        stick.value = 0.4  # ... and drives again
        peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] > 0, timeout=5)
    finally:
        stick.close()
        camera.close()
