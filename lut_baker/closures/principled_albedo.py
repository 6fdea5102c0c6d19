"""The colour a dielectric Principled BSDF renders under uniform white light, per channel: its
bihemispherical albedo (the mean colour of a large convex object with it under a uniform white
sky), split into the gloss of its specular layer and the body (diffuse or subsurface) under it.
Cycles and EEVEE, Blender 4.5 - 5.0.

The shader: Base Color, Roughness, IOR, Subsurface Weight, subsurface method and distribution
as given; Metallic, Transmission, Coat, Sheen and Emission 0, Specular IOR Level 0.5, Specular
Tint white, Diffuse Roughness 0, Subsurface IOR 1.4 and Anisotropy 0 (the defaults), Subsurface
Radius x Scale small against the object (measured with 3 mm on a 1 m sphere).

A convex object under a uniform sky sees only the sky, so the radiance it sends to a view at
cosine ``mu`` is the shader's directional albedo there, and the mean over the object's
projected area weighs the views by ``2 mu dmu``:

    total = gloss + W [(1 - w) base + w base rho(base)]

- ``gloss = Int 2 mu k(mu) E_F(mu) dmu``: the specular lobe's albedo, GGX with the real
  dielectric Fresnel (:func:`lut_baker.closures.cycles.microfacet_albedo`) times Multiscatter
  GGX's compensation ``k`` (:func:`lut_baker.closures.cycles.coat_view_terms`; 1 for GGX);
- ``W = Int 2 mu (1 - a(mu)) dmu``: what Cycles' layering (``closure_layering_weight``) leaves
  the layers below, ``a`` the specular layer's estimated albedo at the view
  (:func:`lut_baker.closures.cycles.layering_albedo`, with Multiscatter GGX's darkening);
  Multiscatter GGX conserves energy, ``gloss + W = 1``;
- ``w`` Subsurface Weight; ``rho`` the subsurface method's albedo relative to a Diffuse
  closure's of the same Base Color under the same layer: measured by rendering
  (``tools/measure_principled_albedo.py``, table :data:`TABLE_FILE`).  Random walks turn Base
  Color into a single-scattering albedo by a fitted inversion so that the multiply scattered
  colour is about Base Color: between Base Color 0.06 and 0.9 Random Walk (Skin) lands within
  -0.3% and +1.2% of it and Christensen-Burley within 0.2%; Random Walk, which enters through a
  GGX interface of the Principled's Roughness and IOR, falls 3-18% short at Roughness up to 0.5
  (most at dark colours and high IOR), within 2% at Roughness 1.  Above Base Color 0.92 the
  random walks' single-scattering albedo sits at Cycles' ceiling (0.999999): their body stops
  growing, at 0.91-0.92 of ``W``.

Cycles' gloss and ``W`` come from the replicas times measured residuals (renders and replicas
agree within 0.25%: Cycles reads the layering albedo from a coarse table).  EEVEE's gloss is
Cycles' Multiscatter GGX gloss times a measured ratio (its split-sum specular reflects 1-26%
less, ~12% at Roughness 0.5), its ``W`` the rest, ``1 - gloss``, with either distribution
(measured), and its subsurface is as bright as diffuse (``rho = 1``, measured).  Cycles
clamps the subsurface colour to [0, 1] and the diffuse one to ``>= 0`` only; so does
:func:`principled_albedo`.  docs/principled_albedo.md has the measurements.

Functions
---------
- :class:`PrincipledAlbedo` -- ``total``, ``gloss``, ``body`` (RGB on the last axis).
- :func:`specular_layer` -- Cycles' ``(gloss, W)`` of the specular layer from the replicas.
- :func:`albedo_table` -- the measured table (read once).
- :func:`rendered_layer` -- ``(gloss, W)`` as an engine renders them (replicas and measurements).
- :func:`subsurface_ratio` -- ``rho`` at Base Colors, Roughness, IOR, per method and engine.
- :func:`principled_albedo` -- the albedo and its split.
- :func:`base_color_for_body` -- the inverse: the Base Color whose body is a given colour.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..numerics.quadrature import gauss_legendre
from . import cycles as cc

__all__ = ["TABLE_FILE", "ENGINES", "DISTRIBUTIONS", "PrincipledAlbedo", "specular_layer",
           "albedo_table", "rendered_layer", "subsurface_ratio", "principled_albedo",
           "base_color_for_body"]

TABLE_FILE = Path(__file__).with_name("principled_albedo.json")
"""The measured table (``tools/measure_principled_albedo.py --write`` rewrites it)."""
ENGINES = ("CYCLES", "EEVEE")
"""Render engines covered."""
DISTRIBUTIONS = ("MULTI_GGX", "GGX")
"""The Principled BSDF's distributions covered (Multiscatter GGX is Blender's default)."""
VIEW_NODES = 48
"""Gauss-Legendre nodes in the view cosine for ``gloss`` and ``W`` (converged to 1e-6)."""
INVERSE_NODES = 1025
"""Base Color nodes on [0, 1] over which :func:`base_color_for_body` inverts the body."""


@dataclass(frozen=True)
class PrincipledAlbedo:
    """A Principled BSDF's bihemispherical albedo per channel (last axis RGB): ``total`` =
    ``gloss`` (its specular layer, the same in every channel) + ``body`` (what the layers under
    it send out: diffuse and subsurface)."""

    total: np.ndarray
    gloss: np.ndarray
    body: np.ndarray


def _check(roughness: float, ior: float, distribution: str) -> tuple[float, float]:
    if distribution not in DISTRIBUTIONS:
        raise ValueError(f"distribution must be one of {DISTRIBUTIONS}, got {distribution!r}")
    if not ior >= 1.0:
        raise ValueError(f"ior must be at least 1 (a dielectric seen from outside), got {ior}")
    return float(np.clip(roughness, 0.0, 1.0)), float(ior)


@lru_cache(maxsize=256)
def _specular_layer(roughness: float, ior: float, distribution: str) -> tuple[float, float]:
    if ior == 1.0:  # Cycles allocates no specular closure at eta 1
        return 0.0, 1.0
    mu, weight = gauss_legendre(VIEW_NODES)
    lobe = cc.microfacet_albedo(mu, roughness, lambda c: cc.dielectric_fresnel(c, ior))
    if distribution == "MULTI_GGX":
        # Specular IOR Level 0.5 and a white tint make the generalised Schlick Fresnel the
        # real one, so its compensation and darkening are the coat's at the same IOR.
        scale, layered = cc.coat_view_terms(mu, roughness, ior, weighted=lobe)
        lobe = scale * lobe
    else:
        layered = cc.layering_albedo(mu, roughness, ior, weighted=lobe)
    gloss = float(np.sum(weight * 2.0 * mu * lobe))
    passed = float(np.sum(weight * 2.0 * mu * np.clip(1.0 - layered, 0.0, 1.0)))
    return gloss, passed


def specular_layer(roughness: float, ior: float,
                   distribution: str = "MULTI_GGX") -> tuple[float, float]:
    """``(gloss, W)`` of a Principled BSDF's specular layer in Cycles under a uniform white
    sky (module docstring): the layer's own bihemispherical albedo and the share of the layers
    below that reaches the viewer, from the replicas of :mod:`lut_baker.closures.cycles`.
    ``roughness`` Blender's socket (clamped to [0, 1]), ``ior`` >= 1."""
    roughness, ior = _check(roughness, ior, distribution)
    return _specular_layer(roughness, ior, distribution)


