"""Floorplans from disk: the campus rover's `all_maps.json` and standard ROS map_server yaml files.

Two shapes of catalog entry are accepted in `all_maps.json` (paths relative to the catalog's folder
joined with the entry's `files.path`):

    "Science Hall Basement": {                      # the campus rover's format
        "files": {"path": "basement/",
                  "png_file": {"file_name": "basement.png", "cm_per_pixel": 5},
                  "waypoint_file": "basement_waypoints.json"},
        "yaml_parameters": {"resolution": 0.05, "origin": [-2.0, -1.5, 0.0]}}

    "Robotics Lab": {                               # a map_server yaml beside its PGM or PNG
        "files": {"path": "lab/", "yaml_file": "lab.yaml", "waypoint_file": "lab_waypoints.json"}}

The settings file may also name one map_server yaml directly; the map is then named after the file.
Every problem is a ConfigError naming the file and the key, raised before the app serves anything.
Every file must lie inside the catalog's folder: names with `..`, absolute paths or symlinks that
lead elsewhere are refused, so no request can ever reach a file outside it.
"""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
import threading
from collections.abc import Callable
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from rover_web.config import ROOT, ConfigError

from .geometry import MapGeometry, wrap_angle
from .keep_out import KeepOutArea, parse_keep_out
from .map_images import MAP_IMAGE_FORMATS, MAX_IMAGE_SIDE_PX, display_png, make_thumbnail

IMAGE_SUFFIXES = (".png", ".pgm")
MAX_NAME_CHARS = 80
_BAD_NAME = re.compile(r"[/\\\x00-\x1f\x7f]")
MAP_SERVER_DEFAULTS = {"negate": 0, "occupied_thresh": 0.65, "free_thresh": 0.25, "mode": "trinary"}
MODES = ("trinary", "scale", "raw")
CHECK_TIMEOUT_S = 60.0

# Image sizes (by resolved path) found by the child process that read the same catalog in full at
# start (load_catalog_checked_apart): while set, images are not decoded again and keep-out areas are
# not checked again here, so the server itself loads neither Pillow nor shapely until first used.
_CHECKED_SIZES: ContextVar[dict[str, list[int]] | None] = ContextVar("checked_sizes", default=None)


@dataclass(frozen=True)
class Waypoint:
    name: str
    x: float
    y: float
    yaw: float = 0.0

    def as_dict(self) -> dict:
        return {"name": self.name, "x": self.x, "y": self.y, "yaw": self.yaw}


@dataclass
class MapDefinition:
    """One floorplan: its geometry, the files it came from, its named waypoints, its image."""

    name: str
    geometry: MapGeometry
    files: dict[str, Any]          # the campus rover's `files` block, with the image's pixel size
    yaml: dict[str, Any]           # resolution, origin and the map_server fields
    waypoints: tuple[Waypoint, ...] = ()
    label: str = ""
    source: str = "file"           # "file" or "live" (an OccupancyGrid topic)
    version: int = 1
    image_path: Path | None = None
    renderer: Callable[[], bytes] | None = field(default=None, repr=False)  # live maps draw their own PNG
    keep_out: tuple[KeepOutArea, ...] = ()  # goals inside one are refused (keep_out.py)
    _png: bytes | None = field(default=None, repr=False)
    _thumbnail: bytes | None = field(default=None, repr=False)
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)

    def __post_init__(self):
        self.label = self.label or self.name

    def png(self) -> bytes:
        """The floorplan as PNG bytes (PGM converted, negate applied), made once."""
        with self._lock:
            if self._png is None:
                self._png = self.renderer() if self.renderer else display_png(self.image_path, self.yaml)
            return self._png

    def thumbnail(self) -> bytes:
        png = self.png()
        with self._lock:
            if self._thumbnail is None:
                self._thumbnail = make_thumbnail(png)
            return self._thumbnail

    def waypoint(self, name: str) -> Waypoint | None:
        return next((w for w in self.waypoints if w.name == name), None)


# --- loading ---


class _Source:
    """Error messages that name the file and the key."""

    def __init__(self, path: Path, shown: str | None = None):
        self.path = path
        self.shown = shown or str(path)

    def error(self, key: str, problem: str) -> ConfigError:
        return ConfigError(f"{self.shown}: {key}: {problem}" if key else f"{self.shown}: {problem}")


def _display_path(path: Path, root: Path) -> str:
    """A file named the way an operator finds it: relative to the folder above the catalog's."""
    try:
        return str(path.relative_to(root.parent))
    except ValueError:
        return str(path)


