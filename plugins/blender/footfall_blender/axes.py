"""Blender (Z up, characters face -Y) <-> footfall (Y up, characters face +Z), the same
conversion as Blender's glTF importer: footfall (x, y, z) is Blender (x, -z, y). It is a proper
rotation (90 degrees about X), so quaternions convert by rotating their vector part."""


def to_ff(v):
    """A Blender world point or direction -> footfall world (tuple)."""
    return (float(v[0]), float(v[2]), -float(v[1]))


def from_ff(v):
    """A footfall world point or direction -> Blender world (tuple)."""
    return (float(v[0]), -float(v[2]), float(v[1]))


def quat_from_ff(q):
    """footfall rotation (x, y, z, w) -> Blender unit quaternion, order (w, x, y, z). Scaled to
    unit length as footfall's walk reader takes it (Blender's matrices take the quaternion as
    unit: [0, 2, 0, 2] was keyed as 49 degrees, not 90). ValueError for a zero quaternion."""
    x, y, z, w = (float(c) for c in q)
    m = max(abs(x), abs(y), abs(z), abs(w))
    if not 0 < m < float("inf") or any(c != c for c in (x, y, z, w)):  # (c != c: a NaN)
        raise ValueError("rotation %r: expected a non-zero quaternion of finite numbers" % (q,))
    if not 1e-100 < m < 1e100:  # the squares would lose digits, or be 0 or infinite
        x, y, z, w = x / m, y / m, z / m, w / m
    n = (x * x + y * y + z * z + w * w) ** 0.5
    return (w / n, x / n, -z / n, y / n)


def quat_to_ff(q):
    """Blender quaternion (w, x, y, z) -> footfall (x, y, z, w)."""
    w, x, y, z = (float(c) for c in q)
    return (x, z, -y, w)
