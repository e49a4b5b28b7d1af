"""Sign-in and roles: who may watch (viewer), drive and command (operator), and manage users (admin).

  GET  /login, POST /login    the sign-in form (fields username, password; JSON works for curl)
  POST /logout                ends the session
  GET  /api/me                {"user", "role", "sign_in", "via"}
  /api/users, /api/tokens     users and API tokens (admin)
Sessions are Flask-Login's signed cookie (HttpOnly, SameSite=Strict, Secure over HTTPS); API tokens
go in `Authorization: Bearer <token>`. ROVER_WEB_AUTH decides whether any of it is required.
"""

from __future__ import annotations

from flask import Flask, request
from flask.sessions import SecureCookieSessionInterface
from flask_login import LoginManager

from rover_web import process
from rover_web.core.state import Rover

from . import routes
from .cli import init_cli
from .identity import Anonymous, SignedIn, current_identity, may, signed_in_name
from .routes import require_role
from .service import AuthService, secret_key

__all__ = ["init_app", "init_cli", "current_identity", "may", "require_role", "signed_in_name", "AuthService"]

BEARER = "bearer "


class _SessionInterface(SecureCookieSessionInterface):
    # Secure exactly when the request came over HTTPS: flask run --cert, the demo with
    # ROVER_WEB_TLS_CERT, or gunicorn with a certificate, without a second setting to keep in step.
    def get_cookie_secure(self, app: Flask) -> bool:
        return request.is_secure or super().get_cookie_secure(app)


def init_app(app: Flask, rover: Rover) -> None:
    service = AuthService(rover.db, rover.config["ROVER_WEB_AUTH"], process.listen_hosts(rover.config), rover.config)
    service.check_startable()
    rover.add_feature(service)
    rover.on_shutdown(service.accounts.gate.close)  # the password-hashing threads
    app.secret_key = secret_key(rover.config["ROVER_WEB_SECRET_KEY"], app.instance_path)
    app.config.update(SESSION_COOKIE_HTTPONLY=True, SESSION_COOKIE_SAMESITE="Strict")
    app.session_interface = _SessionInterface()

    manager = LoginManager(app)
    manager.anonymous_user = Anonymous
    manager.session_protection = "basic"

    @manager.user_loader
    def _load_user(name: str):
        if "Authorization" in request.headers:
            return None  # explicit credentials win over a cookie: the token alone decides (request_loader)
        user = service.accounts.get(name)  # each request: a removed user or a new role counts at once
        return SignedIn(user.name, user.role, "session") if user else None

    @manager.request_loader
    def _load_from_token(req):
        header = req.headers.get("Authorization", "")
        if header[: len(BEARER)].lower() != BEARER:
            return None
        user = service.accounts.user_for_token(header[len(BEARER):].strip())
        return SignedIn(user.name, user.role, "token") if user else None

    app.register_blueprint(routes.bp)

    @app.context_processor
    def _identity_context():
        identity = current_identity()
        return {"signed_in": identity if service.required else None, "sign_in_on": service.required,
                "can_operate": may("operator", service.required),
                "can_admin": may("admin", service.required)}  # the geofence editor (PUT /api/geofence)
