"""Session: one embedded engine or footfalld connection, with Pythonic errors."""

import ctypes
import functools
import itertools
import json
import os
import threading
from array import array
from collections import namedtuple

from .library import FfcFoothold, load_library

# ff_status values (footfall_c.h, rpc/footfall.x), by number.
STATUS_NAMES = {
    0: "ok",
    1: "no_foothold",
    2: "invalid_argument",
    3: "unknown_terrain",
    4: "limit_exceeded",
    5: "io_error",
    6: "parse_error",
    7: "access_denied",
    8: "unavailable",
    9: "internal_error",
}
OK, NO_FOOTHOLD, INVALID_ARGUMENT, UNKNOWN_TERRAIN, LIMIT_EXCEEDED, UNAVAILABLE = 0, 1, 2, 3, 4, 8


class FootfallError(Exception):
    """A failed footfall call: `status` (int), `status_name` ("unavailable", ...), `message`
    (the library's one-line reason) and `call` (the C function that failed)."""

    def __init__(self, status, message, call=""):
        self.status = status
        self.status_name = STATUS_NAMES.get(status, "status_%d" % status)
        self.message = message
        self.call = call
        super().__init__("%s: %s" % (self.status_name, message))

    def __reduce__(self):
        # Rebuilt from the same arguments, so the error crosses pickling (a multiprocessing
        # pool's worker raising it): Exception's default passes only the text.
        return (type(self), (self.status, self.message, self.call))


def _raise_if_out_of_memory(lib, call):
    """Raises FootfallError 'limit_exceeded' when the last ffc_open_* on this thread ran out of
    memory (the library says so through ffc_last_error(NULL)): it was reported as a bad host."""
    why = lib.lib.ffc_last_error(None)
    why = why.decode("utf-8", "replace") if why else ""
    if "out of memory" in why:
        raise FootfallError(LIMIT_EXCEEDED, why, call)


class WalkStopped(FootfallError):
    """generate() stopped before every step was made (a cliff, the server gone). `walk` holds
    the keys made up to that point (footfall's walk JSON as a dict), or None; `notes` that
    walk's notes (see Session.generate_json_with_notes)."""

    def __init__(self, status, message, walk, call="ffc_generate", notes=()):
        super().__init__(status, message, call)
        self.walk = walk
        self.notes = list(notes)

    def __reduce__(self):
        return (type(self), (self.status, self.message, self.walk, self.call, self.notes))


# One answer of snap/normal/next. point and normal are world-space 3-tuples (None unless ok).
Foothold = namedtuple("Foothold", "status status_name index point normal")
Foothold.ok = property(lambda self: self.status == OK)


def _path_bytes(path, function):
    """A path (str, bytes or os.PathLike) as the bytes the C library opens: str paths as the
    file system encodes them (undecodable names round-trip), bytes as they are."""
    try:
        encoded = os.fsencode(path)
    except (TypeError, UnicodeError) as e:
        raise FootfallError(INVALID_ARGUMENT, "path %r: %s" % (path, e), function)
    if b"\0" in encoded:  # C would read it cut short at the NUL
        raise FootfallError(INVALID_ARGUMENT, "path %r: holds a NUL byte" % (path,), function)
    return encoded


def _flat_fast(rows, width):
    """_flat's array('d') without a Python step per number, for the shapes callers pass: an
    object with the buffer protocol holding native doubles (array('d'), a numpy float64 array:
    flat, or `width` columns), a list or tuple of floats and ints, or a list or tuple of
    `width`-tuples (or lists) of floats and ints, as sampling.sample_triangles returns. The same
    numbers as float() of each. None for anything else, or anything wrong: _flat's loop then
    takes it, with its errors. An array('d') (sampling.sample_triangles_flat's samples) is
    given back as it is, not copied: the C library only reads it, during the call."""
    if type(rows) is array and rows.typecode == "d":
        return rows if len(rows) % width == 0 else None
    try:
        view = memoryview(rows)
    except TypeError:
        view = None
    if view is not None:
        with view:
            if (view.format in ("d", "@d") and view.c_contiguous
                    and (view.ndim == 1 or (view.ndim == 2 and view.shape[1] == width))
                    and view.nbytes % (8 * width) == 0):
                flat = array("d")
                flat.frombytes(view.cast("B"))
                return flat
        return None
    if type(rows) not in (list, tuple):
        return None
    # Only exact floats and ints: array('d') reads a float subclass's value where float()
    # calls its __float__, and refuses the strings float() parses.
    numbers = {float, int}
    kinds = set(map(type, rows))
    if kinds <= numbers:
        items = rows
    elif kinds <= {tuple, list} and set(map(len, rows)) == {width}:
        if not set(map(type, itertools.chain.from_iterable(rows))) <= numbers:
            return None
        items = itertools.chain.from_iterable(rows)
    else:
        return None
    try:
        flat = array("d", items)
    except OverflowError:  # (an int beyond a double)
        return None
    return flat if len(flat) % width == 0 else None


