"""The 3D view in Chromium (software WebGL), fed by real ROS publishers in another process playing
robot_state_publisher's part: the description latched on /robot_description, /joint_states, and the
TF those joints give. Pixel checks: each coloured link is drawn where its TF puts it, a joint turned
by /joint_states turns the link on the page, a mesh from a package share is drawn, markers of every
kind are drawn in their frame, and a point cloud arrives and is drawn; without WebGL the page says so."""

import io
import math
import struct
import time

import pytest
from PIL import Image

from tests.support.view3d_support import ROBOT_URDF, ament_prefix
from tests.support.waiting import wait_until

pytestmark = [pytest.mark.browser, pytest.mark.ros]

STRING = "std_msgs/msg/String"
JOINT_STATE = "sensor_msgs/msg/JointState"
TF = "tf2_msgs/msg/TFMessage"
MARKERS = "visualization_msgs/msg/MarkerArray"
CLOUD = "sensor_msgs/msg/PointCloud2"
BASE_IN_ODOM = (2.0, 1.0)  # where TF puts the robot: far from the URDF's own origin


def stamp(t):
    return {"sec": int(t), "nanosec": int((t - int(t)) * 1e9)}


def transform(parent, child, xyz, yaw=0.0, t=None):
    return {"header": {"stamp": stamp(t if t is not None else time.time()), "frame_id": parent},
            "child_frame_id": child,
            "transform": {"translation": dict(zip("xyz", map(float, xyz), strict=True)),
                          "rotation": {"z": math.sin(yaw / 2), "w": math.cos(yaw / 2)}}}


class UrdfPeer:
    """robot_state_publisher's part: the description, the joint's state and the TF it gives."""

    def __init__(self, peer):
        self.peer = peer
        peer.advertise("/robot_description", STRING, qos="latched")
        peer.publish("/robot_description", {"data": ROBOT_URDF})
        peer.advertise("/tf_static", TF, qos="latched")
        peer.publish("/tf_static", {"transforms": [transform("base_link", "mast", (-0.2, 0, 0.1), t=0)]})
        peer.advertise("/tf", TF, qos=100)
        peer.advertise("/joint_states", JOINT_STATE, qos=10)

    def joint(self, angle):
        now = time.time()
        self.peer.publish("/joint_states", {"header": {"stamp": stamp(now)}, "name": ["arm_joint"],
                                            "position": [angle]})
        self.peer.publish("/tf", {"transforms": [
            transform("odom", "base_link", (*BASE_IN_ODOM, 0), t=now),
            transform("base_link", "arm", (0, 0, 0.15), yaw=angle, t=now)]})


def canvas_image(page):
    return Image.open(io.BytesIO(page.locator("#view3d canvas").screenshot())).convert("RGB")


def colour_at(page, image, x, y, z=0.0):
    p = page.evaluate("([x, y, z]) => document.getElementById('view3d').view3d.project(x, y, z)", [x, y, z])
    r, g, b = image.getpixel((round(p["x"]), round(p["y"])))
    if r > 110 and g < 90 and b < 90:
        return "red"
    if g > 110 and r < 90 and b < 90:
        return "green"
    if b > 110 and r < 90 and g < 90:
        return "blue"
    if max(r, g, b) < 60:
        return "background"
    return f"other{(r, g, b)}"


def dataset(page):
    return page.evaluate("() => ({...document.getElementById('view3d').dataset})")


@pytest.fixture
def scene(live_server_factory, ros_peer, page, tmp_path, monkeypatch):
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(ament_prefix(tmp_path)))
    urdf = UrdfPeer(ros_peer("urdf_peer"))
    server = live_server_factory(ROVER_WEB_POINTCLOUD_TOPIC="/points")
    urdf.peer.wait_match("/tf")
    urdf.joint(0.0)
    page.goto(server.url + "/3d")
    wait_until(lambda: dataset(page).get("links") == "3", 20, "the model built")
    page.select_option("#view3d-fixed", "odom")
    return server, urdf


