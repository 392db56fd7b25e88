"""Tuning shared by the longitudinal laws, each constant defined once."""

STANDSTILL_GAP_M = 4.0
"""Gap kept to a stopped vehicle ahead [m] (d0 of the constant time-gap policy)."""
STANDING_MPS = 1.0
"""Speed below which a target, or the car itself, is taken to stand still [m/s]."""
STOP_GAIN = 1.3
"""Braking towards something standing, and in an emergency, over the constant deceleration stopping needs: 30 %
harder than needed, so that an estimate's error does not end the stop short of the margin."""
