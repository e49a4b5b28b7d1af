"""Issue 25 in one scene: Chromium drives the demo's simulator through the link emulator's
`wifi-edge` profile (2 Mbit/s, 60 ± 40 ms each way, stalls) with the camera streaming MJPEG over
the same link. Driving stays smooth through a 400 ms stall, the video stays fresh (the time code
the simulated camera draws into each frame, read back from the page's own <img>), and the e-stop
stops the robot.

The bounds here are behaviour, not speed: a zero while the stick is held is a stutter whatever the
machine; a frame seconds old is video buried in the link's buffer (before adaptation it was 5-7 s,
BENCHMARKS.md). The figures themselves come from bench/link.py.
"""

import base64
import io
import statistics
import time

import numpy as np
import pytest
import requests
from PIL import Image

from rover_web.linkemu import LinkEmulator
from rover_web.sim import timecode
from tests.support.teleop_support import is_zero, subscribe_cmd_vel, twists, warm_up

pytestmark = [pytest.mark.browser, pytest.mark.ros]

FRESH_MS = 2500  # well above what an adapted stream shows here, well below a buried one
# The frame at 160 pixels wide (a quarter of the camera's 640; the time code's cells survive it,
# and the smallest step the stream adapts down to is that wide already): a tiny PNG, so reading it
# costs the page's main thread, which also sends the stick's frames, next to nothing.
READ_FRAME = """() => {
  const img = document.getElementById('camera-image');
  if (!img || !img.naturalWidth) return null;
  const canvas = document.createElement('canvas');
  const scale = Math.min(1, 160 / img.naturalWidth);
  canvas.width = Math.round(img.naturalWidth * scale); canvas.height = Math.round(img.naturalHeight * scale);
  canvas.getContext('2d').drawImage(img, 0, 0, canvas.width, canvas.height);
  return {png: canvas.toDataURL('image/png'), now: Date.now()};
}"""


def frame_age_ms(page) -> float | None:
    shot = page.evaluate(READ_FRAME)
    if shot is None:
        return None
    png = base64.b64decode(shot["png"].split(",", 1)[1])
    rgb = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))
    stamp = timecode.read(rgb, shot["now"])
    return None if stamp is None else shot["now"] - stamp


@pytest.fixture
def field(live_server_factory, ros_peer, sim_process):
    # The deadman stays at its default 0.3 s, shorter than the 400 ms stall: under the old rule this
    # stall stopped the robot. The hard bound is 2 s rather than 1 so that a loaded test machine
    # starving Chromium's timers is not taken for the link (the 1 s default is tested in
    # tests/integration/teleop/test_jittery_link.py).
    server = live_server_factory(ROVER_WEB_TELEOP_DEADMAN_MAX_S=2.0)
    sim_process("--only", "rover", "--only", "camera")
    peer = ros_peer()
    subscribe_cmd_vel(peer)
    warm_up(peer, server.url)
    with LinkEmulator("wifi-edge", listen="127.0.0.1:0", target=f"127.0.0.1:{server.port}", seed=7) as link:
        yield server, peer, link


def test_driving_through_wifi_edge_with_the_camera_on(field, browser):
    server, peer, link = field
    context = browser.new_context(viewport={"width": 1280, "height": 1000}, bypass_csp=True)
    # MJPEG: the video that shares the TCP link with the stick and the e-stop (WebRTC would take UDP).
    context.add_init_script("localStorage.setItem('rover_web.camera.transport', 'mjpeg')")
    page = context.new_page()
    try:
        page.goto(f"http://127.0.0.1:{link.port}/")
        page.wait_for_selector("#teleop-link[data-state='live']", timeout=20000)
        page.wait_for_function("document.getElementById('camera-image').naturalWidth > 0", timeout=30000)

        stick = page.locator("#teleop-joystick")
        stick.scroll_into_view_if_needed()
        box = stick.bounding_box()
        x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        page.mouse.move(x, y)
        page.mouse.down()
        page.mouse.move(x, y - 60, steps=6)
        try:
            peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] > 0.5, timeout=10)
        except TimeoutError:
            pytest.fail(f"the stick did not drive: /cmd_vel had {sorted({lin for _, lin, _ in twists(peer)})}; "
                        f"teleop {requests.get(server.url + '/api/teleop', timeout=5).json()}")
        t_held = time.monotonic()

        # Hold for a while with the video on, one forced 400 ms stall of the whole link in it.
        ages = []
        deadline = time.monotonic() + 8.0
        stalled = False
        while time.monotonic() < deadline:
            if not stalled and time.monotonic() > deadline - 5.0:
                link.stall(400)
                stalled = True
            age = frame_age_ms(page)
            if age is not None:
                ages.append(age)
            page.wait_for_timeout(500)
        t_end = time.monotonic()

        held = [(t, lin) for t, lin, _ in twists(peer) if t_held <= t <= t_end]
        assert len(held) > 100, f"only {len(held)} commands reached /cmd_vel in 8 s of holding"
        stops = [t for t, lin in held if lin <= 0]
        if stops:
            state = requests.get(server.url + "/api/teleop", timeout=5).json()
            around = [(round(t - t_held, 3), lin) for t, lin in held if abs(t - stops[0]) < 1.5]
            pytest.fail(f"the held stick stuttered: a zero reached /cmd_vel {stops[0] - t_held:.2f} s into the "
                        f"hold; last stop {state['last_stop']}; around it {around}")

        widths = page.evaluate("() => document.getElementById('camera-image').naturalWidth")
        assert len(ages) >= 5, f"only {len(ages)} readable frames in 8 s (the image is {widths} wide)"
        assert statistics.median(ages) < FRESH_MS, f"video not fresh: frame ages {sorted(ages)}"

        # The e-stop, still holding the stick, with the video running: the robot stops.
        page.click("#estop-engage")
        peer.wait_for("/cmd_vel", lambda m: is_zero(m), timeout=5)
        # The page shows "sending…" at once and the latch only once the server confirmed it: the
        # click's frame may still be queued behind video on the link when a stale stick's zero lands.
        page.wait_for_selector("#estop[data-engaged='yes'][data-unconfirmed='no']", timeout=10000)
        assert requests.get(server.url + "/api/estop", timeout=5).json()["engaged"] is True
        time.sleep(0.5)
        last = twists(peer)[-1]
        assert last[1] == 0.0 and last[2] == 0.0, "something moved after the e-stop"
        page.mouse.up()
    finally:
        context.close()
