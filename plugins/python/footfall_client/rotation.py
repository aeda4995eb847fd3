"""Body rotations for DCCs that key Euler angles (Maya): footfall's quaternions as Euler angles
in degrees, unwrapped key to key, the same conversions as client/export/src/euler.cpp. Pure
Python. Bodies are keyed in rotate order ZXY (R = Ry * Rx * Rz), as the MEL export keys them:
heading is the Y angle alone, so an upright body is never at gimbal lock whatever its heading
(in Maya's default XYZ order a body heading +-X is). XYZ (R = Rz * Ry * Rx) turns other nodes."""

import math

from .vectors import cross, unit


def unit_quat(q):
    """q (x, y, z, w), any non-zero length, as a unit quaternion, as footfall's walk reader
    takes it: scaled by its largest component first, so that neither tiny (1e-320) nor huge
    (1e200) components underflow or overflow. ValueError for a zero or non-finite q."""
    q = tuple(float(c) for c in q)
    if not all(math.isfinite(c) for c in q) or not any(q):
        raise ValueError("rotation %r: expected a non-zero quaternion of finite numbers" % (q,))
    n2 = sum(c * c for c in q)
    if not 1e-200 < n2 < 1e200:  # its square would lose digits, or be 0 or infinite
        m = max(abs(c) for c in q)
        q = tuple(c / m for c in q)
        n2 = sum(c * c for c in q)
    n = math.sqrt(n2)
    return tuple(c / n for c in q)


def quat_to_euler_xyz(q):
    """(x, y, z, w) -> (rx, ry, rz) degrees with R = Rz(rz) * Ry(ry) * Rx(rx)."""
    return quat_to_euler(q, "xyz")


def _unwrap(angle, target):
    return angle + 360.0 * round((target - angle) / 360.0)


def closest_euler(euler, previous):
    """The XYZ angles equal to `euler` as a rotation that lie closest to `previous` (degrees), so
    that interpolating between keys turns the short way instead of spinning through 360."""
    return closest_euler_in_order(euler, previous, "xyz")


def quat_to_euler_zxy(q):
    """(x, y, z, w) -> (rx, ry, rz) degrees with R = Ry(ry) * Rx(rx) * Rz(rz): Maya's rotate
    order ZXY (rotateOrder 2). rx is in [-90, 90]; at gimbal lock (rx = +-90) rz is 0."""
    return quat_to_euler(q, "zxy")


def closest_euler_zxy(euler, previous):
    """As closest_euler, for ZXY angles (quat_to_euler_zxy): the alternative solution is
    (180 - rx, ry + 180, rz + 180)."""
    return closest_euler_in_order(euler, previous, "zxy")


# Maya's rotateOrder values: the axes in the order they turn (xyz: X first, R = Rz * Ry * Rx).
ROTATE_ORDERS = ("xyz", "yzx", "zxy", "xzy", "yxz", "zyx")


