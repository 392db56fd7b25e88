"""3-vectors as tuples of Python floats, for model code that builds geometry a few vectors at a time.

numpy's dispatch of each operation on a (3,) array costs several times the arithmetic; these plain functions do
the same float64 operations in the same order (``mul(k, a)`` is k·aᵢ, ``madd(a, k, b)`` is aᵢ + k·bᵢ), so a
figure built with them has the coordinates the numpy expressions give. Dot products are summed left to right
(numpy's BLAS may fuse the multiply-adds; the two differ in the last bit at most).

Each is also ``register_jitable``: a compiled kernel (numba) that calls one compiles it into itself, while Python
callers (on tuples or on numpy columns) call the plain function.
"""

from __future__ import annotations

import math

from numba.extending import register_jitable

Vec3 = tuple[float, float, float]

__all__ = ["UP", "Vec3", "add", "cross", "dot", "madd", "mul", "norm", "sub", "vec"]

UP: Vec3 = (0.0, 0.0, 1.0)


def vec(v) -> Vec3:
    """Any 3-sequence (a tuple, a list, a (3,) array) as a tuple of floats."""
    return (float(v[0]), float(v[1]), float(v[2]))


@register_jitable
def add(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@register_jitable
def sub(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@register_jitable
def mul(k: float, a: Vec3) -> Vec3:
    return (k * a[0], k * a[1], k * a[2])


@register_jitable
def madd(a: Vec3, k: float, b: Vec3) -> Vec3:
    """a + k b."""
    return (a[0] + k * b[0], a[1] + k * b[1], a[2] + k * b[2])


@register_jitable
def dot(a: Vec3, b: Vec3) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@register_jitable
def cross(a: Vec3, b: Vec3) -> Vec3:
    """a × b, written out as ``np.cross`` computes it."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@register_jitable
def norm(a: Vec3) -> float:
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