def look_down(page, urdf, angle):
    """Publish the joint until the page has placed every link from TF, then look straight down."""
    def placed():
        urdf.joint(angle)
        return dataset(page).get("tfLinks") == "3" and dataset(page).get("fixedKnown") == "true"
    wait_until(placed, 20, "every link placed from TF in odom", interval=0.2)
    page.click("#view3d-top")
    time.sleep(0.3)


def test_links_are_drawn_where_tf_puts_them_and_a_joint_turns(scene, page):
    server, urdf = scene
    bx, by = BASE_IN_ODOM
    look_down(page, urdf, 0.0)
    image = canvas_image(page)
    assert colour_at(page, image, bx + 0.2, by + 0.2, 0.1) == "blue"       # the base, at TF's odom -> base_link
    assert colour_at(page, image, bx + 0.8, by, 0.2) == "red"              # the arm along +x at angle 0
    assert colour_at(page, image, bx, by + 0.8, 0.2) == "background"
    assert colour_at(page, image, bx - 0.2, by, 0.6) == "green"            # the mast: a package:// mesh
    assert colour_at(page, image, 0.2, 0.2, 0.1) == "background"           # nothing at the URDF's own origin

    def turned():
        urdf.joint(math.pi / 2)
        image = canvas_image(page)
        return (colour_at(page, image, bx, by + 0.8, 0.2) == "red"
                and colour_at(page, image, bx + 0.8, by, 0.2) == "background")
    wait_until(turned, 15, "the arm turned to +y by /joint_states through TF", interval=0.3)
    assert page.watch.console_errors == []
    assert page.watch.offhost == []


def marker(kind, mid, xy, rgb, **extra):
    base = {"header": {"frame_id": "odom"}, "ns": "kinds", "id": mid, "type": kind, "action": 0,
            "pose": {"position": {"x": xy[0], "y": xy[1], "z": 0.1}, "orientation": {"w": 1.0}},
            "scale": {"x": 0.4, "y": 0.4, "z": 0.4}, "color": {"r": rgb[0], "g": rgb[1], "b": rgb[2], "a": 1.0}}
    base.update(extra)
    return base


def pts(*xyz):
    return [{"x": x, "y": y, "z": z} for x, y, z in xyz]


def test_markers_of_every_kind(scene, page):
    server, urdf = scene
    square = pts((-0.2, -0.2, 0), (0.2, -0.2, 0), (0.2, 0.2, 0), (-0.2, 0.2, 0), (-0.2, -0.2, 0))
    triangles = pts((-0.3, -0.3, 0), (0.3, -0.3, 0), (0, 0.3, 0))
    mesh = "package://testbot_description/meshes/mast.stl"
    markers = [
        marker(0, 0, (-1, 3), (1, 0, 0), scale={"x": 0.6, "y": 0.15, "z": 0.15}),   # arrow
        marker(1, 1, (0, 3), (1, 0, 0)),                                            # cube
        marker(2, 2, (1, 3), (0, 1, 0)),                                            # sphere
        marker(3, 3, (2, 3), (0, 0, 1)),                                            # cylinder
        marker(4, 4, (3, 3), (1, 0, 0), points=square, scale={"x": 0.05}),          # line strip
        marker(5, 5, (4, 3), (0, 1, 0), points=square[:4], scale={"x": 0.05}),      # line list
        marker(6, 6, (-1, -1), (1, 0, 0), points=pts((0, 0, 0), (0.5, 0, 0))),      # cube list
        marker(7, 7, (0, -1), (0, 1, 0), points=pts((0, 0, 0), (0.5, 0, 0))),       # sphere list
        marker(8, 8, (1, -1), (0, 0, 1), points=pts((0, 0, 0), (0.1, 0, 0)), scale={"x": 0.1, "y": 0.1}),
        marker(9, 9, (2, -1), (1, 1, 1), text="hello"),                             # text
        marker(10, 10, (3, -1), (0, 1, 0), mesh_resource=mesh, scale={"x": 2, "y": 2, "z": 1}),  # mesh
        marker(11, 11, (4, -1), (1, 0, 0), points=triangles, scale={"x": 1, "y": 1, "z": 1}),  # triangles
    ]
    urdf.peer.advertise("/visualization_marker_array", MARKERS, qos=10)
    urdf.peer.wait_match("/visualization_marker_array")

    def drawn():
        urdf.peer.publish("/visualization_marker_array", {"markers": markers})
        return page.evaluate("""() => document.getElementById('view3d').view3d.layers.markers.items
                                      .filter((i) => i.holder.visible).map((i) => i.holder.userData.kind)""")
    kinds = wait_until(lambda: (k := drawn()) and len(k) == 12 and k, 15, "12 markers drawn")
    assert sorted(kinds) == sorted(["arrow", "cube", "sphere", "cylinder", "line_strip", "line_list", "cube_list",
                                    "sphere_list", "points", "text", "mesh", "triangle_list"])
    look_down(page, urdf, 0.0)
    page.evaluate("""() => { const v = document.getElementById('view3d').view3d;
                             v.camera.position.set(1.5, 1.0, 12); v.controls.target.set(1.5, 1.0, 0);
                             v.controls.update(); v.requestDraw(); }""")
    time.sleep(0.5)
    image = canvas_image(page)
    assert colour_at(page, image, 0, 3, 0.3) == "red"          # cube
    assert colour_at(page, image, 1, 3, 0.3) == "green"        # sphere
    assert colour_at(page, image, 2, 3, 0.3) == "blue"         # cylinder
    assert colour_at(page, image, -1, -1, 0.6) == "red"        # cube list, first cube
    assert colour_at(page, image, -0.5, -1, 0.6) == "red"      # cube list, second
    assert colour_at(page, image, 0.5, -1, 0.6) == "green"     # sphere list, second
    assert colour_at(page, image, 3, -1, 0.6) == "green"       # the mesh, from the package share
    assert colour_at(page, image, 4, -1.1, 0.1) == "red"       # the triangle
    assert colour_at(page, image, -0.6, 3, 0.1) == "red"       # the arrow's shaft, along x
    assert page.watch.console_errors == []


