"""Sign-in pages and API (/login, /logout, /api/me), the admin API for users and tokens, the
check every request passes before its view runs, and the revocation hook of streamed responses."""

from __future__ import annotations

import socket
from urllib.parse import unquote, urlsplit

from flask import Blueprint, g, jsonify, make_response, redirect, render_template, request, session, url_for
from flask_babel import gettext
from flask_login import current_user, login_user, logout_user

from rover_web.core.state import current_feature, current_rover
from rover_web.i18n import N_
from rover_web.web.http import ApiError, accepts_form, error_response, json_body, wants_json
from rover_web.web.validate import InvalidInput, only_keys, text

from .accounts import AccountError, HashingBusy, check_password, check_role
from .identity import SignedIn, current_credential
from .policy import is_admin_endpoint, required_role, role_allows
from .service import ADD_USER_HINT, AuthService

bp = Blueprint("auth", __name__)


def _service() -> AuthService:
    return current_feature(AuthService)


def _audit(action: str, by: str, detail: str) -> None:
    """Sign-ins concern every robot: the graph-wide AuditHub (the only robot's, when there is one)."""
    rover = current_rover()
    hub = rover.fleet.graph.audit if rover.fleet is not None else rover.audit
    hub.record(action, by=by, detail=detail, address=request.remote_addr or "unknown")


@bp.before_app_request
def check_access():
    auth = _service()
    exposure = auth.exposure(request)
    g.rover_web_sign_in = sign_in_on = auth.required or exposure is not None
    if not sign_in_on:
        if is_admin_endpoint(request.endpoint):
            # Anyone may call anything with sign-in off; a user or token made now would still work once
            # sign-in is turned on. Accounts are managed with the CLI until then.
            return error_response(403, "sign_in_off",
                                  "the users and tokens API needs sign-in on (ROVER_WEB_AUTH); until then "
                                  "use `flask --app rover_web users ...` and `tokens ...` on the robot's computer")
        return None
    needed = required_role(request.method, request.path, request.endpoint)
    if needed is None:
        return None
    if not current_user.is_authenticated and exposure is not None and auth.accounts.count() == 0:
        return error_response(403, "sign_in_needed",
                              f"sign-in is off only for requests made on this machine, and {exposure}; "
                              f"set ROVER_WEB_AUTH=required and add a user with `{ADD_USER_HINT}`")
    if not current_user.is_authenticated:
        if request.method == "GET" and not wants_json(request):
            # With the script root: sign-in at /robots/drone/login returns to the drone's page.
            return redirect(url_for("auth.login_form", next=request.script_root + request.full_path.rstrip("?")))
        response = error_response(401, "unauthenticated",
                                  "sign in at /login, or send the header Authorization: Bearer <token>")
        response.headers["WWW-Authenticate"] = 'Bearer realm="rover_web"'
        return response
    if not role_allows(current_user.role, needed):
        return _forbidden(needed)
    return None


def _forbidden(needed: str):
    return error_response(403, "forbidden",
                          f"this needs the {needed} role; {current_user.name} is a {current_user.role}")


def require_role(role: str) -> None:
    """For views whose rule depends on the request body (releasing the e-stop needs an operator)."""
    if _service().sign_in_on() and not role_allows(current_user.role, role):
        raise ApiError(403, "forbidden", f"this needs the {role} role; {current_user.name} is a {current_user.role}")


MAX_NEXT_LEN = 2000


def _safe_next(target: object) -> str:
    """`target` if it is a path on this server, else the robot's own page: never an open redirect.

    Browsers drop tabs and line breaks inside a URL and read a backslash as a slash, so
    `/<tab>/evil.example` is `//evil.example`, another site; a line break in a Location header is
    an error (it was a 500). So: one leading `/`, then no `/` or `\\` right after it, no backslash
    and no control character anywhere, also once percent-decoded, and no scheme or host.
    """
    default = request.script_root + "/"
    if not isinstance(target, str) or not target.startswith("/") or len(target) > MAX_NEXT_LEN:
        return default
    for form in (target, unquote(target)):
        if form.startswith(("//", "/\\")) or "\\" in form or not form.isprintable():
            return default
    parts = urlsplit(target)
    if parts.scheme or parts.netloc:
        return default
    return target


# --- sign-in ---

@bp.get("/login")
def login_form():
    if current_user.is_authenticated:
        return redirect(_safe_next(request.args.get("next")))
    return _login_page(_safe_next(request.args.get("next")), None, "")


