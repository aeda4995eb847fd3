"""Resamples triangles at a point separation into terrain samples (pure Python, no bpy).

Each triangle is cut into a barycentric lattice whose edges are at most `separation` long; the
lattice points are the samples (points shared by neighbouring triangles are kept once). Normals
are the vertex normals interpolated across the triangle (smooth) or the face normal.
"""

import math


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _length(a):
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def _unit(a):
    n = _length(a)
    return None if n <= 1e-300 else (a[0] / n, a[1] / n, a[2] / n)


def sample_triangles(points, triangles, separation, vertex_normals=None):
    """points: (x, y, z) per vertex; triangles: (i, j, k) vertex indices, counter-clockwise
    seen from the side the normals point to; separation [world units] > 0; vertex_normals:
    per-vertex normals for smooth shading, or None for face normals. Returns a list of
    (x, y, z, nx, ny, nz). Degenerate triangles are skipped."""
    if not separation > 0:
        raise ValueError("separation must be > 0, got %r" % (separation,))
    seen = set()
    quantum = separation * 1e-4
    out = []
    for tri in triangles:
        a, b, c = (points[i] for i in tri)
        face = _unit(_cross(_sub(b, a), _sub(c, a)))
        if face is None:
            continue
        longest = max(_length(_sub(b, a)), _length(_sub(c, b)), _length(_sub(a, c)))
        k = max(1, int(math.ceil(longest / separation - 1e-9)))
        na = nb = nc = None
        if vertex_normals is not None:
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
    """Writes samples as footfall's point file, with every double exactly (repr)."""
    with open(path, "w") as f:
        f.write("# %s: x y z nx ny nz\n" % comment)
        for s in samples:
            f.write(" ".join(repr(float(v)) for v in s) + "\n")