def cloud_msg(n_side=60):
    """A flat square of points at z = 0.5 m, 1 m on a side, around (5, 0) in base_link, with intensity."""
    data = bytearray()
    for i in range(n_side):
        for j in range(n_side):
            data += struct.pack("<4f", 4.5 + i / n_side, -0.5 + j / n_side, 0.5, float(i))
    fields = [{"name": n, "offset": 4 * k, "datatype": 7, "count": 1}
              for k, n in enumerate(("x", "y", "z", "intensity"))]
    return {"header": {"frame_id": "base_link"}, "height": 1, "width": n_side * n_side, "fields": fields,
            "is_bigendian": False, "point_step": 16, "row_step": 16 * n_side * n_side, "data": list(data),
            "is_dense": True}


def test_a_point_cloud_is_drawn_where_its_frame_is(scene, page):
    server, urdf = scene
    urdf.peer.advertise("/points", CLOUD, qos="sensor_data")
    urdf.peer.wait_match("/points")
    msg = cloud_msg()

    def arrived():
        urdf.peer.publish("/points", msg)
        return page.evaluate("() => document.getElementById('view3d').view3d.layers.cloud.received")
    wait_until(arrived, 15, "a cloud drawn", interval=0.3)
    header = page.evaluate("() => document.getElementById('view3d').view3d.layers.cloud.last.header")
    assert header["count"] == 3600 and header["frame_id"] == "base_link" and header["intensity"] is True
    look_down(page, urdf, 0.0)
    page.evaluate("""() => { const v = document.getElementById('view3d').view3d;
                             v.camera.position.set(7, 1, 6); v.controls.target.set(7, 1, 0);
                             v.controls.update(); v.requestDraw(); }""")
    time.sleep(0.3)
    image = canvas_image(page)
    bx, by = BASE_IN_ODOM
    inside = colour_at(page, image, bx + 5.0, by + 0.0, 0.5)
    assert inside not in ("background",), inside                 # points where base_link + (5, 0) is in odom
    assert colour_at(page, image, bx + 5.0, by + 1.5, 0.5) == "background"


def test_without_webgl_the_page_says_so(live_server, page):
    page.add_init_script("HTMLCanvasElement.prototype.getContext = function () { return null; };")
    page.goto(live_server.url + "/3d")
    notice = page.locator("#view3d-nowebgl")
    notice.wait_for(state="visible", timeout=10000)
    assert "no WebGL" in notice.inner_text()