def _file_in(directory: Path, root: Path, name: Any, src: _Source, key: str, what: str) -> Path:
    """directory/name, refusing anything that could lead outside root: '..', an absolute path
    elsewhere, or a symlink out. The result is resolved."""
    if not isinstance(name, str) or not name.strip():
        raise src.error(key, f"expected the {what} as a non-empty string, got {name!r}")
    if "\x00" in name:
        raise src.error(key, f"the {what} name contains a NUL byte")
    candidate = Path(name)
    if ".." in candidate.parts:
        raise src.error(key, f"{name!r} may not contain '..'; {what}s must be inside {root}")
    resolved = (directory / candidate).resolve()
    try:
        resolved.relative_to(root)
    except ValueError:
        raise src.error(key, f"{name!r} leads outside {root}; {what}s must be inside it") from None
    return resolved


def _number(value: Any, src: _Source, key: str, *, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise src.error(key, f"expected a finite number, got {value!r}")
    if positive and value <= 0:
        raise src.error(key, f"expected a positive number, got {value!r}")
    return float(value)


def _origin(value: Any, src: _Source, key: str) -> list[float]:
    if not isinstance(value, (list, tuple)) or len(value) not in (2, 3):
        raise src.error(key, f"expected [x, y, yaw] in metres and radians, got {value!r}")
    numbers = [_number(v, src, f"{key}[{i}]") for i, v in enumerate(value)]
    return numbers + [0.0] * (3 - len(numbers))


def _map_server_params(raw: dict, src: _Source, prefix: str, *, need_image: bool) -> dict:
    """The map_server keys, checked, with map_server's defaults for the optional ones."""
    if not isinstance(raw, dict):
        raise src.error(prefix.rstrip("."), f"expected a mapping, got {type(raw).__name__}")
    required = ("image", "resolution", "origin") if need_image else ("resolution", "origin")
    for key in required:
        if key not in raw:
            raise src.error(prefix + key, "missing; a map needs " + ", ".join(required))
    params: dict[str, Any] = {}
    if need_image:
        params["image"] = raw["image"]
    params["resolution"] = _number(raw["resolution"], src, prefix + "resolution", positive=True)
    params["origin"] = _origin(raw["origin"], src, prefix + "origin")
    negate = raw.get("negate", MAP_SERVER_DEFAULTS["negate"])
    if negate not in (0, 1) or isinstance(negate, float):  # True/False are 1/0 here, like map_server
        raise src.error(prefix + "negate", f"expected 0 or 1, got {negate!r}")
    params["negate"] = int(negate)
    params["occupied_thresh"] = _number(raw.get("occupied_thresh", MAP_SERVER_DEFAULTS["occupied_thresh"]),
                                        src, prefix + "occupied_thresh")
    params["free_thresh"] = _number(raw.get("free_thresh", MAP_SERVER_DEFAULTS["free_thresh"]),
                                    src, prefix + "free_thresh")
    if not 0.0 <= params["free_thresh"] < params["occupied_thresh"] <= 1.0:
        raise src.error(prefix + "free_thresh",
                        "need 0 <= free_thresh < occupied_thresh <= 1, got "
                        f"{params['free_thresh']} and {params['occupied_thresh']}")
    mode = raw.get("mode", MAP_SERVER_DEFAULTS["mode"])
    if mode not in MODES:
        raise src.error(prefix + "mode", f"expected one of {', '.join(MODES)}, got {mode!r}")
    params["mode"] = mode
    return params


def _image_size(path: Path, src: _Source, key: str) -> tuple[int, int]:
    if path.suffix.lower() not in IMAGE_SUFFIXES:
        raise src.error(key, f"{path.name}: expected a .png or .pgm image")
    if not path.is_file():
        raise src.error(key, f"{path} not found")
    checked = _CHECKED_SIZES.get()
    if checked is not None and str(path.resolve()) in checked:
        width, height = checked[str(path.resolve())]
        return width, height
    from PIL import Image

    try:
        with Image.open(path, formats=MAP_IMAGE_FORMATS) as image:
            size = image.size
            if max(size) > MAX_IMAGE_SIDE_PX:
                raise src.error(key, f"{path.name} is {size[0]}x{size[1]} px; at most {MAX_IMAGE_SIDE_PX} a side")
            image.load()  # a truncated or corrupt image fails here, at start, not on the first request
    except ConfigError:
        raise
    except (OSError, ValueError, Image.DecompressionBombError) as exc:
        raise src.error(key, f"{path.name} is not a readable image: {exc}") from None
    return size


def _check_name(name: Any, src: _Source, what: str) -> str:
    if not isinstance(name, str) or not name.strip():
        raise src.error(repr(name), f"{what} names must be non-empty strings")
    if len(name) > MAX_NAME_CHARS or _BAD_NAME.search(name) or name in (".", ".."):
        raise src.error(repr(name), f"{what} names may not contain '/', '\\' or control characters, "
                                    f"nor be longer than {MAX_NAME_CHARS} characters")
    return name


def load_waypoints(path: Path, geometry: MapGeometry, shown: str) -> tuple[Waypoint, ...]:
    """`{"waypoints": [{"name", "x", "y", "yaw"?}, ...]}`, a bare list of those, or `{name: {x, y, yaw?}}`."""
    src = _Source(path, shown)
    if not path.is_file():
        raise src.error("", "waypoint file not found")
    try:
        raw = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise src.error("", f"not valid JSON: {exc}") from None
    if isinstance(raw, dict) and "waypoints" in raw:
        items, key_of = raw["waypoints"], (lambda i, item: f"waypoints[{i}]")
        if not isinstance(items, list):
            raise src.error("waypoints", "expected a list of {name, x, y, yaw}")
    elif isinstance(raw, list):
        items, key_of = raw, (lambda i, item: f"[{i}]")
    elif isinstance(raw, dict):
        items = [dict(v, name=k) if isinstance(v, dict) else v for k, v in raw.items()]
        key_of = lambda i, item: repr(list(raw)[i])  # noqa: E731
    else:
        raise src.error("", "expected {\"waypoints\": [...]}, a list, or a mapping of names to {x, y, yaw}")
    waypoints: list[Waypoint] = []
    for i, item in enumerate(items):
        key = key_of(i, item)
        if not isinstance(item, dict):
            raise src.error(key, f"expected an object with name, x, y and optional yaw, got {item!r}")
        unknown = sorted(set(item) - {"name", "x", "y", "yaw"})
        if unknown:
            raise src.error(f"{key}.{unknown[0]}", "unknown key; a waypoint has name, x, y and yaw")
        for required in ("name", "x", "y"):
            if required not in item:
                raise src.error(f"{key}.{required}", "missing")
        name = _check_name(item["name"], src, "waypoint")
        x = _number(item["x"], src, f"{key}.x")
        y = _number(item["y"], src, f"{key}.y")
        yaw = wrap_angle(_number(item.get("yaw", 0.0), src, f"{key}.yaw"))
        if not geometry.contains(x, y):
            raise src.error(key, f"waypoint {name!r} at ({x:g}, {y:g}) is outside the map "
                                 f"({geometry.width_m:g} m x {geometry.height_m:g} m from its origin)")
        if any(w.name == name for w in waypoints):
            raise src.error(f"{key}.name", f"duplicate waypoint name {name!r}")
        waypoints.append(Waypoint(name, x, y, yaw))
    return tuple(waypoints)


def _read_yaml(path: Path, src: _Source, key: str) -> dict:
    if not path.is_file():
        raise src.error(key, f"{path} not found")
    try:
        raw = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        raise src.error(key, f"{path.name} is not valid YAML: {exc}") from None
    return raw


def load_map_server_yaml(path: Path, root: Path, name: str, shown: str, waypoint_file: Path | None = None,
                         files_extra: dict | None = None) -> MapDefinition:
    """One standard map_server yaml (image, resolution, origin, negate, thresholds, mode)."""
    src = _Source(path, shown)
    raw = _read_yaml(path, src, "")
    params = _map_server_params(raw, src, "", need_image=True)
    image_path = _file_in(path.parent, root, params["image"], src, "image", "image file")
    width, height = _image_size(image_path, src, "image")
    geometry = MapGeometry(width, height, params["resolution"], *params["origin"])
    files = dict(files_extra or {})
    files.setdefault("path", _relative_dir(path.parent, root))
    files["yaml_file"] = path.name
    files["png"] = {"file_name": image_path.name, "cm_per_pixel": geometry.cm_per_pixel,
                    "pixel_width": width, "pixel_height": height}
    waypoints: tuple[Waypoint, ...] = ()
    if waypoint_file is not None:
        waypoints = load_waypoints(waypoint_file, geometry, _display_path(waypoint_file, root))
    yaml_block = {k: v for k, v in params.items() if k != "image"}
    return MapDefinition(name, geometry, files, yaml_block, waypoints, image_path=image_path)


def _relative_dir(directory: Path, root: Path) -> str:
    rel = directory.resolve().relative_to(root.resolve()).as_posix()
    return "" if rel == "." else rel + "/"


def _catalog_entry(name: str, entry: Any, root: Path, src: _Source) -> MapDefinition:
    definition = _catalog_map(name, entry, root, src)
    if "keep_out" in entry:
        try:
            definition.keep_out = parse_keep_out(entry["keep_out"], f"{json.dumps(name)}.keep_out",
                                                 check_shape=_CHECKED_SIZES.get() is None)
        except ValueError as exc:
            raise src.error("", str(exc)) from None
    return definition


def _catalog_map(name: str, entry: Any, root: Path, src: _Source) -> MapDefinition:
    key = json.dumps(name)
    if not isinstance(entry, dict):
        raise src.error(key, f"expected an object with files and yaml_parameters, got {type(entry).__name__}")
    files = entry.get("files")
    if not isinstance(files, dict):
        raise src.error(f"{key}.files", "missing or not an object")
    unknown = sorted(set(entry) - {"files", "yaml_parameters", "keep_out"})
    if unknown:
        raise src.error(f"{key}.{unknown[0]}", "unknown key; an entry has files, yaml_parameters and keep_out")
    unknown = sorted(set(files) - {"path", "png_file", "yaml_file", "waypoint_file"})
    if unknown:
        raise src.error(f"{key}.files.{unknown[0]}",
                        "unknown key; files has path, png_file or yaml_file, waypoint_file")
    rel_dir = files.get("path", "")
    if rel_dir in ("", "./", "."):
        directory = root.resolve()
    else:
        directory = _file_in(root, root, rel_dir, src, f"{key}.files.path", "folder")
        if not directory.is_dir():
            raise src.error(f"{key}.files.path", f"{rel_dir!r} is not a folder inside {root}")
    waypoint_path = None
    if files.get("waypoint_file") is not None:
        waypoint_path = _file_in(directory, root, files["waypoint_file"], src, f"{key}.files.waypoint_file",
                                 "waypoint file")
        if not waypoint_path.is_file():
            raise src.error(f"{key}.files.waypoint_file", f"{_display_path(waypoint_path, root)} not found")
    if "yaml_file" in files:
        if "png_file" in files or "yaml_parameters" in entry:
            raise src.error(f"{key}.files.yaml_file",
                            "give either yaml_file (a map_server yaml) or png_file with yaml_parameters, not both")
        yaml_path = _file_in(directory, root, files["yaml_file"], src, f"{key}.files.yaml_file", "yaml file")
        if not yaml_path.is_file():
            raise src.error(f"{key}.files.yaml_file", f"{yaml_path} not found")
        extra = {"path": _relative_dir(directory, root)}
        if waypoint_path is not None:
            extra["waypoint_file"] = files["waypoint_file"]
        return load_map_server_yaml(yaml_path, root, name, _display_path(yaml_path, root), waypoint_path, extra)
    png_file = files.get("png_file")
    if not isinstance(png_file, dict) or "file_name" not in png_file:
        raise src.error(f"{key}.files.png_file", "missing; expected {\"file_name\": ..., \"cm_per_pixel\": ...} "
                                                 "(or files.yaml_file naming a map_server yaml)")
    unknown = sorted(set(png_file) - {"file_name", "cm_per_pixel"})
    if unknown:
        raise src.error(f"{key}.files.png_file.{unknown[0]}", "unknown key; png_file has file_name and cm_per_pixel")
    image_path = _file_in(directory, root, png_file["file_name"], src, f"{key}.files.png_file.file_name",
                          "image file")
    if "yaml_parameters" not in entry:
        raise src.error(f"{key}.yaml_parameters", "missing; expected {\"resolution\": ..., \"origin\": [x, y, yaw]}")
    params = _map_server_params(entry["yaml_parameters"], src, f"{key}.yaml_parameters.", need_image=False)
    if "cm_per_pixel" in png_file:
        cm = _number(png_file["cm_per_pixel"], src, f"{key}.files.png_file.cm_per_pixel", positive=True)
        if not math.isclose(cm, params["resolution"] * 100.0, rel_tol=1e-9):
            raise src.error(f"{key}.files.png_file.cm_per_pixel",
                            f"{cm:g} cm per pixel disagrees with yaml_parameters.resolution "
                            f"{params['resolution']:g} m per pixel; fix one of them")
    width, height = _image_size(image_path, src, f"{key}.files.png_file.file_name")
    geometry = MapGeometry(width, height, params["resolution"], *params["origin"])
    waypoints = ()
    if waypoint_path is not None:
        waypoints = load_waypoints(waypoint_path, geometry, _display_path(waypoint_path, root))
    files_block = {"path": _relative_dir(directory, root),
                   "png": {"file_name": png_file["file_name"], "cm_per_pixel": geometry.cm_per_pixel,
                           "pixel_width": width, "pixel_height": height}}
    if waypoint_path is not None:
        files_block["waypoint_file"] = files["waypoint_file"]
    return MapDefinition(name, geometry, files_block, params, waypoints, image_path=image_path)


def maps_file_path(setting: str | None) -> Path | None:
    """ROVER_WEB_MAPS_FILE as a path: relative ones start at the repository root; empty means none."""
    if not setting:
        return None
    path = Path(setting).expanduser()
    if path.is_absolute():
        return path
    return ROOT / path


def load_catalog(path: str | Path) -> dict[str, MapDefinition]:
    """Every map in an all_maps.json (in file order), or the one map of a map_server yaml."""
    path = Path(path)
    src = _Source(path)
    if not path.is_file():
        raise src.error("", "maps file not found (set ROVER_WEB_MAPS_FILE, or leave it empty for no floorplans)")
    root = path.parent.resolve()
    if path.suffix.lower() in (".yaml", ".yml"):
        name = _check_name(path.stem, src, "map")
        return {name: load_map_server_yaml(path.resolve(), root, name, str(path))}
    try:
        raw = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise src.error("", f"not valid JSON: {exc}") from None
    if not isinstance(raw, dict) or not raw:
        raise src.error("", "expected an object mapping map names to {files, yaml_parameters}")
    catalog: dict[str, MapDefinition] = {}
    for name, entry in raw.items():
        _check_name(name, src, "map")
        catalog[name] = _catalog_entry(name, entry, root, src)
    return catalog


_checked_apart: dict[str, tuple[list, dict[str, list[int]]]] = {}  # catalog -> (files' stats, sizes)
_checked_apart_lock = threading.Lock()


def load_catalog_checked_apart(path: str | Path) -> dict[str, MapDefinition]:
    """load_catalog(path), with the images decoded and keep-out areas checked by a child process.

    Every check still runs before the app serves anything, and a bad floorplan still stops it with
    the same ConfigError; but Pillow and shapely (7 MB of a server's idle RSS, issue 32) are loaded
    by the child, and by the server only when a page first asks for an image or a goal meets a
    keep-out area. The result is kept per process while the files are unchanged (the tests make
    many apps on the same floorplans)."""
    path = Path(path)
    key = str(path.resolve()) if path.is_file() else str(path)
    with _checked_apart_lock:
        kept = _checked_apart.get(key)
        if kept is None or kept[0] != _stats([key, *kept[1]]):
            sizes = _check_in_child(path)
            if sizes is None:  # no child could be run: every check here instead, as before
                return load_catalog(path)
            kept = _checked_apart[key] = (_stats([key, *sizes]), sizes)
    token = _CHECKED_SIZES.set(kept[1])
    try:
        return load_catalog(path)
    finally:
        _CHECKED_SIZES.reset(token)


def _stats(paths: list[str]) -> list:
    out = []
    for p in paths:
        try:
            st = Path(p).stat()
            out.append((p, st.st_mtime_ns, st.st_size))
        except OSError:
            out.append((p, None, None))
    return out


def _check_in_child(path: Path) -> dict[str, list[int]] | None:
    """The images' sizes from the child, ConfigError for a bad floorplan, or None when no child
    could be run or it said nothing usable (a process limit, a clock under faketime that makes the
    wait fail): the caller then checks in this process, which only costs the memory."""
    try:
        done = subprocess.run([sys.executable, "-m", "rover_web.livemap.check_maps", str(path)], capture_output=True,
                              text=True, timeout=CHECK_TIMEOUT_S, check=False)
        answer = json.loads(done.stdout.strip().splitlines()[-1]) if done.stdout.strip() else {}
    except (OSError, subprocess.TimeoutExpired, ValueError):
        return None
    if "error" in answer:
        raise ConfigError(answer["error"])
    return answer.get("sizes")


def first_waypoint_or_centre(definition: MapDefinition) -> tuple[float, float, float]:
    """Where a simulated robot starts on a map: its first named waypoint, else the image centre."""
    if definition.waypoints:
        w = definition.waypoints[0]
        return w.x, w.y, w.yaw
    g = definition.geometry
    x, y = g.pixel_to_world(g.width_px / 2, g.height_px / 2)
    return x, y, 0.0
