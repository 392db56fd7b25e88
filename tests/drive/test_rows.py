"""The scorers' compact per-frame rows: the values appended, in 8 bytes a value."""

import numpy as np
import pytest

from percept.drive.rows import Rows


def test_rows_give_back_the_appended_values_in_order_and_shape():
    r = Rows(3)
    assert len(r) == 0 and r.values().shape == (0, 3)
    rows = [(0.1, -2.0, np.nan), (3.0, 4.5, 1e-9)]
    for row in rows:
        r.append(row)
    got = r.values()
    assert len(r) == 2 and got.shape == (2, 3)
    np.testing.assert_array_equal(got, np.asarray(rows))
    # taking the values does not stop the rows from growing
    r.append(np.array([7.0, 8.0, 9.0]))
    assert len(r) == 3 and r.values()[2].tolist() == [7.0, 8.0, 9.0]


def test_a_row_of_the_wrong_width_is_refused():
    with pytest.raises(ValueError, match="a row of 2 values where 3 are kept"):
        Rows(3).append((1.0, 2.0))


def test_a_row_costs_eight_bytes_a_value():
    r = Rows(4)
    for k in range(10_000):
        r.append((k, k, k, k))
    # allocated bytes, spare room included (CPython's array grows by about 1/16 at a time)
    assert 8 * 4 * 10_000 <= r.nbytes < 1.15 * 8 * 4 * 10_000
