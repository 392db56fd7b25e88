"""The compiled normal draws against numpy's own: the same values and the same generator state after them."""

import numpy as np
import pytest

from percept.sims.normals import standard_normal_f32


@pytest.mark.parametrize("shape", [(7,), (480, 640), (31, 17, 3)])
def test_draws_and_state_equal_numpys(shape):
    for seed in range(3):
        a, b = np.random.default_rng([seed, 5, 0xC0FFEE]), np.random.default_rng([seed, 5, 0xC0FFEE])
        ref = a.standard_normal(shape, dtype=np.float32)
        got = standard_normal_f32(b, np.empty(shape, np.float32))
        assert got.tobytes() == ref.tobytes()
        # the generator goes on where numpy's would: the next draws of every kind agree
        assert a.standard_normal(3, dtype=np.float32).tobytes() == b.standard_normal(3, dtype=np.float32).tobytes()
        assert a.random() == b.random() and a.integers(0, 1000, 4).tolist() == b.integers(0, 1000, 4).tolist()


def test_the_rare_branches_are_numpys():
    """A million draws pass the wedge test (in double precision, where numba's own float32 test differs) ~10 000 times
    and the tail ~300 times; the values beyond 3.65 come from the tail."""
    a, b = np.random.default_rng(2024), np.random.default_rng(2024)
    ref = a.standard_normal(1_000_000, dtype=np.float32)
    got = standard_normal_f32(b, np.empty(1_000_000, np.float32))
    assert (np.abs(ref) > 3.6541529).sum() > 100
    assert got.tobytes() == ref.tobytes()


def test_only_contiguous_float32_is_filled():
    rng = np.random.default_rng(0)
    with pytest.raises(ValueError, match="C-contiguous float32"):
        standard_normal_f32(rng, np.empty(10, np.float64))
    with pytest.raises(ValueError, match="C-contiguous float32"):
        standard_normal_f32(rng, np.empty((10, 10), np.float32)[:, ::2])


def test_a_kept_half_is_drawn_first():
    """PCG64 gives 64 bits at a time, numpy hands out their low half and keeps the high half for the next uint32:
    after an odd number of uint32s the fill starts from the kept half, as numpy's draws do."""
    a, b = np.random.default_rng(11), np.random.default_rng(11)
    for g in (a, b):
        g.standard_normal(1, dtype=np.float32)
    assert b.bit_generator.state["has_uint32"] == 1
    ref = a.standard_normal((5, 9), dtype=np.float32)
    assert standard_normal_f32(b, np.empty((5, 9), np.float32)).tobytes() == ref.tobytes()
    assert a.bit_generator.state == b.bit_generator.state


@pytest.mark.parametrize("bits", [np.random.MT19937, np.random.Philox, np.random.SFC64])
def test_other_bit_generators_draw_as_numpy(bits):
    a, b = np.random.Generator(bits(3)), np.random.Generator(bits(3))
    ref = a.standard_normal((40, 7), dtype=np.float32)
    assert standard_normal_f32(b, np.empty((40, 7), np.float32)).tobytes() == ref.tobytes()
    assert a.random() == b.random()
