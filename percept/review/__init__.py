"""Review: Rerun recordings and blueprints (the only place that imports rerun)."""

from .blueprint import blueprint
from .context import Part, PartContext, Plot, RecordOptions
from .recorder import RunRecorder, partial_path
from .series import ColumnBuffer

__all__ = ["ColumnBuffer", "Part", "PartContext", "Plot", "RecordOptions", "RunRecorder", "blueprint", "partial_path"]