def _login_page(next_path: str, error: str | None, username: str) -> str:
    return render_template("login.html", next=next_path, error=error, username=username,
                           login_estop=current_rover().config["ROVER_WEB_LOGIN_ESTOP"])


@bp.post("/login")
@accepts_form
def login():
    auth = _service()
    as_json = request.mimetype == "application/json"
    fields = json_body() if as_json else request.form
    username, password = fields.get("username"), fields.get("password")
    next_path = _safe_next(fields.get("next") if not as_json else None)
    if not isinstance(username, str) or not isinstance(password, str) or not username or not password:
        return _login_refused(as_json, 400, "missing_field", "enter a user name and a password", "", next_path)
    username = username.strip()[:80]
    address = request.remote_addr or "unknown"
    wait_s, why = auth.throttle.admit(username, address)
    if wait_s > 0:
        return _login_refused(as_json, 429, "too_many_attempts", f"{why}: try again in {wait_s:.0f} s",
                              username, next_path, retry_after_s=wait_s)
    try:
        user = auth.accounts.authenticate(username, password)
    except HashingBusy:
        # Refused before any hash is computed: the server's memory is bounded, not the queue's wait.
        return _login_refused(as_json, 503, "busy", "the server is checking other sign-ins: try again in a second",
                              username, next_path, retry_after_s=1)
    if user is None:
        auth.throttle.failed(username, address)
        _audit("auth.sign_in_refused", username, f"wrong password or user name for {username!r}")
        return _login_refused(as_json, 401, "bad_credentials", "wrong user name or password", username, next_path)
    auth.throttle.succeeded(username, address)
    _start_session(auth, user.name)
    _audit("auth.sign_in", user.name, f"{user.name} signed in ({user.role})")
    if as_json:
        return jsonify(user=user.name, role=user.role)
    return redirect(next_path, 303)


def _login_refused(as_json: bool, status: int, code: str, message: str, username: str, next_path: str,
                   retry_after_s: float | None = None):
    if as_json:
        response = error_response(status, code, message)
    else:
        html = _login_page(next_path, _page_message(code, message, retry_after_s), username)
        response = make_response(html, status, {"Content-Type": "text/html; charset=utf-8"})
    if retry_after_s is not None:
        response.headers["Retry-After"] = str(max(1, int(retry_after_s + 0.999)))
    return response


def _page_message(code: str, message: str, retry_after_s: float | None) -> str:
    """The sign-in page's words for a refusal, in the page's language (the JSON answer keeps `message`)."""
    if code == "too_many_attempts":
        return gettext("too many sign-in attempts: try again in %(seconds)s s", seconds=round(retry_after_s or 0))
    known = {"missing_field": N_("enter a user name and a password"),
             "busy": N_("the server is checking other sign-ins: try again in a second"),
             "bad_credentials": N_("wrong user name or password")}
    return gettext(known[code]) if code in known else message


# --- sessions ---

def _start_session(auth: AuthService, user_name: str) -> None:
    started = auth.sessions.start(user_name)
    if started is None:  # removed between the password check and now
        raise ApiError(401, "bad_credentials", "wrong user name or password")
    session.clear()  # nothing of an earlier session (or of none) carries over into this one
    login_user(SignedIn(started[1], started[0]))


@bp.post("/logout")
@accepts_form
def logout():
    auth = _service()
    if current_user.is_authenticated:
        _audit("auth.sign_out", current_user.name, f"{current_user.name} signed out")
    if current_user.is_authenticated and current_user.via == "session":
        auth.sessions.end(current_user.get_id())  # a copy of the cookie is refused from now on
        logout_user()
        auth.revoked()  # streams and sockets opened with this session close now
    else:
        logout_user()
    session.clear()
    if request.mimetype == "application/json" or request.accept_mimetypes.best == "application/json":
        return jsonify(signed_out=True)
    return redirect(url_for("auth.login_form"), 303)


@bp.post("/api/me/sessions/revoke")
def revoke_my_sessions():
    """Sign out everywhere: every session of the caller (this one too) and every stream or socket
    they have open, whatever it was opened with. API tokens stay valid."""
    json_body(required=False)
    auth = _service()
    if not auth.sign_in_on():
        raise ApiError(409, "sign_in_off", "sign-in is off: there is no session to end")
    name = current_user.name
    auth.sessions.end_everywhere(name)
    logout_user()
    session.clear()
    closed = auth.revoked()
    return jsonify(user=name, signed_out_everywhere=True, streams_closed=closed)