def test_the_dashboard_card_draws_the_model_and_stops_while_hidden(live_server_factory, page, tmp_path, monkeypatch):
    import requests

    monkeypatch.setenv("AMENT_PREFIX_PATH", str(ament_prefix(tmp_path)))
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(ROBOT_URDF)
    server = live_server_factory(ROVER_WEB_URDF_FILE=str(urdf), ROVER_WEB_POINTCLOUD_TOPIC="/points")
    doc = {"version": 1, "name": "3D", "cards": [{"type": "view3d", "x": 0, "y": 0, "w": 6, "h": 6,
                                                  "settings": {"fixed": "robot"}}]}
    made = requests.post(server.url + "/api/layouts", json=doc, timeout=5)
    assert made.status_code == 201, made.text
    assert requests.put(server.url + "/api/me/layout", json={"id": made.json()["id"]}, timeout=5).status_code == 200
    cloud_polls = []
    page.on("request", lambda r: cloud_polls.append(time.monotonic()) if "/api/3d/cloud" in r.url else None)
    page.goto(server.url + "/")
    stage = page.locator("[data-view3d-stage]")
    wait_until(lambda: stage.get_attribute("data-links") == "3", 20, "the card's model built")
    image = Image.open(io.BytesIO(stage.locator("canvas").screenshot())).convert("RGB")
    p = page.evaluate("() => document.querySelector('[data-view3d-stage]').view3d.project(-0.2, -0.2, 0.1)")
    r, g, b = image.getpixel((round(p["x"]), round(p["y"])))
    assert b > 110 and r < 90 and g < 90, (r, g, b)  # the blue base at the robot's origin
    wait_until(lambda: cloud_polls, 10, "the card asks for the cloud while shown")
    # Hidden (another tab in front): no more drawing and no more cloud requests.
    page.evaluate("""() => { Object.defineProperty(document, 'hidden', { value: true, configurable: true });
                             document.dispatchEvent(new Event('visibilitychange')); }""")
    time.sleep(0.5)
    drawn, polls = stage.get_attribute("data-drawn"), len(cloud_polls)
    page.evaluate("() => document.querySelector('[data-view3d-stage]').view3d.requestDraw()")
    time.sleep(3)
    assert stage.get_attribute("data-drawn") == drawn
    assert len(cloud_polls) == polls
    assert page.watch.console_errors == []


def test_a_marker_is_drawn_where_its_frame_was_at_its_stamp(scene, page):
    """tf2's and RViz's placement: a cube stamped a second ago in base_link stays where base_link was
    then while the robot drives on; the same cube frame_locked rides with base_link, red over green."""
    server, urdf = scene
    look_down(page, urdf, 0.0)
    urdf.peer.advertise("/visualization_marker_array", MARKERS, qos=10)
    urdf.peer.wait_match("/visualization_marker_array")
    then = time.time() - 1.0

    def cube(mid, rgb, frame_locked):
        m = marker(1, mid, (0, -1), rgb, frame_locked=frame_locked)  # 1 m right of base_link: clear of the model
        m["header"] = {"frame_id": "base_link", "stamp": stamp(then)}
        return m

    def holders():
        now = time.time()
        urdf.peer.publish("/tf", {"transforms": [transform("odom", "base_link", (*BASE_IN_ODOM, 0), t=then),
                                                 transform("base_link", "arm", (0, 0, 0.15), t=then)]})
        urdf.peer.publish("/tf", {"transforms": [transform("odom", "base_link", (5.0, -2.0, 0), t=now),
                                                 transform("base_link", "arm", (0, 0, 0.15), t=now)]})
        urdf.peer.publish("/visualization_marker_array", {"markers": [cube(1, (0, 1, 0), False),
                                                                      cube(2, (1, 0, 0), True)]})
        return page.evaluate("""() => Object.fromEntries(document.getElementById('view3d').view3d.layers.markers.items
            .filter((i) => i.holder.visible).map((i) => [i.holder.userData.id, [i.holder.matrix.elements[12],
                                                                                i.holder.matrix.elements[13]]]))""")
    placed = wait_until(lambda: (h := holders()) and len(h) == 2 and h["2"][0] > 4.9 and h, 15,
                        "both cubes placed, the frame-locked one with the robot's latest pose", interval=0.3)
    assert placed["1"] == pytest.approx(list(BASE_IN_ODOM), abs=1e-3)  # where base_link was at the stamp
    assert placed["2"] == pytest.approx([5.0, -2.0], abs=1e-3)          # frame_locked: where it is now
    page.evaluate("""() => { const v = document.getElementById('view3d').view3d;
                             v.camera.position.set(3.5, -1.5, 12); v.controls.target.set(3.5, -1.5, 0);
                             v.controls.update(); v.requestDraw(); }""")
    time.sleep(0.5)
    image = canvas_image(page)
    assert colour_at(page, image, BASE_IN_ODOM[0], BASE_IN_ODOM[1] - 1, 0.3) == "green"
    assert colour_at(page, image, 5.0, -3.0, 0.3) == "red"
    assert page.watch.console_errors == []


