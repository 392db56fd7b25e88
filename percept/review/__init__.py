"""Review: Rerun recordings and blueprints (the only place that imports rerun)."""

from .recorder import RunRecorder, blueprint

__all__ = ["RunRecorder", "blueprint"]
