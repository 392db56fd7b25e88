"""percept: a camera-only driving stack on highway-env."""

import os

# One BLAS thread per process (set before numpy loads OpenBLAS): percept's matrix products are small, a second
# thread only contends with the other worker processes of a batch and makes single-thread benchmarks dishonest.
for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
