"""What a run's numbers depend on besides percept's code: the numeric libraries, their versions and the CPU code paths
they chose.

The same code, scenario and seed give the same run JSON on one machine, bit for bit, but not always on another:
OpenBLAS picks its kernels by CPU (its ``architecture``, e.g. Haswell or SkylakeX), and the order of a product's sums
goes with the kernel; OpenCV and numba likewise dispatch by CPU features, and another release of a library may
compute a value differently. So each evaluation run records its environment, and a report lists the environments
its runs came from.
"""

from __future__ import annotations

import json
import platform
from functools import lru_cache
from pathlib import Path

__all__ = ["environments", "numeric_environment"]


def _cpu_model() -> str:
    """The CPU's model name (Linux's /proc/cpuinfo), else what the platform module says."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _opencv_version(module_version: str) -> str:
    """The installed OpenCV wheel's own version (its build number too: 5.0.0.93), else the module's."""
    from importlib.metadata import PackageNotFoundError, version

    wheels = ("opencv-contrib-python-headless", "opencv-python-headless", "opencv-contrib-python", "opencv-python")
    for wheel in wheels:
        try:
            return version(wheel)
        except PackageNotFoundError:
            continue
    return module_version


@lru_cache(maxsize=1)
def numeric_environment() -> dict:
    """This process's numeric environment: Python, numpy, OpenCV and numba versions, every BLAS library loaded
    (numpy's, scipy's, OpenCV's) with the kernels it chose (``threadpoolctl``), OpenCV's CPU features
    (``cv2.getCPUFeaturesLine``: a ``*`` marks code it dispatches to), the CPU model and architecture. A JSON object
    of strings."""
    import cv2
    import numba
    import numpy as np
    from threadpoolctl import threadpool_info

    blas = [i for i in threadpool_info() if i.get("user_api") == "blas"]
    # every BLAS loaded (numpy's, scipy's, OpenCV's own), by library, in a fixed order (processes load them in theirs)
    blas_text = ", ".join(sorted(f"{i.get('prefix')} {i.get('version')} ({i.get('architecture') or 'kernels unknown'})"
                                 for i in blas)) or "none found"
    return {"python": platform.python_version(), "numpy": np.__version__, "opencv": _opencv_version(cv2.__version__),
            "numba": numba.__version__, "blas": blas_text, "opencv_cpu": cv2.getCPUFeaturesLine(),
            "cpu": _cpu_model(), "machine": platform.machine()}


def environments(results: list[dict]) -> list[dict]:
    """The distinct ``environment`` records of the finished runs, each with how many runs it drove (``runs``), most
    runs first; runs without one count under {"environment": "not recorded"}."""
    counts: dict[str, list] = {}
    for r in results:
        if "error" in r:
            continue
        env = r.get("environment") if isinstance(r.get("environment"), dict) else {"environment": "not recorded"}
        key = json.dumps(env, sort_keys=True)
        counts.setdefault(key, [env, 0])[1] += 1
    return [{**env, "runs": n} for env, n in sorted(counts.values(), key=lambda en: -en[1])]