@bp.get("/api/me")
def me():
    auth = _service()
    if not auth.sign_in_on():
        return jsonify(user=None, role="admin", sign_in=False, via=None)
    return jsonify(user=current_user.name, role=current_user.role, sign_in=True, via=current_user.via)


@bp.after_app_request
def end_stream_on_revocation(response):
    """A streamed body (an event stream, a camera stream, a topic echo) goes on after its view
    returned and its access was checked: register it, so that its socket is shut down when its
    credential ends. The client sees the end at once; the stream's thread at its next write or
    liveness check (at most a second). Views with a close of their own (the teleop socket, the
    Broadcaster's streams) register with on_revoke instead, inside the view."""
    if not response.is_streamed or request.environ.get("HTTP_UPGRADE", "").lower() == "websocket":
        return response
    auth = _service()
    credential = current_credential() if auth.sign_in_on() else None
    sock = request.environ.get("werkzeug.socket") or request.environ.get("gunicorn.socket")
    if credential is None or sock is None:
        return response
    registration = auth.revocations.register(credential, lambda _reason: _cut(sock))
    response.call_on_close(registration.cancel)
    return response


def _cut(sock) -> None:
    try:
        # socket.socket's own shutdown, also under TLS: SSLSocket.shutdown would drop its TLS state
        # while the request thread may be writing through it.
        socket.socket.shutdown(sock, socket.SHUT_RDWR)
    except OSError:
        pass  # gone already


# --- users and tokens (admin) ---

@bp.errorhandler(AccountError)
def account_error(exc: AccountError):
    status = 404 if exc.code.startswith("no_such") else 409 if exc.code == "user_exists" else 400
    return error_response(status, exc.code, str(exc))


@bp.errorhandler(InvalidInput)
def invalid_input(exc: InvalidInput):
    return error_response(400, exc.code, str(exc))


@bp.get("/api/users")
def admin_list_users():
    return jsonify(users=_service().accounts.users())


@bp.post("/api/users")
def admin_add_user():
    body = json_body()
    only_keys(body, {"name", "role", "password"})
    user = _service().accounts.add_user(text(body, "name", max_len=40), text(body, "role", max_len=20),
                                        text(body, "password", max_len=1024))
    return jsonify(name=user.name, role=user.role), 201


@bp.patch("/api/users/<name>")
def admin_update_user(name: str):
    body = json_body()
    auth = _service()
    accounts = auth.accounts
    only_keys(body, {"role", "password"})
    if not body:
        raise InvalidInput("send 'role', 'password' or both", "missing_field")
    role = text(body, "role", max_len=20, default=None)
    password = text(body, "password", max_len=1024, default=None)
    if accounts.get(name) is None:
        raise AccountError(f"no user {name!r}", "no_such_user")
    # Both checked before either is written: a bad password must not leave a changed role.
    if role is not None:
        check_role(role)
    if password is not None:
        check_password(password)
        accounts.set_password(name, password)
    if role is not None:
        accounts.set_role(name, role)
    # The change renewed the user's epoch (a trigger, sessions.py): their sessions have ended.
    own_session = current_user.via == "session" and current_user.name == name
    auth.revoked()
    if own_session and password is not None and role in (None, "admin"):
        _start_session(auth, name)  # an admin changing their own password stays signed in here
    user = accounts.get(name)
    return jsonify(name=user.name, role=user.role)


@bp.delete("/api/users/<name>")
def admin_remove_user(name: str):
    auth = _service()
    auth.accounts.remove_user(name)
    auth.revoked()
    return jsonify(removed=name)


@bp.get("/api/tokens")
def admin_list_tokens():
    return jsonify(tokens=_service().accounts.tokens())


@bp.post("/api/tokens")
def admin_create_token():
    body = json_body()
    only_keys(body, {"user", "label"})
    user = text(body, "user", max_len=40)
    token_id, token = _service().accounts.create_token(user, text(body, "label", max_len=80, default=""))
    return jsonify(id=token_id, user=user, token=token), 201


@bp.delete("/api/tokens/<int:token_id>")
def admin_revoke_token(token_id: int):
    auth = _service()
    auth.accounts.revoke_token(token_id)
    auth.revoked()
    return jsonify(revoked=token_id)
