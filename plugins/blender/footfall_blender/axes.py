"""Blender (Z up, characters face -Y) <-> footfall (Y up, characters face +Z), the same
conversion as Blender's glTF importer: footfall (x, y, z) is Blender (x, -z, y). It is a proper
rotation (90 degrees about X), so quaternions convert by rotating their vector part.

Lengths: footfall's are metres (the character files' unit), Blender's are scene units, each
the scene's Unit Scale (scale_length) in metres, as the glTF importer converts: a point is
multiplied by the scale on its way to footfall and divided by it on its way back. At Unit
Scale 1 (the default) the numbers are unchanged, bit for bit."""


def unit_scale(scene):
    """Metres per Blender unit in `scene`: its Unit Scale (1 when it is not a positive finite
    number)."""
    try:
        s = float(scene.unit_settings.scale_length)
    except (AttributeError, TypeError, ValueError):
        return 1.0
    return s if 0.0 < s < float("inf") else 1.0


def to_ff(v, scale=1.0):
    """A Blender world point -> footfall world (tuple), its coordinates times `scale` (metres
    per Blender unit: unit_scale(); a direction: 1)."""
    return (float(v[0]) * scale, float(v[2]) * scale, -float(v[1]) * scale)


def from_ff(v, scale=1.0):
    """A footfall world point -> Blender world (tuple), its coordinates divided by `scale`
    (metres per Blender unit: unit_scale(); a direction: 1)."""
    return (float(v[0]) / scale, -float(v[2]) / scale, float(v[1]) / scale)


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