@lru_cache(maxsize=1)
def albedo_table() -> dict:
    """The measured table of :data:`TABLE_FILE` as plain data (lists), read once."""
    return json.loads(TABLE_FILE.read_text())


def _bracket(nodes: ArrayLike, x: float) -> tuple[int, int, float]:
    """Neighbouring node indices and the weight of the second, ``x`` held at the ends (a
    single node: that node)."""
    grid = np.asarray(nodes, float)
    if grid.size == 1:
        return 0, 0, 0.0
    x = float(np.clip(x, grid[0], grid[-1]))
    i = int(np.clip(np.searchsorted(grid, x, side="right") - 1, 0, grid.size - 2))
    return i, i + 1, (x - grid[i]) / (grid[i + 1] - grid[i])


def _on_plane(values: ArrayLike, roughness_nodes: ArrayLike, ior_nodes: ArrayLike,
              roughness: float, ior: float) -> NDArray[np.float64]:
    """``values`` (roughness, IOR, ...) bilinear at ``(roughness, ior)``, held beyond the
    nodes."""
    table = np.asarray(values, float)
    i0, i1, s = _bracket(roughness_nodes, roughness)
    j0, j1, t = _bracket(ior_nodes, ior)
    return ((1.0 - s) * ((1.0 - t) * table[i0, j0] + t * table[i0, j1])
            + s * ((1.0 - t) * table[i1, j0] + t * table[i1, j1]))


