"""numpy versions of sampling.py's resampling, giving the pure-Python results bit for bit.

sampling.py calls these when numpy imports, and keeps its own loops for a Python without it.
Each function here returns exactly what the pure-Python function of sampling.py does for the
same arguments: the same samples in the same order, the same doubles (every sum, product and
square root in the same order, each a single IEEE operation as Python's floats do it), the same
duplicates dropped. Where that cannot be promised (arguments of other types, numbers a double
cannot hold as Python's integers do, a sample whose quantised key is not finite so that Python
would raise), they raise Unsupported and sampling.py takes its pure-Python path, which gives
the answer, or the error, that it always gave.

Only numpy; nothing here imports bpy or maya.
"""

import itertools
import operator
import struct
from array import array

import numpy as np

# Lattice points (or corner-neighbour pairs) computed in one block. It bounds the temporaries
# whatever one triangle's lattice or the mesh holds, and small blocks are quicker than whole
# arrays: the allocator hands the same memory back block after block, where memory new to the
# process costs a page fault per 4 KiB (measured: 8 ms for the product of two 350,000-double
# arrays in fresh memory, 0.1 ms into memory used before).
_BLOCK = 1 << 16

# Coordinates that are Python ints go through pure Python's exact integer arithmetic (sub,
# cross, the squares of a length) before they meet a float. Up to this magnitude every such
# integer, a sum of three squared cross terms included (3 * (8 * 2048**2)**2 < 2**53), is a
# double exactly, so doubles give the same numbers; beyond it the pure path is taken.
_MAX_INT_COORDINATE = 2048


class Unsupported(Exception):
    """Arguments whose pure-Python result these functions cannot promise to give bit for bit:
    the caller takes the pure-Python path."""


def _chain(rows):
    return itertools.chain.from_iterable(rows)


def _widths(rows, width):
    """Raises Unsupported unless every row of the list or tuple `rows` has `width` items."""
    try:
        if rows and set(map(len, rows)) != {width}:
            raise Unsupported
    except TypeError:  # a row without len()
        raise Unsupported from None


def _points(points):
    """`points` ((x, y, z) per vertex) as an (n, 3) float64 array, or Unsupported."""
    if isinstance(points, np.ndarray):
        # (Pure Python does float64 arithmetic on a float64 array's items: the same numbers.)
        if points.dtype != np.float64 or points.ndim != 2 or points.shape[1] != 3:
            raise Unsupported
        return points
    if not isinstance(points, (list, tuple)):  # (an iterator is read once: pure Python's)
        raise Unsupported
    _widths(points, 3)
    kinds = set(map(type, _chain(points)))
    if not kinds <= {float, int}:
        raise Unsupported
    if int in kinds and any(abs(v) > _MAX_INT_COORDINATE
                            for v in _chain(points) if type(v) is int):
        raise Unsupported
    return np.fromiter(_chain(points), np.float64, 3 * len(points)).reshape(len(points), 3)


def _triangles(triangles, n):
    """`triangles` ((i, j, k) per triangle) as an (m, 3) int64 array of indices in [0, n), or
    Unsupported (a negative index, which pure Python takes from the end, included: corner
    normals group triangles by the index as written)."""
    if isinstance(triangles, np.ndarray):
        if triangles.dtype.kind not in "iu" or triangles.ndim != 2 or triangles.shape[1] != 3:
            raise Unsupported
        tris = triangles.astype(np.int64)
        if triangles.dtype.kind == "u" and triangles.size and triangles.max() >= n:
            raise Unsupported  # (before a uint64 beyond int64 wrapped to a valid index)
    else:
        if not isinstance(triangles, (list, tuple)):
            raise Unsupported
        _widths(triangles, 3)
        if not all(issubclass(kind, (int, np.integer)) and kind is not bool
                   for kind in set(map(type, _chain(triangles)))):
            raise Unsupported
        try:
            tris = np.fromiter(_chain(triangles), np.int64, 3 * len(triangles))
        except OverflowError:
            raise Unsupported from None
        tris = tris.reshape(len(triangles), 3)
    if tris.size and (tris.min() < 0 or tris.max() >= n):
        raise Unsupported  # (pure Python raises IndexError)
    return tris


