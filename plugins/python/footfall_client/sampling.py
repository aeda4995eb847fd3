"""Resamples triangles at a point separation into terrain samples (no bpy).

Each triangle is cut into a barycentric lattice whose edges are at most `separation` long; the
lattice points are the samples (points shared by neighbouring triangles are kept once). Normals
are the triangle's corner normals interpolated across it (smooth: corner_normals, sharp at
edges past a crease angle, as footfall's own sampler), or the face normal.

With numpy (Blender's Python has it; Maya's may not) the work is done by sampling_numpy with
the same results bit for bit; without numpy, or for arguments numpy cannot take exactly (see
sampling_numpy), by the pure-Python loops here. Each function's `pure=True`, or USE_NUMPY =
False, takes the pure-Python loops. sample_triangles returns a list of tuples (240 bytes a
sample, most of numpy's time making them); sample_triangles_flat, which the plugins use, the
same numbers as one array('d') (48 bytes a sample), which Session.load_samples sends and
write_point_file writes as they are.
"""

import itertools
import math
import os
from array import array

from .vectors import cross as _cross, length as _length, sub as _sub, unit as _unit

try:
    from . import sampling_numpy as _numpy
except Exception:  # no numpy (or a broken one, whose import may raise anything): pure Python
    _numpy = None

# Whether the functions here use numpy (when it imported): False takes the pure-Python loops.
USE_NUMPY = _numpy is not None


def _use_numpy(pure):
    return not pure and USE_NUMPY and _numpy is not None


# Edges whose faces meet at more than this many degrees stay sharp (footfall's
# kDefaultCreaseAngleDeg): a stair's nose, a wall's foot, a block's rim.
DEFAULT_CREASE_ANGLE_DEG = 60.0


def corner_normals(points, triangles, crease_deg=DEFAULT_CREASE_ANGLE_DEG, pure=False):
    """Smooth normals that keep sharp edges, per triangle corner: corner k of triangle t gets the
    area-weighted mean normal of the triangles around its vertex whose normals lie within
    `crease_deg` of t's (t's own included). Returns, per triangle, three unit normals (None for
    a degenerate triangle). pure: the pure-Python loops even where numpy is present."""
    cos_crease = -2.0 if crease_deg >= 180 else math.cos(math.radians(max(crease_deg, 0.0)))
    if _use_numpy(pure):
        try:
            return _numpy.corner_normals(points, triangles, cos_crease)
        except _numpy.Unsupported:
            pass
    crosses = []
    around = {}
    for t, tri in enumerate(triangles):
        a, b, c = (points[i] for i in tri)
        crosses.append(_cross(_sub(b, a), _sub(c, a)))  # length = 2 * area: area weighting
        for v in tri:
            around.setdefault(v, []).append(t)
    lengths = [_length(n) for n in crosses]
    out = []
    for t, tri in enumerate(triangles):
        face = _unit(crosses[t])
        if face is None:
            out.append(None)
            continue
        corners = []
        for v in tri:
            sum_ = [0.0, 0.0, 0.0]
            for u in around[v]:
                n = crosses[u]
                if lengths[u] > 0 and n[0] * face[0] + n[1] * face[1] + n[2] * face[2] >= \
                        cos_crease * lengths[u]:
                    sum_ = [sum_[d] + n[d] for d in range(3)]
            corners.append(_unit(sum_) or face)
        out.append(tuple(corners))
    return out


# Beyond the limits a DCC would stall for seconds to a minute and hold gigabytes (a 10 m plane at
# 1 mm: 100 million samples). From the count to the array load_samples sends, at the peak
# (bench/python_sampling_bench.py, a 2-core VM, lattices of 8 points a side):
#   sample_triangles_flat, numpy: 0.45 us and 88 bytes a sample (the keys and sorts that find
#     the duplicates; 63 to 71 bytes for finer lattices);
#   sample_triangles_flat, pure Python: 3.4 us and 236 bytes (its set of the keys seen);
#   sample_triangles (a list of tuples, 240 bytes a sample more): numpy 1.5 us and 290 bytes,
#     pure Python 4.8 us and 427 bytes.
# MAX_SAMPLES bounds sample_triangles and the pure-Python loops (numpy's fallback included):
# 2 million, about 470 MB for the loops' flat array (850 MB for their tuples). MAX_FLAT_SAMPLES
# bounds sample_triangles_flat on numpy, where a sample costs a third of the loops' memory and
# a seventh of their time: 5 million, about 440 MB and 4 s (measured at 4.96 million samples:
# 3.6 s from the count to the array, 290 MB resident). (Lattices of 1 to 4 points a side cost
# numpy 850, 300, 190 and 170 bytes a sample; a mesh that fine holds more in its own lists,
# hundreds of bytes a triangle, whatever the limit.)
MAX_SAMPLES = 2000000
MAX_FLAT_SAMPLES = 5000000