def test_livemap_overlays_in_3d_in_the_map_frame(live_server_factory, ros_peer, page, tmp_path, monkeypatch):
    """The scan, a costmap and the plan the overlays already send, drawn on the ground where the map
    frame is (map -> odom from TF), from the same channels LiveMap reads."""
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(ament_prefix(tmp_path)))
    urdf = UrdfPeer(ros_peer("urdf_peer"))
    urdf.peer.publish("/tf_static", {"transforms": [transform("base_link", "mast", (-0.2, 0, 0.1), t=0),
                                                    transform("map", "odom", (-1.0, 0.0, 0), t=0)]})
    urdf.peer.advertise("/scan", "sensor_msgs/msg/LaserScan", qos="sensor_data")
    urdf.peer.advertise("/global_costmap/costmap", "nav_msgs/msg/OccupancyGrid", qos="latched")
    urdf.peer.advertise("/plan", "nav_msgs/msg/Path", qos=1)
    server = live_server_factory(ROVER_WEB_COSTMAP_TOPICS=["/global_costmap/costmap"])
    # a lethal square 1 m a side at (3, -3)..(4, -2) in the map frame
    urdf.peer.publish("/global_costmap/costmap", {
        "header": {"frame_id": "map"},
        "info": {"width": 10, "height": 10, "resolution": 0.1,
                 "origin": {"position": {"x": 3.0, "y": -3.0}, "orientation": {"w": 1.0}}},
        "data": [100] * 100})
    page.goto(server.url + "/3d")
    wait_until(lambda: dataset(page).get("links") == "3", 20, "the model built")
    page.check("[data-layer='costmap']")
    page.select_option("#view3d-fixed", "map")
    ranges = [float("inf")] * 360
    ranges[180] = 3.0  # straight ahead, along the map's +x (a scan in the map frame, as a simulator's)
    scan = {"header": {"frame_id": "map"}, "angle_min": -math.pi, "angle_max": math.pi - math.pi / 180,
            "angle_increment": math.pi / 180, "range_min": 0.05, "range_max": 20.0, "ranges": ranges}
    plan = {"header": {"frame_id": "map"},
            "poses": [{"header": {"frame_id": "map"}, "pose": {"position": {"x": float(x), "y": 2.0}}}
                      for x in range(5)]}

    def drawn():
        urdf.joint(0.0)
        urdf.peer.publish("/scan", scan)
        urdf.peer.publish("/plan", plan)
        return page.evaluate("""() => { const v = document.getElementById('view3d').view3d;
            const n = (name) => v.overlays.groups[name].children.length;
            return v.overlays.map.visible && n('scan') && n('costmap') && n('plan') ? true : false; }""")
    wait_until(drawn, 20, "scan, costmap and plan in 3D", interval=0.3)
    page.evaluate("""() => { const v = document.getElementById('view3d').view3d;
                             v.camera.position.set(2, 0, 10); v.controls.target.set(2, 0, 0);
                             v.controls.update(); v.requestDraw(); }""")
    time.sleep(0.5)
    image = canvas_image(page)

    def rgb(x, y, z):
        p = page.evaluate("([x, y, z]) => document.getElementById('view3d').view3d.project(x, y, z)", [x, y, z])
        return image.getpixel((round(p["x"]), round(p["y"])))

    r, g, b = rgb(3.0, 0.0, 0.1)
    assert r > 150 and g < 100, (r, g, b)           # the scan's return, 3 m along the map's x
    r, g, b = rgb(3.5, -2.5, 0.01)
    assert r > 90 and b > 90 and g < 60, (r, g, b)  # the lethal costmap, magenta, at its map cells
    assert max(rgb(5.5, -2.5, 0.01)) < 60          # nothing past the costmap's edge
    assert page.watch.console_errors == []


