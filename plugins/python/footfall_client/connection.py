"""Connection: what a DCC plugin keeps between its commands. One Session to the configured
footfalld (starting a local footfalld when none answers, if allowed) and the terrains loaded
through it, uploaded again when the session changes (a new local server)."""

from .server import LocalServer, ServerError
from .session import UNAVAILABLE, UNKNOWN_TERRAIN, FootfallError, Session


class Connection:
    def __init__(self):
        self.session = None
        self.local = None          # LocalServer this connection started, if any
        self._local_for = None     # ((host, port), footfalld) it was started in place of
        self._target = None        # (host, port) the session talks to
        self._timeout = None       # its call timeout [s]
        self._terrains = {}        # name -> [source, terrain id, session]

    def describe(self):
        if self.session is None:
            return "not connected"
        own = " (started by footfall)" if self.local and self.local.running() else ""
        return self.session.description + own

    def get(self, host="127.0.0.1", port=7407, start_local=True, footfalld=None, timeout=10.0):
        """A Session that answers. Tries host:port (or the local server started earlier); when
        nothing answers and start_local is set, starts footfalld on a free loopback port.
        `timeout` [s] bounds each call and the wait for a local footfalld to listen (a program
        that starts but never listens holds the caller that long, not longer).
        Raises FootfallError('unavailable') with what to do when no server can be had."""
        target = (host or "127.0.0.1", int(port))
        wanted = (target, footfalld or None)
        if self.local is not None:
            if start_local and self.local.running() and self._local_for == wanted:
                target = ("127.0.0.1", self.local.port)
            else:
                # Stopped, or started for other preferences (another server, another footfalld,
                # or local servers no longer allowed): the configured server is asked again.
                self._stop_local(timeout)
        if self.session is None or self._target != target or self._timeout != timeout:
            self._open(target, timeout)  # (a changed timeout was ignored until host or port changed)
        if self.session.ping():
            return self.session
        reason = self.session.last_error()
        # The library's words for a call that waited its whole timeout: a server is there, but
        # busy or hung (stopped in a debugger, SIGSTOP).
        hung = "no answer within the call timeout" in reason
        # A server restarted on the same port since the last call: the first call finds the
        # old connection broken and the session reconnects on the next, so ask twice; not
        # after a whole timeout (that doubled the wait, and said to start a server there).
        if not hung and self.session.ping():
            return self.session
        if hung and not start_local:
            # (Or something else answers there, not in ONC RPC: an HTTP server's reply reads as
            # a record a gigabyte long, waited for until the timeout.)
            raise FootfallError(UNAVAILABLE, "footfalld at %s:%d does not answer within %g s: it "
                                "is there, but busy or hung, or the port is another program's "
                                "(%s)" % (target + (timeout, reason)), "connect")
        if not start_local:
            raise FootfallError(UNAVAILABLE, "no footfalld answers at %s:%d: start one there or "
                                "allow starting a local footfalld" % target, "connect")
        self._stop_local(timeout)  # (a hung one held get 5 s more whatever its timeout)
        try:
            self.local = LocalServer(executable=footfalld or None).start(timeout)
            self._local_for = wanted
        except ServerError as e:
            self.local = None
            raise FootfallError(UNAVAILABLE, "no footfalld answers at %s:%d and a local one "
                                "could not be started: %s" % (target + (e,)), "connect") from None
        self._open(("127.0.0.1", self.local.port), timeout)
        if not self.session.ping():
            raise FootfallError(UNAVAILABLE, "the local footfalld on port %d does not answer"
                                % self.local.port, "connect")
        return self.session

    def _stop_local(self, timeout=5.0):
        """Stops the server this connection started, closing the session to it first; one that
        has not ended `timeout` s after SIGTERM (a hung one never does) is killed."""
        if self.local is None:
            return
        if self.session is not None and self._target == ("127.0.0.1", self.local.port):
            self.session.close()
            self.session = None
            self._target = None
        self.local.stop(min(timeout, 5.0))
        self.local = None
        self._local_for = None

    def _open(self, target, timeout):
        if self.session is not None:
            self.session.close()
        self.session = Session.rpc(target[0], target[1], timeout)
        self._target, self._timeout = target, timeout

    # -- terrains -----------------------------------------------------------------------------

    def load_samples(self, name, samples):
        """Loads samples on the current session as terrain `name` (replacing an older one)."""
        return self._load(name, ("samples", samples))

    def load_file(self, name, path, separation=0.0):
        """Loads a terrain file read on this machine as terrain `name`."""
        return self._load(name, ("file", path, separation))

    def _load(self, name, source):
        if self.session is None:
            raise FootfallError(UNAVAILABLE, "not connected", "load")
        # The new terrain first: when its upload fails, the old one stays loaded and in use.
        terrain = self._upload(source)
        old = self._terrains.get(name)
        self._terrains[name] = [source, terrain, self.session]
        if old and old[2] is self.session and old[1] != terrain:
            try:
                self.session.unload(old[1])
            except FootfallError:
                pass
        return terrain

    def _upload(self, source):
        if source[0] == "samples":
            return self.session.load_samples(source[1], "blender")
        return self.session.load_file(source[1], source[2])

    def terrain(self, name):
        """The id of terrain `name` on the current session, uploading it again if the session
        changed since it was loaded."""
        entry = self._terrains.get(name)
        if entry is None:
            raise FootfallError(UNKNOWN_TERRAIN, "no terrain '%s' loaded in this session: run "
                                "Terrain Setup first" % name, "terrain")
        if entry[2] is not self.session:
            entry[1] = self._upload(entry[0])
            entry[2] = self.session
        return entry[1]

    def has_terrain(self, name):
        return name in self._terrains

    def terrain_names(self):
        """The names of the terrains loaded through this connection."""
        return list(self._terrains)

    def unload(self, name):
        """Forgets terrain `name` and unloads it from the server, when it was loaded on the
        current session (a failure to unload is ignored: the server drops it with the session)."""
        entry = self._terrains.pop(name, None)
        if entry and self.session is not None and entry[2] is self.session:
            try:
                self.session.unload(entry[1])
            except FootfallError:
                pass

    def shutdown(self):
        """Closes the session and stops a server this connection started."""
        if self.session is not None:
            self.session.close()
            self.session = None
        if self.local is not None:
            self.local.stop()
            self.local = None
        self._terrains.clear()
        self._target = None
