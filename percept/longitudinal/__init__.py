"""Longitudinal: range, range rate and time to contact of what is ahead; following and emergency braking inputs."""

from .metrics import RANGE_BINS_M, bin_key, range_abs_rel_err, range_abs_rel_err_by_bin, ttc_abs_err_s

__all__ = ["RANGE_BINS_M", "bin_key", "range_abs_rel_err", "range_abs_rel_err_by_bin", "ttc_abs_err_s"]
