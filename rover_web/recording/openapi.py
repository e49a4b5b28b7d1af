"""The recordings' routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import BODY_ERRORS, obj, op, page

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
}, ("id", "state", "started_at", "size", "topics", "counts"), closed=False)
NOT_FOUND = {404: "not_found"}

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
        "get": page("Replay a recording in the browser: track, logs and audit trail on a time slider",
                    tag="recording", errors=NOT_FOUND)},
    "/api/recordings/{recording_id}/timeline": {
        "get": op("A recording as a timeline: GPS and odometry tracks, /rosout lines, the audit trail", tag="recording",
                  ok=obj({"id": {"type": "string"}, "start": {"type": ["number", "null"]},
                          "end": {"type": ["number", "null"]}, "complete": {"type": "boolean"},
                          "series": {"type": "object"}, "logs": {"type": "array"}, "audit": {"type": "array"}},
                         ("start", "end", "series", "logs", "audit")),
                  errors={**NOT_FOUND, 409: "recording_in_progress", 422: "not_a_recording"}),
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
