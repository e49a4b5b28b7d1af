"""JSON errors, strict request bodies and the protection every route gets from the start."""

from __future__ import annotations

import sqlite3
from urllib.parse import urlsplit

from flask import Flask, Request, current_app, jsonify, render_template, request
from flask_babel import gettext
from werkzeug.exceptions import HTTPException, NotFound
from werkzeug.middleware.proxy_fix import ProxyFix

from .api_messages import Text, as_text, explain
from .validate import InvalidInput, loads_strict

JSON_PREFIXES = ("/api/", "/ws/", "/stream", "/snapshot", "/metrics")  # /metrics: Prometheus gets 401, not a page
STATE_CHANGING = frozenset({"POST", "PUT", "PATCH", "DELETE"})


class ApiError(Exception):
    """A JSON 4xx/5xx: `code` an English identifier clients branch on, `message` an English msgid with
    `%(name)s` placeholders filled from `values`, answered in the request's language
    (api_messages.py). `message` may also be a Text another part raised (api_messages.text_of)."""

    def __init__(self, status: int, code: str, message: str | Text, retry_after_s: float | None = None,
                 **values):
        self.text = as_text(message, values)
        self.message = self.text.english()  # logs and str(exc) stay English
        super().__init__(self.message)
        self.status, self.code = status, code
        self.retry_after_s = retry_after_s


def too_many(what: Text, wait_s: float) -> ApiError:
    """429 with the whole seconds to wait, in the message and in Retry-After."""
    seconds = max(1, int(wait_s + 0.999))
    return ApiError(429, "rate_limited", "too many %(what)s; try again in %(seconds)s s", retry_after_s=seconds,
                    what=what, seconds=seconds)


def error_response(status: int, code: str, message: str | Text, **values):
    """The JSON error answer; its message rendered in the request's language, its code never."""
    response = jsonify(error=code, message=as_text(message, values).translated())
    response.status_code = status
    return response


def json_body(required: bool = True) -> dict:
    """The request's JSON object, parsed strictly; ApiError(400) for anything else."""
    raw = request.get_data(cache=True)  # honours MAX_CONTENT_LENGTH (413)
    if not raw.strip():
        if required:
            raise ApiError(400, "missing_body", "send a JSON object in the request body")
        return {}
    try:
        body = loads_strict(raw)
    except InvalidInput as exc:
        raise ApiError(400, exc.code, exc.text) from None
    if not isinstance(body, dict):
        raise ApiError(400, "bad_json", "body must be a JSON object, got %(type)s", type=type(body).__name__)
    return body


def wants_json(req: Request) -> bool:
    path = req.path
    if path.startswith("/robots/"):
        # /robots/<name>/api/... of a robot that does not exist: rover_web/fleet/prefix.py left the
        # prefix in the path, and an API client still reads the answer as JSON.
        path = "/" + path[len("/robots/"):].partition("/")[2]
    return path.startswith(JSON_PREFIXES) or req.method != "GET" or req.accept_mimetypes.best == "application/json"


def host_is_trusted(host: str, trusted: list[str]) -> bool:
    if host.startswith("["):  # [::1]:5000
        name = host[1:host.find("]")] if "]" in host else host
    else:
        name = host.rsplit(":", 1)[0] if host.count(":") == 1 else host
    name = name.lower().rstrip(".")
    for entry in trusted:
        entry = entry.lower()
        if entry.startswith(".") and (name.endswith(entry) or name == entry[1:]):
            return True
        if name == entry:
            return True
    return False


def origin_allowed(origin: str, host: str, allowed: list[str]) -> bool:
    """Same origin as the Host the browser used, or explicitly allowed."""
    parts = urlsplit(origin)
    if parts.scheme in ("http", "https") and parts.netloc.lower() == host.lower():
        return True
    return origin.rstrip("/") in {a.rstrip("/") for a in allowed}


FORM_TYPES = ("application/x-www-form-urlencoded", "multipart/form-data")

# What every response may load and who may frame it. The pages load scripts, styles, images and
# fonts from this server only; MapLibre builds its worker from a blob: URL and draws tiles from
# blob: and data: images. No inline styles either: a page sets computed styles from its scripts
# through the CSSOM (`el.style.x = ...`), which the policy does not restrict, so injected markup
# can neither run nor restyle the page (e.g. hide the e-stop).
CONTENT_SECURITY_POLICY = "; ".join([
    "default-src 'self'",
    "script-src 'self'",
    "style-src 'self'",
    "img-src 'self' data: blob:",
    "worker-src 'self' blob:",
    "child-src 'self' blob:",
    "connect-src 'self'",
    "object-src 'none'",
    "base-uri 'self'",
    "form-action 'self'",
    "frame-ancestors 'none'",
])
SECURITY_HEADERS = {
    "Content-Security-Policy": CONTENT_SECURITY_POLICY,
    "X-Frame-Options": "DENY",
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "same-origin",
}