def flat_sample_limit(pure=False):
    """The most samples sample_triangles_flat makes by default: MAX_FLAT_SAMPLES where numpy
    does the work, MAX_SAMPLES in the pure-Python loops (pure, or no numpy). Give it to
    check_sample_count before the corner normals to refuse a mesh as sample_triangles_flat
    will."""
    return MAX_FLAT_SAMPLES if _use_numpy(pure) else MAX_SAMPLES


def _not_finite(t, corners):
    return ValueError("triangle %d (vertices %s): its corners are not finite numbers, or too far "
                      "apart to measure"
                      % (t, ", ".join("(%g, %g, %g)" % tuple(p) for p in corners)))


def _too_many(separation, max_samples):
    return ValueError("a separation of %g would make more than %d samples: choose a larger "
                      "separation, or resample the mesh with `footfall terrain convert` and load "
                      "the point file" % (separation, max_samples))


def check_sample_count(points, triangles, separation, max_samples=MAX_SAMPLES, pure=False):
    """Raises ValueError when sampling `triangles` at `separation` would make more than
    max_samples samples: the vertices, plus each triangle's lattice points inside it and half
    of those on its edges (shared with the neighbour). Cheap: call it before anything slow.
    pure: the pure-Python loop even where numpy is present (the same errors)."""
    if not separation > 0:
        raise ValueError("separation must be > 0, got %r" % (separation,))
    if _use_numpy(pure):
        try:
            problem = _numpy.count_problem(points, triangles, separation, max_samples)
        except _numpy.Unsupported:
            pass
        else:
            if problem is None:
                return
            what, t = problem
            if what == "too many":
                raise _too_many(separation, max_samples)
            raise _not_finite(t, [points[i] for i in triangles[t]])
    total = len(points)
    for t, tri in enumerate(triangles):
        a, b, c = (points[i] for i in tri)
        longest = max(_length(_sub(b, a)), _length(_sub(c, b)), _length(_sub(a, c)))
        # (A vertex at infinity or NaN, as a huge object scale makes in Blender's floats,
        # raised OverflowError, or ValueError "cannot convert float NaN to integer"; max()
        # drops a NaN length after the first, so the corners are checked themselves.)
        ratio = longest / separation
        if not (math.isfinite(ratio) and all(math.isfinite(v) for p in (a, b, c) for v in p)):
            raise _not_finite(t, (a, b, c))
        # (At most 1e9 a side, whose 5e17 samples are refused below, so the count stays a float.)
        k = max(1, int(math.ceil(min(ratio, 1e9) - 1e-9)))
        total += (k - 1) * (k - 2) // 2 + 1.5 * (k - 1)
        if total > max_samples:
            raise _too_many(separation, max_samples)


def sample_triangles(points, triangles, separation, vertex_normals=None, corner_normals=None,
                     max_samples=MAX_SAMPLES, pure=False):
    """points: (x, y, z) per vertex; triangles: (i, j, k) vertex indices, counter-clockwise
    seen from the side the normals point to; separation [world units] > 0. Normals are
    interpolated from `corner_normals` (per triangle, its three corners': see corner_normals),
    else from `vertex_normals` (one per vertex, smooth across every edge), else the face's.
    Returns a list of (x, y, z, nx, ny, nz). Degenerate triangles are skipped. ValueError, before
    any sampling, when the lattices would hold more than max_samples points. pure: the
    pure-Python loops even where numpy is present (the same samples, bit for bit).
    (sample_triangles_flat gives the same numbers as one flat array, 48 bytes a sample.)"""
    check_sample_count(points, triangles, separation, max_samples, pure)
    if _use_numpy(pure):
        try:
            return _numpy.sample_triangles(points, triangles, separation, vertex_normals,
                                           corner_normals)
        except _numpy.Unsupported:
            pass
    return list(_pure_samples(points, triangles, separation, vertex_normals, corner_normals))


