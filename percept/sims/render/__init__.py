"""The stereo renderer: ground, road paint, vehicles, pedestrians, signs and roadside scenery."""

from .ground import GroundLayer, Palette
from .raster import PatchBatch, PatchBuilder, RenderTarget, rasterize
from .rear import RearRenderer, forward_twin, turned
from .renderer import StereoImages, StereoRenderer
from .scene import ObjectKind, ObjectState, Scene

__all__ = ["GroundLayer", "ObjectKind", "ObjectState", "Palette", "PatchBatch", "PatchBuilder", "RearRenderer",
           "RenderTarget", "Scene", "StereoImages", "StereoRenderer", "forward_twin", "rasterize", "turned"]