def accepts_form(view):
    """Mark a view that takes an HTML form's POST (the sign-in form) besides JSON."""
    view.accepts_form = True
    return view


def _view_accepts_form() -> bool:
    view = current_app.view_functions.get(request.endpoint) if request.endpoint else None
    return bool(getattr(view, "accepts_form", False))


# Only over HTTPS (a browser ignores it over http anyway): after one visit over https, a browser
# goes to this host over https only for a year, so a sign-in is never sent in clear by a typed
# http:// address. No includeSubDomains: a robot's name says nothing about its neighbours'.
HSTS = "max-age=31536000"


def accepts_media(*types: str):
    """Mark a view whose body has a media type of its own besides JSON (WHEP's application/sdp)."""
    def mark(view):
        view.accepts_media = types
        return view
    return mark


def _view_accepts_media() -> tuple[str, ...]:
    view = current_app.view_functions.get(request.endpoint) if request.endpoint else None
    return getattr(view, "accepts_media", ())


def body_limit(max_bytes):
    """Mark a view whose body may be larger than ROVER_WEB_MAX_BODY_BYTES (an uploaded file):
    max_bytes(config) is its limit, which the view checks itself (to say which setting it is),
    and which reading its body enforces (request.max_content_length)."""
    def mark(view):
        view.max_body_bytes = max_bytes
        return view
    return mark


def _view_body_limit():
    view = current_app.view_functions.get(request.endpoint) if request.endpoint else None
    limit_of = getattr(view, "max_body_bytes", None)
    return limit_of(current_app.config) if limit_of is not None else None


def _security_headers(response):
    for name, value in SECURITY_HEADERS.items():
        response.headers.setdefault(name, value)
    if request.is_secure:
        response.headers.setdefault("Strict-Transport-Security", HSTS)
    return response


def _guard():
    config = current_app.config
    host = request.environ.get("HTTP_HOST", "")
    if not host_is_trusted(host, config["ROVER_WEB_TRUSTED_HOSTS"]):
        return error_response(400, "untrusted_host",
                              "Host %(host)s is not in ROVER_WEB_TRUSTED_HOSTS; "
                              "add it there to reach the GUI by that name", host=repr(host[:80]))
    is_websocket = request.headers.get("Upgrade", "").lower() == "websocket"
    if request.method in STATE_CHANGING or is_websocket:
        origin = request.headers.get("Origin")
        if origin and not origin_allowed(origin, host, config["ROVER_WEB_ALLOWED_ORIGINS"]):
            return error_response(403, "foreign_origin",
                                  "requests from %(origin)s may not control this robot; "
                                  "add it to ROVER_WEB_ALLOWED_ORIGINS", origin=origin[:80])
    limit = config["ROVER_WEB_MAX_BODY_BYTES"]
    own_limit = _view_body_limit()
    if own_limit is not None:
        request.max_content_length = own_limit  # the view says why it refuses more; reading stops there
    elif request.content_length is not None and request.content_length > limit:
        # Refuse before routing or reading, whatever the route does with its body.
        return error_response(413, "request_entity_too_large", "request body is larger than %(limit)s bytes",
                              limit=limit)
    if (request.method in ("POST", "PUT", "PATCH") and request.mimetype != "application/json"
            and not (request.mimetype in FORM_TYPES and _view_accepts_form())
            and request.mimetype not in _view_accepts_media()):
        return error_response(415, "unsupported_media_type",
                              "send the body as JSON with the header Content-Type: application/json")
    return None


def trust_proxies(app: Flask) -> None:
    """Behind ROVER_WEB_PROXY_HOPS reverse proxies, believe what they forward.

    Every per-address limit (sign-in back-off, the sign-in page's e-stop, stream shares with
    sign-in off) keys on request.remote_addr; behind a proxy that is the proxy's address for every
    client, so one client's failures would make everyone wait. Each proxy appends the address it
    saw to X-Forwarded-For; ProxyFix takes the Nth value from the right, the one the outermost
    trusted proxy wrote, so what a client put further left is never believed. With 0 nothing
    forwarded is read: a client that reaches the app directly cannot choose its own address.
    ProxyFix leaves the headers themselves in place, which keeps a proxied request "exposed"
    under ROVER_WEB_AUTH=auto (auth/policy.py forwarded_header reads them, not REMOTE_ADDR).
    """
    hops = app.config["ROVER_WEB_PROXY_HOPS"]
    if hops:
        app.wsgi_app = ProxyFix(app.wsgi_app, x_for=hops, x_proto=hops, x_host=hops)


