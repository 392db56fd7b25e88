"""What a run accepts, in one place (the CLI reads these without importing the simulator)."""

MAX_SEED = 2**31 - 1
"""Largest seed of a run (``--seed``, ``--seeds``): numpy's legacy seeding, which highway-env uses, takes 32 bits."""
MAX_DURATION_S = 24 * 3600.0
"""Longest run a configuration accepts [s]: a day of simulated driving."""