def _normals(rows):
    """Normals ((x, y, z) each, floats or ints) as an (n, 3) float64 array, or Unsupported.
    (A normal's ints meet floats at once, w * n[d], so they count as the doubles they round
    to, as numpy converts them.)"""
    if isinstance(rows, np.ndarray):
        if rows.dtype != np.float64 or rows.ndim != 2 or rows.shape[1] != 3:
            raise Unsupported
        return rows
    if not isinstance(rows, (list, tuple)):
        raise Unsupported
    _widths(rows, 3)
    if not set(map(type, _chain(rows))) <= {float, int}:
        raise Unsupported
    try:
        return np.fromiter(_chain(rows), np.float64, 3 * len(rows)).reshape(len(rows), 3)
    except OverflowError:
        raise Unsupported from None


def _separation(separation):
    """The separation as the double pure Python divides by, or Unsupported."""
    if type(separation) not in (float, int):
        raise Unsupported
    try:
        return float(separation)  # (float / int converts the int just so)
    except OverflowError:
        raise Unsupported from None


def _length(x, y, z):
    """vectors.length per row: sqrt((x*x + y*y) + z*z)."""
    return np.sqrt(x * x + y * y + z * z)


def _edges(P, T):
    """Corners a, b, c ((m, 3) each) and the longest edge per triangle, as pure Python's
    max(|b - a|, |c - b|, |a - c|)."""
    a, b, c = P[T[:, 0]], P[T[:, 1]], P[T[:, 2]]
    lengths = [_length(*(q - p).T) for p, q in ((a, b), (b, c), (c, a))]
    # (max() and np.maximum agree on lengths that are not NaN; a NaN length comes of a corner
    # that is not finite, which check_sample_count refuses whatever the longest edge.)
    return a, b, c, np.maximum(np.maximum(lengths[0], lengths[1]), lengths[2])


def _cross(a, b, c):
    """vectors.cross(b - a, c - a) per row, as (x, y, z) columns."""
    e, f = b - a, c - a
    return (e[:, 1] * f[:, 2] - e[:, 2] * f[:, 1],
            e[:, 2] * f[:, 0] - e[:, 0] * f[:, 2],
            e[:, 0] * f[:, 1] - e[:, 1] * f[:, 0])


def _unit(x, y, z):
    """vectors.unit per row: (x, y, z) / length and a mask of the rows that have none
    (length <= 1e-300: vectors.unit's None; those rows' values are meaningless)."""
    n = _length(x, y, z)
    none = n <= 1e-300
    return x / n, y / n, z / n, none


