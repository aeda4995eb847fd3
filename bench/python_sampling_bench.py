#!/usr/bin/env python3
"""The plugins' mesh resampling (footfall_client.sampling), pure Python against numpy, on the
same generated mesh in the same run: each stage's time, their ratio, and the peak memory a
sample holds, for the list of tuples sample_triangles returns and for the flat array('d')
sample_triangles_flat returns (what the plugins send). Also checks that both paths give the
same samples, bit for bit, and the flat array the tuples' numbers; and times write_point_file
of each (the same text, checked). (The pure column's `_flat` row of the tuples times
Session.load_samples' loop over the numbers, as before its fast path; the numpy column's the
fast path. The flat array is sent as it is on both.)

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
import tempfile
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
    """({stage: seconds}, samples, flat) of one Terrain Setup's resampling, on one path, with
    the samples made both ways."""
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
    flat = sampling.sample_triangles_flat(points, triangles, separation, corner_normals=normals,
                                          pure=pure)
    t5 = time.perf_counter()
    sent = _flat(flat, 6, "samples")
    t6 = time.perf_counter()
    assert sent is flat  # (sent as it is)
    common = (t1 - t0) + (t2 - t1)
    times["check_sample_count"] = t1 - t0
    times["corner_normals"] = t2 - t1
    times["sample_triangles"] = t3 - t2
    times["load_samples' _flat"] = t4 - t3
    times["total, tuples"] = common + (t4 - t2)
    times["sample_triangles_flat"] = t5 - t4
    times["_flat of the array"] = t6 - t5
    times["total, flat"] = common + (t6 - t4)
    return times, samples, flat


def memory(points, triangles, separation, pure, flat):
    """(peak, kept, peak to the array sent) bytes a sample: while sample_triangles (flat:
    sample_triangles_flat) runs, in what it returns, and from its start until load_samples'
    _flat has made the array sent (the samples still held)."""
    normals = sampling.corner_normals(points, triangles, pure=pure)
    fn = sampling.sample_triangles_flat if flat else sampling.sample_triangles
    tracemalloc.start()
    base = tracemalloc.get_traced_memory()[0]
    samples = fn(points, triangles, separation, corner_normals=normals, pure=pure)
    kept, peak = tracemalloc.get_traced_memory()
    sent = _flat(samples, 6, "samples")
    peak_sent = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    count = len(samples) // 6 if flat else len(samples)
    del sent
    return (peak - base) / count, (kept - base) / count, (peak_sent - base) / count


def packed(samples):
    return b"".join(struct.pack("<6d", *s) for s in samples)


def written(path, samples, runs):
    """(best seconds of write_point_file, the file's bytes)."""
    best = None
    for _ in range(runs):
        t0 = time.perf_counter()
        sampling.write_point_file(path, samples)
        seconds = time.perf_counter() - t0
        best = seconds if best is None else min(best, seconds)
    with open(path, "rb") as f:
        return best, f.read()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
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
            times, samples, flat = stages(points, triangles, args.separation, pure)
            del samples, flat
            for stage, seconds in times.items():
                best[name, stage] = min(best.get((name, stage), seconds), seconds)
    _, tuples, flat = stages(points, triangles, args.separation, True)
    want = packed(tuples)
    print("%d vertices, %d triangles at separation %g: %d samples"
          % (len(points), len(triangles), args.separation, len(want) // 48))
    print("pure Python's flat array holds its tuples' numbers, bit for bit: %s"
          % ("yes" if struct.pack("<%dd" % len(flat), *flat) == want else "NO"))
    if len(paths) > 1:
        _, tuples_np, flat_np = stages(points, triangles, args.separation, False)
        print("numpy's samples identical to pure Python's, bit for bit: %s"
              % ("yes" if packed(tuples_np) == want else "NO"))
        print("numpy's flat array identical to pure Python's, bit for bit: %s"
              % ("yes" if flat_np.tobytes() == flat.tobytes() else "NO"))
        del tuples_np, flat_np
    del want
    print("\nbest of %d runs, seconds:" % args.runs)
    print("%-24s %10s %10s %8s" % ("stage", "pure", "numpy", "ratio"))
    for stage in ("check_sample_count", "corner_normals", "sample_triangles",
                  "load_samples' _flat", "total, tuples", "sample_triangles_flat",
                  "_flat of the array", "total, flat"):
        pure_s = best[("pure", stage)]
        numpy_s = best.get(("numpy", stage))
        print("%-24s %10.3f %10s %8s" % (stage, pure_s,
                                         "" if numpy_s is None else "%.3f" % numpy_s,
                                         "" if numpy_s is None or numpy_s < 1e-3 else
                                         "%.1fx" % (pure_s / numpy_s)))
    print("\nflat against tuples, time ratio (flat / tuples):")
    for name, _ in paths:
        print("%-6s sampling %.2f, total %.2f" % (
            name, best[name, "sample_triangles_flat"] / best[name, "sample_triangles"],
            best[name, "total, flat"] / best[name, "total, tuples"]))
    print("\nmemory, bytes a sample (tracemalloc): peak while sampling, kept in what it "
          "returns, peak until the array sent is made")
    peaks = {}
    for name, pure in paths:
        for kind, is_flat in (("tuples", False), ("flat", True)):
            peak, kept, peak_sent = memory(points, triangles, args.separation, pure, is_flat)
            peaks[name, kind] = peak_sent
            print("%-6s %-7s peak %6.0f, returned %6.0f, to the array sent %6.0f"
                  % (name, kind, peak, kept, peak_sent))
    for name, _ in paths:
        print("%-6s flat / tuples, peak to the array sent: %.2f"
              % (name, peaks[name, "flat"] / peaks[name, "tuples"]))
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "samples.pts")
        t_tuples, text_tuples = written(path, tuples, args.runs)
        t_flat, text_flat = written(path, flat, args.runs)
    print("\nwrite_point_file, best of %d: tuples %.3f s, flat %.3f s (%.2f); the same bytes: %s"
          % (args.runs, t_tuples, t_flat, t_flat / t_tuples,
             "yes" if text_tuples == text_flat else "NO"))


if __name__ == "__main__":
    main()
