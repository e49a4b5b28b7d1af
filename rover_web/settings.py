"""Every setting rover_web reads: its name (after ROVER_WEB_), default, kind, meaning and bounds.

The table alone, so config.py (which loads, converts and checks them) stays small; docs/configuration.md
is generated from it (scripts/update_settings_doc.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Setting:
    name: str
    default: Any
    kind: str  # str | int | float | bool | list | topic | optional_str | optional_int | optional_topic
    meaning: str
    low: float | None = None
    high: float | None = None
    choices: tuple[str, ...] | None = None


SETTINGS: tuple[Setting, ...] = (
    # --- process and ROS node ---
    Setting("NODE_NAME", "rover_web", "str", "name of the app's ROS 2 node"),
    Setting("ROBOTS", [], "robots",
            "the robots served: JSON [{\"name\": \"boat\", \"namespace\": \"/boat\", \"kind\": \"boat\"}, ...] "
            "or the short form boat,rover,drone; empty: one robot, no namespace (docs/fleet.md)"),
    Setting("ROS_DOMAIN_ID", None, "optional_int",
            "ROS domain id for the app's node; unset uses ROS_DOMAIN_ID from the environment (or 0)", 0, 232),
    Setting("HOST", None, "optional_str",
            "address the demo and gunicorn.conf.py bind to (unset: 127.0.0.1); under another server, where it "
            "listens, or sign-in stays required (ROVER_WEB_AUTH=auto); 0.0.0.0 exposes the GUI"),
    Setting("PORT", 5000, "int", "port `python -m rover_web.demo` and gunicorn.conf.py listen on", 1, 65535),
    Setting("SHUTDOWN_TIMEOUT_S", 2.0, "float", "how long shutdown waits for the executor thread", 0.1, 30),
    Setting("STATIC_BUILD_DIR", None, "optional_str",
            "where hashed, brotli and gzip copies of static/ are kept (made at start, content-addressed); "
            "unset: build/static beside static/ (docs/page_load.md)"),
    Setting("BUNDLE", True, "bool",
            "serve each page's modules as one bundle and its stylesheets as one file (esbuild, made at a page's "
            "first request, kept in the store); off: each file on its own, named up front (docs/page_load.md)"),
    Setting("DB_PATH", None, "optional_str",
            "SQLite database file; unset means rover_web.sqlite3 in the Flask instance folder"),
    # --- HTTP protection ---
    Setting("TRUSTED_HOSTS", ["127.0.0.1", "localhost", "::1"], "list",
            "Host header values accepted (port ignored; '.example.org' matches subdomains); guards DNS rebinding"),
    Setting("ALLOWED_ORIGINS", [], "list",
            "extra Origins (scheme://host:port) allowed to change state, besides the page's own origin"),
    Setting("PROXY_HOPS", 0, "int",
            "reverse proxies in front of the app whose X-Forwarded-For, -Proto and -Host are believed (Werkzeug's "
            "ProxyFix), so each client keeps its own address; 0: none (a client could forge them); set it only "
            "when nothing but the proxy can reach the app", 0, 10),
    # --- fleet over Zenoh: robots report to a hub (docs/fleet.md#a-hub-over-zenoh) ---
    Setting("ZENOH_MODE", "off", "str",
            "Zenoh link to a fleet hub: off, peer or client (client needs a router or peer in "
            "ROVER_WEB_ZENOH_CONNECT)", choices=("off", "peer", "client")),
    Setting("ZENOH_CONNECT", [], "list", "Zenoh endpoints to connect to, e.g. tcp/10.0.0.5:7447"),
    Setting("ZENOH_LISTEN", [], "list", "Zenoh endpoints to listen on, e.g. tcp/0.0.0.0:7447 (the hub's)"),
    Setting("ZENOH_CONFIG", None, "optional_str",
            "a Zenoh JSON5 config file (TLS, access control); ROVER_WEB_ZENOH_MODE, _CONNECT and _LISTEN "
            "override its mode and endpoints"),
    Setting("ZENOH_MULTICAST_SCOUTING", False, "bool",
            "let Zenoh find peers by UDP multicast on the LAN; off: only the endpoints listed are used"),
    Setting("FLEET_NAME", "fleet", "str",
            "the fleet's name in Zenoh key expressions (rover_web/<fleet>/<robot>/...): 1-32 of a-z 0-9 _"),
    Setting("FLEET_KEY_FILE", None, "optional_str",
            "file holding the fleet's shared secret (at least 32 bytes) that signs summaries and stop commands; "
            "required when ROVER_WEB_ZENOH_MODE is not off"),
    Setting("PUBLIC_URL", None, "optional_str",
            "this rover_web's own address as others reach it (https://boat.example.org:5000), for the hub's links"),
    Setting("HUB", False, "bool",
            "serve as a fleet hub: no ROS node, every robot heard over Zenoh on /robots, stop-all to each"),
    Setting("FLEET_LOST_AFTER_S", 3.0, "float",
            "the hub shows a robot lost when no summary came for this long (or its liveliness token went)", 1.5, 60),
    Setting("FLEET_FORGET_AFTER_S", 3600.0, "float",
            "the hub drops a robot from its list once it has been lost this long (it stays in the history)",
            10, 30 * 86400),
    Setting("HUB_HISTORY_DAYS", 30.0, "float", "how long the hub keeps each robot's history", 0.01, 3650),
    Setting("HUB_HISTORY_MAX_ROWS", 10000, "int", "the most history rows the hub keeps per robot", 10, 10_000_000),
    Setting("FLEET_STOP_TIMEOUT_S", 2.0, "float",
            "how long the hub's stop-all waits for each robot's answer (no_answer after)", 0.1, 30),
    Setting("FLEET_COMMAND_WINDOW_S", 10.0, "float",
            "a robot refuses a signed stop whose timestamp is further than this from its clock", 1, 300),
    Setting("METRICS", "on", "str",
            "GET /metrics in the Prometheus text format: on (open on loopback as the API is; a viewer's token "
            "when exposed) or off (404)", choices=("on", "off")),
    # --- sign-in and HTTPS ---
    Setting("AUTH", "auto", "str",
            "sign-in: auto (required unless the server listens on loopback only), required, or off",
            choices=("auto", "required", "off")),
    Setting("SECRET_KEY", None, "optional_str",
            "signs session cookies; unset: a random key kept in the instance folder (secret_key); at least 32 bytes"),
    Setting("SESSION_HOURS", 12.0, "float",
            "a sign-in session ends this many hours after sign-in, whatever the browser does", 0.05, 720),
    Setting("TLS_CERT", None, "optional_str",
            "PEM certificate for HTTPS (the demo and gunicorn.conf.py); `flask tls self-signed` writes one"),
    Setting("TLS_KEY", None, "optional_str", "PEM private key that goes with ROVER_WEB_TLS_CERT"),
    Setting("MAX_BODY_BYTES", 262144, "int", "largest request body accepted (413 beyond)", 1024, 64 * 1024 * 1024),
    # --- sign-in work (docs/security.md#what-a-sign-in-may-cost) ---
    Setting("SIGNIN_MAX_HASHING", 2, "int",
            "password hashes computed at once; a sign-in beyond them is answered 503 at once, unhashed", 1, 64),
    Setting("SIGNIN_ATTEMPTS_PER_MIN", 20, "int",
            "sign-in attempts one client address may make in a sliding minute, across all names (429 beyond)",
            1, 10000),
    Setting("ARGON2_MEMORY_KIB", 19456, "int",
            "Argon2id memory per password hash, KiB (OWASP: 19456 with 2 passes, or 12288 with 3)", 8192, 1048576),
    Setting("ARGON2_TIME_COST", 2, "int", "Argon2id passes per password hash", 1, 20),
    Setting("LOGIN_ESTOP", True, "bool",
            "the sign-in page offers a button that engages (never releases) every robot's e-stop, to anyone"),
    # --- live events and link health ---
    Setting("SSE_KEEPALIVE_S", 10.0, "float", "seconds between SSE keep-alive comments (at most 15)", 0.05, 15),
    Setting("SSE_RETRY_MS", 1000, "int", "reconnect delay the SSE stream asks browsers to use", 100, 60000),
    Setting("SSE_MAX_CLIENTS", 256, "int", "most SSE streams served at once (503 beyond)", 1, 4096),
    Setting("STATUS_PERIOD_S", 1.0, "float", "how often the `status` channel is refreshed", 0.1, 60),
    Setting("STALE_AFTER_S", 2.0, "float", "a topic with no message for this long is shown stale", 0.1, 3600),
    Setting("LINK_TOPICS", ["/odom"], "list",
            "topics whose freshness defines the server-robot link in the health bar"),
    Setting("ODOM_TOPIC", "/odom", "topic", "nav_msgs/Odometry the dashboard shows speed from"),
    Setting("BATTERY_TOPIC", "/battery_state", "topic",
            "sensor_msgs/BatteryState shown as the battery level on the dashboard and /robots, when published"),
    Setting("ODOM_MAX_HZ", 10.0, "float", "most `odom` channel updates a second sent to browsers", 0.1, 1000),
    # --- e-stop ---
    Setting("ESTOP_TOPIC", "/e_stop", "topic",
            "std_msgs/Bool the e-stop publishes (reliable, transient local): true engaged, false released"),
    Setting("ESTOP_REPEAT_S", 1.0, "float", "how often the e-stop state is republished on ROVER_WEB_ESTOP_TOPIC",
            0.05, 60),
    Setting("ESTOP_CANCEL_ACTIONS", ["/navigate_to_pose", "/navigate_through_poses", "/follow_waypoints",
                                     "/follow_gps_waypoints"], "list",
            "actions whose goals are all canceled (action_msgs/srv/CancelGoal) when the e-stop engages"),
    Setting("MAX_STREAMS", 64, "int",
            "most long-lived streams (SSE, MJPEG, topic echo, teleop sockets) at once, 503 beyond; keep it "
            "below the server's thread count so short requests such as the e-stop always find a thread", 1, 4096),
    Setting("MAX_STREAMS_PER_CLIENT", 16, "int",
            "most long-lived streams one user (one non-loopback address with sign-in off) may hold, 503 "
            "beyond; teleop sockets are not counted against it", 1, 4096),
    Setting("SUBSCRIPTIONS_PER_CLIENT", 4, "int",
            "most different topic echoes, and apart from them most different camera encodings, one user (one "
            "non-loopback address with sign-in off) may have open at once, 503 beyond", 1, 4096),
    Setting("STREAMS_RESERVED", 2, "int",
            "slots of ROVER_WEB_MAX_STREAMS only teleop sockets (and, with sign-in on, operators and admins) "
            "may take", 0, 4096),
    # --- teleop ---
    Setting("CMD_VEL_TOPIC", "/cmd_vel", "topic", "velocity command topic"),
    Setting("CMD_VEL_STAMPED", False, "bool",
            "publish geometry_msgs/TwistStamped instead of Twist (Jazzy's diff_drive_controller wants it)"),
    Setting("CMD_VEL_FRAME_ID", "base_link", "str", "frame_id of TwistStamped commands"),
    Setting("MAX_LINEAR_MPS", 5.0, "float", "linear speed at full joystick deflection (m/s)", 0.0, 100),
    Setting("MAX_ANGULAR_RPS", 2.0, "float", "turn rate at full joystick deflection (rad/s)", 0.0, 100),
    Setting("TELEOP_RATE_HZ", 40.0, "float",
            "rate at which the server republishes the held joystick/keyboard/REST command on the velocity topic",
            1, 200),
    Setting("TELEOP_DEADMAN_S", 0.3, "float",
            "a joystick/keyboard command with no fresh input for this long is held as it was, then ramps down "
            "(see TELEOP_DEADMAN_MAX_S)", 0.05, 5),
    Setting("TELEOP_DEADMAN_MAX_S", 1.0, "float",
            "hard bound: this long after a joystick/keyboard command's last fresh input zero is published "
            "whatever happens, the speed ramping down to it from TELEOP_DEADMAN_S (a smaller value is taken "
            "as TELEOP_DEADMAN_S: hold, then stop)", 0.05, 5),
    Setting("TELEOP_MAX_FRAME_BYTES", 4096, "int",
            "largest teleop WebSocket frame; a bigger one closes the socket with 1009", 256, 65536),
    Setting("TELEOP_WS_PING_S", 10.0, "float",
            "teleop WebSocket ping interval; a client that misses a pong loses the socket and control (0: off)",
            0, 300),
    Setting("TELEOP_REST_DEFAULT_SPEED", 0.2, "float",
            "speed of POST /api/teleop without `speed`, as a fraction of the maxima", 0, 1),
    Setting("TELEOP_REST_DEFAULT_DURATION_S", 0.5, "float",
            "how long POST /api/teleop drives without `duration_s` before it stops by itself", 0.01, 60),
    Setting("TELEOP_REST_MAX_DURATION_S", 5.0, "float", "longest `duration_s` POST /api/teleop accepts", 0.01, 60),
    # --- waypoints ---
    Setting("WAYPOINTS_TOPIC", "/waypoints", "topic",
            "std_msgs/Float64MultiArray [lng, lat] published for every waypoint added (the RobotX GUI's topic)"),
    Setting("MISSION_TOPIC", "/mission", "topic",
            "std_msgs/Float64MultiArray (n x 2, lng then lat) the whole ordered mission goes to on \"send mission\""),
    Setting("FIX_TOPIC", "/fix", "topic", "sensor_msgs/NavSatFix shown as the robot's marker and track on the map"),
    Setting("MAX_WAYPOINTS", 500, "int", "most waypoints a mission may hold (409 beyond)", 1, 100000),
    Setting("GPS_HEADING_TOPIC", "/odom", "optional_topic",
            "the robot's heading on the GPS map: its yaw in an east-aligned frame (REP 105); unset: no heading"),
    Setting("GPS_HEADING_TYPE", "odometry", "str", "what ROVER_WEB_GPS_HEADING_TOPIC carries: nav_msgs/Odometry, "
            "sensor_msgs/Imu (with orientation) or geometry_msgs/PoseStamped", choices=("odometry", "imu", "pose")),
    Setting("GPS_HEADING_OFFSET_DEG", 0.0, "float",
            "the angle from east to the heading frame's x axis, counter-clockwise (subtracted from the "
            "bearing drawn)", -360, 360),
    Setting("GPS_HEADING_STALE_S", 2.0, "float", "the map drops the heading arrow when it is older than this",
            0.1, 3600),
    Setting("FIX_TRACK_POINTS", 500, "int", "GPS track points kept and drawn behind the robot (oldest dropped)",
            2, 20000),
    Setting("MAP_PLACE_NAME", "Nathan Benderson Park, FL", "str", "name of the place the map opens on"),
    Setting("MAP_CENTER_LNG", -82.4500873, "float", "longitude the map opens on (degrees east)", -180, 180),
    Setting("MAP_CENTER_LAT", 27.3742443, "float", "latitude the map opens on (degrees north)", -85, 85),
    Setting("MAP_ZOOM", 14.0, "float", "zoom level the map opens at", 0, 22),
    Setting("MAP_TILES", "map_files/tiles", "optional_str",
            "offline basemap: a z/x/y tile folder or an .mbtiles file (relative paths from the repository root); "
            "unset or missing means no basemap"),
    Setting("MAP_GEOJSON_DIR", "map_files/basemap", "optional_str",
            "drawn basemaps: a folder of <name>.geojson files (land, water, paths; see docs/basemap.md) the GPS map "
            "draws itself; relative paths from the repository root; unset: none"),
    # --- geofence ---
    Setting("GEOFENCE_MAX_VERTICES", 2000, "int", "most vertices a geofence may have in all (400 beyond)", 4, 100000),
    Setting("GEOFENCE_ESTOP", False, "bool", "engage the e-stop when /fix leaves the geofence"),
    Setting("GEOFENCE_FILE", None, "optional_str",
            "GeoJSON fence stored when the database has none (the demo: map_files/geofence.geojson)"),
    # --- panels ---
    Setting("PANELS_FILE", None, "optional_str",
            "TOML file defining the mission control panels; unset means the drone panel in "
            "rover_web/panels/drone.toml"),
    Setting("PANEL_UNLOCKS_PER_MIN", 10, "int",
            "unlock attempts one client (user, or address with sign-in off) may make a minute (429 beyond)", 1, 10000),
    Setting("PANEL_REFUSALS_PER_MIN", 20, "int",
            "refused or invalid panel commands one client may make a minute; beyond, its commands get 429 "
            "and nothing more is logged", 1, 10000),
    Setting("PANELS_LOG_SHOWN", 20, "int", "operator-log entries a panel page shows (newest first)", 1, 500),
    Setting("PANELS_LOG_KEEP", 10000, "int", "operator-log entries kept per panel in the database (oldest deleted)",
            100, 10_000_000),
    # --- TF: the robot's frames (docs/tf.md) ---
    Setting("TF_CACHE_S", 10.0, "float",
            "how long dynamic transforms (/tf) are kept for lookups at past stamps, as tf2's cache; static ones "
            "(/tf_static) are kept forever", 0.5, 600),
    Setting("TF_STALE_S", 1.0, "float",
            "the TF page warns of a dynamic frame whose newest transform is older than this (or than five of its "
            "periods, if longer)", 0.05, 3600),
    Setting("MAP_FRAME", "map", "str", "the fixed world frame (REP 105's map)"),
    Setting("ODOM_FRAME", "odom", "str", "the odometry frame (REP 105's odom)"),
    Setting("BASE_FRAME", "base_link", "str", "the robot's body frame (REP 105's base_link)"),
    # --- livemap ---
    Setting("MAPS_FILE", "map_files/all_maps.json", "optional_str",
            "floorplans: an all_maps.json catalog or one map_server yaml (relative paths from the repository "
            "root); set it empty in the environment for none"),
    Setting("LIVEMAP_DEFAULT_MAP", None, "optional_str",
            "map /livemap and the dashboard show first; unset: the first one"),
    Setting("LIVEMAP_BOT_DIAMETER_CM", 35.4, "float", "robot diameter drawn on the map (cm)", 1, 10000),
    Setting("AMCL_POSE_TOPIC", "/amcl_pose", "topic",
            "geometry_msgs/PoseWithCovarianceStamped robot pose in the map frame (transient local)"),
    Setting("GOAL_TOPIC", "/goal_pose", "topic",
            "geometry_msgs/PoseStamped goal, published by the map page and shown when others publish it "
            "(ROS 1: /move_base_simple/goal)"),
    Setting("GOAL_FRAME_ID", "map", "str", "frame_id of goals and initial poses sent from the map page"),
    Setting("INITIAL_POSE_TOPIC", "/initialpose", "topic",
            "geometry_msgs/PoseWithCovarianceStamped the map page's 'Set pose' publishes (AMCL's /initialpose)"),
    Setting("PLAN_TOPIC", "/plan", "topic", "nav_msgs/Path drawn as the robot's route"),
    Setting("LIVEMAP_MAP_TOPIC", None, "optional_topic",
            "nav_msgs/OccupancyGrid (transient local, e.g. /map from SLAM) shown as the map 'live map'; unset: off"),
    Setting("LIVEMAP_POSE_MAX_HZ", 30.0, "float", "most `pose` channel updates per second", 0.5, 200),
    Setting("LIVEMAP_POSE_STALE_S", 5.0, "float",
            "the map shows 'no pose' when the last pose is older than this; 0: never (AMCL only publishes when moving)",
            0, 3600),
    Setting("LIVEMAP_PLAN_MAX_POINTS", 500, "int", "longer paths are evenly thinned to this many points", 2, 100000),
    # --- Nav2's actions (docs/nav2.md) ---
    Setting("NAV2_GOAL_MODE", "auto", "str",
            "how LiveMap sends a goal: action (Nav2's NavigateToPose, with feedback and a result), topic "
            "(ROVER_WEB_GOAL_TOPIC) or auto (the action when nav2_msgs is installed and the server answers)",
            choices=("auto", "action", "topic")),
    Setting("NAV2_FEEDBACK_MAX_HZ", 5.0, "float", "most `nav2` channel updates a second (feedback, states)", 0.5, 50),
    Setting("NAV2_TIMEOUT_S", 3.0, "float", "how long a goal waits for Nav2's action server to accept it", 0.2, 30),
    Setting("NAV2_MAX_POSES", 100, "int", "most poses in a route (NavigateThroughPoses, FollowWaypoints)", 1, 10000),
    Setting("NAV2_LIFECYCLE_NODES", ["bt_navigator", "planner_server", "controller_server", "behavior_server",
                                     "smoother_server", "velocity_smoother", "waypoint_follower", "map_server",
                                     "amcl"], "list",
            "Nav2 servers whose lifecycle state (<node>/get_state) is shown, under the robot's namespace"),
    Setting("NAV2_LIFECYCLE_PERIOD_S", 2.0, "float", "how often the lifecycle states are asked for", 0.2, 60),
    # --- livemap overlays: what the robot senses (docs/livemap.md#overlays-what-the-robot-senses) ---
    Setting("SCAN_TOPIC", "/scan", "optional_topic", "sensor_msgs/LaserScan drawn on LiveMap; empty: off"),
    Setting("SCAN_MAX_POINTS", 360, "int", "angular bins a scan is thinned to, each its nearest return", 8, 10000),
    Setting("SCAN_MAX_HZ", 10.0, "float", "most `scan` channel updates per second", 0.2, 50),
    Setting("SCAN_LASER_OFFSET", ["0", "0", "0"], "list", "the laser on the robot: x,y,yaw (m, rad), base frame"),
    Setting("COSTMAP_TOPICS", ["/global_costmap/costmap", "/local_costmap/costmap"], "list",
            "nav_msgs/OccupancyGrid costmaps drawn on LiveMap; empty: off"),
    Setting("COSTMAP_MAX_HZ", 1.0, "float", "most `costmap` channel updates per second", 0.1, 5),
    Setting("COSTMAP_MAX_SIDE", 512, "int", "a larger costmap is shrunk, keeping each block's top cost", 16, 4096),
    Setting("COSTMAP_MAX_CELLS", 4_000_000, "int", "a costmap with more cells is skipped and counted", 1, 10**8),
    Setting("MARKERS_TOPIC", "/visualization_marker_array", "optional_topic", "MarkerArray on LiveMap; empty: off"),
    Setting("MARKERS_MAX_HZ", 5.0, "float", "most `markers` channel updates per second", 0.2, 30),
    Setting("MARKERS_MAX_POINTS", 5000, "int", "markers past this many points in all are skipped", 10, 1_000_000),
    Setting("FOOTPRINT_TOPIC", "/global_costmap/published_footprint", "optional_topic",
            "geometry_msgs/PolygonStamped footprint drawn on LiveMap; empty: off"),
    Setting("LIVEMAP_TRAIL_S", 60.0, "float", "how far back LiveMap's recent path reaches (s)", 1, 3600),
    # --- the 3D view (docs/view3d.md) ---
    Setting("ROBOT_DESCRIPTION_TOPIC", "/robot_description", "optional_topic",
            "std_msgs/String URDF, transient local, as robot_state_publisher serves it; empty: only URDF_FILE"),
    Setting("URDF_FILE", None, "optional_str", "a URDF file drawn instead of the description topic's"),
    Setting("POINTCLOUD_TOPIC", "", "optional_topic",
            "sensor_msgs/PointCloud2 drawn in the 3D view, thinned on a voxel grid; empty: off"),
    Setting("POINTCLOUD_MAX_POINTS", 20000, "int", "points a cloud is thinned to for the browser", 100, 200_000),
    Setting("VIEW3D_POSE_HZ", 10.0, "float", "how often the TF frames' poses go to 3D viewers", 1, 30),
    # --- camera ---
    Setting("CAMERA_TOPIC", "/camera/image_raw", "topic",
            "image topic (sensor_msgs/Image or CompressedImage) the dashboard's camera panel shows first"),
    Setting("CAMERA_QUALITY", 80, "int", "JPEG quality of /stream and /snapshot when the URL gives none", 1, 100),
    Setting("CAMERA_MAX_DIMENSION", 4096, "int", "largest width or height a /stream or /snapshot may ask for",
            16, 16384),
    Setting("CAMERA_IDLE_TIMEOUT_S", 2.0, "float",
            "how long an image subscription stays after its last viewer leaves (a reload reuses it)", 0.0, 600),
    Setting("CAMERA_MAX_VIEWERS", 24, "int",
            "most /stream and /snapshot requests served at once (503 beyond); each holds a server thread", 1, 1024),
    Setting("CAMERA_SNAPSHOT_TIMEOUT_S", 5.0, "float", "how long /snapshot waits for a frame", 0.1, 60),
    Setting("CAMERA_SNAPSHOTS_PER_MIN", 120, "int",
            "most /snapshot requests one client (user, or address with sign-in off) makes a minute (429 beyond)",
            1, 100000),
    Setting("CAMERA_MAX_PRODUCERS", 8, "int",
            "most different streams (topic, size, quality, QoS) encoded at once; viewers of the same one "
            "share it (503 beyond)", 1, 256),
    Setting("CAMERA_MAX_OUTPUT_PIXELS", 3840 * 2160, "int",
            "largest width × height a stream is encoded at (a larger asked size is refused, a derived one "
            "scaled down)", 256, 64 * 1024 * 1024),
    Setting("CAMERA_ADAPT", True, "bool",
            "fit each MJPEG viewer's frame rate, quality and size to what its link delivers (docs/camera.md); "
            "false: every frame the camera makes, as asked"),
    Setting("CAMERA_VIEWER_MAX_KBPS", 0, "int",
            "most kbit/s one MJPEG viewer gets (0: no cap beyond its link); needs CAMERA_ADAPT", 0, 10_000_000),
    Setting("CAMERA_TOTAL_MAX_KBPS", 0, "int",
            "most kbit/s all MJPEG viewers together get, shared fairly (0: no total cap); needs CAMERA_ADAPT",
            0, 10_000_000),
    # --- camera over WebRTC (WHEP) ---
    Setting("WEBRTC_MAX_VIEWERS", 4, "int",
            "most WebRTC camera sessions at once, each with its own encoder (503 beyond: watch MJPEG)", 0, 64),
    Setting("WEBRTC_VIEWERS_PER_CLIENT", 2, "int",
            "most WebRTC camera sessions one user (one non-loopback address with sign-in off) may hold, 503 "
            "beyond", 1, 64),
    Setting("WEBRTC_MAX_FPS", 30.0, "float", "most frames a second a WebRTC viewer is sent", 1, 60),
    Setting("WEBRTC_LINK_SHARE", 0.75, "float",
            "the part of the browser's bandwidth estimate a WebRTC viewer's encoder may use; the rest drains "
            "what a stall queued and carries the e-stop, teleop and events (not below 0.75: the browser never "
            "estimates more than 1.5 × what arrives, and with less the estimate cannot climb)", 0.75, 1.0),
    Setting("WEBRTC_IDLE_TIMEOUT_S", 15.0, "float",
            "a WebRTC session not connected for this long (never, or lost) is closed", 1, 3600),
    Setting("WEBRTC_ICE_SERVERS", [], "list",
            "ICE servers (stun:host:port, turn:user:secret@host:port); empty: none, no STUN to the internet"),
    Setting("WEBRTC_HOST_ADDRESSES", [], "list",
            "the only IP addresses offered as host candidates (e.g. the radio's); empty: every interface's"),
    # --- topic browser ---
    Setting("TOPICS_REFRESH_S", 1.0, "float",
            "how often the topic list (`topics` channel) is re-read from the ROS graph",
            0.2, 60),
    Setting("TOPICS_ECHO_HZ", 5.0, "float", "most messages a second the topic browser shows of one topic", 0.1, 50),
    Setting("TOPICS_ECHO_MAX_ITEMS", 32, "int",
            "arrays and byte fields longer than this are shown cut, with their length", 1, 10000),
    Setting("TOPICS_ECHO_IDLE_TIMEOUT_S", 2.0, "float",
            "how long a topic browser subscription stays after its last viewer leaves", 0.0, 600),
    Setting("TOPICS_ECHO_MAX_SUBSCRIPTIONS", 16, "int",
            "most different topics (and types) echoed at once; viewers of the same one share it (503 beyond)",
            1, 1024),
    # --- ROS admin (/ros: other nodes' parameters, services, action goals) ---
    Setting("ROS_ADMIN", "on", "str",
            "the /ros page and its API: on, read-only (look, never set, call or send) or off (403, no nav link)",
            choices=("on", "read-only", "off")),
    Setting("ROS_ADMIN_ALLOW", [], "list",
            "if not empty, the only nodes, parameters, services and actions /ros may write to: [kind:]glob, "
            "kind node, param, service or action (docs/ros_admin.md#allow-and-deny)"),
    Setting("ROS_ADMIN_DENY", ["param:use_sim_time", "service:*/set_parameters*", "service:*/change_state",
                               "service:*/load_parameters", "service:*/manage_nodes", "service:*/_action/*",
                               "service:*/_container/*"], "list",
            "[kind:]glob entries /ros never writes to, even for an admin; setting it replaces this default list"),
    Setting("ROS_ADMIN_SAFETY_NODES", ["*"], "list",
            "globs of node names whose parameters /ros never sets while the e-stop is engaged (409)"),
    # --- observability: /rosout, diagnostics, plots ---
    Setting("ROSOUT_KEEP", 5000, "int", "/rosout lines kept in memory (oldest dropped)", 10, 1000000),
    Setting("ROSOUT_KEEP_BYTES", 16 * 1024 * 1024, "int",
            "most bytes of /rosout text kept in memory (oldest lines dropped); each line is cut on arrival",
            64 * 1024, 1024 * 1024 * 1024),
    Setting("DIAGNOSTICS_STALE_S", 5.0, "float", "a diagnostic status older than this is stale",
            0.1, 3600),
    Setting("PLOT_KEEP_POINTS", 20000, "int", "samples kept per plotted series", 100, 1000000),
    Setting("PLOT_MAX_MESSAGE_BYTES", 65536, "int",
            "plotted topics' messages larger than this are dropped unread (images and point clouds are refused)",
            1024, 16 * 1024 * 1024),
    Setting("PLOT_SERIES_PER_CLIENT", 16, "int",
            "most series one user (or, with sign-in off, one non-loopback address) keeps plotted at once "
            "(503 beyond), so no client takes every series of the 64", 1, 64),
    Setting("PLOT_IDLE_S", 30.0, "float",
            "a plotted series ends this long after a page last asked for it",
            1.0, 3600),
    # --- scan the code ---
    Setting("LIGHT_SEQUENCE_TOPIC", "/light_sequence", "topic",
            "std_msgs/String colour names from the light tower detector (Scan the Code)"),
    Setting("LIGHT_SEQUENCE_QOS", "default", "str",
            "QoS of that subscription: default (reliable) or sensor_data (best effort, for best-effort detectors)",
            choices=("default", "sensor_data")),
    Setting("LIGHT_COLOURS", ["red", "green", "blue", "yellow"], "list",
            "colours a code is made of (case-insensitive); black ends a cycle, anything else is unknown"),
    Setting("LIGHT_STALE_AFTER_S", 3.0, "float", "the light sequence is shown stale after this long without a message",
            0.1, 3600),
    Setting("CODE_TOPIC", "/scan_the_code/code", "topic",
            "where each confirmed code is published: std_msgs/String such as `red,green,blue`, transient local"),
    Setting("CODE_CONFIRM_CYCLES", 1, "int",
            "complete cycles in a row that must agree before a code is confirmed and published", 1, 20),
    Setting("CODE_HISTORY_LENGTH", 10, "int", "completed cycles (codes and invalid ones) kept in the history", 1, 100),
    # --- recordings (docs/recording.md) ---
    Setting("RECORDINGS_DIR", None, "optional_str",
            "folder MCAP recordings are written to; unset: recordings/ in the Flask instance folder"),
    Setting("RECORDING_MAX_MB", 2048.0, "float",
            "a recording stops (max_size) once its file reaches this size (MB, one chunk may pass it)", 0.01, 1e7),
    Setting("RECORDINGS_MAX_MB", 20480.0, "float",
            "all recordings together may take this much (MB): a recording stops (folder_full) there, and none "
            "starts beyond it", 0.01, 1e8),
    Setting("RECORDINGS_MIN_FREE_MB", 1024.0, "float",
            "a recording stops (disk_low), and none starts, while the disk holding them has less free (MB)",
            0, 1e8),
    Setting("RECORDING_PRESETS", ["navigation=/odom /fix /amcl_pose /plan /goal_pose /cmd_vel /e_stop /rosout "
                                  "/diagnostics"], "list",
            "topic sets a recording can name as preset:NAME, each NAME=/topic /topic ... (under each robot's "
            "namespace)"),
    Setting("RECORDING_CAMERA_MAX_HZ", 2.0, "float",
            "most frames a second a recording keeps of each image topic when it records the camera", 0.1, 60),
    Setting("RECORDING_QUEUE", 10000, "int",
            "messages waiting for the recording's writer thread; beyond, new ones are counted as dropped", 100,
            1000000),
    Setting("RECORDING_UPLOAD_MAX_MB", 1024.0, "float",
            "largest MCAP file an operator may upload to replay (MB; 413 beyond); uploads count towards "
            "ROVER_WEB_RECORDINGS_MAX_MB", 0.01, 1e7),
)
