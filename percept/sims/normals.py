"""numpy's single-precision normal draws, compiled: ``standard_normal_f32(rng, out)`` fills ``out`` exactly as
``rng.standard_normal(out.shape, dtype=np.float32, out=out)`` does and leaves ``rng`` in the same state.

numpy draws them with the ziggurat method (Marsaglia & Tsang 2000, "The ziggurat method for generating random
variables", J. Stat. Softw. 5(8); numpy/random/src/distributions/distributions.c, ``random_standard_normal_f``):
a uint32 gives the layer, the sign and a 23-bit magnitude; 99 % of draws end there, the rest are tested against the
density (in double precision, ``exp(-0.5 x x)``) or drawn from the tail. numba ships the same algorithm for its
own ``Generator.standard_normal``, but tests the density in single precision, so once in a few million draws it
keeps a value numpy rejects and the stream parts from numpy's. This is numpy's algorithm line for line, with numba's
copy of numpy's tables.

The uint32s come from the Generator's own bit generator, PCG64 (``np.random.default_rng``'s; O'Neill 2014, "PCG: A
Family of Simple Fast Space-Efficient Statistically Good Algorithms for Random Number Generation", the XSL-RR
128/64 output), stepped here in the kernel from its state and written back after, as numpy's pcg64.h steps it: a
128-bit LCG, each 64-bit output giving two uint32s, the low half first and the high half kept for the next: stepped
in the kernel, not through numba's call into the bit generator, which costs a call through a pointer per uint32.
Another bit generator is left to numpy's own draws. The conditions' noise (night, noise) is drawn with it.
"""

from __future__ import annotations

import math

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic
from numba.np.random._constants import fi_float, ki_float, wi_float, ziggurat_nor_inv_r_f, ziggurat_nor_r_f

from percept.compiled import kernel

__all__ = ["standard_normal_f32"]

PCG_MULTIPLIER = 0x2360ED051FC65DA44385DF649FCCF645
"""PCG's default 128-bit LCG multiplier (numpy's ``PCG_DEFAULT_MULTIPLIER_128``)."""
_MASK64 = (1 << 64) - 1


def standard_normal_f32(rng: np.random.Generator, out: np.ndarray) -> np.ndarray:
    """``out`` (any shape, C-contiguous float32) filled with standard normal draws of ``rng``, in C order: the
    values and the generator's state after them are numpy's ``rng.standard_normal(out.shape, np.float32, out=out)``."""
    if out.dtype != np.float32 or not out.flags.c_contiguous:
        raise ValueError(f"standard_normal_f32 fills a C-contiguous float32 array, got {out.dtype}, "
                         f"contiguous={out.flags.c_contiguous}")
    bits = rng.bit_generator
    if not isinstance(bits, np.random.PCG64):
        return rng.standard_normal(out.shape, dtype=np.float32, out=out)
    s = bits.state
    state, inc = s["state"]["state"], s["state"]["inc"]
    pcg = np.array([state >> 64, state & _MASK64, s["has_uint32"], s["uinteger"]], np.uint64)
    _fill(out.reshape(-1), pcg, np.uint64(inc >> 64), np.uint64(inc & _MASK64))
    s["state"]["state"] = (int(pcg[0]) << 64) | int(pcg[1])
    s["has_uint32"], s["uinteger"] = int(pcg[2]), int(pcg[3])
    bits.state = s
    return out


@intrinsic
def _lcg_step(typingctx, hi, lo, inc_hi, inc_lo):
    """PCG64's state step on 128-bit integers: s <- s PCG_MULTIPLIER + inc (mod 2^128), each given and returned as
    its (high, low) uint64 halves."""
    sig = types.UniTuple(types.uint64, 2)(types.uint64, types.uint64, types.uint64, types.uint64)

    def codegen(context, builder, signature, args):
        i128, i64 = ir.IntType(128), ir.IntType(64)
        shift = ir.Constant(i128, 64)

        def joined(h, l):
            return builder.or_(builder.shl(builder.zext(h, i128), shift), builder.zext(l, i128))

        s = builder.add(builder.mul(joined(args[0], args[1]), ir.Constant(i128, PCG_MULTIPLIER)),
                        joined(args[2], args[3]))
        return context.make_tuple(builder, signature.return_type,
                                  [builder.trunc(builder.lshr(s, shift), i64), builder.trunc(s, i64)])
    return sig, codegen


