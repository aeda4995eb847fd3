#!/usr/bin/env python3
"""The plugins' mesh resampling (footfall_client.sampling), pure Python against numpy, on the
same generated mesh in the same run: each stage's time, their ratio, and the peak memory a
sample of sample_triangles holds. Also checks that both give the same samples, bit for bit.
(The `_flat` row compares Session.load_samples' loop over the numbers with its fast path.)

Run by hand (numpy needed for the second column; /usr/bin/python3 on Debian has it):

    python3 bench/python_sampling_bench.py [--n 100] [--spacing 0.5] [--separation 0.1]

The mesh: an n x n vertex grid, `spacing` apart, waved in height (2 (n - 1)^2 triangles),
resampled at `separation`, with corner normals as the Blender add-on's Terrain Setup does.
"""

import argparse
import math
import os
import struct
import sys
import time
import tracemalloc

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "plugins", "python"))

from footfall_client import sampling  # noqa: E402
from footfall_client.session import _flat  # noqa: E402


def wavy_grid(n, spacing):
    points = [(i * spacing, 0.3 * math.sin(0.9 * i * spacing) * math.cos(0.7 * j * spacing),
               j * spacing) for j in range(n) for i in range(n)]
    triangles = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            triangles += [(a, a + n, a + 1), (a + 1, a + n, a + n + 1)]
    return points, triangles


def stages(points, triangles, separation, pure):
    """({stage: seconds}, samples) of one Terrain Setup's resampling, on one path."""
    times = {}
    t0 = time.perf_counter()
    sampling.check_sample_count(points, triangles, separation, pure=pure)
    t1 = time.perf_counter()
    normals = sampling.corner_normals(points, triangles, pure=pure)
    t2 = time.perf_counter()
    samples = sampling.sample_triangles(points, triangles, separation, corner_normals=normals,
                                        pure=pure)
    t3 = time.perf_counter()
    # What Session.load_samples sends: the pure column times _flat's loop (as before its fast
    # path for lists of tuples; an iterator takes the loop), the numpy column the fast path.
    _flat(iter(samples) if pure else samples, 6, "samples")
    t4 = time.perf_counter()
    times["check_sample_count"] = t1 - t0
    times["corner_normals"] = t2 - t1
    times["sample_triangles"] = t3 - t2
    times["load_samples' _flat"] = t4 - t3
    times["total"] = t4 - t0
    return times, samples


def memory(points, triangles, separation, pure):
    """(peak, kept) bytes a sample while sample_triangles runs and in the list it returns."""
    normals = sampling.corner_normals(points, triangles, pure=pure)
    tracemalloc.start()
    base = tracemalloc.get_traced_memory()[0]
    samples = sampling.sample_triangles(points, triangles, separation, corner_normals=normals,
                                        pure=pure)
    kept, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return (peak - base) / len(samples), (kept - base) / len(samples)


def packed(samples):
    return b"".join(struct.pack("<6d", *s) for s in samples)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100, help="vertices along each side")
    ap.add_argument("--spacing", type=float, default=0.5, help="between vertices")
    ap.add_argument("--separation", type=float, default=0.1, help="between samples")
    ap.add_argument("--runs", type=int, default=3, help="timed runs a path (the best counts)")
    args = ap.parse_args()
    points, triangles = wavy_grid(args.n, args.spacing)
    paths = [("pure", True)]
    if sampling.USE_NUMPY:
        paths.append(("numpy", False))
    else:
        print("numpy did not import: the pure path alone")
    best = {}
    for _ in range(args.runs):  # interleaved, so a busy spell falls on both paths
        for name, pure in paths:
            times, samples = stages(points, triangles, args.separation, pure)
            del samples
            for stage, seconds in times.items():
                best[name, stage] = min(best.get((name, stage), seconds), seconds)
    want = packed(stages(points, triangles, args.separation, True)[1])
    print("%d vertices, %d triangles at separation %g: %d samples"
          % (len(points), len(triangles), args.separation, len(want) // 48))
    if len(paths) > 1:
        same = packed(stages(points, triangles, args.separation, False)[1]) == want
        print("numpy's samples identical to pure Python's, bit for bit: %s"
              % ("yes" if same else "NO"))
    del want
    print("\nbest of %d runs, seconds:" % args.runs)
    print("%-22s %10s %10s %8s" % ("stage", "pure", "numpy", "ratio"))
    for stage in ("check_sample_count", "corner_normals", "sample_triangles",
                  "load_samples' _flat", "total"):
        pure_s = best[("pure", stage)]
        numpy_s = best.get(("numpy", stage))
        print("%-22s %10.3f %10s %8s" % (stage, pure_s,
                                         "" if numpy_s is None else "%.3f" % numpy_s,
                                         "" if numpy_s is None else "%.1fx" % (pure_s / numpy_s)))
    print("\nsample_triangles' memory, bytes a sample (tracemalloc):")
    for name, pure in paths:
        peak, kept = memory(points, triangles, args.separation, pure)
        print("%-6s peak %6.0f, the returned list %6.0f" % (name, peak, kept))


if __name__ == "__main__":
    main()
