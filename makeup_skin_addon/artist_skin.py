"""What the made-up skin takes from the artist's shader: the skin under the film, and the
colour the artist's render has under uniform light (docs/addon.md, "Over the artist's skin").

The artist's shader (:mod:`.artist_shader`) stays the bare skin.  Under the film the model
needs a skin: :func:`read_skin` reads it from that shader's leaves, weighted by their shares
(the Mix Shaders' factors, a linked factor by its mean over the surface):

- the body colour: what each skin BSDF's body (its diffuse and subsurface layers) reflects
  under uniform light, which for a Principled BSDF is not its Base Color (its specular layer
  takes its albedo from the layers below, random walk inverts its albedo:
  :func:`lut_baker.closures.principled_albedo.principled_albedo`).  Per leaf the ratio of that
  colour to the mean Base Color (``factor``) scales the Base Color's own source, so a texture
  keeps its detail under the film (:mod:`.convert` builds those nodes);
- the roughness, index, subsurface method, weight and radius of the dominant skin BSDF (the
  skin leaf with the largest share, a Principled BSDF first among equals);
- the colour to match (``target``): the whole shader's colour under uniform white light, its
  gloss included, the mean over the surface (:mod:`.surface_values` evaluates what feeds each
  input at points of the surface), each leaf's gloss apart with its roughness, and what a
  uniform sky leaves to the surface as the camera sees it (:mod:`.sky_visibility`: the match
  weighs the gloss by it).

What cannot be followed (an emission, a metallic or coated Principled BSDF, a node it cannot
evaluate) is a warning that says what the made-up skin uses instead.

- :class:`SkinReading` -- all of it.
- :func:`read_skin` -- read it from a shader tree at a surface's samples.
- :func:`read_material` -- read it from a material (its surface sampled, the scene's engine).
- :func:`render_engine` -- ``CYCLES`` or ``EEVEE``: the scene's engine as the model names it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import bpy
import numpy as np

from . import artist_shader, convert, pages, skin_sampling, sky_visibility, surface_values
from .artist_shader import Leaf, Source, source
from .core import principled_albedo

__all__ = ["SkinReading", "LeafReading", "read_skin", "read_material", "render_engine",
           "PRINCIPLED_LEFT_OUT"]

PRINCIPLED_LEFT_OUT = (
    # (input identifier, its neutral value, what it is called in a sentence)
    ("Metallic", 0.0, "metallic"),
    ("Transmission Weight", 0.0, "transmission"),
    ("Coat Weight", 0.0, "coat"),
    ("Sheen Weight", 0.0, "sheen"),
    ("Emission Strength", 0.0, "emission"),
)
"""Principled BSDF layers the skin under the film leaves out (the bare skin keeps them)."""
SPECULAR_LEVEL = 0.5
"""The Principled BSDF's Specular IOR Level at which its gloss is its IOR's
(:func:`principled_albedo`'s assumption)."""


@dataclass
class LeafReading:
    """One leaf of the artist's shader as read: its ``share``, mean ``base`` colour, the
    ``body`` and ``total`` colours it renders under uniform light (RGB), and ``factor`` =
    body / base (per channel: what scales its Base Color's source under the film)."""

    leaf: Leaf
    share: float
    base: np.ndarray
    body: np.ndarray
    total: np.ndarray
    factor: np.ndarray


@dataclass
class SkinReading:
    """The skin under the film and the colour to match, read from the artist's shader.

    ``leaves``: :class:`LeafReading` per leaf; ``dominant``: the main skin leaf (None when
    the shader has none); ``target``: the shader's colour under uniform light (RGB, gloss
    included); ``body``: the body colour of the skin under the film (RGB, the leaves' bodies
    by share); ``roughness``, ``ior``, ``method``, ``subsurface_weight``: the dominant leaf's
    (for the bake and the group); ``where``: the surface it was read over (the end of a
    sentence); ``warnings``: sentences saying what could not be followed and what is used
    instead; ``notes``: what evaluating the inputs assumed; ``glosses``: each leaf's gloss
    under uniform light (RGB, by its share) and its roughness; ``sky``: what a uniform sky
    leaves to the surface (:class:`.sky_visibility.SkyVisibility`, or None)."""

    leaves: list
    dominant: Leaf | None
    target: np.ndarray
    body: np.ndarray
    where: str = ""
    roughness: float | None = None
    ior: float | None = None
    method: str | None = None
    subsurface_weight: float = 1.0
    warnings: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    glosses: list = field(default_factory=list)
    sky: sky_visibility.SkyVisibility | None = None

    def factor_of(self, leaf: Leaf) -> np.ndarray | None:
        """The body factor of ``leaf`` (RGB; the same node reached through the same groups,
        read again or not), or None if it has no body."""
        key = _leaf_key(leaf)
        for reading in self.leaves:
            if _leaf_key(reading.leaf) == key:
                return reading.factor
        return None


def _leaf_key(leaf: Leaf) -> tuple:
    return leaf.node.as_pointer(), tuple(group.as_pointer() for group in leaf.groups)


def _input(node, identifier: str):
    return next((s for s in node.inputs if s.identifier == identifier), None)


def _mean(node, identifier: str, groups, samples, notes, kind="VALUE"):
    socket = _input(node, identifier)
    if socket is None:
        return None
    return surface_values.mean(source(socket, groups), samples, notes, kind)


def _principled(leaf: Leaf, samples, notes, warnings, engine: str) -> tuple:
    """``(base, body, total, roughness, ior, weight)`` of a Principled BSDF leaf."""
    node, groups = leaf.node, leaf.groups
    bases = np.clip(surface_values.values(source(node.inputs["Base Color"], groups), samples,
                                          notes), 0.0, 1.0)
    base = _weighted_mean(bases, samples)
    roughness = float(np.clip(_mean(node, "Roughness", groups, samples, notes), 0.0, 1.0))
    ior = float(max(_mean(node, "IOR", groups, samples, notes), 1.0))
    weight = float(np.clip(_mean(node, "Subsurface Weight", groups, samples, notes), 0.0,
                           1.0))
    left_out = []
    for identifier, neutral, name in PRINCIPLED_LEFT_OUT:
        value = _mean(node, identifier, groups, samples, notes)
        if value is not None and abs(value - neutral) > 1e-6:
            left_out.append(f"{name} {value:.3g}")
    level = _mean(node, "Specular IOR Level", groups, samples, notes)
    if level is not None and abs(level - SPECULAR_LEVEL) > 1e-6:
        left_out.append(f"Specular IOR Level {level:.3g} (read as {SPECULAR_LEVEL:g})")
    if left_out:
        warnings.append(f"{node.name!r}: its {', '.join(left_out)} is not followed under the "
                        f"film (the bare skin keeps it; the skin under the film is its "
                        f"dielectric layers)")
    # Each point's Base Color: the body is not linear in it (random walk's inversion), and a
    # texture's dark freckles weigh more than its mean says.
    albedo = principled_albedo.principled_albedo(bases, roughness, ior, weight,
                                                 node.subsurface_method, engine=engine)
    return base, _weighted_mean(np.asarray(albedo.body, float), samples), \
        _weighted_mean(np.asarray(albedo.total, float), samples), roughness, ior, weight


def _weighted_mean(values: np.ndarray, samples) -> np.ndarray:
    """The mean of per-point ``values`` ``(n, 3)`` (or one row) by the points' weights."""
    weights = getattr(samples, "weights", None)
    if weights is not None and len(values) == len(weights) and len(values) > 1:
        return (weights @ values) / weights.sum()
    return values.mean(axis=0)


def _leaf_reading(leaf: Leaf, share: float, samples, notes, warnings, engine) -> tuple:
    """``(LeafReading or None, (roughness, ior, weight) or None)``."""
    node = leaf.node
    if node.type == "BSDF_PRINCIPLED":
        base, body, total, roughness, ior, weight = _principled(leaf, samples, notes,
                                                                warnings, engine)
        values = (roughness, ior, weight)
    elif node.type in ("BSDF_DIFFUSE", "SUBSURFACE_SCATTERING"):
        base = np.clip(_mean(node, "Color", leaf.groups, samples, notes, "RGBA"), 0.0, 1.0)
        body = total = base
        values = None
    elif node.type == "BSDF_GLOSSY":
        colour = np.clip(_mean(node, "Color", leaf.groups, samples, notes, "RGBA"), 0.0, 1.0)
        base, body, total = colour, np.zeros(3), colour
        values = None
    else:
        if node.type == "EMISSION" and _mean(node, "Strength", leaf.groups, samples,
                                             notes) == 0.0:
            return None, None  # adds nothing
        warnings.append(f"{node.name!r} ({node.bl_label}, weight {share:.2g} in the shader) is "
                        f"rendered as it is where the film does not cover, but not followed "
                        f"under it")
        return None, None
    factor = np.where(base > 1e-4, body / np.maximum(base, 1e-4), 0.0)
    return LeafReading(leaf, share, base, body, total, factor), values


def read_skin(tree, samples, engine: str = "CYCLES") -> SkinReading:
    """The skin under the film and the colour to match, read from the artist's shader tree
    ``tree`` (:func:`.artist_shader.read`) at the surface's ``samples``
    (:class:`.surface_values.Samples`); ``engine``: ``"CYCLES"`` or ``"EEVEE"`` (a
    Principled BSDF's albedo as that engine renders it)."""
    notes: list = []
    warnings: list = []

    def factor_mean(where: Source) -> float:
        return surface_values.mean(where, samples, notes, "VALUE")

    readings, values_of, glosses = [], {}, []
    for leaf, share in artist_shader.leaves(tree, factor_mean):
        reading, values = _leaf_reading(leaf, share, samples, notes, warnings, engine)
        if reading is not None:
            readings.append(reading)
            if values is not None:
                values_of[id(leaf)] = values
            roughness = values[0] if values is not None else _mean(
                leaf.node, "Roughness", leaf.groups, samples, notes)
            if roughness is not None and np.any(reading.total > reading.body):
                glosses.append((share * (reading.total - reading.body), float(roughness)))
    target = sum((r.share * r.total for r in readings), np.zeros(3))
    body = sum((r.share * r.body for r in readings), np.zeros(3))
    skins = [r for r in readings if r.leaf.role == "skin"]
    dominant = max(skins, key=lambda r: (r.share, r.leaf.node.type == "BSDF_PRINCIPLED"),
                   default=None)
    notes += [n for n in getattr(samples, "notes", []) if n not in notes]
    problem = getattr(samples, "problem", "")
    if problem:
        notes.insert(0, f"{problem}: the shader's inputs are read at UV (0, 0)")
    faces = getattr(samples, "faces", 0)
    seen_by = getattr(samples, "seen_by", "")
    where = (f"over the {faces} faces that use it" if faces else "") + (
        f", as the camera {seen_by!r} sees them" if faces and seen_by else "")
    reading = SkinReading(readings, dominant.leaf if dominant else None, target, body, where,
                          warnings=warnings, notes=notes, glosses=glosses)
    if dominant is None:
        warnings.append("no skin BSDF (Principled, Diffuse or Subsurface Scattering) behind "
                        "the surface: the skin under the film is the skin preset's")
        return reading
    node = dominant.leaf.node
    if id(dominant.leaf) in values_of:
        reading.roughness, reading.ior, reading.subsurface_weight = values_of[id(dominant.leaf)]
        reading.method = node.subsurface_method
    elif node.type == "SUBSURFACE_SCATTERING":
        reading.subsurface_weight, reading.method = 1.0, node.falloff
    else:
        reading.subsurface_weight = 0.0
    return reading


def render_engine(scene) -> str:
    """``"CYCLES"`` when ``scene`` renders with Cycles (or there is no scene), else ``"EEVEE"``
    (``BLENDER_EEVEE`` in 5.0, ``BLENDER_EEVEE_NEXT`` in 4.2-4.5; Workbench counts as EEVEE: it
    does not render the material, and its Material Preview is EEVEE). The name the Auto tier
    and the tier registry give the engine, and the engine whose BSDFs the artist's shader is
    read as."""
    engine = scene.render.engine if scene is not None else "CYCLES"
    return "CYCLES" if engine == "CYCLES" else "EEVEE"


@pages.ordinary()
def read_material(material, scene=None, progress=None) -> SkinReading | None:
    """:func:`read_skin` of ``material``'s artist shader (:func:`.convert.artist_tree`) over
    its surface (:func:`.skin_sampling.surface_samples`, cached per mesh and image) as the
    engine of ``scene`` (default: the context's) renders it; None when the material has no
    shader of the artist's."""
    tree = convert.artist_tree(material)
    if tree is None:
        return None
    scene = scene if scene is not None else bpy.context.scene
    samples = skin_sampling.surface_samples(material, progress=progress, scene=scene)
    reading = read_skin(tree, samples, render_engine(scene))
    reading.sky = sky_visibility.sky_visibility(samples)
    return reading