def subsurface_ratio(base_color: ArrayLike, roughness: float, ior: float,
                     method: str = "RANDOM_WALK", engine: str = "CYCLES") -> NDArray[np.float64]:
    """``rho``: the subsurface closure's albedo over a Diffuse closure's of the same Base
    Color under the same specular layer (module docstring), at ``base_color`` (any shape,
    clamped to [0, 1] as Cycles clamps it), as measured: linear in Base Color and bilinear in
    Roughness and IOR between the table's nodes, held beyond them (IOR 1.3-1.6).  EEVEE: 1."""
    if method not in cc.SUBSURFACE_METHODS:
        raise ValueError(f"method must be one of {cc.SUBSURFACE_METHODS}, got {method!r}")
    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {ENGINES}, got {engine!r}")
    base = np.clip(np.asarray(base_color, float), 0.0, 1.0)
    if engine == "EEVEE":
        return np.ones_like(base)
    entry = albedo_table()["cycles"]["subsurface_ratio"][method]
    ratio = _on_plane(entry["ratio"], entry["roughness"], entry["ior"],
                      float(np.clip(roughness, 0.0, 1.0)), float(ior))
    return np.interp(base, entry["base"], ratio)


def rendered_layer(roughness: float, ior: float, distribution: str = "MULTI_GGX",
                   engine: str = "CYCLES") -> tuple[float, float]:
    """``(gloss, W)`` as ``engine`` renders them: Cycles' from the replicas times the measured
    residuals (within 0.25% of 1); EEVEE's gloss
    Cycles' Multiscatter GGX gloss times the measured ratio (either distribution), its ``W``
    the rest (EEVEE's layering conserves energy with both, measured)."""
    if engine == "CYCLES":
        gloss, passed = specular_layer(roughness, ior, distribution)
        r, eta = _check(roughness, ior, distribution)
        entry = albedo_table()["cycles"]["layer"]

        def residual(key: str) -> float:
            return float(_on_plane(entry[key][distribution], entry["roughness"], entry["ior"],
                                   r, eta))

        return gloss * residual("gloss_residual"), passed * residual("passed_residual")
    if engine != "EEVEE":
        raise ValueError(f"engine must be one of {ENGINES}, got {engine!r}")
    r, eta = _check(roughness, ior, distribution)
    entry = albedo_table()["eevee"]
    gloss = specular_layer(r, eta, "MULTI_GGX")[0] * float(_on_plane(
        entry["gloss_ratio"][distribution], entry["roughness"], entry["ior"], r, eta))
    return gloss, 1.0 - gloss


