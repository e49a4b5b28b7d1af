"""The recordings' routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import BODY_ERRORS, obj, op, page, query

TOPICS = {"oneOf": [{"const": "all"}, {"type": "string", "pattern": "^preset:.+"},
                    {"type": "array", "items": {"type": "string"}, "minItems": 1, "maxItems": 500}]}
START = obj({"topics": TOPICS, "camera": {"type": "boolean"}, "name": {"type": "string", "maxLength": 80}})
COUNTS = {"type": "object", "additionalProperties": {"type": "integer"}}
RECORDING = obj({
    "id": {"type": "string"}, "name": {"type": "string"}, "robot": {"type": "string"},
    "state": {"enum": ["recording", "stopped", "interrupted"]},
    "stop_reason": {"enum": [None, "requested", "shutdown", "max_size", "folder_full", "disk_low", "write_error",
                             "interrupted", "subscribe_failed"]},
    "error": {"type": ["string", "null"]},
    "started_at": {"type": "number"}, "ended_at": {"type": ["number", "null"]}, "duration_s": {"type": "number"},
    "size": {"type": "integer"}, "started_by": {"type": "string"}, "stopped_by": {"type": ["string", "null"]},
    "selection": {}, "camera": {"type": "boolean"},
    "topics": {"type": "object", "additionalProperties": {"type": "string"}},
    "counts": COUNTS, "messages": {"type": "integer"}, "dropped": COUNTS,
    "skipped": {"type": "array", "items": {"type": "string"}},
    "left_out": {"type": "array", "items": {"type": "string"}},
    "file": {"type": "string"},
    "source": {"enum": ["recorded", "uploaded"]},
}, ("id", "state", "started_at", "size", "topics", "counts"), closed=False)
NOT_FOUND = {404: "not_found"}
# A file over one of recording/bounds.py's bounds (issue 40), met while reading it: the code names it.
BOUNDS = ("chunk_too_large, read_budget, time_budget, message_too_large, schema_too_large, "
          "schema_too_many_fields, corrupt")
READABLE = {404: "not_found", 409: "recording_in_progress", 422: "not_a_recording, " + BOUNDS}
TOPIC = query("topic", {"type": "string", "maxLength": 256}, "a topic of the recording", required=True)
TIME = query("t", {"type": "number", "minimum": 0}, "the time to show, in seconds since the epoch (as the "
             "timeline's start and end)", required=True)
TF_TIME = query("t", {"type": "number", "minimum": 0}, "the time of the recording (s since the epoch); absent: "
                "its end")
NUMBERS = {"type": "array", "items": {"type": ["number", "null"]}}

FRAME = op("The camera frame at a time of the recording, as JPEG (X-Frame-Time: its log time; X-Frame-Error when "
           "the frame cannot be shown and the JPEG says why)", tag="recording", media="image/jpeg",
           params=[TOPIC, TIME,
                   query("width", {"type": "integer", "minimum": 16}, "scale to this width"),
                   query("height", {"type": "integer", "minimum": 16}, "scale to this height"),
                   query("quality", {"type": "integer", "minimum": 1, "maximum": 100}, "JPEG quality")],
           ok={"type": "string", "format": "binary"},
           errors={**READABLE, 400: "missing_field, bad_topic, bad_time, bad_width, bad_height, bad_quality",
                   404: "not_found, unknown_topic", 422: "not_a_recording, not_an_image"})
FRAME["responses"]["204"] = {"description": "the time is before the topic's first frame: nothing to show yet"}

PATHS = {
    "/recordings": {"get": page("Recordings: start, stop, status, the list with downloads", tag="recording")},
    "/api/recordings": {
        "get": op("Every recording of the robot: start, duration, size, topics, message counts", tag="recording",
                  ok=obj({"recordings": {"type": "array", "items": RECORDING},
                          "presets": {"type": "array", "items": {"type": "string"}}}, ("recordings",))),
        "post": op("Start recording (MCAP: the chosen topics' raw CDR and the audit trail)", tag="recording",
                   role="operator", status=201, body=START, ok=RECORDING, body_required=False,
                   errors={400: "bad_json, missing_body, unknown_field, bad_topics, bad_topic, bad_type, bad_name, "
                                "unknown_preset",
                           409: "recording_in_progress (one at a time per robot)",
                           422: "unknown_topic (a listed topic has no publisher, or no installed definition)",
                           503: "subscribe_failed",
                           507: "folder_full, disk_low, cannot_write", **BODY_ERRORS},
                   fuzz="last", fuzz_why="a recording started by the fuzzer runs until stopped: the rest of the "
                                         "POSTs would meet 409"),
    },
    "/api/recordings/{recording_id}": {
        "get": op("One recording's status (live counts while it runs; why it stopped)", tag="recording",
                  ok=RECORDING, errors=NOT_FOUND),
        "delete": op("Delete a recording and its file", tag="recording", role="admin",
                     ok=obj({"deleted": {"type": "string"}}),
                     errors={**NOT_FOUND, 409: "recording_in_progress"}),
    },
    "/recordings/{recording_id}/replay": {
        "get": page("Replay a recording in the browser: track, LiveMap, plots, diagnostics, camera, logs and "
                    "audit trail on a time slider; nothing is published", tag="recording", errors=NOT_FOUND)},
    "/api/recordings/{recording_id}/timeline": {
        "get": op("A recording as a timeline: what it holds, GPS, odometry and pose tracks, paths, /rosout lines, "
                  "the audit trail (each track evenly thinned to 5,000 points)", tag="recording",
                  ok=obj({"id": {"type": "string"}, "start": {"type": ["number", "null"]},
                          "end": {"type": ["number", "null"]}, "complete": {"type": "boolean"},
                          "topics": {"type": "object"}, "series": {"type": "object"}, "thinned": {"type": "object"},
                          "logs": {"type": "array"}, "audit": {"type": "array"}},
                         ("start", "end", "series", "logs", "audit")),
                  errors=READABLE),
    },
    "/api/recordings/{recording_id}/fields": {
        "get": op("The numeric field paths of a recorded topic, for plots", tag="recording", params=[TOPIC],
                  ok=obj({"topic": {"type": "string"}, "type": {"type": "string"},
                          "fields": {"type": "array", "items": {"type": "string"}}}),
                  errors={**READABLE, 400: "missing_field, bad_topic", 404: "not_found, unknown_topic",
                          422: "not_a_recording, not_plottable, not_decodable"}),
    },
    "/api/recordings/{recording_id}/series": {
        "get": op("Numeric fields of a recorded topic over time (at most 5,000 samples, evenly spread)",
                  tag="recording",
                  params=[TOPIC, query("field", {"type": "array", "items": {"type": "string", "maxLength": 200},
                                                 "minItems": 1, "maxItems": 8},
                                       "a field path such as pose.pose.position.x; up to 8", required=True)],
                  ok=obj({"topic": {"type": "string"}, "type": {"type": "string"}, "t": NUMBERS,
                          "v": {"type": "object", "additionalProperties": NUMBERS}, "count": {"type": "integer"},
                          "decoded": {"type": "integer"}, "skipped_nonfinite": {"type": "integer"}}),
                  errors={**READABLE, 400: "missing_field, bad_topic, bad_field",
                          404: "not_found, unknown_topic", 422: "not_a_recording, not_plottable"}),
    },
    "/api/recordings/{recording_id}/diagnostics": {
        "get": op("The diagnostics board at a time of the recording (as the diagnostics channel shows it live)",
                  tag="recording", params=[TIME],
                  ok=obj({"t": {"type": "number"}, "stale_after_s": {"type": "number"},
                          "statuses": {"type": "array"}, "hardware": {"type": "array"},
                          "thinned": {"type": "boolean"}, "arrays": {"type": "integer"}}),
                  errors={**READABLE, 400: "bad_time"}),
    },
    "/api/recordings/{recording_id}/frame": {"get": FRAME},
    # The recording's frames (rover_web/tf/replay.py): what a TF listener held at t, read from the file.
    "/recordings/{recording_id}/tf": {"get": page("The TF page for a recording: its frames at ?t= (the end by "
                                                  "default)", tag="pages", params=[TF_TIME],
                                                  errors={**READABLE, 400: "bad_time"})},
    "/api/recordings/{recording_id}/tf": {
        "get": op("The recording's TF tree at a time, in GET /api/tf's shape: static transforms logged up to t, "
                  "dynamic ones in the cache window before it, from every tf2_msgs/msg/TFMessage topic (a name "
                  "ending in tf_static is static)", tag="recording", params=[TF_TIME],
                  ok=obj({"t": {"type": "number"}, "start": {"type": "number"}, "end": {"type": "number"},
                          "tf_topics": {"type": "object", "additionalProperties": {"type": "boolean"}},
                          "read": {"type": "object"}, "frames": {"type": "object"}, "roots": {"type": "array"},
                          "warnings": {"type": "array"}}, closed=False),
                  errors={**READABLE, 400: "bad_time"}),
    },
    "/api/recordings/{recording_id}/tf/lookup": {
        "get": op("A transform between two of the recording's frames at ?t= (as GET /api/tf/lookup answers live)",
                  tag="recording",
                  params=[TF_TIME, query("target", {"type": "string", "minLength": 1, "maxLength": 256},
                                         "the frame the answer is expressed in", required=True),
                          query("source", {"type": "string", "minLength": 1, "maxLength": 256},
                                "the frame whose points are mapped", required=True),
                          query("time", {"type": "number", "minimum": 0},
                                "the stamp to look up at (s); absent or 0: the latest common time")],
                  ok=obj({"target": {"type": "string"}, "source": {"type": "string"},
                          "translation": {"type": "array"}, "rotation": {"type": "array"}, "yaw": {"type": "number"},
                          "stamp": {"type": "number"}, "stamp_ns": {"type": "integer"}}),
                  errors={**READABLE, 400: "bad_time, missing_frame, bad_frame, invalid",
                          404: "not_found, unknown_frame",
                          409: "recording_in_progress, not_connected, extrapolation_past, extrapolation_future"}),
    },
    "/api/recordings/upload": {
        "post": op("Upload an MCAP file from elsewhere to replay it (the body is the file); listed as uploaded",
                   tag="recording", role="operator", status=201, ok=RECORDING,
                   params=[query("name", {"type": "string", "maxLength": 80}, "a label for the list")],
                   errors={400: "bad_name, upload_incomplete",
                           413: "upload_too_large (ROVER_WEB_RECORDING_UPLOAD_MAX_MB), request_entity_too_large",
                           415: "unsupported_media_type (send Content-Type: application/octet-stream)",
                           422: "not_mcap, truncated, corrupt, not_ros2, " + BOUNDS,
                           507: "folder_full, disk_low, cannot_write"},
                   description="The body is the file itself (Content-Type: application/octet-stream), at most "
                               "ROVER_WEB_RECORDING_UPLOAD_MAX_MB. It is stored only once read whole and found "
                               "sound (every chunk's CRC): a cut, damaged or non-MCAP file is a 422 and nothing is "
                               "left in the recordings folder.",
                   fuzz="skip", fuzz_why="a binary body; its refusals have their own tests "
                                         "(tests/integration/recording/test_upload.py)",
                   extra={"requestBody": {"required": True, "content": {
                       "application/octet-stream": {"schema": {"type": "string", "format": "binary"}}}}}),
    },
    "/api/recordings/{recording_id}/stop": {
        "post": op("Stop the recording: its file gets its summary and footer", tag="recording", role="operator",
                   ok=RECORDING, errors=NOT_FOUND),
    },
    "/api/recordings/{recording_id}/file": {
        "get": op("Download the MCAP file (answers HTTP Range)", tag="recording", media="application/octet-stream",
                  ok={"type": "string", "format": "binary"},
                  errors={**NOT_FOUND, 409: "recording_in_progress"}),
    },
}
