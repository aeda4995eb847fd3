"""footfall_client: footfall's C ABI (libfootfall.so, footfall_c.h) for Python, through ctypes.

Shared by the Blender and Maya plugins; plain Python 3.8+ with no other dependency.

    from footfall_client import Session, FootfallError
    with Session.rpc("127.0.0.1", 7407) as s:
        terrain = s.load_file("hills.pts")
        hold = s.snap(terrain, [(1.0, 5.0, 1.0)])[0]

Every failed call raises FootfallError (status, status_name, message); nothing here lets a C++
exception or a signal reach the host application. Points are world space in footfall's frame
(Y up unless the request says otherwise), lengths in world units.
"""

from .library import LibraryNotFound, find_library, load_library
from .session import (
    STATUS_NAMES,
    FootfallError,
    Foothold,
    Session,
    WalkStopped,
)
from .server import LocalServer, ServerError, find_footfalld
from .connection import Connection
from . import character, rotation, sampling, vectors

__all__ = [
    "Connection",
    "FootfallError",
    "Foothold",
    "LibraryNotFound",
    "LocalServer",
    "STATUS_NAMES",
    "ServerError",
    "Session",
    "WalkStopped",
    "find_footfalld",
    "find_library",
    "load_library",
]