@njit(cache=True, inline="always")
def _step64(hi, lo, inc_hi, inc_lo):  # pragma: no cover - compiled
    """numpy's ``pcg64_random_r``: the state (hi, lo) stepped, and the new state's 64-bit output. Returns
    (hi, lo, output)."""
    hi, lo = _lcg_step(hi, lo, inc_hi, inc_lo)
    # XSL-RR: (high ^ low) rotated right by the state's top 6 bits
    x, rot = hi ^ lo, hi >> np.uint64(58)
    return hi, lo, (x >> rot) | (x << ((np.uint64(64) - rot) & np.uint64(63)))


@njit(cache=True, inline="always")
def _next_uint32(pcg, inc_hi, inc_lo):  # pragma: no cover - compiled
    """numpy's ``pcg64_next32``; pcg: (state high, state low, has_uint32, uinteger) uint64, updated in place."""
    if pcg[2]:
        pcg[2] = 0
        return np.uint32(pcg[3])
    pcg[0], pcg[1], v = _step64(pcg[0], pcg[1], inc_hi, inc_lo)
    # the low half now, the high half kept for the next call
    pcg[2], pcg[3] = 1, v >> np.uint64(32)
    return np.uint32(v & np.uint64(0xFFFFFFFF))


@njit(cache=True, inline="always")
def _next_float(pcg, inc_hi, inc_lo):  # pragma: no cover - compiled
    """numpy's ``next_float``: the top 24 bits of a uint32 over 2^24, in float32."""
    return np.float32(np.float32(_next_uint32(pcg, inc_hi, inc_lo) >> 8) * np.float32(1.0) / np.float32(16777216.0))


@njit(cache=True)
def _rare(r, pcg, inc_hi, inc_lo):  # pragma: no cover - compiled
    """numpy's ``random_standard_normal_f`` from a first uint32 ``r`` that missed its layer's rectangle: the tail,
    the wedge's density test, or a new uint32 and all again."""
    while True:
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
                xx = -ziggurat_nor_inv_r_f * np.log1p(-_next_float(pcg, inc_hi, inc_lo))
                yy = -np.log1p(-_next_float(pcg, inc_hi, inc_lo))
                if yy + yy > xx * xx:
                    return -(ziggurat_nor_r_f + xx) if (rabs >> 8) & 0x1 else ziggurat_nor_r_f + xx
        else:
            # under the density: a float32 point of the wedge against exp(-x^2 / 2) in double, as numpy's C
            y = (fi_float[idx - 1] - fi_float[idx]) * _next_float(pcg, inc_hi, inc_lo) + fi_float[idx]
            if np.float64(y) < math.exp(-0.5 * np.float64(x) * np.float64(x)):
                return x
        r = _next_uint32(pcg, inc_hi, inc_lo)


@kernel()
def _fill(flat, pcg, inc_hi, inc_lo):  # pragma: no cover - compiled
    """``flat`` filled with draws; the common draw (99 %: its layer's rectangle) with the generator's state in
    locals (``_next_uint32``'s steps, unrolled), the others by ``_rare`` on the state written back to ``pcg``."""
    hi, lo, has, kept = pcg[0], pcg[1], pcg[2], pcg[3]
    i, n = 0, flat.size
    while i < n:
        if has:
            has, r = 0, np.uint32(kept)
        else:
            hi, lo, v = _step64(hi, lo, inc_hi, inc_lo)
            has, kept, r = 1, v >> np.uint64(32), np.uint32(v & np.uint64(0xFFFFFFFF))
        idx = r & 0xFF
        rabs = (r >> 9) & 0x7FFFFF
        if rabs < ki_float[idx]:
            x = np.float32(rabs) * wi_float[idx]
            flat[i] = -x if (r >> 8) & 0x1 else x
        else:
            pcg[0], pcg[1], pcg[2], pcg[3] = hi, lo, has, kept
            flat[i] = _rare(r, pcg, inc_hi, inc_lo)
            hi, lo, has, kept = pcg[0], pcg[1], pcg[2], pcg[3]
        i += 1
    pcg[0], pcg[1], pcg[2], pcg[3] = hi, lo, has, kept
