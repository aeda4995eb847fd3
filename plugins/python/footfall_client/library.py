"""Finds and loads libfootfall.so and declares the C signatures of footfall_c.h."""

import ctypes
import ctypes.util
import os

from .installed import installed_path

ABI_VERSION = 1  # FFC_ABI_VERSION this package was written against

_LIB_NAME = "libfootfall.so"
_loaded = {}


class LibraryNotFound(OSError):
    """libfootfall.so could not be found or loaded; the message lists where we looked."""


class FfcFoothold(ctypes.Structure):
    """ffc_foothold: one query answer."""

    _fields_ = [
        ("status", ctypes.c_int32),
        ("index", ctypes.c_uint32),
        ("point", ctypes.c_double * 3),
        ("normal", ctypes.c_double * 3),
    ]


def _candidates():
    """Where the library may be, in order: $FOOTFALL_LIB, next to this package, the install
    this package belongs to (cmake --install), a build tree, the system's library path."""
    env = os.environ.get("FOOTFALL_LIB")
    if env:
        yield env
    here = os.path.dirname(os.path.abspath(__file__))
    yield os.path.join(here, _LIB_NAME)
    yield os.path.join(os.path.dirname(here), _LIB_NAME)
    installed = installed_path("lib")
    if installed:
        yield installed
    # The source tree: plugins/python/footfall_client -> <repo>/build/client/lib.
    repo = os.path.dirname(os.path.dirname(os.path.dirname(here)))
    yield os.path.join(repo, "build", "client", "lib", _LIB_NAME)
    system = ctypes.util.find_library("footfall")
    if system:
        yield system


def find_library():
    """The path of the first libfootfall.so candidate that exists; LibraryNotFound otherwise.
    $FOOTFALL_LIB, when set, must name the library: a wrong one is an error, not passed over
    for a library found elsewhere."""
    env = os.environ.get("FOOTFALL_LIB")
    if env and not os.path.isfile(env):
        raise LibraryNotFound("FOOTFALL_LIB names %s, which is %s: set it to libfootfall.so's "
                              "path, or unset it to use the one found beside this package"
                              % (env, "a directory" if os.path.isdir(env) else "not a file"))
    tried = []
    for path in _candidates():
        tried.append(path)
        if os.path.sep not in path or os.path.isfile(path):
            return path
    raise LibraryNotFound(
        "libfootfall.so not found (set FOOTFALL_LIB to its path); looked in: " + ", ".join(tried))


def _declare(lib):
    c = ctypes
    sess = c.c_void_p
    dptr = c.POINTER(c.c_double)
    hold = c.POINTER(FfcFoothold)
    u32p = c.POINTER(c.c_uint32)
    sigs = {
        "ffc_abi_version": (c.c_int, []),
        "ffc_open_embedded": (sess, []),
        "ffc_open_rpc": (sess, [c.c_char_p, c.c_int, c.c_double]),
        "ffc_close": (None, [sess]),
        "ffc_last_error": (c.c_char_p, [sess]),
        "ffc_status_name": (c.c_char_p, [c.c_int32]),
        "ffc_load_file": (c.c_int32, [sess, c.c_char_p, c.c_double, u32p]),
        "ffc_load_server_file": (c.c_int32, [sess, c.c_char_p, c.c_double, u32p]),
        "ffc_load_samples": (c.c_int32, [sess, dptr, c.c_size_t, c.c_char_p, u32p]),
        "ffc_unload": (c.c_int32, [sess, c.c_uint32]),
        "ffc_info": (c.c_int32, [sess, c.c_uint32, c.POINTER(c.c_uint64), dptr]),
        "ffc_snap": (c.c_int32, [sess, c.c_uint32, dptr, c.c_size_t, hold]),
        "ffc_normal": (c.c_int32, [sess, c.c_uint32, dptr, c.c_size_t, hold]),
        "ffc_next": (c.c_int32, [sess, c.c_uint32, dptr, c.c_size_t, c.c_double, hold]),
        # char** out: declared as a void pointer so ctypes leaves the memory to ffc_free_string.
        "ffc_generate": (c.c_int32, [sess, c.c_uint32, c.c_char_p, c.POINTER(c.c_void_p)]),
        "ffc_generate_with_notes": (c.c_int32, [sess, c.c_uint32, c.c_char_p,
                                                c.POINTER(c.c_void_p), c.POINTER(c.c_void_p)]),
        "ffc_free_string": (None, [c.c_void_p]),
        "ffc_check_character": (c.c_int32, [sess, c.c_char_p]),
        "ffc_ping": (c.c_int32, [sess]),
        "ffc_walk_stop": (c.c_int32, [sess]),
    }
    missing = []
    for name, (restype, argtypes) in sigs.items():
        try:
            fn = getattr(lib, name)
        except AttributeError:
            missing.append(name)
            continue
        fn.restype = restype
        fn.argtypes = argtypes
    return missing


def _load_failure(path, reason):
    """Why `path` could not be loaded, saying which library it needs when one is missing (a zip
    or install copied from the machine that built footfall, to one without its libraries)."""
    marker = ": cannot open shared object file"
    needed = reason.split(marker)[0] if marker in reason else ""
    if needed and os.path.basename(needed) != os.path.basename(path):
        return ("cannot load %s: it needs %s, which this machine does not have (footfall's "
                "runtime libraries: on Debian and Ubuntu, apt-get install libopenmesh1 "
                "libtirpc3; or build footfall on this machine): %s" % (path, needed, reason))
    return "cannot load %s: %s" % (path, reason)


class Library:
    """A loaded libfootfall.so: `lib` is the ctypes handle, `missing` the entry points it lacks
    (an older library), `path` where it was loaded from."""

    def __init__(self, path):
        try:
            self.lib = ctypes.CDLL(path)
        except OSError as e:
            raise LibraryNotFound(_load_failure(path, str(e))) from None
        self.path = path
        self.missing = _declare(self.lib)
        if "ffc_abi_version" in self.missing or "ffc_open_rpc" in self.missing:
            raise LibraryNotFound("%s is not libfootfall (no ffc_open_rpc)" % path)
        version = self.lib.ffc_abi_version()
        if version != ABI_VERSION:
            raise LibraryNotFound("%s has C ABI version %d; this package needs %d"
                                  % (path, version, ABI_VERSION))

    def has(self, name):
        return name not in self.missing


def load_library(path=None):
    """The Library at `path` (default: find_library()), loaded once per path."""
    path = path or find_library()
    lib = _loaded.get(path)
    if lib is None:
        lib = _loaded[path] = Library(path)
    return lib
