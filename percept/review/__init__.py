"""Review: Rerun recordings and blueprints (the only place that imports rerun)."""

import os

# The recorder streams a drive without an RRD footer and adds the footer when the run finishes (``recorder.py``: the
# footer's manifest would grow in memory through a long drive), and Rerun warns of the missing footer once per file.
# Its logging reads RUST_LOG when rerun is first imported, here: that one warning is silenced unless the user set
# RUST_LOG, and so are the file writer's and the stream's reports of a failed write, which the recorder reports
# itself as one line (``RunRecorder``: the free space is watched).
QUIET_RUST_LOG = "warn,re_log_encoding::rrd::file_sink=off,re_sdk::recording_stream=off"
"""The log filter set for the recorder when the user set none (the viewer's own processes go without it: its web
server says at INFO level where to open it)."""
os.environ.setdefault("RUST_LOG", QUIET_RUST_LOG)

from .blueprint import blueprint
from .context import Part, PartContext, Plot, RecordOptions
from .recorder import RunRecorder, partial_path
from .series import ColumnBuffer

__all__ = ["QUIET_RUST_LOG", "ColumnBuffer", "Part", "PartContext", "Plot", "RecordOptions", "RunRecorder", "blueprint",
           "partial_path"]
