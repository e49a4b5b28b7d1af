"""Sign-in, users and tokens, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op, page, query

ROLE = {"type": "string", "enum": ["viewer", "operator", "admin"]}
USER = obj({"name": {"type": "string"}, "role": ROLE}, closed=False)
LOSES = "could take the fuzz's own access away; its own user and token are kept out of reach too"
OFF = {403: "sign_in_off (sign-in is off: manage users and tokens with `flask --app rover_web users ...`)"}
ACCOUNT_400 = ("missing_body, bad_json, non_finite, unknown_field, missing_field, bad_type, too_long, "
               "bad_name, bad_role, bad_password")

PATHS = {
    "/login": {
        "get": page("The sign-in form", tag="pages", public=True,
                    params=[query("next", {"type": "string"}, "where to go after signing in (a local path)")]),
        "post": op(
            "Sign in: sets the session cookie", tag="auth", public=True, ok=USER,
            body=obj({"username": {"type": "string"}, "password": {"type": "string"}}, ("username", "password"),
                     closed=False),
            form=obj({"username": {"type": "string"}, "password": {"type": "string"}, "next": {"type": "string"}},
                     closed=False),
            errors={400: "missing_field, bad_json", 401: "bad_credentials",
                    429: "too_many_attempts (with Retry-After)",
                    503: "busy: every password-hashing slot is taken (with Retry-After; no hash computed)"},
            description="A form post answers with a redirect (303) or the form again; JSON answers JSON."),
    },
    "/logout": {
        "post": op("Sign out (ends the session; API tokens stay valid)", tag="auth",
                   ok=obj({"signed_out": {"type": "boolean"}}), body=obj(closed=False), body_required=False,
                   description="The session is deleted on the server, so a copy of its cookie is refused too; "
                               "streams and sockets opened with it close within a second."),
    },
    "/api/me/sessions/revoke": {
        "post": op("Sign out everywhere: end every session of the caller and close their open streams",
                   tag="auth", body=obj(closed=False), body_required=False,
                   ok=obj({"user": {"type": "string"}, "signed_out_everywhere": {"type": "boolean"},
                           "streams_closed": {"type": "integer"}}),
                   errors={400: "bad_json", 409: "sign_in_off"},
                   description="Renews the caller's session epoch: every session of theirs ends (this one too), "
                               "and every teleop socket, event stream, camera stream and topic echo they have "
                               "open closes, whatever it was opened with (the teleop socket stops the robot and "
                               "closes with 1008). API tokens stay valid; revoke them with "
                               "DELETE /api/tokens/{token_id}.",
                   fuzz="last", fuzz_why="ends the fuzz's own open streams"),
    },
    "/api/me": {"get": op("Who is calling, with which role", tag="auth", ok=obj(closed=False))},
    "/api/users": {
        "get": op("Every user", tag="auth", role="admin", ok=obj({"users": {"type": "array"}}), errors=OFF),
        "post": op("Add a user", tag="auth", role="admin", status=201, ok=USER,
                   body=obj({"name": {"type": "string", "maxLength": 40}, "role": ROLE,
                             "password": {"type": "string", "maxLength": 1024}}, ("name", "role", "password")),
                   errors={400: ACCOUNT_400, 409: "user_exists", **OFF}),
    },
    "/api/users/{name}": {
        "patch": op("Change a user's role or password", tag="auth", role="admin", ok=USER,
                    body=obj({"role": ROLE, "password": {"type": "string", "maxLength": 1024}}, minProperties=1),
                    errors={400: ACCOUNT_400, 404: "no_such_user", **OFF}, fuzz="last",
                    fuzz_why=LOSES,
                    description="The user's session epoch is renewed: their sessions end, and their open streams "
                                "and sockets close (an admin changing their own password gets a new session)."),
        "delete": op("Remove a user and their tokens", tag="auth", role="admin",
                     ok=obj({"removed": {"type": "string"}}),
                     errors={404: "no_such_user", **OFF}, fuzz="last", fuzz_why=LOSES,
                     description="Their sessions end and their open streams and sockets close."),
    },
    "/api/tokens": {
        "get": op("Every API token (without its secret)", tag="auth", role="admin",
                  ok=obj({"tokens": {"type": "array"}}), errors=OFF),
        "post": op("Make an API token for a user (the secret is shown once)", tag="auth", role="admin", status=201,
                   ok=obj({"id": {"type": "integer"}, "user": {"type": "string"}, "token": {"type": "string"}}),
                   body=obj({"user": {"type": "string", "maxLength": 40}, "label": {"type": "string", "maxLength": 80}},
                            ("user",)),
                   errors={400: "missing_body, bad_json, unknown_field, missing_field, bad_type, too_long",
                           404: "no_such_user", **OFF}),
    },
    "/api/tokens/{token_id}": {
        "delete": op("Revoke an API token", tag="auth", role="admin", ok=obj({"revoked": {"type": "integer"}}),
                     errors={404: "no_such_token", **OFF}, fuzz="last", fuzz_why=LOSES,
                     description="Streams and sockets opened with the token close within a second."),
    },
}