def _flat(rows, width, what):
    """rows: a sequence of `width`-tuples, or an already flat sequence of floats -> array('d').
    FootfallError 'invalid_argument' when they are not numbers in rows of `width`."""
    flat = _flat_fast(rows, width)
    if flat is not None:
        return flat
    flat = array("d")
    try:
        for row in rows:
            if isinstance(row, (int, float)):
                flat.append(float(row))
            else:
                if len(row) != width:
                    raise ValueError
                flat.extend(float(v) for v in row)
    except (TypeError, ValueError, OverflowError):
        raise FootfallError(INVALID_ARGUMENT, "%s: expected %d numbers per item" % (what, width),
                            "python") from None
    if len(flat) % width:
        raise FootfallError(INVALID_ARGUMENT, "%s: %d numbers is not a multiple of %d"
                            % (what, len(flat), width), "python")
    return flat


def _terrain(terrain, function):
    """A terrain id as the C library takes it (uint32_t): ids beyond it wrapped onto others."""
    if isinstance(terrain, bool) or not isinstance(terrain, int) or not 0 <= terrain < 2 ** 32:
        raise FootfallError(INVALID_ARGUMENT, "terrain %r: expected a terrain id as a load_* call "
                            "returned (a whole number from 0 to 4294967295)" % (terrain,), function)
    return terrain


def _number(value, what, function):
    """A float for the C library, or FootfallError naming `what`."""
    try:
        return float(value)
    except (TypeError, ValueError, OverflowError):
        raise FootfallError(INVALID_ARGUMENT, "%s %r: expected a number" % (what, value),
                            function) from None


def _json_text(value, what, function):
    """A dict (or JSON text) as UTF-8 JSON bytes, or FootfallError naming `what`."""
    if isinstance(value, str):
        if "\0" in value:  # C would read the text cut short at the NUL, and blame what is left
            raise FootfallError(INVALID_ARGUMENT, "%s: the JSON text holds a NUL byte at offset "
                                "%d" % (what, value.index("\0")), function)
        return value.encode("utf-8", "replace")
    if not isinstance(value, dict):
        raise FootfallError(INVALID_ARGUMENT, "%s: expected a dict or JSON text, got %s"
                            % (what, type(value).__name__), function)
    path = value.get("character_file")
    if isinstance(path, str):
        try:
            path.encode("utf-8")
        except UnicodeEncodeError:  # a file name that is not UTF-8 (os.fsdecode's surrogates)
            raise FootfallError(
                INVALID_ARGUMENT, "%s: character_file %r: the name is not UTF-8, which a JSON "
                "request cannot carry: rename the file, or give the character's data as "
                "\"character\"" % (what, path), function) from None
    try:
        return json.dumps(value, allow_nan=False).encode("utf-8", "replace")
    except (TypeError, ValueError, RecursionError) as e:
        raise FootfallError(INVALID_ARGUMENT, "%s: %s" % (what, e), function) from None


def _pointer(flat):
    if not flat:
        return ctypes.POINTER(ctypes.c_double)()
    return (ctypes.c_double * len(flat)).from_buffer(flat)


