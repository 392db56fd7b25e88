"""The stereo renderer: ground, road paint, vehicles, pedestrians, signs and roadside scenery."""

from .ground import GroundLayer, Palette
from .raster import PatchBatch, PatchBuilder, RenderTarget, rasterize
from .renderer import StereoImages, StereoRenderer
from .scene import ObjectKind, ObjectState, Scene

__all__ = ["GroundLayer", "ObjectKind", "ObjectState", "Palette", "PatchBatch", "PatchBuilder", "RenderTarget",
           "Scene", "StereoImages", "StereoRenderer", "rasterize"]
