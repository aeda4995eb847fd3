"""3-vectors as tuples, for the plugins' own geometry (sampling, rotations). Pure Python."""

import math


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def length(a):
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def unit(a):
    """a scaled to length 1, or None when it has no direction."""
    n = length(a)
    return None if n <= 1e-300 else (a[0] / n, a[1] / n, a[2] / n)
