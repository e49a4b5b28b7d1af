"""Mesh files named by `package://<pkg>/<path>`, found through the ament index and served only from
inside that package's share folder.

A path is refused before the file system is asked when it is absolute, has a `..` or an empty part,
a backslash or a NUL; then the realpath of the file (every symlink followed) must still lie inside
the realpath of the share folder, so a symlink in the package cannot lead out of it. Pure (no Flask).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass

from rover_web.web.api_messages import as_text, explain

MESH_TYPES = {".stl": "model/stl", ".dae": "model/vnd.collada+xml", ".obj": "model/obj", ".mtl": "text/plain",
              ".png": "image/png", ".jpg": "image/jpeg", ".jpeg": "image/jpeg", ".tga": "image/x-tga"}
_PACKAGE = re.compile(r"\A[A-Za-z][A-Za-z0-9_]{0,99}\Z")  # REP 144's package names
MAX_PATH = 1024


class MeshRefused(Exception):
    def __init__(self, status: int, code: str, message: str):
        self.text = as_text(message, {})
        super().__init__(self.text.english())
        self.status, self.code, self.message = status, code, self.text.english()


@dataclass(frozen=True)
class MeshFile:
    path: str          # the realpath, inside the share folder
    content_type: str
    size: int
    mtime_ns: int

    @property
    def etag(self) -> str:
        return f"{self.size:x}-{self.mtime_ns:x}"  # unquoted: werkzeug quotes it


def share_folder(package: str) -> str:
    """The package's share folder from the ament index (AMENT_PREFIX_PATH), or MeshRefused 404."""
    from ament_index_python.packages import PackageNotFoundError, get_package_share_directory

    try:
        return get_package_share_directory(package)
    except (PackageNotFoundError, ValueError, LookupError):
        raise MeshRefused(404, "unknown_package",
                          explain("package %(package)s is not in the ament index (AMENT_PREFIX_PATH)",
                                  package=repr(package))) from None


def check_relative(path: str) -> list[str]:
    """The parts of a relative path inside a package, or MeshRefused 400."""
    if not path or len(path) > MAX_PATH:
        raise MeshRefused(400, "bad_mesh_path", explain("a mesh path inside the package is 1 to 1024 characters"))
    if "\\" in path or "\x00" in path or path.startswith("/"):
        raise MeshRefused(400, "bad_mesh_path", explain("a mesh path is relative to its package, with '/' between "
                                                        "parts"))
    parts = path.split("/")
    if any(part in ("", ".", "..") for part in parts):
        raise MeshRefused(403, "outside_package", explain("a mesh path may not leave its package ('..', '.' or an "
                                                          "empty part)"))
    return parts


def resolve(package: str, path: str) -> MeshFile:
    if not _PACKAGE.match(package):
        raise MeshRefused(400, "bad_package", explain("%(package)s is not a package name",
                                                      package=repr(package[:100])))
    parts = check_relative(path)
    suffix = os.path.splitext(parts[-1])[1].lower()
    if suffix not in MESH_TYPES:
        raise MeshRefused(415, "not_a_mesh", explain("only %(mesh_types)s files are served",
                                                     mesh_types=', '.join(sorted(MESH_TYPES))))
    share = os.path.realpath(share_folder(package))
    real = os.path.realpath(os.path.join(share, *parts))
    if os.path.commonpath([share, real]) != share:
        raise MeshRefused(403, "outside_package", explain("%(path)s leads outside package %(package)s's share "
                                                          "folder",
                                                          path=repr(path[:200]), package=repr(package)))
    try:
        stat = os.stat(real)
    except OSError:
        raise MeshRefused(404, "no_such_mesh", explain("package %(package)s has no %(path)s",
                                                       package=repr(package), path=repr(path[:200]))) from None
    if not os.path.isfile(real):
        raise MeshRefused(404, "no_such_mesh", explain("%(path)s in package %(package)s is not a file",
                                                       path=repr(path[:200]), package=repr(package)))
    return MeshFile(real, MESH_TYPES[suffix], stat.st_size, stat.st_mtime_ns)


def package_uri(uri: str) -> tuple[str, str] | None:
    """(package, path) of a `package://` URI, or None for any other."""
    if not uri.startswith("package://"):
        return None
    package, _, path = uri[len("package://"):].partition("/")
    return package, path
