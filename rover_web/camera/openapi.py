"""Camera routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import BODY_ERRORS, obj, op, path, query

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
ACK = query("ack", {"type": "string", "enum": ["0", "1"]},
            "1: the page will acknowledge the bytes it receives (POST /api/camera/viewers/{viewer_id}/ack), so "
            "the server sees the queue even behind a hop that terminates TCP; the response's X-Camera-Viewer "
            "header names the stream and each part carries X-Frame-Seq (adaptive streams only)")
BAD = ("missing_field, bad_topic, bad_value, out_of_range, unsupported_stream_type, type_mismatch, "
       "not_an_image_topic, unknown_type")

PATHS = {
    "/stream": {
        "get": op("An MJPEG stream of an image topic", tag="camera", media="multipart/x-mixed-replace",
                  ok={"type": "string"}, params=[*PARAMS, VIEWER, ACK],
                  errors={400: BAD + ", bad_value (viewer, ack)", 404: "unknown_topic",
                          503: "too_many_viewers, too_many_producers, too_many_streams, shutting_down"},
                  extra={"x-stream": "mjpeg"}),
    },
    "/snapshot": {
        "get": op("One JPEG from an image topic", tag="camera", media="image/jpeg",
                  ok={"type": "string", "contentMediaType": "image/jpeg"}, params=PARAMS,
                  errors={400: BAD, 404: "unknown_topic", 415: "an image the server cannot decode",
                          429: "rate_limited (CAMERA_SNAPSHOTS_PER_MIN; Retry-After)",
                          503: "too_many_viewers, too_many_producers, shutting_down", 504: "no_frame"},
                  cross_site=True),
    },
    "/api/camera/streams": {"get": op("The open camera streams and viewers", tag="camera", ok=obj(closed=False))},
    "/api/camera/viewers": {
        "get": op("What each MJPEG viewer gets: fps, size, kbit/s, and its path as the rate control sees it",
                  tag="camera", ok=obj(closed=False), params=[
                      query("viewer", {"type": "string", "pattern": "^[A-Za-z0-9_-]{1,64}$"},
                            "only the viewers whose stream carried this label")],
                  errors={400: "bad_value"}),
    },
    "/api/camera/viewers/{viewer_id}/ack": {
        "post": op("An acknowledging MJPEG page says how many body bytes of its stream it has received in all",
                   tag="camera", status=204, ok={},
                   params=[path("viewer_id", {"type": "string", "maxLength": 64},
                                "the X-Camera-Viewer header of GET /stream?ack=1")],
                   body=obj({"bytes": {"type": "integer", "minimum": 0,
                                       "description": "body bytes received on the stream in all; a count "
                                                      "smaller than one already acknowledged is ignored"}},
                            required=("bytes",)),
                   errors={**BODY_ERRORS, 400: "missing_body, bad_json, non_finite, unknown_field, missing_field, "
                                              "bad_type, out_of_range (more than the server has sent)",
                           404: "unknown_viewer (ended, never opened, or opened by someone else)"},
                   description="The server keeps its rate control's queue at the bytes sent and not yet "
                               "acknowledged (docs/camera.md#acknowledging-pages)."),
    },
}
