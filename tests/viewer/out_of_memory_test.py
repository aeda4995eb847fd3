#!/usr/bin/env python3
"""footfall-view when memory runs out, anywhere: takes a screenshot with a state dump again and
again on a private Xvfb, through a preloaded operator new, with the Nth C++ allocation of its
main failing alone, then with every allocation from the Nth on failing, for N spread over the
whole run. Each run must end with its picture and dump, or exit 1 with a message; never abort,
crash or hang. The picture and the dump are replaced together or not at all (both their
previous files, or both new), and no temporary file is left.

Mesa's softpipe draws (GALLIUM_DRIVER=softpipe): llvmpipe compiles shaders with LLVM, whose own
allocations failing crash or hang within the driver, which footfall-view cannot answer for, and
its threads would make the allocations' order differ from run to run.

Arguments: FOOTFALL_VIEW FOOTFALL FAILING_NEW_LIBRARY SOURCE_DIR
"""
import os
import subprocess
import sys
import tempfile

VIEW, FOOTFALL, FAILING_NEW, SOURCE = sys.argv[1:5]
TERRAIN = os.path.join(SOURCE, "data", "terrain", "rocks.pts")
CHARACTER = os.path.join(SOURCE, "data", "characters", "hexapod.json")
SAMPLES = 120  # values of N per way of failing: about half a minute in all
OUTPUTS = ("shot.png", "state.json")
failures = []


def start_xvfb():
    read_end, write_end = os.pipe()
    xvfb = subprocess.Popen(["Xvfb", "-displayfd", str(write_end), "-screen", "0", "1280x1024x24",
                             "-nolisten", "tcp"], pass_fds=(write_end,),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write_end)
    with os.fdopen(read_end) as f:
        number = f.readline().strip()
    if not number:
        sys.exit("could not start Xvfb (install the viewer group: scripts/install-deps.sh viewer)")
    return xvfb, ":" + number


def run(cwd, display, after=None, every=1):
    env = dict(os.environ, DISPLAY=display, GALLIUM_DRIVER="softpipe", LIBGL_ALWAYS_SOFTWARE="1")
    for name in ("FOOTFALL_FAIL_NEW_WHILE", "FOOTFALL_FAIL_NEW_AFTER", "LD_PRELOAD"):
        env.pop(name, None)
    if after is not None:
        env.update(LD_PRELOAD=FAILING_NEW, FOOTFALL_FAIL_NEW_AFTER=str(after),
                   FOOTFALL_FAIL_NEW_EVERY=str(every), FOOTFALL_FAIL_NEW_IN_MAIN="1")
    args = [VIEW, "--terrain", TERRAIN, "--walk", "walk.json", "--query", "next 1 1 1 0.3 0 0",
            "--query", "snap 0 0 0", "--cells", "--size", "320x200", "--screenshot", OUTPUTS[0],
            "--dump-state", OUTPUTS[1]]
    try:
        return subprocess.run(args, capture_output=True, env=env, cwd=cwd, timeout=60)
    except subprocess.TimeoutExpired:
        return None


def outputs(cwd):
    files = []
    for out in OUTPUTS:
        with open(os.path.join(cwd, out), "rb") as f:
            files.append(f.read())
    return files


def reset(cwd):
    for out in OUTPUTS:
        with open(os.path.join(cwd, out), "wb") as f:
            f.write(b"OLD")


xvfb, display = start_xvfb()
try:
    with tempfile.TemporaryDirectory() as cwd:
        subprocess.run([FOOTFALL, "generate", "--terrain", TERRAIN, "--character", CHARACTER,
                        "--steps", "6", "--out", "walk.json"], cwd=cwd, check=True,
                       capture_output=True)
        reset(cwd)
        baseline = run(cwd, display)
        if baseline is None or baseline.returncode != 0:
            sys.exit("footfall-view failed with memory to spare: %r" % (baseline,))
        new = outputs(cwd)
        # The allocations of a whole run: the least N from which every allocation may fail and
        # the run still succeeds.
        lo, hi = 0, 1 << 24
        while lo < hi:
            mid = (lo + hi) // 2
            p = run(cwd, display, mid)
            if p is not None and p.returncode == 0:
                hi = mid
            else:
                lo = mid + 1
        total = lo
        runs = 0
        for every in (10 ** 9, 1):  # the Nth allocation failing alone; every one from the Nth on
            for n in sorted(set(range(0, total, max(1, total // SAMPLES)))):
                reset(cwd)
                p = run(cwd, display, n, every)
                runs += 1
                what = "allocation %d%s failing" % (n, "" if every > 1 else " on")
                if p is None:
                    failures.append("%s: did not end within 60 s" % what)
                    continue
                err = p.stderr.decode(errors="replace")
                lines = err.strip().splitlines()
                if p.returncode < 0 or p.returncode == 134 or "terminate called" in err:
                    failures.append("%s: aborted or crashed (%d): %s" % (what, p.returncode,
                                                                         err[-300:]))
                elif p.returncode not in (0, 1) or (p.returncode == 1 and (
                        not lines or not lines[-1].startswith("footfall-view: "))):
                    failures.append("%s: exit %d without a message: %s" % (what, p.returncode,
                                                                           err[-300:]))
                got = outputs(cwd)
                if p.returncode == 0 and got != new:
                    failures.append("%s: exit 0, but the picture or the dump is not the one "
                                    "made with memory to spare" % what)
                elif got not in ([b"OLD", b"OLD"], new):
                    failures.append("%s: the picture and the dump are not both their previous "
                                    "files nor both new: %s" % (
                                        what, ["old" if g == b"OLD" else "new" if g == w else
                                               "other" for g, w in zip(got, new)]))
                left = [f for f in os.listdir(cwd) if f.startswith(".")]
                if left:
                    failures.append("%s: temporary files left: %s" % (what, left))
                    for f in left:
                        os.remove(os.path.join(cwd, f))
        print("%d runs over %d allocations" % (runs, total))
finally:
    xvfb.terminate()
    xvfb.wait()

for f in failures[:40]:
    print("FAIL:", f)
if len(failures) > 40:
    print("... and %d more" % (len(failures) - 40))
sys.exit(1 if failures else 0)
