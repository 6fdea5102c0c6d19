"""What the Auto tier needs to know of a scene.

- :func:`pixel_footprint_mm` -- millimetres of the object per pixel (ortho or perspective).
- :class:`SceneDescription` -- the object's size, the footprint, lights, engine, samples.
"""

from __future__ import annotations

from dataclasses import dataclass

from .candidates import ENGINES

__all__ = ["pixel_footprint_mm", "SceneDescription"]


def pixel_footprint_mm(camera: str, resolution_px: int, *, ortho_scale_mm: float | None = None,
                       distance_mm: float | None = None, sensor_mm: float = 36.0,
                       focal_mm: float = 50.0) -> float:
    """Millimetres of the object one pixel covers.  ``camera`` ``"ORTHO"``: ``ortho_scale_mm``
    (the view's width) over ``resolution_px`` (the larger image side); ``"PERSP"``: at
    ``distance_mm`` from the camera, ``distance sensor / (focal resolution)`` (pinhole)."""
    if resolution_px < 1:
        raise ValueError(f"resolution_px must be >= 1, got {resolution_px}")
    if camera == "ORTHO":
        if not (ortho_scale_mm and ortho_scale_mm > 0):
            raise ValueError("an orthographic camera needs ortho_scale_mm > 0")
        return float(ortho_scale_mm) / resolution_px
    if camera == "PERSP":
        if not (distance_mm and distance_mm > 0) or not (focal_mm > 0 and sensor_mm > 0):
            raise ValueError("a perspective camera needs distance_mm, focal_mm, sensor_mm > 0")
        return float(distance_mm) * sensor_mm / (focal_mm * resolution_px)
    raise ValueError(f"camera must be 'ORTHO' or 'PERSP', got {camera!r}")


@dataclass(frozen=True)
class SceneDescription:
    """What the Auto tier needs of a scene.

    ``object_size_mm``: the object's largest dimension (mm); ``footprint_mm``: mm per pixel at
    the object (:func:`pixel_footprint_mm`); ``lights_deg``: each light's angle from the view
    direction at the object (degrees; an environment counts as 45); ``engine``: ``CYCLES`` or
    ``EEVEE``; ``samples`` per pixel; ``denoise``: a denoiser is on.
    """

    object_size_mm: float
    footprint_mm: float
    lights_deg: tuple[float, ...] = (45.0,)
    engine: str = "CYCLES"
    samples: int = 128
    denoise: bool = False

    def __post_init__(self) -> None:
        if not (self.object_size_mm > 0 and self.footprint_mm > 0):
            raise ValueError("object_size_mm and footprint_mm must be > 0 (mm)")
        if self.engine not in ENGINES:
            raise ValueError(f"engine must be one of {ENGINES}, got {self.engine!r}")
        if not self.lights_deg:
            raise ValueError("lights_deg needs at least one light angle (degrees)")

    @property
    def object_pixels(self) -> float:
        """The object's size in pixels."""
        return self.object_size_mm / self.footprint_mm