def count_problem(points, triangles, separation, max_samples):
    """What sampling.check_sample_count finds for these arguments (separation > 0): None when
    they pass, ("not finite", t) when triangle t is the first it refuses for its corners, or
    ("too many", t) when the count passes max_samples first at triangle t. Unsupported for
    arguments it cannot answer for exactly."""
    if type(max_samples) not in (float, int) or (type(max_samples) is int
                                                 and abs(max_samples) > 2 ** 53):
        raise Unsupported  # (Python compares a float with a larger int exactly)
    sep = _separation(separation)
    P = _points(points)
    T = _triangles(triangles, len(P))
    if not len(T):
        return None  # (no triangle: the count is never compared)
    with np.errstate(all="ignore"):
        a, b, c, longest = _edges(P, T)
        ratio = longest / sep
        bad = ~(np.isfinite(ratio) & np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1)
                & np.isfinite(c).all(axis=1))
        ratio[bad] = 0.0  # (counts nothing: the walk stops at the first bad triangle anyway)
        k = np.maximum(np.ceil(np.minimum(ratio, 1e9) - 1e-9), 1.0).astype(np.int64)
        # (k - 1) * (k - 2) // 2 is an exact integer (k <= 1e9), rounded to a double as Python
        # adds it to the float 1.5 * (k - 1); the running total is summed in triangle order
        # (cumsum adds one after the other), from the vertex count.
        inc = ((k - 1) * (k - 2) // 2).astype(np.float64) + 1.5 * (k - 1).astype(np.float64)
        total = np.cumsum(np.concatenate(([float(len(P))], inc)))[1:]
    over = np.flatnonzero(total > max_samples)
    first_bad = np.flatnonzero(bad)
    if len(first_bad) and (not len(over) or first_bad[0] <= over[0]):
        return ("not finite", int(first_bad[0]))
    if len(over):
        return ("too many", int(over[0]))
    return None


def corner_normals(points, triangles, cos_crease):
    """sampling.corner_normals with its crease as the cosine it compares with (cos_crease):
    per triangle, three unit normals as 3-tuples of floats, or None for a degenerate triangle.
    Unsupported for arguments it cannot answer for exactly."""
    P = _points(points)
    T = _triangles(triangles, len(P))
    m = len(T)
    if not m:
        return []
    with np.errstate(all="ignore"):
        cx, cy, cz = _cross(P[T[:, 0]], P[T[:, 1]], P[T[:, 2]])  # length 2 * area: weights
        lengths = _length(cx, cy, cz)
        fx, fy, fz, degenerate = _unit(cx, cy, cz)
        # The triangles around each vertex in pure Python's order: by triangle, a triangle
        # that names the vertex twice listed twice (a stable sort of the corners by vertex).
        corners = T.ravel()
        order = np.argsort(corners, kind="stable")
        around = order // 3  # the triangle of each corner, grouped by vertex
        start = np.searchsorted(corners[order], np.arange(len(P) + 1))
        # Each corner of each face that has a normal, one block of corners at a time: the
        # (corner, neighbouring triangle) pairs, summed per corner in the neighbours' order.
        kept_corners = np.flatnonzero(np.repeat(~degenerate, 3))
        sx, sy, sz = (np.zeros(3 * m) for _ in range(3))
        degree = start[1:] - start[:-1]
        pairs = degree[corners[kept_corners]]  # per corner
        ends = np.cumsum(pairs)
        lo = 0
        while lo < len(kept_corners):
            # About _BLOCK pairs (a corner's all in one block, however many).
            hi = max(lo + 1, int(np.searchsorted(ends, ends[lo] - pairs[lo] + _BLOCK, "right")))
            cs = kept_corners[lo:hi]
            lo = hi
            v = corners[cs]
            counts = degree[v]
            pair_corner = np.repeat(cs, counts)
            # Position of each pair within its corner's neighbour list.
            offsets = np.arange(len(pair_corner)) - np.repeat(np.cumsum(counts) - counts, counts)
            u = around[np.repeat(start[v], counts) + offsets]
            t = pair_corner // 3
            dot = cx[u] * fx[t] + cy[u] * fy[t] + cz[u] * fz[t]
            take = (lengths[u] > 0) & (dot >= cos_crease * lengths[u])
            pair_corner, u = pair_corner[take] - cs[0], u[take]
            # bincount adds its weights one after the other in index order, from 0.0, as the
            # pure-Python loop adds each neighbour's normal to its sum (each corner's sum is
            # made in one block: adding it to the 0.0 before leaves it as it is).
            span = slice(cs[0], cs[-1] + 1)
            for s, n in ((sx, cx), (sy, cy), (sz, cz)):
                s[span] += np.bincount(pair_corner, weights=n[u], minlength=cs[-1] + 1 - cs[0])
        nx, ny, nz, none = _unit(sx, sy, sz)
        face = np.repeat(np.stack((fx, fy, fz), axis=1), 3, axis=0)
        out = np.where(none[:, None], face, np.stack((nx, ny, nz), axis=1))
    rows = list(struct.iter_unpack("3d", np.ascontiguousarray(out)))  # (tuples of floats)
    result = list(zip(rows[0::3], rows[1::3], rows[2::3]))
    for t in np.flatnonzero(degenerate).tolist():
        result[t] = None
    return result


def _corner_normal_rows(normals, m, valid):
    """corner_normals given to sample_triangles as a (m, 3, 3) array and a mask of the
    triangles whose entry is None (interpolating nothing), or Unsupported. Entries of
    degenerate triangles (`valid` false), which pure Python never reads, may be anything."""
    if not isinstance(normals, (list, tuple)) or len(normals) != m:
        raise Unsupported
    none = np.fromiter(map(operator.is_, normals, itertools.repeat(None)), bool, m)
    use = np.flatnonzero(~none & valid)
    rows = [normals[t] for t in use.tolist()]
    _widths(rows, 3)
    flat = _normals(list(_chain(rows)))
    out = np.zeros((m, 3, 3))
    out[use] = flat.reshape(len(use), 3, 3)
    return out, none


def _lattice(k):
    """(i, j) of a triangle's lattice of size k in sample_triangles' order: i, then j."""
    rows = np.arange(k + 1, 0, -1)  # row i holds k + 1 - i points
    i = np.repeat(np.arange(k + 1), rows)
    j = np.arange(len(i)) - np.repeat(np.cumsum(rows) - rows, rows)
    return i, j


def _interpolate(i, j, k, a, b, c):
    """w * a + u * b + v * c per coordinate, as pure Python sums it (u = i / k, v = j / k,
    w = 1.0 - u - v): a, b, c are (m, 3) corners or corner normals, i, j, k per point (or i, j
    per point of one lattice and k a number, with a, b, c one row per triangle and a result of
    (triangles, points) per coordinate)."""
    u = i / k
    v = j / k
    w = 1.0 - u - v
    return [w * a[..., d] + u * b[..., d] + v * c[..., d] for d in range(3)]


def sample_triangles(points, triangles, separation, vertex_normals, corner_normals):
    """sampling.sample_triangles once check_sample_count has passed: the list of
    (x, y, z, nx, ny, nz) tuples of floats it returns. Unsupported for arguments it cannot
    answer for exactly, or when pure Python would raise (a key it could not round to an
    integer)."""
    return _sample(points, triangles, separation, vertex_normals, corner_normals, False)


def sample_triangles_flat(points, triangles, separation, vertex_normals, corner_normals):
    """sample_triangles' samples as one array('d') of x y z nx ny nz each, in the same order,
    the same doubles, made with no Python object a sample: each block of samples is written
    into the array's memory as numpy makes it. The same Unsupported."""
    return _sample(points, triangles, separation, vertex_normals, corner_normals, True)


def _sample(points, triangles, separation, vertex_normals, corner_normals, flat):
    """sample_triangles (flat false: a list of tuples) or sample_triangles_flat (an array)."""
    sep = _separation(separation)
    quantum = separation * 1e-4  # (as pure Python computes it: int * float included)
    P = _points(points)
    T = _triangles(triangles, len(P))
    m = len(T)
    if corner_normals is None and vertex_normals is not None:
        N = _normals(vertex_normals)
        if m and T.max() >= len(N):
            raise Unsupported  # (pure Python raises IndexError)
    with np.errstate(all="ignore"):
        a, b, c, longest = _edges(P, T)
        fx, fy, fz, degenerate = _unit(*_cross(a, b, c))
        valid = ~degenerate
        if corner_normals is not None:  # (read once the degenerate triangles are known)
            corners, no_corners = _corner_normal_rows(corner_normals, m, valid)
        k = np.maximum(np.ceil(longest / sep - 1e-9), 1.0)
        tri = np.flatnonzero(valid)  # the triangles sampled, in order
        if not len(tri):
            return array("d") if flat else []
        k = k[tri].astype(np.int64)
        size = (k + 1) * (k + 2) // 2  # lattice points per triangle
        first = np.cumsum(size) - size  # of each triangle's lattice in the candidates
        count = int(size.sum())
        # The quantised key of every candidate, in pure Python's order (triangle, i, j),
        # computed per lattice size, a block of triangles at a time. rint rounds half to even
        # as round() does, and its doubles are those integers exactly; + 0.0 makes rint's
        # -0.0 the 0.0 that Python's int 0 is, so equal keys have equal bits.
        keys = [np.empty(count) for _ in range(3)]
        for kk in np.unique(k).tolist():
            i, j = _lattice(kk)
            which = np.flatnonzero(k == kk)
            per_block = max(1, _BLOCK // len(i))
            for lo in range(0, len(which), per_block):
                w_ = which[lo:lo + per_block]
                t = tri[w_]
                place = (first[w_][:, None] + np.arange(len(i))).ravel()
                coords = _interpolate(i, j, kk, a[t, None, :], b[t, None, :], c[t, None, :])
                for d in range(3):
                    key = np.rint(coords[d] / quantum) + 0.0
                    if not np.isfinite(key).all():
                        raise Unsupported  # (Python's int(round(...)) raises here)
                    keys[d][place] = key.ravel()
        keep = _first_of_each(keys)
        del keys
        if corner_normals is not None:
            normals = (corners[:, 0], corners[:, 1], corners[:, 2], ~no_corners)
        elif vertex_normals is not None:
            normals = (N[T[:, 0]], N[T[:, 1]], N[T[:, 2]], np.ones(m, bool))
        else:
            normals = None
        if flat:
            # The array at its final size (zeros by repetition: no temporary), written through
            # a numpy view of its memory; the view is dropped before the array is returned, so
            # the caller may resize it.
            out = array("d", (0.0,)) * (6 * len(keep))
            view = np.frombuffer(out, np.float64).reshape(len(keep), 6)
            for lo in range(0, len(keep), _BLOCK):
                _samples(keep[lo:lo + _BLOCK], first, tri, k, a, b, c, (fx, fy, fz), normals,
                         view[lo:lo + _BLOCK])
            del view
            return out
        out = []
        for lo in range(0, len(keep), _BLOCK):
            # struct makes each row's tuple of floats straight from the doubles (tolist() and
            # zip() build lists on the way).
            rows = _samples(keep[lo:lo + _BLOCK], first, tri, k, a, b, c, (fx, fy, fz), normals)
            out.extend(struct.iter_unpack("6d", rows))
    return out


def _samples(keep, first, tri, k, a, b, c, face, normals, out=None):
    """The (len(keep), 6) samples of the candidates `keep` (indices into the lattices of the
    triangles `tri`, each of size k, starting at `first`): each one's lattice point and
    weights again, its position and its normal (face's, or interpolated from `normals`:
    per triangle its corners' normals and whether to interpolate, or None). Written into
    `out` (a (len(keep), 6) float64 array) when given, else into a new array."""
    where = np.searchsorted(first, keep, side="right") - 1
    t = tri[where]
    kk = k[where]
    index = keep - first[where]
    i = np.empty(len(keep), np.int64)
    j = np.empty(len(keep), np.int64)
    for size in np.unique(kk).tolist():
        rows = np.arange(size + 1, 0, -1)  # row i of the lattice holds size + 1 - i points
        starts = np.cumsum(rows) - rows
        sel = np.flatnonzero(kk == size)
        i[sel] = np.searchsorted(starts, index[sel], "right") - 1
        j[sel] = index[sel] - starts[i[sel]]
    if out is None:
        out = np.empty((len(keep), 6))
    out[:, 0], out[:, 1], out[:, 2] = _interpolate(i, j, kk, a[t], b[t], c[t])
    for d in range(3):
        out[:, 3 + d] = face[d][t]
    if normals is not None:
        na, nb, nc, smooth = normals
        smooth = smooth[t]
        if smooth.any():
            nx, ny, nz, none = _unit(*_interpolate(i, j, kk, na[t], nb[t], nc[t]))
            use = smooth & ~none
            out[use, 3], out[use, 4], out[use, 5] = nx[use], ny[use], nz[use]
    return out


def _mix(bits):
    """A 64-bit hash of each uint64 (splitmix64's finaliser): spreads the few bits in which
    keys differ (doubles of whole numbers end in zeros) over all 64."""
    h = bits ^ (bits >> np.uint64(30))
    h *= np.uint64(0xBF58476D1CE4E5B9)
    h ^= h >> np.uint64(27)
    h *= np.uint64(0x94D049BB133111EB)
    h ^= h >> np.uint64(31)
    return h


def _first_of_each(keys):
    """Indices of the first candidate of each distinct key (three columns of doubles, compared
    by value: no NaN, no -0.0, so equal keys have equal bits), in increasing order: pure
    Python's `seen` set, which keeps a sample the first time its key comes."""
    n = len(keys[0])
    if n == 0:
        return np.empty(0, np.int64)
    # One stable sort by a hash of the key (lexsort's three passes cost twice as much); the
    # earliest candidate of equal hashes comes first. A run of equal hashes holding two keys
    # (a collision) could hide a key between others: then lexsort sorts the keys themselves.
    bits = [column.view(np.uint64) for column in keys]
    h = _mix(bits[0])
    h = _mix(h ^ bits[1])
    h = _mix(h ^ bits[2])
    order = np.argsort(h, kind="stable")
    h = h[order]
    same = h[1:] == h[:-1]
    del h
    same_key = np.ones(n - 1, bool)
    for column in keys:
        s = column[order]
        same_key &= s[1:] == s[:-1]
        del s
    if (same & ~same_key).any():
        order = np.lexsort((keys[2], keys[1], keys[0]))  # (stable, as argsort above)
        same = np.ones(n - 1, bool)
        for column in keys:
            s = column[order]
            same &= s[1:] == s[:-1]
            del s
    keep = order[np.concatenate(([True], ~same))]
    keep.sort()
    return keep