def _one_call_at_a_time(method):
    """Runs a Session method holding the session's lock: calls from several threads take turns
    (as the C ABI's do), each failure's message is its own call's, and close() waits for a call
    under way (closing a session another thread was calling freed it under that call: a crash)."""
    @functools.wraps(method)
    def locked(self, *args, **kwargs):
        with self._lock:
            return method(self, *args, **kwargs)
    return locked


class Session:
    """A footfall session. Open with Session.rpc(...) or Session.embedded(); close() or use
    `with`. Calls from several threads take turns (close() waits for a call under way); open a
    session per thread to query in parallel. Methods raise FootfallError on failure."""

    def __init__(self, handle, library, description):
        self._lock = threading.RLock()
        self._h = handle
        self._lib = library
        self.description = description
        # The notes of the walk the last generate() gave or raised (WalkStopped) in its walk:
        # a list of one-line texts, [] when it had none or gave no walk.
        self.last_notes = []

    @classmethod
    def rpc(cls, host="127.0.0.1", port=7407, timeout=10.0, library=None):
        """A footfalld client at host:port; it connects lazily (the first call may raise
        FootfallError 'unavailable'). `timeout` is per call in seconds."""
        lib = load_library(library)
        if host is not None and not isinstance(host, str):
            raise FootfallError(INVALID_ARGUMENT, "host %r: expected a host name or address as "
                                "text" % (host,), "ffc_open_rpc")
        if host and "\0" in host:  # C would read it cut short at the NUL: another host
            raise FootfallError(INVALID_ARGUMENT, "host %r: holds a NUL byte" % (host,),
                                "ffc_open_rpc")
        if isinstance(port, bool) or not isinstance(port, int) or not 1 <= port <= 65535:
            raise FootfallError(INVALID_ARGUMENT, "port %r: expected 1 to 65535" % (port,), "ffc_open_rpc")
        try:
            timeout = float(timeout)
        except (TypeError, ValueError, OverflowError):
            timeout = float("nan")
        if not timeout <= 1e6 or 0 < timeout < 0.001:
            raise FootfallError(INVALID_ARGUMENT, "timeout %r: expected 0.001 to 1e6 seconds (0 "
                                "or less: the default)" % (timeout,), "ffc_open_rpc")
        handle = lib.lib.ffc_open_rpc((host or "").encode("utf-8", "replace"), port, timeout)
        if not handle:  # (the other arguments are checked above)
            _raise_if_out_of_memory(lib, "ffc_open_rpc")
            raise FootfallError(INVALID_ARGUMENT, "host %r: expected a host name or an IPv4 or "
                                "IPv6 address ([::1] or ::1), without a port (the port is "
                                "given apart)" % (host,), "ffc_open_rpc")
        return cls(handle, lib, "rpc %s:%d" % (host or "127.0.0.1", port))

    @classmethod
    def embedded(cls, library=None):
        """The in-process engine of libfootfall.so."""
        lib = load_library(library)
        handle = lib.lib.ffc_open_embedded()
        if not handle:
            _raise_if_out_of_memory(lib, "ffc_open_embedded")
            raise FootfallError(INTERNAL_ERROR, "cannot open the embedded engine", "ffc_open_embedded")
        return cls(handle, lib, "embedded")

    @_one_call_at_a_time
    def close(self):
        if self._h:
            self._lib.lib.ffc_close(self._h)
            self._h = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:  # interpreter shutdown: the library may be gone already
            pass

    def __repr__(self):
        return "<footfall_client.Session %s%s>" % (self.description, "" if self._h else " closed")

    # -- internals --------------------------------------------------------------------------

    def _handle(self, call):
        if not self._h:
            raise FootfallError(INVALID_ARGUMENT, "the session is closed", call)
        return self._h

    @_one_call_at_a_time
    def last_error(self):
        if not self._h:
            return "the session is closed"
        return self._lib.lib.ffc_last_error(self._h).decode("utf-8", "replace")

    def _check(self, status, call):
        if status != OK:
            raise FootfallError(status, self.last_error() or STATUS_NAMES.get(status, ""), call)

    def _answers(self, out, count):
        result = []
        for i in range(count):
            h = out[i]
            if h.status == OK:
                result.append(Foothold(h.status, "ok", h.index, tuple(h.point), tuple(h.normal)))
            else:
                result.append(Foothold(h.status, STATUS_NAMES.get(h.status, str(h.status)), h.index,
                                       None, None))
        return result

    # -- terrains -----------------------------------------------------------------------------

    @_one_call_at_a_time
    def load_file(self, path, separation=0.0):
        """Reads a terrain file on this machine and loads it; returns the terrain id.
        separation [world units] resamples meshes (0: the library's default)."""
        h = self._handle("ffc_load_file")
        out = ctypes.c_uint32()
        self._check(self._lib.lib.ffc_load_file(h, _path_bytes(path, "ffc_load_file"),
                                                _number(separation, "separation", "ffc_load_file"),
                                                ctypes.byref(out)),
                    "ffc_load_file")
        return out.value

    @_one_call_at_a_time
    def load_server_file(self, path, separation=0.0):
        """Loads a file under footfalld's data root (RPC) or a local path (embedded)."""
        h = self._handle("ffc_load_server_file")
        out = ctypes.c_uint32()
        self._check(self._lib.lib.ffc_load_server_file(
                        h, _path_bytes(path, "ffc_load_server_file"),
                        _number(separation, "separation", "ffc_load_server_file"),
                        ctypes.byref(out)),
                    "ffc_load_server_file")
        return out.value

    @_one_call_at_a_time
    def load_samples(self, samples, name="samples"):
        """Loads samples (x, y, z, nx, ny, nz) given as 6-tuples or one flat sequence (an
        array('d') as sampling.sample_triangles_flat returns is sent as it is, with no copy);
        returns the terrain id. The name is text (sent as UTF-8) or bytes (sent as they are:
        footfalld's log shows bytes that are not UTF-8 escaped); anything else as str() gives
        it."""
        h = self._handle("ffc_load_samples")
        if isinstance(name, (bytes, bytearray)):
            encoded = bytes(name)  # (str() gave "b'...'", the repr, as the name)
        else:
            encoded = str(name).encode("utf-8", "replace")
        if b"\0" in encoded:  # C would read it cut short at the NUL: another name in the log
            raise FootfallError(INVALID_ARGUMENT, "name %r: holds a NUL byte" % (name,),
                                "ffc_load_samples")
        flat = _flat(samples, 6, "samples")
        out = ctypes.c_uint32()
        self._check(self._lib.lib.ffc_load_samples(h, _pointer(flat), len(flat) // 6, encoded,
                                                   ctypes.byref(out)),
                    "ffc_load_samples")
        return out.value

    @_one_call_at_a_time
    def unload(self, terrain):
        self._check(self._lib.lib.ffc_unload(self._handle("ffc_unload"),
                                             _terrain(terrain, "ffc_unload")), "ffc_unload")

    @_one_call_at_a_time
    def info(self, terrain):
        """(sample count, (min x, min y, min z, max x, max y, max z)) of a terrain."""
        h = self._handle("ffc_info")
        count = ctypes.c_uint64()
        bounds = (ctypes.c_double * 6)()
        self._check(self._lib.lib.ffc_info(h, _terrain(terrain, "ffc_info"), ctypes.byref(count),
                                           bounds), "ffc_info")
        return count.value, tuple(bounds)

    @_one_call_at_a_time
    def ping(self):
        """True when the server answers, False when it is unavailable; never raises for a
        missing server. Calls the RPC NULL procedure (ffc_ping), which footfalld answers however
        busy it is building other clients' terrains, and loads nothing. (A library without
        ffc_ping, an older one: loads and unloads a one-sample terrain, where any answer but
        'unavailable' counts as alive.)"""
        if self._h is None:
            return False  # closed: nothing answers
        if self._lib.has("ffc_ping"):
            return self._lib.lib.ffc_ping(self._h) != UNAVAILABLE
        try:
            t = self.load_samples([(0.0, 0.0, 0.0, 0.0, 1.0, 0.0)], "ping")
        except FootfallError as e:
            return e.status != UNAVAILABLE
        try:
            self.unload(t)
        except FootfallError:
            pass
        return True

    # -- queries ------------------------------------------------------------------------------

    @_one_call_at_a_time
    def _points(self, fn_name, terrain, points):
        h = self._handle(fn_name)
        terrain = _terrain(terrain, fn_name)
        flat = _flat(points, 3, "points")
        n = len(flat) // 3
        out = (FfcFoothold * max(n, 1))()
        self._check(getattr(self._lib.lib, fn_name)(h, terrain, _pointer(flat), n, out), fn_name)
        return self._answers(out, n)

    def snap(self, terrain, points):
        """The nearest terrain sample to each point: a list of Foothold."""
        return self._points("ffc_snap", terrain, points)

    def normal(self, terrain, points):
        """The terrain normal at each point: a list of Foothold."""
        return self._points("ffc_normal", terrain, points)

    @_one_call_at_a_time
    def next(self, terrain, steps, tolerance=0.0):
        """The next foothold for each step (foot x, y, z, direction x, y, z): a list of
        Foothold. tolerance <= 0: the candidate radius is the step length."""
        h = self._handle("ffc_next")
        terrain = _terrain(terrain, "ffc_next")
        tolerance = _number(tolerance, "tolerance", "ffc_next")
        flat = _flat(steps, 6, "steps")
        n = len(flat) // 6
        out = (FfcFoothold * max(n, 1))()
        self._check(self._lib.lib.ffc_next(h, terrain, _pointer(flat), n, tolerance, out),
                    "ffc_next")
        return self._answers(out, n)

    # -- walks --------------------------------------------------------------------------------

    @_one_call_at_a_time
    def check_character(self, data, name="character"):
        """Raises FootfallError naming the first problem of a character (a dict, or a character
        file's text) as the generator reads it; nothing is generated. A library without
        ffc_check_character (an older one) checks nothing."""
        h = self._handle("ffc_check_character")
        if not self._lib.has("ffc_check_character"):
            return
        if not isinstance(data, (str, dict)):
            raise FootfallError(INVALID_ARGUMENT, "%s: expected a character as a dict or JSON "
                                "text, got %s" % (name, type(data).__name__),
                                "ffc_check_character")
        text = _json_text(data, name, "ffc_check_character")
        status = self._lib.lib.ffc_check_character(h, text)
        if status != OK:
            message = self.last_error()
            if message.startswith("character"):
                message = name + message[len("character"):]
            raise FootfallError(status, message, "ffc_check_character")

    def generate_json(self, terrain, request):
        """Runs the step generator (as `footfall generate` does) and returns (status, walk JSON
        text or None, message). request: a dict or JSON text (keys of footfall_c.h)."""
        return self.generate_json_with_notes(terrain, request)[:3]

    @_one_call_at_a_time
    def generate_json_with_notes(self, terrain, request):
        """generate_json, and the walk's notes: (status, walk JSON text or None, message, notes).
        notes is a list of one-line texts, what `footfall generate` prints as "note:" lines (a
        start far from the terrain, a step_length beyond the reach, a path walk's goal not
        reached), which the walk JSON does not carry; [] when there are none, when no walk was
        made, and with an older library (without ffc_generate_with_notes)."""
        h = self._handle("ffc_generate")
        if not self._lib.has("ffc_generate"):
            raise FootfallError(INTERNAL_ERROR, "%s has no ffc_generate (an older library)"
                                % self._lib.path, "ffc_generate")
        terrain = _terrain(terrain, "ffc_generate")
        text = _json_text(request, "request", "ffc_generate")
        out = ctypes.c_void_p()
        notes_out = ctypes.c_void_p()
        if self._lib.has("ffc_generate_with_notes"):
            status = self._lib.lib.ffc_generate_with_notes(h, terrain, text, ctypes.byref(out),
                                                           ctypes.byref(notes_out))
        else:
            status = self._lib.lib.ffc_generate(h, terrain, text, ctypes.byref(out))
        walk, notes = None, []
        try:
            if out.value:
                walk = ctypes.string_at(out.value).decode("utf-8")
            if notes_out.value:
                notes = ctypes.string_at(notes_out.value).decode("utf-8", "replace").splitlines()
        finally:
            if out.value:
                self._lib.lib.ffc_free_string(out.value)
            if notes_out.value:
                self._lib.lib.ffc_free_string(notes_out.value)
        message = self.last_error() if (status != OK or walk is None) else ""
        return status, walk, message, notes

    @_one_call_at_a_time
    def generate(self, terrain, request, chunk_steps=0, progress=None):
        """The walk as a dict (footfall's walk JSON). Raises WalkStopped (with .walk holding the
        keys made so far) when the walk stopped early, FootfallError when nothing was made.

        A server that dies after the walk's first step stops it there (WalkStopped, its walk
        kept by the library); one gone before it fails the call. chunk_steps > 0 asks for the
        walk that many steps at a time, as the plugins key it (the generator is deterministic,
        so each call's walk starts with the one before; the calls together cost about
        steps / chunk_steps / 2 walks), and a call that fails after another gave a walk raises
        WalkStopped with that walk, its message naming the steps that failed. Chunks need the request's "steps" (an integer from 1); without it
        the walk is asked for in one call. progress(done, total) is called after each chunk.
        The walk's notes (generate_json_with_notes) are in `last_notes` after the call, and in
        WalkStopped's `notes`: those of the last call that gave a walk."""
        self.last_notes = []
        if isinstance(chunk_steps, bool) or not isinstance(chunk_steps, int) or chunk_steps < 0:
            raise FootfallError(INVALID_ARGUMENT, "chunk_steps %r: expected a whole number of "
                                "steps from 0 (one call)" % (chunk_steps,), "ffc_generate")
        fields = request
        if isinstance(request, str):
            try:
                fields = json.loads(request)
            except (ValueError, RecursionError):
                fields = None  # the library says what is wrong with it
        total = fields.get("steps") if isinstance(fields, dict) else None
        if (not chunk_steps or isinstance(total, bool) or not isinstance(total, int) or
                total < 1):
            try:
                return self._generate_once(terrain, request)
            except WalkStopped:
                raise
            except FootfallError as e:
                if e.status != UNAVAILABLE:
                    raise
                raise FootfallError(e.status, "%s; no key of the walk was kept (ask for it in "
                                    "chunks, chunk_steps, to keep the steps made before a "
                                    "failure)" % e.message, e.call) from None
        walk, done, keys = None, 0, None
        while done < total:
            ask = min(total, done + chunk_steps)
            try:
                part = self._generate_once(terrain, dict(fields, steps=ask))
            except WalkStopped:
                raise  # stopped (no foothold): its walk holds every key up to the stop
            except FootfallError as e:
                if walk is None:
                    raise
                raise WalkStopped(e.status, "%s (generating steps %d to %d); walk stopped, keys "
                                  "up to step %d kept" % (e.message, done + 1, ask, done),
                                  walk, notes=self.last_notes) from None
            walk, done = part, ask
            if progress is not None:
                progress(done, total)
            count = sum(len(t.get("keys", [])) for t in walk.get("tracks", []))
            if count == keys:
                break  # no new step: the walk ended (a path's goal reached) before `total`
            keys = count
        return walk

    def _generate_once(self, terrain, request):
        status, text, message, notes = self.generate_json_with_notes(terrain, request)
        if text is not None:
            self.last_notes = notes
        walk = None
        if text is not None:
            try:
                walk = json.loads(text)
            except ValueError as e:
                raise FootfallError(INTERNAL_ERROR, "walk JSON from the library: %s" % e,
                                    "ffc_generate") from None
        stopped = walk.get("stopped") if isinstance(walk, dict) else None
        if status == NO_FOOTHOLD and walk is not None and self._lib.has("ffc_walk_stop"):
            # 'unavailable' when footfalld failed mid-walk, not the terrain (the same return).
            status = self._lib.lib.ffc_walk_stop(self._handle("ffc_walk_stop")) or status
        if status != OK:
            if walk is not None:
                raise WalkStopped(status, message or stopped or "walk stopped", walk, notes=notes)
            raise FootfallError(status, message, "ffc_generate")
        if walk is None:
            raise FootfallError(INTERNAL_ERROR, "ffc_generate gave no walk", "ffc_generate")
        if stopped:
            raise WalkStopped(NO_FOOTHOLD, message or stopped, walk, notes=notes)
        return walk


INTERNAL_ERROR = 9