def test_follow_the_robot_and_orbit_by_touch(scene, page):
    server, urdf = scene
    look_down(page, urdf, 0.0)
    page.check("#view3d-follow")
    target = "() => document.getElementById('view3d').view3d.controls.target.toArray()"
    assert page.evaluate(target)[:2] == pytest.approx(list(BASE_IN_ODOM), abs=1e-3)

    def moved():
        now = time.time()
        urdf.peer.publish("/tf", {"transforms": [transform("odom", "base_link", (5.0, -2.0, 0), t=now),
                                                 transform("base_link", "arm", (0, 0, 0.15), t=now)]})
        return page.evaluate(target)[:2] == pytest.approx([5.0, -2.0], abs=1e-3)
    wait_until(moved, 15, "the camera following the robot to (5, -2)", interval=0.3)

    # One finger dragged across the stage orbits the camera about the robot (OrbitControls' touch rotate).
    camera = "() => document.getElementById('view3d').view3d.camera.position.toArray()"
    before = page.evaluate(camera)
    box = page.locator("#view3d canvas").bounding_box()
    x0, y0 = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    cdp = page.context.new_cdp_session(page)
    cdp.send("Input.dispatchTouchEvent", {"type": "touchStart", "touchPoints": [{"x": x0, "y": y0}]})
    for step in range(1, 11):
        cdp.send("Input.dispatchTouchEvent", {"type": "touchMove", "touchPoints": [{"x": x0 + 20 * step, "y": y0}]})
    cdp.send("Input.dispatchTouchEvent", {"type": "touchEnd", "touchPoints": []})
    after = page.evaluate(camera)
    assert after != pytest.approx(before, abs=1e-3)
    assert page.evaluate(target)[:2] == pytest.approx([5.0, -2.0], abs=1e-3)  # still about the robot


def test_the_page_and_the_card_keep_the_content_security_policy(live_server_factory, browser, tmp_path, monkeypatch):
    """With the policy enforced (no bypass): the model, its package mesh, the text sprites and the card."""
    import requests

    from tests.browser.test_csp import RECORD_VIOLATIONS
    from tests.conftest import PageWatch

    monkeypatch.setenv("AMENT_PREFIX_PATH", str(ament_prefix(tmp_path)))
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(ROBOT_URDF)
    server = live_server_factory(ROVER_WEB_URDF_FILE=str(urdf))
    made = requests.post(server.url + "/api/layouts", timeout=5, json={
        "version": 1, "name": "3D", "cards": [{"type": "view3d", "x": 0, "y": 0, "w": 6, "h": 6}]})
    assert requests.put(server.url + "/api/me/layout", json={"id": made.json()["id"]}, timeout=5).status_code == 200
    context = browser.new_context(viewport={"width": 1280, "height": 900})
    context.add_init_script(RECORD_VIOLATIONS)
    try:
        page = context.new_page()
        watch = PageWatch(page)
        for path, stage in (("/3d", "#view3d"), ("/", "[data-view3d-stage]")):
            page.goto(server.url + path)
            page.wait_for_selector(f"{stage}[data-links='3'][data-mesh-errors='0']", timeout=20000)
            if path == "/3d":
                page.check("[data-layer='tf']")  # frame names: text drawn into canvas textures
            page.wait_for_load_state("networkidle")
            assert page.evaluate("window.__csp") == [], path
        assert watch.console_errors == [] and watch.offhost == []
    finally:
        context.close()
