"""The Zenoh settings, checked at start, and a session opened from them.

Key expressions, one set per robot (names are a-z 0-9 _, so never a Zenoh wildcard or separator):
  rover_web/<fleet>/<robot>/summary   the robot's line of the fleet page, signed, ~1 Hz and on change
  rover_web/<fleet>/<robot>/alive     its liveliness token: gone when its process or link is
  rover_web/<fleet>/<robot>/stop      its queryable: a signed stop command engages its e-stop
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from typing import Any

from rover_web.config import ConfigError

from .signing import load_key

ROOT_KEY = "rover_web"
NAME = re.compile(r"[a-z][a-z0-9_]{0,31}\Z")


def summary_key(fleet: str, robot: str) -> str:
    return f"{ROOT_KEY}/{fleet}/{robot}/summary"


def alive_key(fleet: str, robot: str) -> str:
    return f"{ROOT_KEY}/{fleet}/{robot}/alive"


def stop_key(fleet: str, robot: str) -> str:
    return f"{ROOT_KEY}/{fleet}/{robot}/stop"


def robot_of(key_expr: object) -> str:
    """The <robot> part of rover_web/<fleet>/<robot>/<what>."""
    parts = str(key_expr).split("/")
    return parts[2] if len(parts) == 4 else ""


@dataclass(frozen=True)
class LinkSettings:
    mode: str
    connect: list[str]
    listen: list[str]
    config_file: str | None
    multicast_scouting: bool
    fleet: str
    key: bytes


def link_settings(settings: dict[str, Any]) -> LinkSettings | None:
    """None with ROVER_WEB_ZENOH_MODE=off; else every Zenoh setting checked (ConfigError names the bad one)."""
    mode = settings["ROVER_WEB_ZENOH_MODE"]
    if mode == "off":
        return None
    fleet = settings["ROVER_WEB_FLEET_NAME"]
    if not NAME.match(fleet):
        raise ConfigError(f"ROVER_WEB_FLEET_NAME: {fleet!r} is not 1-32 of a-z 0-9 _ starting with a letter")
    for name in ("ROVER_WEB_ZENOH_CONNECT", "ROVER_WEB_ZENOH_LISTEN"):
        for endpoint in settings[name]:
            if "/" not in endpoint:
                raise ConfigError(f"{name}: {endpoint!r} is not a Zenoh endpoint such as tcp/192.168.1.5:7447")
    public_url = settings["ROVER_WEB_PUBLIC_URL"]
    if public_url is not None and not public_url.lower().startswith(("http://", "https://")):
        raise ConfigError(f"ROVER_WEB_PUBLIC_URL: {public_url!r} is not an http:// or https:// address")
    if mode == "client" and not settings["ROVER_WEB_ZENOH_CONNECT"] and not settings["ROVER_WEB_ZENOH_CONFIG"]:
        raise ConfigError("ROVER_WEB_ZENOH_CONNECT: client mode needs a router or peer to connect to")
    return LinkSettings(mode, list(settings["ROVER_WEB_ZENOH_CONNECT"]), list(settings["ROVER_WEB_ZENOH_LISTEN"]),
                        settings["ROVER_WEB_ZENOH_CONFIG"], settings["ROVER_WEB_ZENOH_MULTICAST_SCOUTING"], fleet,
                        load_key(settings["ROVER_WEB_FLEET_KEY_FILE"]))


def own_url(settings: dict[str, Any]) -> str | None:
    """Where others reach this rover_web: ROVER_WEB_PUBLIC_URL, else ROVER_WEB_HOST and _PORT when
    the host is a concrete address (not 0.0.0.0 or ::, which name no one machine), https when it
    serves TLS; None when neither says."""
    if settings["ROVER_WEB_PUBLIC_URL"]:
        return settings["ROVER_WEB_PUBLIC_URL"]
    # gunicorn.conf.py may leave a list here ("127.0.0.1,::1"): the first concrete one is as good as any.
    hosts = [h.strip() for h in (settings.get("ROVER_WEB_HOST") or "").split(",")]
    concrete = [h for h in hosts if h and h.strip("[]") not in ("0.0.0.0", "::", "*") and not set(h) & set("/@?#")]
    if not concrete:
        return None
    host = concrete[0]
    if ":" in host and not host.startswith("["):
        host = f"[{host}]"  # an IPv6 address in a URL
    scheme = "https" if settings.get("ROVER_WEB_TLS_CERT") else "http"
    return f"{scheme}://{host}:{settings['ROVER_WEB_PORT']}"


def zenoh_config(link: LinkSettings):
    import zenoh

    if link.config_file:
        try:
            config = zenoh.Config.from_file(link.config_file)
        except Exception as exc:  # zenoh raises its own ZError for an unreadable or invalid file
            raise ConfigError(f"ROVER_WEB_ZENOH_CONFIG: {link.config_file}: {exc}") from None
    else:
        config = zenoh.Config()
    config.insert_json5("mode", json.dumps(link.mode))
    config.insert_json5("scouting/multicast/enabled", json.dumps(link.multicast_scouting))
    if link.connect:
        config.insert_json5("connect/endpoints", json.dumps(link.connect))
    if link.listen:
        config.insert_json5("listen/endpoints", json.dumps(link.listen))
    return config


def open_session(link: LinkSettings):
    """A Zenoh session, or zenoh's error (ZError) when it cannot open now (a client with no router yet)."""
    import zenoh

    return zenoh.open(zenoh_config(link))
