"""numpy's single-precision normal draws, compiled: ``standard_normal_f32(rng, out)`` fills ``out`` exactly as
``rng.standard_normal(out.shape, dtype=np.float32, out=out)`` does and leaves ``rng`` in the same state.

numpy draws them with the ziggurat method (Marsaglia & Tsang 2000, "The ziggurat method for generating random
variables", J. Stat. Softw. 5(8); numpy/random/src/distributions/distributions.c, ``random_standard_normal_f``):
a uint32 gives the layer, the sign and a 23-bit magnitude; 99 % of draws end there, the rest are tested against the
density (in double precision, ``exp(-0.5 x x)``) or drawn from the tail. numba ships the same algorithm for its
own ``Generator.standard_normal``, but tests the density in single precision, so once in a few million draws it
keeps a value numpy rejects and the stream parts from numpy's. This is numpy's algorithm line for line on the same
bit generator (the Generator's own, advanced in place) and numba's copy of numpy's tables; the conditions' noise is
drawn with it (night, noise), about 1.5x as fast as numpy's own loop.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numba.np.random._constants import fi_float, ki_float, wi_float, ziggurat_nor_inv_r_f, ziggurat_nor_r_f
from numba.np.random.generator_core import next_float, next_uint32

from percept.compiled import kernel

__all__ = ["standard_normal_f32"]


def standard_normal_f32(rng: np.random.Generator, out: np.ndarray) -> np.ndarray:
    """``out`` (any shape, C-contiguous float32) filled with standard normal draws of ``rng``, in C order: the
    values and the generator's state after them are numpy's ``rng.standard_normal(out.shape, np.float32, out=out)``."""
    if out.dtype != np.float32 or not out.flags.c_contiguous:
        raise ValueError(f"standard_normal_f32 fills a C-contiguous float32 array, got {out.dtype}, "
                         f"contiguous={out.flags.c_contiguous}")
    _fill(rng, out.reshape(-1))
    return out


@njit(cache=True)
def _draw(bitgen):  # pragma: no cover - compiled
    """One draw of numpy's ``random_standard_normal_f``."""
    while True:
        r = next_uint32(bitgen)
        idx = r & 0xFF
        sign = (r >> 8) & 0x1
        rabs = (r >> 9) & 0x7FFFFF
        x = np.float32(rabs) * wi_float[idx]
        if sign & 0x1:
            x = -x
        if rabs < ki_float[idx]:
            return x
        if idx == 0:
            while True:
                # the tail beyond r: 1 - U avoids log(0)
                xx = -ziggurat_nor_inv_r_f * np.log1p(-next_float(bitgen))
                yy = -np.log1p(-next_float(bitgen))
                if yy + yy > xx * xx:
                    return -(ziggurat_nor_r_f + xx) if (rabs >> 8) & 0x1 else ziggurat_nor_r_f + xx
        else:
            # under the density: a float32 point of the wedge against exp(-x^2 / 2) in double, as numpy's C
            y = (fi_float[idx - 1] - fi_float[idx]) * next_float(bitgen) + fi_float[idx]
            if np.float64(y) < math.exp(-0.5 * np.float64(x) * np.float64(x)):
                return x


@kernel()
def _fill(rng, flat):  # pragma: no cover - compiled
    bitgen = rng.bit_generator
    for i in range(flat.size):
        flat[i] = _draw(bitgen)
