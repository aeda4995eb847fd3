#!/usr/bin/env python3
"""footfalld when memory runs out while it starts, and stopped the moment it says it listens.

Runs footfalld again and again through a preloaded operator new: with the Nth C++ allocation of
its main failing alone, then with every allocation from the Nth on failing, for N from 0 until
it has started 30 times in a row (past its startup). Each run is sent SIGTERM as soon as it says
it listens. Every run must either exit 1 saying why, leaving no port file, or start (its port
file naming its port) and stop cleanly, exit 0; never abort or die of the signal. With rpcbind,
no run may leave footfalld registered. (CLI11's own directory check and option lookup aborted
footfalld when memory ran out inside them; SIGTERM just after "listening" killed it, and with
rpcbind left a dead registration.)

Arguments: FOOTFALLD FAILING_NEW_LIBRARY
"""
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

FOOTFALLD, FAILING_NEW = sys.argv[1:3]
failures = []


def rpcbind_running():
    return subprocess.run(["rpcinfo", "-p", "127.0.0.1"], capture_output=True).returncode == 0


def start_rpcbind():
    """rpcbind is a test dependency (scripts/install-deps.sh test): started when not running."""
    if rpcbind_running():
        return
    subprocess.run("rpcbind -w || rpcbind", shell=True, capture_output=True)
    for _ in range(100):
        if rpcbind_running():
            return
        time.sleep(0.05)
    sys.exit("rpcbind did not start")


def registered(program):
    out = subprocess.run(["rpcinfo", "-p", "127.0.0.1"], capture_output=True, text=True).stdout
    return any(line.split()[:1] == [str(program)] for line in out.splitlines())


def run(flags, n, every, port_file):
    """One start of footfalld; returns (exit status, log, said it listens, port file text)."""
    if os.path.exists(port_file):
        os.remove(port_file)
    env = dict(os.environ, LD_PRELOAD=FAILING_NEW, FOOTFALL_FAIL_NEW_AFTER=str(n),
               FOOTFALL_FAIL_NEW_EVERY=str(every), FOOTFALL_FAIL_NEW_IN_MAIN="1")
    env.pop("FOOTFALL_FAIL_NEW_WHILE", None)
    p = subprocess.Popen([FOOTFALLD, "--listen", "127.0.0.1:0", "--port-file", port_file] + flags,
                         env=env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE, text=True, errors="replace")
    log, listening = [], False
    for line in p.stderr:
        log.append(line)
        if not listening and "footfalld: listening on" in line:
            listening = True
            p.send_signal(signal.SIGTERM)  # at once: a supervisor may stop it this soon
    try:
        code = p.wait(timeout=20)
    except subprocess.TimeoutExpired:
        p.kill()
        code = p.wait()
        log.append("(did not stop within 20 s of SIGTERM)\n")
    port = None
    if os.path.exists(port_file):
        with open(port_file) as f:
            port = f.read()
    return code, "".join(log), listening, port


def sweep(name, flags, port_file, program_box):
    runs = 0
    for every in (10 ** 9, 1):  # the Nth allocation failing alone; every one from the Nth on
        started_in_a_row, n = 0, 0
        while started_in_a_row < 30 and n < 20000:
            code, log, listening, port = run(flags, n, every, port_file)
            runs += 1
            what = "%s, allocation %d%s failing" % (name, n, "" if every > 1 else " on")
            said = re.search(r"listening on 127\.0\.0\.1:(\d+) \(program (\d+)", log)
            if said:
                program_box[0] = int(said.group(2))
            if code < 0 or code == 134 or "terminate called" in log:
                failures.append("%s: aborted or killed (%d):\n%s" % (what, code, log[-400:]))
            elif listening:
                if code != 0 or "footfalld: stopped" not in log:
                    failures.append("%s: started, then did not stop cleanly on SIGTERM (exit %d):"
                                    "\n%s" % (what, code, log[-400:]))
                if port is None or not said or port.strip() != said.group(1):
                    failures.append("%s: started, but its port file holds %r" % (what, port))
            else:
                last = log.strip().splitlines()[-1] if log.strip() else ""
                if code != 1 or not last.startswith("footfalld: ") or len(last) < 20:
                    failures.append("%s: exit %d without saying why it stopped:\n%s"
                                    % (what, code, log[-400:]))
                if port is not None:
                    failures.append("%s: failed to start, yet left a port file %r"
                                    % (what, port))
            started_in_a_row = started_in_a_row + 1 if listening else 0
            n += 1
        if started_in_a_row < 30:
            failures.append("%s: never started" % name)
    return runs


with tempfile.TemporaryDirectory() as temp:
    root = os.path.join(temp, "root")
    os.mkdir(root)
    port_file = os.path.join(temp, "port")
    program = [None]
    runs = sweep("every flag, no rpcbind",
                 ["--no-rpcbind", "--data-root", root, "--threads", "2", "--max-samples", "2e6",
                  "--orphan-timeout", "5", "--unread-timeout", "3", "--request-timeout", "4",
                  "--upload-timeout", "6", "--batch-time-limit", "0.5",
                  "--max-client-terrains", "9"], port_file, program)
    start_rpcbind()
    runs += sweep("registering with rpcbind", ["--threads", "1"], port_file, program)
    if program[0] is None:
        failures.append("no run said its program number")
    elif registered(program[0]):
        failures.append("footfalld's program %d is still registered with rpcbind after every "
                        "run stopped" % program[0])

print("%d runs of footfalld" % runs)
if failures:
    print("%d failures; the first 20:" % len(failures))
    for f in failures[:20]:
        print(" -", f)
    sys.exit(1)
print("every run exited 1 saying why, or started and stopped cleanly")
