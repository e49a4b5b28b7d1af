"""Sign-in and roles: who may watch (viewer), drive and command (operator), and manage users (admin).

  GET  /login, POST /login    the sign-in form (fields username, password; JSON works for curl)
  POST /logout                ends the session
  POST /api/me/sessions/revoke  signs the caller out everywhere
  GET  /api/me                {"user", "role", "sign_in", "via"}
  /api/users, /api/tokens     users and API tokens (admin; refused while sign-in is off)
Sessions are server-side rows (sessions.py) named by Flask-Login's signed cookie (HttpOnly,
SameSite=Strict, Secure over HTTPS); API tokens go in `Authorization: Bearer <token>`.
ROVER_WEB_AUTH decides whether any of it is required. Open streams and sockets end when their
credentials do (revocation.py: `on_revoke`).
"""

from __future__ import annotations

from datetime import timedelta

from flask import Flask, request
from flask.sessions import SecureCookieSessionInterface
from flask_login import LoginManager

from rover_web import process
from rover_web.core.state import Rover

from . import routes
from .cli import init_cli
from .identity import Anonymous, SignedIn, current_credential, current_identity, may, on_revoke, signed_in_name
from .revocation import Credential, Registration
from .routes import require_role
from .service import AuthService, secret_key

__all__ = ["init_app", "init_cli", "current_identity", "current_credential", "may", "on_revoke", "require_role",
           "signed_in_name", "AuthService", "Credential", "Registration"]

BEARER = "bearer "


class _SessionInterface(SecureCookieSessionInterface):
    # Secure exactly when the request came over HTTPS: flask run --cert, the demo with
    # ROVER_WEB_TLS_CERT, or gunicorn with a certificate, without a second setting to keep in step.
    def get_cookie_secure(self, app: Flask) -> bool:
        return request.is_secure or super().get_cookie_secure(app)


def init_app(app: Flask, rover: Rover) -> None:
    config = rover.config
    app.secret_key = secret_key(config["ROVER_WEB_SECRET_KEY"], app.instance_path)  # before anything starts
    service = AuthService(rover.db, config["ROVER_WEB_AUTH"], process.listen_hosts(config), config,
                          session_hours=config["ROVER_WEB_SESSION_HOURS"],
                          trusted_hosts=config["ROVER_WEB_TRUSTED_HOSTS"])
    service.check_startable()
    rover.add_feature(service)
    rover.on_shutdown(service.accounts.gate.close)  # the password-hashing threads
    service.start(rover)
    # The signed cookie's own age limit too (Flask's default is 31 days); the session row decides.
    app.config.update(SESSION_COOKIE_HTTPONLY=True, SESSION_COOKIE_SAMESITE="Strict",
                      PERMANENT_SESSION_LIFETIME=timedelta(hours=config["ROVER_WEB_SESSION_HOURS"]))
    app.session_interface = _SessionInterface()

    manager = LoginManager(app)
    manager.anonymous_user = Anonymous
    manager.session_protection = "basic"

    @manager.user_loader
    def _load_user(session_id: str):
        if "Authorization" in request.headers:
            return None  # explicit credentials win over a cookie: the token alone decides (request_loader)
        # Each request: a signed-out, expired or renewed session, a removed user or a new role counts at once.
        credential = service.sessions.for_session(session_id)
        return SignedIn(credential, session_id) if credential else None

    @manager.request_loader
    def _load_from_token(req):
        header = req.headers.get("Authorization", "")
        if header[: len(BEARER)].lower() != BEARER:
            return None
        credential = service.sessions.for_token(header[len(BEARER):].strip())
        return SignedIn(credential) if credential else None

    app.register_blueprint(routes.bp)

    @app.context_processor
    def _identity_context():
        identity = current_identity()
        sign_in_on = service.sign_in_on()
        return {"signed_in": identity if sign_in_on else None, "sign_in_on": sign_in_on,
                "can_operate": may("operator", sign_in_on),
                "can_admin": may("admin", sign_in_on)}  # the geofence editor (PUT /api/geofence)
