"""Per-frame rows held per entity and sent as columns.

Each frame a run logs about 34 scalars (every task's truth, estimate and command series), the ego's transform, one
point of each trail, what the parts draw around the car and a few clears. One ``rr.log`` call costs 40-230 us (the
archetype's conversion to Arrow, then the SDK's batcher), 3 ms a frame in all (5 with building the archetypes); one
``rr.send_columns`` call per entity over many frames costs a small fraction of that. The recording holds the same
data: each row at its frame's time (nanoseconds, rounded as ``RecordingStream.set_time`` rounds them) and at the
wall-clock time it was added (``log_time``, which ``rr.log`` adds), with the same components; ``rerun rrd compare
--unordered`` finds a recording made this way and one logged frame by frame identical once both are compacted
(``rerun rrd optimize``). The recorder holds 10 simulated seconds (3-5 s of wall time at the loop's speed; the SDK's
batcher holds its chunks for 5 s) and sends what it holds before it closes, also when a run fails or is interrupted.
"""

from __future__ import annotations

import math
import time
from collections import defaultdict

import numpy as np
import rerun as rr


class ColumnBuffer:
    """Rows per (entity path, archetype), sent by ``flush`` as one ``send_columns`` call each on ``timeline`` (a
    duration timeline) and ``log_time``."""

    def __init__(self, timeline: str):
        self.timeline = timeline
        self._ns = 0
        # (path, archetype) -> (times [ns], log times [ns since the epoch], component -> one batch per row)
        self._rows: dict[tuple[str, type], tuple[list[int], list[int], dict[str, list]]] = defaultdict(
            lambda: ([], [], defaultdict(list)))

    def set_time(self, seconds: float) -> None:
        """The time of the rows added next [s]."""
        # as RecordingStream.set_time(duration=seconds) converts it
        self._ns = round(1e9 * float(seconds))

    def add(self, path: str, archetype: type, **components) -> None:
        """One row of ``archetype`` at ``path`` at the current time: each component the batch ``archetype(...)``
        would log, as a list or array of elements (e.g. ``positions=[[x, y, z]], colors=[rgb], radii=[r]``; a
        single element applies to all, as in ``rr.log``)."""
        times, log_times, batches = self._rows[(path, archetype)]
        times.append(self._ns)
        log_times.append(time.time_ns())
        for name, batch in components.items():
            batches[name].append(batch)

    def clear(self, path: str) -> None:
        """``rr.Clear(recursive=False)`` at ``path``: what it showed is gone from the current time on."""
        self.add(path, rr.Clear, is_recursive=[False])

    def scalar(self, path: str, value: float | None) -> None:
        """``value`` at ``path``; None (or not finite) clears the series there (which breaks its line)."""
        if value is None or not math.isfinite(value):
            self.clear(path)
        else:
            self.add(path, rr.Scalars, scalars=[float(value)])

    def __len__(self) -> int:
        """Rows held."""
        return sum(len(times) for times, _, _ in self._rows.values())

    def held_s(self) -> float:
        """How long before the current time the oldest row held was added [s] (0 when none is held)."""
        return (self._ns - min(times[0] for times, _, _ in self._rows.values())) / 1e9 if self._rows else 0.0

    def flush(self, rec: rr.RecordingStream) -> None:
        """Send every row held to ``rec`` and forget them."""
        for (path, archetype), (times, log_times, batches) in self._rows.items():
            indexes = [rr.TimeColumn(self.timeline, duration=np.asarray(times, np.int64).astype("timedelta64[ns]")),
                       rr.TimeColumn("log_time", timestamp=np.asarray(log_times, np.int64).astype("datetime64[ns]"))]
            columns = []
            for name, rows in batches.items():
                # every row's elements in one column, cut back into the rows' batches
                flat = np.concatenate(rows) if all(isinstance(b, np.ndarray) for b in rows) else [
                    item for batch in rows for item in batch]
                columns += archetype.columns(**{name: flat}).partition([len(b) for b in rows])
            rec.send_columns(path, indexes=indexes, columns=columns)
        self._rows.clear()
