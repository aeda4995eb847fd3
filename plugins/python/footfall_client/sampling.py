"""Resamples triangles at a point separation into terrain samples (no bpy).

Each triangle is cut into a barycentric lattice whose edges are at most `separation` long; the
lattice points are the samples (points shared by neighbouring triangles are kept once). Normals
are the triangle's corner normals interpolated across it (smooth: corner_normals, sharp at
edges past a crease angle, as footfall's own sampler), or the face normal.

With numpy (Blender's Python has it; Maya's may not) the work is done by sampling_numpy with
the same results bit for bit, sample_triangles in about a third of the time (most of what is
left is making the list of tuples it returns); without numpy, or for arguments numpy cannot
take exactly (see sampling_numpy), by the pure-Python loops here. Each function's `pure=True`,
or USE_NUMPY = False, takes the pure-Python loops.
"""

import math
import os

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


# From the count to the array load_samples sends, pure Python takes 5 to 6 us a sample and holds
# up to about 480 bytes of it (the list of tuples returned 240 of them, the array sent 48); with
# numpy 2 us and 310 bytes (bench/python_sampling_bench.py, a 2-core VM). Beyond this many, a
# DCC would stall for seconds to a minute and hold gigabytes (a 10 m plane at 1 mm: 100
# million). numpy keeps the limit: the list of tuples, the same on both paths, is most of the
# memory (480 MB at the limit).
MAX_SAMPLES = 2000000


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
    pure-Python loops even where numpy is present (the same samples, bit for bit)."""
    check_sample_count(points, triangles, separation, max_samples, pure)
    if _use_numpy(pure):
        try:
            return _numpy.sample_triangles(points, triangles, separation, vertex_normals,
                                           corner_normals)
        except _numpy.Unsupported:
            pass
    seen = set()
    quantum = separation * 1e-4
    out = []
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
                out.append(p + n)
    return out


def write_point_file(path, samples, comment="footfall terrain points from Blender"):
    """Writes samples as footfall's point file, with every double exactly (repr). ValueError for
    a path that exists and is not a regular file (opening a FIFO waits for a reader)."""
    if os.path.exists(path) and not os.path.isfile(path):
        raise ValueError("%s: not a regular file: expected a point file to write" % path)
    with open(path, "w") as f:
        f.write("# %s: x y z nx ny nz\n" % comment)
        for s in samples:
            f.write(" ".join(repr(float(v)) for v in s) + "\n")