def _body_per_layer(base: ArrayLike, subsurface_weight: float, roughness: float, ior: float,
                    method: str, engine: str) -> NDArray[np.float64]:
    """``(1 - w) base + w base rho``: the body over ``W`` (Cycles' clamps of Base Color)."""
    colour = np.maximum(np.asarray(base, float), 0.0)
    w = float(np.clip(subsurface_weight, 0.0, 1.0))
    if w == 0.0:
        return colour
    clamped = np.minimum(colour, 1.0)
    return ((1.0 - w) * colour
            + w * clamped * subsurface_ratio(clamped, roughness, ior, method, engine))


def principled_albedo(base_color: ArrayLike, roughness: float, ior: float,
                      subsurface_weight: float = 0.0,
                      method: str = "RANDOM_WALK", engine: str = "CYCLES",
                      distribution: str = "MULTI_GGX") -> PrincipledAlbedo:
    """The bihemispherical albedo of a dielectric Principled BSDF (module docstring) per
    channel: ``base_color`` ``(..., 3)`` (any leading shape; linear RGB), Blender's
    ``roughness``, ``ior`` (>= 1; the measured part covers 1.3-1.6), ``subsurface_weight`` (0-1),
    ``method`` its subsurface method, ``engine`` ``CYCLES`` or ``EEVEE``, ``distribution``
    ``MULTI_GGX`` (Blender's default) or ``GGX``."""
    base = np.asarray(base_color, float)
    if base.ndim == 0 or base.shape[-1] != 3:
        raise ValueError(f"base_color must have RGB on its last axis, got shape {base.shape}")
    gloss, passed = rendered_layer(roughness, ior, distribution, engine)
    body = passed * _body_per_layer(base, subsurface_weight, roughness, ior, method, engine)
    gloss_rgb = np.full(base.shape, gloss)
    return PrincipledAlbedo(total=gloss_rgb + body, gloss=gloss_rgb, body=body)


def base_color_for_body(body: ArrayLike, roughness: float, ior: float,
                        subsurface_weight: float = 0.0, method: str = "RANDOM_WALK",
                        engine: str = "CYCLES",
                        distribution: str = "MULTI_GGX") -> NDArray[np.float64]:
    """The Base Color (same shape as ``body``) whose :func:`principled_albedo` body is
    ``body``: exact for diffuse (``body / W``), otherwise by inverting the body's curve on
    :data:`INVERSE_NODES` Base Colors in [0, 1], made increasing (where a random walk's body
    levels off, above Base Color 0.92, a colour of that level gives a Base Color on the level;
    beyond 1 only the diffuse share grows, so with a Subsurface Weight of 1 a body above the
    curve's top gives 1).  Negative colours give 0.

    >>> skin = np.array([0.6, 0.35, 0.25])  # a Base Color, half of it subsurface
    >>> body = principled_albedo(skin, 0.5, 1.4, 0.5, "RANDOM_WALK_SKIN").body
    >>> print(np.round(base_color_for_body(body, 0.5, 1.4, 0.5, "RANDOM_WALK_SKIN"), 4))
    [0.6  0.35 0.25]
    """
    target = np.maximum(np.asarray(body, float), 0.0)
    _, passed = rendered_layer(roughness, ior, distribution, engine)
    w = float(np.clip(subsurface_weight, 0.0, 1.0))
    if w == 0.0:
        return target / passed
    nodes = np.linspace(0.0, 1.0, INVERSE_NODES)
    # Increasing, as np.interp needs: levels lifted by a ramp far below any colour's precision
    curve = (np.maximum.accumulate(_body_per_layer(nodes, w, roughness, ior, method, engine))
             + 1e-12 * nodes) * passed
    base = np.interp(target, curve, nodes)
    if w < 1.0:  # past Base Color 1 the diffuse share alone grows, at slope (1 - w) W
        beyond = target > curve[-1]
        base = np.where(beyond, 1.0 + (target - curve[-1]) / ((1.0 - w) * passed), base)
    return base
