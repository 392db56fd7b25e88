"""Room on the recording's disk: what a run's recording needs, checked before it starts and watched during it, so
that Rerun's file writer never meets a full disk (after a failed write its calls can block beyond Ctrl-C's reach)."""

from __future__ import annotations

import errno
import shutil
from pathlib import Path

from .context import RecordOptions

BASE_BYTES_PER_S = 43e3
"""What a recording holds each simulated second besides the camera images (scalars, boxes, drawings) [bytes/s]."""
IMAGE_BYTES = 26e3
"""One stored JPEG image at the camera's full size and quality 70 or less [bytes]; it scales with the area."""
MARGIN_BYTES = 16 << 20
"""Free space asked for beyond the recording itself: two of the batcher's largest chunks [bytes]."""
RESERVE_BYTES = 4 << 20
"""Free space below which a run stops recording: Rerun's file writer must never meet a full disk, since after a
failed write its calls can block the process beyond the reach of Ctrl-C [bytes]."""


def free_bytes(folder: Path) -> int:
    """Free space for an unprivileged writer on the file system that holds ``folder`` [bytes]."""
    return shutil.disk_usage(folder).free


def expected_bytes(duration_s: float, options: RecordOptions) -> float:
    """Size of a ``duration_s`` [s] recording with ``options`` [bytes]: near 7 MB a simulated minute at the
    defaults; JPEG size grows with the image's area, and up to threefold from quality 70 to 100."""
    quality = 1.0 + 2.0 * max(options.jpeg_quality - 70, 0) / 30
    # bytes = T * (base + f_img * A_rel * I * quality)
    return duration_s * (BASE_BYTES_PER_S + options.camera_hz * options.image_scale ** 2 * IMAGE_BYTES * quality)


def size_text(n: float) -> str:
    """A byte count for a message: 56 KB, 2.6 MB, 1.2 GB."""
    for unit, scale in (("GB", 1e9), ("MB", 1e6)):
        if n >= scale:
            return f"{n / scale:.1f} {unit}"
    return f"{n / 1e3:.0f} KB"


def no_space(path: Path, why: str) -> OSError:
    """The OSError (ENOSPC) of a recording its disk cannot hold; ``why`` (one line) is its text."""
    return OSError(errno.ENOSPC, f"cannot record to {path}: {why}", str(path))


def check_space(path: Path, duration_s: float | None, options: RecordOptions) -> None:
    """Refuse (``no_space``) before anything is written when the disk of ``path`` cannot hold a ``duration_s`` [s]
    run's recording twice (the stream, then its compacted copy written beside it by ``finish``) plus a margin."""
    need = 2 * expected_bytes(duration_s or 0.0, options) + MARGIN_BYTES
    free = free_bytes(path.parent)
    if free < need:
        run = f"a {duration_s:g} s run " if duration_s else "a run "
        raise no_space(path, f"{size_text(free)} free on its disk, {run}needs about {size_text(need)}; free some "
                             f"space, store fewer or smaller images (--camera-hz, --camera-scale) or use --no-record")
