"""footfall with standard streams a parent made non-blocking (Node.js does, on the pipes and
terminals it hands on): input that arrives in bursts and a reader that lags must give the same
answers as plain pipes. Through stdio, `footfall query` failed "Resource temporarily
unavailable" after 4096 lines and lost the rest.

footfalld with such a stderr, read late: log lines that do not fit are counted and said
("N log lines were lost"), never lost without a word, and clients are not held up meanwhile.

Usage: nonblocking_streams_test.py FOOTFALL FOOTFALLD SOURCE_DIR
"""
import fcntl
import re
import os
import subprocess
import sys
import tempfile
import threading
import time

footfall, footfalld, source_dir = sys.argv[1], sys.argv[2], sys.argv[3]
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

# 3. footfalld logging to a full non-blocking 4 KiB pipe: 40 error lines while nobody reads.
with tempfile.TemporaryDirectory() as work:
    r, w = nonblocking_pipe()
    fcntl.fcntl(w, 1031, 4096)  # F_SETPIPE_SZ
    port_file = os.path.join(work, "port")
    server = subprocess.Popen([footfalld, "--listen", "127.0.0.1:0", "--no-rpcbind", "--port-file",
                               port_file, "--data-root", os.path.join(source_dir, "data")],
                              stdout=w, stderr=w)
    os.close(w)
    for _ in range(200):
        if os.path.exists(port_file) and os.path.getsize(port_file) > 0:
            break
        time.sleep(0.05)
    with open(port_file) as f:
        address = "127.0.0.1:" + f.read().strip()
    slowest = 0.0
    refused = 0
    for i in range(40):
        t = time.monotonic()
        p = subprocess.run([footfall, "query", "--server", address, "--server-terrain",
                            "nonexistent_%d_%s.pts" % (i, "x" * 100), "--timeout", "5"],
                           input=b"snap 1 0 1\n", capture_output=True, timeout=60)
        slowest = max(slowest, time.monotonic() - t)
        refused += p.returncode == 1 and b"nonexistent_" in p.stderr
    check("footfalld, full log: every bad load refused (%d of 40)" % refused, refused == 40)
    check("footfalld, full log: no client held up (slowest %.2f s)" % slowest, slowest < 2)
    log = {}
    reader = threading.Thread(target=lambda: log.update(text=read_all(r, 0)))
    reader.start()
    time.sleep(0.5)
    p = subprocess.run([footfall, "query", "--server", address, "--server-terrain",
                        "terrain/hills.pts"], input=b"snap 1 0 1\n", capture_output=True,
                       timeout=60)
    check("footfalld, full log: a good load served", p.returncode == 0)
    time.sleep(0.3)
    server.terminate()
    server.wait(timeout=30)
    reader.join()
    text = log["text"].decode("utf-8", "replace")
    written = text.count("nonexistent_")
    said = re.search(r"footfalld: (\d+) log lines were lost: stderr was full", text)
    lost = int(said.group(1)) if said else 0
    check("footfalld, full log: lines lost are said (%d written, %d said lost)" % (written, lost),
          said is not None and 40 <= written + lost <= 43)
    check("footfalld, full log: the lines after it are written",
          "loaded terrain" in text and "footfalld: stopped" in text)

if failures:
    print("%d check(s) failed" % len(failures))
    sys.exit(1)
print("all checks passed")
