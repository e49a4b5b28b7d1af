"""Camera routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op, query

PARAMS = [
    query("topic", {"type": "string", "minLength": 1}, "the image topic, e.g. /camera/image_raw", required=True),
    query("width", {"type": "integer", "minimum": 1}, "scale to this width (keeps the aspect without height)"),
    query("height", {"type": "integer", "minimum": 1}, "scale to this height"),
    query("quality", {"type": "integer", "minimum": 1, "maximum": 100}, "JPEG quality"),
    query("qos_profile", {"type": "string", "enum": ["default", "sensor_data", "system_default"]},
          "the subscription's QoS (default: as the publishers)"),
    query("type", {"type": "string"}, "mjpeg (the only stream type), or a message type as msg_type"),
    query("msg_type", {"type": "string", "examples": ["sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage"]},
          "the message type, to wait for a topic not up yet"),
]
VIEWER = query("viewer", {"type": "string", "pattern": "^[A-Za-z0-9_-]{1,64}$"},
               "a label the page tags its stream with, to find it in GET /api/camera/viewers")
BAD = ("missing_topic, bad_topic, bad_value, out_of_range, unsupported_stream_type, type_mismatch, "
       "not_an_image_topic, unknown_type")

PATHS = {
    "/stream": {
        "get": op("An MJPEG stream of an image topic", tag="camera", media="multipart/x-mixed-replace",
                  ok={"type": "string"}, params=[*PARAMS, VIEWER],
                  errors={400: BAD + ", bad_value (viewer)", 404: "unknown_topic",
                          503: "too_many_viewers, too_many_producers, too_many_streams, shutting_down"},
                  extra={"x-stream": "mjpeg"}),
    },
    "/snapshot": {
        "get": op("One JPEG from an image topic", tag="camera", media="image/jpeg",
                  ok={"type": "string", "contentMediaType": "image/jpeg"}, params=PARAMS,
                  errors={400: BAD, 404: "unknown_topic", 415: "an image the server cannot decode",
                          429: "rate_limited (CAMERA_SNAPSHOTS_PER_MIN; Retry-After)",
                          503: "too_many_viewers, too_many_producers, shutting_down", 504: "no_frame"}),
    },
    "/api/camera/streams": {"get": op("The open camera streams and viewers", tag="camera", ok=obj(closed=False))},
    "/api/camera/viewers": {
        "get": op("What each MJPEG viewer gets: fps, size, kbit/s, and its path as the rate control sees it",
                  tag="camera", ok=obj(closed=False), params=[
                      query("viewer", {"type": "string", "pattern": "^[A-Za-z0-9_-]{1,64}$"},
                            "only the viewers whose stream carried this label")],
                  errors={400: "bad_value"}),
    },
}
