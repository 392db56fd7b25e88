"""Range and time-to-contact scoring against values computed by hand."""

import math

import numpy as np
import pytest

from percept.longitudinal import RANGE_BINS_M, bin_key, range_abs_rel_err, range_abs_rel_err_by_bin, ttc_abs_err_s


def test_bin_keys_are_the_json_keys():
    assert [bin_key(b) for b in RANGE_BINS_M] == ["0-20", "20-40", "40-60", "60-80"]


def test_constant_overestimate_is_the_error_overall_and_in_each_populated_bin():
    true_m = np.array([5.0, 15.0, 25.0, 45.0, 47.0, 90.0])
    est_m = 1.02 * true_m
    assert range_abs_rel_err(est_m, true_m) == pytest.approx(0.02)
    by_bin = range_abs_rel_err_by_bin(est_m, true_m)
    assert by_bin["0-20"] == pytest.approx(0.02)
    assert by_bin["20-40"] == pytest.approx(0.02)
    assert by_bin["40-60"] == pytest.approx(0.02)
    assert by_bin["60-80"] is None  # 90 m is beyond every bin


def test_median_not_mean_and_underestimate_counts_as_positive():
    true_m = np.array([10.0, 10.0, 10.0])
    est_m = np.array([9.9, 10.2, 15.0])  # errors 0.01, 0.02, 0.5
    assert range_abs_rel_err(est_m, true_m) == pytest.approx(0.02)


def test_bin_edges_lower_inclusive_upper_exclusive():
    true_m = np.array([20.0, 80.0])
    est_m = np.array([21.0, 0.0])  # 5 % at 20 m; 80 m is in no bin
    by_bin = range_abs_rel_err_by_bin(est_m, true_m)
    assert by_bin == {"0-20": None, "20-40": pytest.approx(0.05), "40-60": None, "60-80": None}
    assert range_abs_rel_err(est_m, true_m) == pytest.approx((0.05 + 1.0) / 2)


def test_non_finite_pairs_are_dropped():
    est_m = np.array([np.nan, 11.0, 30.0, np.inf])
    true_m = np.array([10.0, 10.0, np.nan, 50.0])
    assert range_abs_rel_err(est_m, true_m) == pytest.approx(0.1)
    assert range_abs_rel_err_by_bin(est_m, true_m)["40-60"] is None


def test_no_sample_is_none_never_zero():
    assert range_abs_rel_err([], []) is None
    assert range_abs_rel_err([np.nan], [10.0]) is None
    assert range_abs_rel_err_by_bin([], []) == {"0-20": None, "20-40": None, "40-60": None, "60-80": None}
    assert ttc_abs_err_s([], []) is None


def test_true_range_at_contact_is_not_scored():
    assert range_abs_rel_err([0.5, 10.5], [0.0, 10.0]) == pytest.approx(0.05)


def test_mismatched_lengths_raise():
    with pytest.raises(ValueError, match="differ in length"):
        range_abs_rel_err([1.0, 2.0], [1.0])
    with pytest.raises(ValueError, match="1-D"):
        range_abs_rel_err_by_bin(np.ones((2, 2)), np.ones((2, 2)))
    with pytest.raises(ValueError, match="differ in length"):
        ttc_abs_err_s([1.0], [1.0, 2.0])


def test_ttc_error_only_where_the_true_ttc_is_in_range():
    est_s = [2.5, 5.0, 30.0, 1.0, 3.0, np.nan, 7.0]
    true_s = [2.0, 4.0, 20.0, -1.0, math.inf, 3.0, 10.0]
    # kept: |2.5-2| = 0.5, |5-4| = 1, |7-10| = 3 -> median 1
    assert ttc_abs_err_s(est_s, true_s) == pytest.approx(1.0)
    # with a 5 s horizon only the first two remain -> median 0.75
    assert ttc_abs_err_s(est_s, true_s, max_ttc_s=5.0) == pytest.approx(0.75)
    assert ttc_abs_err_s([1.0], [0.0]) is None


def test_ttc_horizon_must_be_positive():
    with pytest.raises(ValueError, match="max_ttc_s"):
        ttc_abs_err_s([1.0], [1.0], max_ttc_s=0.0)
