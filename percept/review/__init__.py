"""Review: Rerun recordings and blueprints (the only place that imports rerun)."""

import os

# The recorder writes its files without an RRD footer (``recorder.py``: the footer's manifest would grow in memory
# through a long drive), and Rerun warns of that once per file. Its logging reads RUST_LOG when rerun is first
# imported, here: that one warning is silenced unless the user set RUST_LOG.
os.environ.setdefault("RUST_LOG", "warn,re_log_encoding::rrd::file_sink=error")

from .blueprint import blueprint
from .context import Part, PartContext, Plot, RecordOptions
from .recorder import RunRecorder, partial_path
from .series import ColumnBuffer

__all__ = ["ColumnBuffer", "Part", "PartContext", "Plot", "RecordOptions", "RunRecorder", "blueprint", "partial_path"]