def _not_found_page(exc: HTTPException):
    """A browser's 404 as a page of the app (its bar, its e-stop, where to go), not Werkzeug's bare one.

    None when the page cannot be drawn (an app with no robot pages, such as the hub): the bare 404
    then, never a 500 for an address that does not exist.
    """
    why = exc.description
    if not why or why == NotFound.description:
        why = gettext("There is no page at %(path)s.", path=request.path[:200])
    try:
        return render_template("not_found.html", why=why), 404
    except Exception:  # noqa: BLE001 - whatever broke drawing it, the answer stays a 404
        current_app.logger.warning("the not-found page could not be drawn for %s", request.path, exc_info=True)
        return None


# Werkzeug's own descriptions of the errors it raises before a view runs (no route, wrong method...),
# written here so the catalogue has them; a description a view gave (abort(404, description=Text))
# is its own msgid.
_WERKZEUG_TEXTS = {
    400: explain("The browser (or proxy) sent a request that this server could not understand."),
    404: explain("The requested URL was not found on the server. If you entered the URL manually please "
                 "check your spelling and try again."),
    405: explain("The method is not allowed for the requested URL."),
    406: explain("The resource identified by the request is only capable of generating response entities "
                 "which have content characteristics not acceptable according to the accept headers sent in "
                 "the request."),
    408: explain("The server closed the network connection because the browser didn't finish the request "
                 "within the specified time."),
    413: explain("The data value transmitted exceeds the capacity limit."),
    415: explain("The server does not support the media type transmitted in the request."),
    429: explain("This user has exceeded an allotted request count. Try again later."),
    500: explain("The server encountered an internal error and was unable to complete your request. Either "
                 "the server is overloaded or there is an error in the application."),
    503: explain("The server is temporarily unable to service your request due to maintenance downtime or "
                 "capacity problems. Please try again later."),
}


def _http_text(exc: HTTPException) -> Text:
    if isinstance(exc.description, Text):
        return exc.description
    known = _WERKZEUG_TEXTS.get(exc.code or 0)
    if known is not None and exc.description == known.msgid:
        return known
    return Text("%(reason)s", {"reason": exc.description or exc.name})


def init_app(app: Flask) -> None:
    trust_proxies(app)
    app.before_request(_guard)
    app.after_request(_security_headers)

    @app.errorhandler(ApiError)
    def _api_error(exc: ApiError):
        response = error_response(exc.status, exc.code, exc.text)
        if exc.retry_after_s is not None:
            response.headers["Retry-After"] = str(max(1, int(exc.retry_after_s + 0.999)))
        return response

    @app.errorhandler(HTTPException)
    def _http_error(exc: HTTPException):
        if not wants_json(request):
            return (_not_found_page(exc) if exc.code == 404 else None) or exc
        code = (exc.name or "error").lower().replace(" ", "_")
        if exc.code == 413:
            return error_response(413, code, "request body is larger than %(limit)s bytes",
                                  limit=current_app.config["ROVER_WEB_MAX_BODY_BYTES"])
        return error_response(exc.code or 500, code, _http_text(exc))

    @app.errorhandler(sqlite3.Error)
    def _storage(exc: sqlite3.Error):
        # A disk that is full or failing is the machine's state, not a bug: say which, and nothing
        # was stored (the transaction rolled back). Motion never waits on the disk.
        current_app.logger.error("database error on %s %s: %s", request.method, request.path, exc)
        if getattr(exc, "sqlite_errorname", "") == "SQLITE_FULL":
            return error_response(507, "disk_full", "the disk under the database is full; nothing was stored. "
                                                    "Free space on it and try again")
        return error_response(503, "storage_unavailable", "the database could not be used: %(why)s; nothing was stored",
                              why=str(exc))

    @app.errorhandler(Exception)
    def _unexpected(exc: Exception):
        # A bug, not bad input: log it, and still answer in the API's shape.
        current_app.logger.exception("unhandled error on %s %s", request.method, request.path)
        return error_response(500, "internal_error", "the server hit an unexpected error; see its log")
