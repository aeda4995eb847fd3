"""LocalServer: starts and stops a footfalld on this machine (plugins and tests)."""

import os
import shutil
import subprocess
import tempfile
import time

from .installed import installed_path


class ServerError(RuntimeError):
    """footfalld could not be found, did not start, or exited early; the message says why."""


def find_footfalld():
    """The footfalld to run: $FOOTFALLD, next to this package, the install this package belongs
    to (cmake --install), a build tree, then PATH. $FOOTFALLD, when set, must name an
    executable file: a wrong one is an error, and its mode is left as it is."""
    env = os.environ.get("FOOTFALLD")
    if env:
        if not os.path.isfile(env) or not os.access(env, os.X_OK):
            raise ServerError("FOOTFALLD names %s, which is %s: set it to footfalld's path, or "
                              "unset it to use the one found beside this package"
                              % (env, "not an executable file" if os.path.isfile(env)
                                 else "a directory" if os.path.isdir(env) else "not a file"))
        return env
    tried = []
    here = os.path.dirname(os.path.abspath(__file__))
    repo = os.path.dirname(os.path.dirname(os.path.dirname(here)))
    bundled = os.path.join(here, "footfalld")
    for path in filter(None, [bundled, installed_path("footfalld"),
                              os.path.join(repo, "build", "server", "service", "footfalld")]):
        tried.append(path)
        if os.path.isfile(path):
            if not os.access(path, os.X_OK):
                if path != bundled:
                    continue
                try:  # unpacked from a zip (Blender's add-on installer drops the mode bits)
                    os.chmod(path, 0o755)
                except OSError:
                    continue
            return path
    found = shutil.which("footfalld")
    if found:
        return found
    raise ServerError("footfalld not found (set FOOTFALLD to its path); looked in: %s and PATH"
                      % ", ".join(tried))


class LocalServer:
    """A footfalld child process on `host`, on a free port unless `port` is given.

        server = LocalServer().start()   # server.port is the bound port
        ...
        server.stop()
    """

    def __init__(self, executable=None, host="127.0.0.1", port=0, data_root=None, log_path=None):
        self.executable = executable
        self.host = host
        self.requested_port = port
        self.data_root = data_root
        self.log_path = log_path
        self.port = None
        self.process = None
        self._dir = None
        self._log = None

    def start(self, timeout=10.0):
        """Starts footfalld and waits (up to `timeout` s) until it listens. Returns self. When
        it cannot, raises ServerError, with nothing left running and its files removed."""
        if self.running():
            return self
        exe = self.executable or find_footfalld()
        try:
            return self._start(exe, timeout)
        except ServerError:
            self.stop()
            raise

    def _start(self, exe, timeout):
        self._dir = tempfile.mkdtemp(prefix="footfalld-")
        port_file = os.path.join(self._dir, "port")
        # An IPv6 address in brackets, as footfalld's --listen takes it (::1:0 was refused).
        host = "[%s]" % self.host if ":" in self.host and not self.host.startswith("[") \
            else self.host
        args = [exe, "--listen", "%s:%d" % (host, self.requested_port),
                "--port-file", port_file, "--no-rpcbind"]
        if self.data_root:
            args += ["--data-root", self.data_root]
        log_path = self.log_path or os.path.join(self._dir, "footfalld.log")
        self._log = open(log_path, "ab")
        try:
            self.process = subprocess.Popen(args, stdin=subprocess.DEVNULL, stdout=self._log,
                                            stderr=subprocess.STDOUT)
        except OSError as e:
            self.process = None
            raise ServerError("cannot run %s: %s" % (exe, e)) from None
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.process.poll() is not None:
                raise ServerError("%s exited with status %d: %s"
                                  % (exe, self.process.returncode, self._tail(log_path)))
            try:
                with open(port_file) as f:
                    text = f.read().strip()
                if text.isdigit():
                    self.port = int(text)
                    return self
            except OSError:
                pass
            time.sleep(0.02)
        raise ServerError("%s did not start listening within %g s" % (exe, timeout))

    @staticmethod
    def _tail(path):
        """The end of the log at `path`, its lines joined into one (for a one-line report)."""
        try:
            with open(path, "rb") as f:
                text = f.read()[-400:].decode("utf-8", "replace")
        except OSError:
            return "(no log)"
        return " / ".join(line.strip() for line in text.splitlines() if line.strip()) \
            or "(no output)"

    def running(self):
        return self.process is not None and self.process.poll() is None

    def kill(self):
        """Kills the server at once (SIGKILL), as a crash would."""
        if self.process is not None and self.process.poll() is None:
            self.process.kill()
            self.process.wait()

    def restart(self, timeout=10.0):
        """Kills the server if it runs and starts it again on the same port."""
        self.kill()
        if self.port:
            self.requested_port = self.port
        self._close_files()
        return self.start(timeout)

    def _close_files(self):
        if self._log:
            self._log.close()
            self._log = None
        if self._dir:
            shutil.rmtree(self._dir, ignore_errors=True)
            self._dir = None

    def stop(self, timeout=5.0):
        """Stops the server (SIGTERM, then SIGKILL after `timeout` s) and removes its files."""
        if self.process is not None and self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self._close_files()

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()