def sample_triangles_flat(points, triangles, separation, vertex_normals=None,
                          corner_normals=None, max_samples=None, pure=False):
    """sample_triangles' samples as one flat array('d'): x y z nx ny nz of each sample in turn,
    the same doubles in the same order (sample_triangles' tuples, flattened), the same errors
    for the same max_samples. With numpy no Python object is made a sample (numpy's blocks of
    samples are written into the array); without it the loops' samples go into the array one
    by one (no list of tuples is kept). What the plugins send and save: Session.load_samples
    and write_point_file take it as it is; len(flat) // 6 is the sample count. max_samples:
    flat_sample_limit(pure) unless given (numpy's larger limit; the pure-Python loops, numpy's
    fallback included, hold to MAX_SAMPLES)."""
    limit = flat_sample_limit(pure) if max_samples is None else max_samples
    check_sample_count(points, triangles, separation, limit, pure)
    if _use_numpy(pure):
        try:
            return _numpy.sample_triangles_flat(points, triangles, separation, vertex_normals,
                                                corner_normals)
        except _numpy.Unsupported:
            pass
        if max_samples is None:  # (arguments numpy cannot take exactly: the loops' own limit)
            check_sample_count(points, triangles, separation, MAX_SAMPLES, pure)
    return array("d", itertools.chain.from_iterable(
        _pure_samples(points, triangles, separation, vertex_normals, corner_normals)))


def _pure_samples(points, triangles, separation, vertex_normals, corner_normals):
    """The pure-Python loops of sample_triangles: yields each (x, y, z, nx, ny, nz) in turn."""
    seen = set()
    quantum = separation * 1e-4
    for t, tri in enumerate(triangles):
        a, b, c = (points[i] for i in tri)
        face = _unit(_cross(_sub(b, a), _sub(c, a)))
        if face is None:
            continue
        longest = max(_length(_sub(b, a)), _length(_sub(c, b)), _length(_sub(a, c)))
        k = max(1, int(math.ceil(longest / separation - 1e-9)))
        na = nb = nc = None
        if corner_normals is not None:
            if corner_normals[t] is not None:
                na, nb, nc = corner_normals[t]
        elif vertex_normals is not None:
            na, nb, nc = (vertex_normals[i] for i in tri)
        for i in range(k + 1):
            for j in range(k + 1 - i):
                u, v = i / k, j / k
                w = 1.0 - u - v
                p = tuple(w * a[d] + u * b[d] + v * c[d] for d in range(3))
                key = tuple(int(round(x / quantum)) for x in p)
                if key in seen:
                    continue
                seen.add(key)
                n = face
                if na is not None:
                    n = _unit(tuple(w * na[d] + u * nb[d] + v * nc[d] for d in range(3))) or face
                yield p + n


def write_point_file(path, samples, comment="footfall terrain points from Blender"):
    """Writes samples as footfall's point file, with every double exactly (repr): samples as
    sample_triangles returns them (rows of 6 numbers), or flat as sample_triangles_flat does
    (an array('d'), or any buffer of doubles: 6 a sample), the same text for the same numbers.
    ValueError for a path that exists and is not a regular file (opening a FIFO waits for a
    reader), or flat doubles that are not whole samples (before the file is opened)."""
    flat = _doubles(samples)
    if flat is not None and len(flat) % 6:
        raise ValueError("%d numbers are not whole samples of 6 (x y z nx ny nz)" % len(flat))
    if os.path.exists(path) and not os.path.isfile(path):
        raise ValueError("%s: not a regular file: expected a point file to write" % path)
    with open(path, "w") as f:
        f.write("# %s: x y z nx ny nz\n" % comment)
        if flat is not None:
            # A line a sample from its six floats: "%r" is repr(float(v)) for a float, so
            # the text is the rows' below.
            f.writelines(map("%r %r %r %r %r %r\n".__mod__, zip(*[iter(flat)] * 6)))
            return
        for s in samples:
            f.write(" ".join(repr(float(v)) for v in s) + "\n")


def _doubles(samples):
    """samples' numbers as a flat memoryview of doubles (iterating it gives Python floats) when
    they are a buffer of native doubles (array('d'), a float64 numpy array flat or of 6
    columns), else None."""
    try:
        view = memoryview(samples)
    except TypeError:
        return None
    if view.format not in ("d", "@d") or not view.c_contiguous or not (
            view.ndim == 1 or (view.ndim == 2 and view.shape[1] == 6)):
        view.release()
        return None
    return view.cast("B").cast("d")
