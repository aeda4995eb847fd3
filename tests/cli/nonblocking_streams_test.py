"""footfall with standard streams a parent made non-blocking (Node.js does, on the pipes and
terminals it hands on): input that arrives in bursts and a reader that lags must give the same
answers as plain pipes. Through stdio, `footfall query` failed "Resource temporarily
unavailable" after 4096 lines and lost the rest.

Usage: nonblocking_streams_test.py FOOTFALL SOURCE_DIR
"""
import fcntl
import os
import subprocess
import sys
import tempfile
import threading
import time

footfall, source_dir = sys.argv[1], sys.argv[2]
hills = os.path.join(source_dir, "data", "terrain", "hills.pts")
biped = os.path.join(source_dir, "data", "characters", "biped.json")
failures = []


def check(what, ok):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def nonblocking_pipe():
    r, w = os.pipe()
    for fd in (r, w):
        fcntl.fcntl(fd, fcntl.F_SETFL, fcntl.fcntl(fd, fcntl.F_GETFL) | os.O_NONBLOCK)
    return r, w


def write_all(fd, data, pause_every=0, pause=0.0):
    """Writes data to a non-blocking descriptor, pausing after each pause_every bytes."""
    at = 0
    while at < len(data):
        end = len(data) if not pause_every else min(len(data), at + pause_every)
        try:
            at += os.write(fd, data[at:end])
        except BlockingIOError:
            time.sleep(0.005)
            continue
        except BrokenPipeError:  # footfall stopped reading: its checks say why
            break
        if pause_every and at % pause_every == 0:
            time.sleep(pause)
    os.close(fd)


def read_all(fd, delay):
    """Reads a non-blocking descriptor to its end, starting after `delay` seconds."""
    time.sleep(delay)
    chunks = []
    while True:
        try:
            b = os.read(fd, 65536)
        except BlockingIOError:
            time.sleep(0.005)
            continue
        if not b:
            break
        chunks.append(b)
    os.close(fd)
    return b"".join(chunks)


def run_nonblocking(args, stdin_data, pause_every, read_delay):
    """Runs footfall with non-blocking stdin, stdout and stderr pipes; returns (rc, out, err)."""
    in_r, in_w = nonblocking_pipe()
    out_r, out_w = nonblocking_pipe()
    err_r, err_w = nonblocking_pipe()
    p = subprocess.Popen([footfall] + args, stdin=in_r, stdout=out_w, stderr=err_w)
    for fd in (in_r, out_w, err_w):
        os.close(fd)
    result = {}
    threads = [
        threading.Thread(target=write_all, args=(in_w, stdin_data, pause_every, 0.05)),
        threading.Thread(target=lambda: result.update(out=read_all(out_r, read_delay))),
        threading.Thread(target=lambda: result.update(err=read_all(err_r, read_delay))),
    ]
    for t in threads:
        t.start()
    rc = p.wait(timeout=300)
    for t in threads:
        t.join()
    return rc, result["out"], result["err"]


# 1. footfall query: 20,000 commands arriving in bursts of 64 KiB, answers read after 1 s.
commands = "".join(
    "snap %g 0 %g\nnext %g 1 %g 0.5 0 0.25\n" % (i % 97 * 0.3, i % 89 * 0.3, i % 83 * 0.3, i % 79 * 0.3)
    for i in range(10000)).encode()
plain = subprocess.run([footfall, "query", "--terrain", hills], input=commands,
                       capture_output=True, timeout=300)
check("query, plain pipes: exit 0", plain.returncode == 0)
check("query, plain pipes: 20,000 answers", plain.stdout.count(b"\n") == 20000)
rc, out, err = run_nonblocking(["query", "--terrain", hills], commands, 65536, 1.0)
check("query, non-blocking streams: exit 0 (got %d, %r)" % (rc, err[:200]), rc == 0)
check("query, non-blocking streams: no message", err == b"")
check("query, non-blocking streams: the same answers as plain pipes (%d lines)"
      % out.count(b"\n"), out == plain.stdout)

# 2. footfall generate --out -: the walk JSON read after 1 s is the one written to a file.
with tempfile.TemporaryDirectory() as work:
    walk = os.path.join(work, "walk.json")
    args = ["generate", "--terrain", hills, "--character", biped, "--steps", "40", "--crowd", "8",
            "--out", walk, "--out", "-"]
    rc, out, err = run_nonblocking(args, b"", 0, 1.0)
    check("generate --out -, non-blocking stdout: exit 0 (got %d, %r)" % (rc, err[:200]), rc == 0)
    written = b""
    if os.path.exists(walk):
        with open(walk, "rb") as f:
            written = f.read()
    check("generate --out -, non-blocking stdout: the walk JSON of the file (%d of %d bytes)"
          % (len(out), len(written)), out == written and len(written) > 65536)

if failures:
    print("%d check(s) failed" % len(failures))
    sys.exit(1)
print("all checks passed")