def quat_to_euler(q, order):
    """(x, y, z, w) -> (rx, ry, rz) degrees in Maya's rotate order `order` (a ROTATE_ORDERS
    name or its rotateOrder number): R = R_last * R_middle * R_first. The middle angle is in
    [-90, 90]; at gimbal lock (+-90) the first is 0, the turn all in the last."""
    if not isinstance(order, str):
        order = ROTATE_ORDERS[int(order)]
    i, j, k = ("xyz".index(a) for a in order)
    # +1 when the axes turn in cyclic order (xyz, yzx, zxy), -1 otherwise.
    sign = 1.0 if (j - i) % 3 == 1 else -1.0
    x, y, z, w = unit_quat(q)
    m = ((1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
         (2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
         (2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)))
    sin_b = max(-1.0, min(1.0, -sign * m[k][i]))
    if abs(sin_b) > 1 - 1e-12:  # gimbal lock: the first and last turn about one axis; all in the last
        a, b, c = 0.0, math.copysign(math.pi / 2, sin_b), math.atan2(-sign * m[i][j], m[j][j])
    else:
        a, b = math.atan2(sign * m[k][j], m[k][k]), math.asin(sin_b)
        c = math.atan2(sign * m[j][i], m[i][i])
    angles = [0.0, 0.0, 0.0]
    angles[i], angles[j], angles[k] = math.degrees(a), math.degrees(b), math.degrees(c)
    return tuple(angles)


def closest_euler_in_order(euler, previous, order):
    """As closest_euler, for angles in rotate order `order` (quat_to_euler): the other solution
    is (first + 180, 180 - middle, last + 180); at gimbal lock (middle +-90) the turn is split
    between the first and last angles as near `previous` as it goes."""
    if not isinstance(order, str):
        order = ROTATE_ORDERS[int(order)]
    i, j, k = ("xyz".index(a) for a in order)

    def unwrap_all(e):
        return tuple(_unwrap(e[n], previous[n]) for n in range(3))

    def l1(e):
        return sum(abs(e[n] - previous[n]) for n in range(3))

    if _at_lock(euler[j]):
        # The first and last angles turn about one axis: first + t and last + s * t give the
        # same rotation for any t. t halfway between the shifts each would need alone, taken
        # within half a turn of each other (the shorter arc).
        s = (1.0 if (j - i) % 3 == 1 else -1.0) * (1.0 if euler[j] > 0 else -1.0)
        to_first = previous[i] - euler[i]
        t = 0.5 * (to_first + _unwrap(s * (previous[k] - euler[k]), to_first))
        locked = list(euler)
        locked[i], locked[k] = euler[i] + t, euler[k] + s * t
        return unwrap_all(locked)
    other = list(euler)
    other[i], other[j], other[k] = euler[i] + 180.0, 180.0 - euler[j], euler[k] + 180.0
    direct, alternative = unwrap_all(euler), unwrap_all(other)
    return alternative if l1(alternative) < l1(direct) else direct


def _at_lock(middle):
    return abs(abs(middle) - 90.0) < 1e-9


def continuous_eulers(quats, order):
    """Keys' rotations (x, y, z, w) as Euler degrees in rotate order `order`, each the triple
    closest to its neighbour's (closest_euler_in_order), so that per-angle interpolation between
    keys turns the short way. Keys at gimbal lock before the first key that is not split their
    turn as that key does (a Z-up body facing +-Y leaned up to 10 degrees between its first
    keys and the next ones otherwise), as client/export/src/euler.cpp does for the MEL export."""
    if not isinstance(order, str):
        order = ROTATE_ORDERS[int(order)]
    j = "xyz".index(order[1])
    out = [quat_to_euler(q, order) for q in quats]
    first = next((n for n, e in enumerate(out) if not _at_lock(e[j])), 0)
    for n in range(first - 1, -1, -1):
        out[n] = closest_euler_in_order(out[n], out[n + 1], order)
    for n in range(first + 1, len(out)):
        out[n] = closest_euler_in_order(out[n], out[n - 1], order)
    return out


def quat_from_frame(up, forward):
    """(x, y, z, w): the rotation taking the character axes (Y up, Z forward) to `up` and to
    `forward` projected across it (any direction across `up` when forward lies along it), as the
    walk's body keys are. Both in footfall's (= Maya's) frame."""
    y = unit(up) or (0.0, 1.0, 0.0)
    d = sum(forward[i] * y[i] for i in range(3))
    z = unit(tuple(forward[i] - d * y[i] for i in range(3)))
    if z is None:
        z = unit(cross((1.0, 0.0, 0.0) if abs(y[0]) < 0.9 else (0.0, 0.0, 1.0), y))
    x = cross(y, z)
    # Columns x, y, z; the matrix to a quaternion (Shepperd).
    m00, m01, m02 = x[0], y[0], z[0]
    m10, m11, m12 = x[1], y[1], z[1]
    m20, m21, m22 = x[2], y[2], z[2]
    trace = m00 + m11 + m22
    if trace > 0:
        s = 2 * math.sqrt(trace + 1)
        q = ((m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, s / 4)
    elif m00 > m11 and m00 > m22:
        s = 2 * math.sqrt(1 + m00 - m11 - m22)
        q = (s / 4, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s)
    elif m11 > m22:
        s = 2 * math.sqrt(1 + m11 - m00 - m22)
        q = ((m01 + m10) / s, s / 4, (m12 + m21) / s, (m02 - m20) / s)
    else:
        s = 2 * math.sqrt(1 + m22 - m00 - m11)
        q = ((m02 + m20) / s, (m12 + m21) / s, s / 4, (m10 - m01) / s)
    return q if q[3] >= 0 else tuple(-c for c in q)
