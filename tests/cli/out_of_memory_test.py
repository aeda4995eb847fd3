#!/usr/bin/env python3
"""footfall when memory runs out, anywhere: runs footfall query and footfall generate again and
again with one C++ allocation failing (the Nth of the run, for N over the whole run), then with
every allocation failing from the Nth on, through a preloaded operator new. Each run must end
with its answers or a message, never an abort (an abort loses a query session's answers and
hands a DCC host's crash to the user); a failed generate leaves its previous outputs whole and
no temporary file, also when a library aborts (tinygltf, whose assertions memory failures
reach).

Arguments: FOOTFALL FAILING_NEW_LIBRARY SOURCE_DIR
"""
import os
import subprocess
import sys
import tempfile

FOOTFALL, FAILING_NEW, SOURCE = sys.argv[1:4]
TERRAIN = os.path.join(SOURCE, "data", "terrain", "blocks.pts")
CHARACTER = os.path.join(SOURCE, "data", "characters", "biped.json")
QUERIES = b"snap 1 1 1\nnext 1 1 1 0.3 0 0.1\nnormal 2 1 2\nbogus\nnext 1 1 1 0 0 0\n"
STRIDE = 3  # every third allocation: the runs stay within a minute or so
failures = []


def run(args, after, every, cwd, stdin=b""):
    # Counted from main: before it, allocations are the static constructors of the libraries
    # footfall loads (OpenMesh), where a failure ends any program.
    env = dict(os.environ, LD_PRELOAD=FAILING_NEW, FOOTFALL_FAIL_NEW_AFTER=str(after),
               FOOTFALL_FAIL_NEW_EVERY=str(every), FOOTFALL_FAIL_NEW_IN_MAIN="1")
    env.pop("FOOTFALL_FAIL_NEW_WHILE", None)
    return subprocess.run([FOOTFALL] + args, input=stdin, capture_output=True, env=env, cwd=cwd,
                          timeout=60)


def aborted(p):
    return p.returncode < 0 or p.returncode == 134 or b"terminate called" in p.stderr


def sweep(name, args, start, stdin=b"", outputs=(), may_abort=False):
    with tempfile.TemporaryDirectory() as cwd:
        def reset():
            for out in outputs:
                with open(os.path.join(cwd, out), "w") as f:
                    f.write("OLD")
        reset()
        baseline = run(args, 10 ** 9, 1, cwd, stdin)  # no allocation fails
        written = {}
        for out in outputs:
            with open(os.path.join(cwd, out), "rb") as f:
                written[out] = f.read()
        reset()
        runs = 0
        for every in (1000000000, 1):  # one allocation failing; every one from N on
            quiet = 0
            n = start
            while quiet < 30 and n < start + 40000:
                p = run(args, n, every, cwd, stdin)
                runs += 1
                what = "%s, allocation %d%s failing" % (name, n, "" if every > 1 else " on")
                if aborted(p) and not may_abort:
                    failures.append("%s: aborted (%d): %s" % (what, p.returncode,
                                                              p.stderr[-300:].decode(errors="replace")))
                left = [f for f in os.listdir(cwd) if f.startswith(".")]
                if left:
                    failures.append("%s: temporary files left: %s" % (what, left))
                    for f in left:
                        os.remove(os.path.join(cwd, f))
                if p.returncode != baseline.returncode and not aborted(p) and not p.stderr.strip():
                    failures.append("%s: exit %d without a message" % (what, p.returncode))
                for line in p.stderr.decode(errors="replace").splitlines():
                    if ": footfall: " in line:  # a message cut by another failure
                        failures.append("%s: a line begun twice: %s" % (what, line))
                # Each output is its previous file or the whole new one (an output that fails
                # leaves its file; the others are written).
                for out in outputs:
                    with open(os.path.join(cwd, out), "rb") as f:
                        if f.read() not in (b"OLD", written[out]):
                            failures.append("%s: %s is neither as it was nor whole" % (what, out))
                # Runs untouched by the failure (past the last allocation) end the sweep.
                same = (p.returncode, p.stdout, p.stderr) == (baseline.returncode,
                                                              baseline.stdout, baseline.stderr)
                quiet = quiet + 1 if same else 0
                reset()
                n += STRIDE
        print("%s: %d runs from allocation %d" % (name, runs, start))


START = 0  # main's first allocation
sweep("query", ["query", "--terrain", TERRAIN], START, stdin=QUERIES)
sweep("generate", ["generate", "--terrain", TERRAIN, "--character", CHARACTER, "--steps", "3",
                   "--out", "w.json", "--out", "w.mel", "--out", "w.pts"], START,
      outputs=("w.json", "w.mel", "w.pts"))
# tinygltf serialises glTF: memory failing within it may abort (a library's assertion); the
# previous files stay and no temporary file is left all the same.
sweep("generate glTF", ["generate", "--terrain", TERRAIN, "--character", CHARACTER, "--steps",
                        "3", "--out", "w.json", "--out", "w.gltf", "--out", "w.glb"], START,
      outputs=("w.json", "w.gltf", "w.glb"), may_abort=True)
for f in failures[:40]:
    print("FAIL:", f)
if len(failures) > 40:
    print("... and %d more" % (len(failures) - 40))
sys.exit(1 if failures else 0)
