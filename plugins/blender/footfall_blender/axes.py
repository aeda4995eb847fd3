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
    """footfall rotation (x, y, z, w) -> Blender quaternion order (w, x, y, z)."""
    x, y, z, w = (float(c) for c in q)
    return (w, x, -z, y)


def quat_to_ff(q):
    """Blender quaternion (w, x, y, z) -> footfall (x, y, z, w)."""
    w, x, y, z = (float(c) for c in q)
    return (x, z, -y, w)
