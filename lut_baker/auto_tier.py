"""The Auto tier: model no more than the scene needs.

From a description of the scene (camera, resolution, the object's size in mm, its distance or
pixel footprint, the lights, the engine, the samples) this module predicts, for every
:class:`Candidate` way of shading made-up skin, its error against the exact model and its
render cost, and picks the cheapest one whose error is within a tolerance of the best.

Error of a candidate (relative RMS over the object's pixels, one render against the converged
exact image)::

    E = sqrt(e_angle^2 + e_subsurface^2 + e_gloss^2 + noise^2)

- ``e_angle``: the tier's angular error against the tables
  (:func:`lut_baker.closures.tiers.tier_errors`, relative RMS of ``f cos(theta_i)``);
- ``e_subsurface``: without the subsurface closure, the light the skin spreads under the
  surface stays where it entered; how much that changes the image is the pixel-footprint blur
  argument, computed by :func:`subsurface_omission_error` (the profile's blur of a sphere's
  shading, averaged over each pixel).  A spread under half a pixel changes no pixel by much.
  With the closure, what is left is the closure's profile mismatch times that;
- ``e_gloss``: without gloss lobes (the group's Gloss input at 0), the change of a sphere's
  image under the scene's lights, from the tier's own replica with and without them
  (:func:`gloss_omission_error`; without a closure fit, the tables' gloss share of
  :func:`gloss_and_skin_shares`);
- ``noise``: the Monte Carlo noise of one render, ``k / sqrt(samples)`` with ``k`` measured
  per candidate and coverage (:data:`NOISE_K`); 0 with a denoiser (its bias is not
  modelled) and in EEVEE.

So a gloss below the noise of the fullest tier costs little to leave out, a subsurface
radius under half a pixel leaves ``e_subsurface`` near 0, and each engine admits the tiers
made for it (:data:`ENGINE_TIERS`: Cycles the Principled and Layered tiers, EEVEE the EEVEE
tier).  :func:`choose` takes the cheapest candidate (costs: :data:`RELATIVE_COST`, measured at
coverage 1 and 0 and interpolated by the material's share of skin light; in EEVEE
:data:`EEVEE_RELATIVE_COST`) whose ``E`` is at most ``min E + tolerance`` (default 2%).

Functions and types
-------------------
- :class:`Candidate`, :data:`CANDIDATES` (Cycles), :data:`EEVEE_CANDIDATES`, :data:`FULLEST`,
  :data:`ENGINE_TIERS`.
- :class:`SceneDescription` -- what the model needs to know of a scene.
- :func:`pixel_footprint_mm` -- millimetres of the object per pixel (ortho or perspective).
- :class:`MaterialTraits`, :func:`paper_traits`, :func:`traits_from_tables` -- what it needs
  to know of the material.
- :func:`profile_mean_radius_mm` -- the mean distance light travels under the skin.
- :func:`gloss_and_skin_shares` -- shares of the gloss and of the spreading skin light in a
  sphere's image.
- :func:`gloss_omission_error`, :func:`gloss_omissions` -- what the tiers' Gloss input at 0
  changes in a sphere's image (their replicas in :mod:`lut_baker.closures.tiers`).
- :func:`profile_mismatch` -- how far a fitted closure's edge response is from the tables'.
- :func:`blur_kernel`, :func:`subsurface_omission_error` -- the pixel-footprint blur argument.
- :func:`relative_cost`, :func:`noise`, :func:`predict`, :class:`Prediction`,
  :func:`needs_subsurface`, :func:`choose`, :class:`Choice`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np

from .bake import RESOLUTIONS, profile_radius
from .closures.profiles import edge_response, profile_grid
from .closures.tiers import TIER_REPLICAS, TIERS, tier_errors
from .model.dipole import dipole_profile, dipole_total_reflectance
from .model.made_up_skin import combine, coverage_weights
from .model.presets import made_up_skin
from .numerics.cache import LRUCache
from .numerics.geometry import polar_angle_deg, sphere_directions, sphere_normals
from .numerics.quadrature import trapezoid_weights
from .tables.table_set import radius_nodes

__all__ = [
    "Candidate",
    "CANDIDATES",
    "EEVEE_CANDIDATES",
    "FULLEST",
    "ENGINES",
    "ENGINE_TIERS",
    "RELATIVE_COST",
    "EEVEE_RELATIVE_COST",
    "NOISE_K",
    "COST_SKIN_SHARE",
    "relative_cost",
    "DEFAULT_TOLERANCE",
    "SceneDescription",
    "pixel_footprint_mm",
    "MaterialTraits",
    "paper_traits",
    "PAPER_TIER_ERRORS",
    "PAPER_SKIN_SHARE",
    "PAPER_GLOSS_SHARE",
    "PAPER_MISMATCH",
    "traits_from_tables",
    "profile_mean_radius_mm",
    "gloss_and_skin_shares",
    "gloss_omission_error",
    "gloss_omissions",
    "PAPER_GLOSS_OMISSION",
    "profile_mismatch",
    "blur_kernel",
    "subsurface_omission_error",
    "noise",
    "Prediction",
    "predict",
    "Choice",
    "needs_subsurface",
    "choose",
    "TRAITS_COMMAND",
    "SHARE_LIGHTS_DEG",
    "COST_COMMAND",
]


# --------------------------------------------------------------------------------------------
# Candidates, their costs and noise
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Candidate:
    """One way to shade made-up skin: an add-on ``tier`` (``PRINCIPLED``, ``LAYERED`` or
    ``EEVEE``) with or without its subsurface closure and its gloss lobes.  The add-on
    realises ``subsurface=False`` with Subsurface Scale 0 (Cycles then turns subsurface
    closures into diffuse ones) and ``gloss=False`` with the group's Gloss input at 0 (Cycles
    then allocates no Glossy closure, coat or specular, and EEVEE picks none: their weights
    are 0)."""

    tier: str
    subsurface: bool = True
    gloss: bool = True

    @property
    def name(self) -> str:
        parts = ["EEVEE" if self.tier == "EEVEE" else self.tier.title()]
        if not self.subsurface:
            parts.append("no subsurface")
        if not self.gloss:
            parts.append("no gloss")
        return ", ".join(parts)


CANDIDATES = tuple(Candidate(tier, subsurface, gloss) for tier in ("LAYERED", "PRINCIPLED")
                   for gloss in (True, False) for subsurface in (True, False))
"""Every candidate of the Cycles tiers, the fullest first."""
EEVEE_CANDIDATES = tuple(Candidate("EEVEE", subsurface, gloss) for gloss in (True, False)
                         for subsurface in (True, False))
"""Every candidate of the EEVEE tier, the fullest first."""
FULLEST = CANDIDATES[0]
"""The LAYERED tier with subsurface and gloss: the most accurate, the costliest (Cycles)."""
ENGINES = ("CYCLES", "EEVEE")
ENGINE_TIERS = {"CYCLES": ("LAYERED", "PRINCIPLED"), "EEVEE": ("EEVEE",)}
"""Tiers per engine: each engine gets the tiers made for it.  The Layered tier's fits choose
Ashikhmin-Shirley and Beckmann lobes that EEVEE renders as GGX, and EEVEE renders GGX itself
through a linearly transformed cosine (:mod:`lut_baker.closures.eevee`); the EEVEE tier is
fitted to that, and Cycles renders its GGX lobes exactly, which they were not fitted to."""
DEFAULT_TOLERANCE = 0.02
"""Error a cheaper candidate may add to the best one's (relative RMS)."""

COST_COMMAND = ("python bench/stability_sweep.py --costs --repeats 3 --size 96 "
                "--samples 16 272")
_ORDER = CANDIDATES  # the tables below list CANDIDATES in this order
RELATIVE_COST = {
    1.0: dict(zip(_ORDER, (1.000, 0.889, 0.868, 0.695, 0.793, 0.595, 0.761, 0.522),
                  strict=True)),
    0.0: dict(zip(_ORDER, (1.000, 0.652, 0.728, 0.522, 0.914, 0.554, 0.772, 0.505),
                  strict=True)),
}
"""Render time per sample relative to :data:`FULLEST`, by coverage (1: the paper's film, 0:
bare skin), then by candidate, as :data:`COST_COMMAND` measures it (Cycles CPU, adaptive
sampling off).  How it was measured and how far the runs spread (up to 0.15, so differences
under ~10% are not resolved): docs/stability.md, "The Auto tier"."""
NOISE_K = {
    1.0: dict(zip(_ORDER, (0.2474, 0.0006, 0.2595, 0.0007, 0.2413, 0.0006, 0.2594, 0.0007),
                  strict=True)),
    0.0: dict(zip(_ORDER, (0.1698, 0.0007, 0.0363, 0.0007, 0.1777, 0.0007, 0.0363, 0.0007),
                  strict=True)),
}
"""Noise coefficient ``k`` by coverage and candidate: one render's relative RMS deviation from
the converged image is ``k / sqrt(samples)`` (:data:`COST_COMMAND`, two seeds at 272 samples).
A sun is assumed: area lights and environments add noise to every candidate alike, so the
choice then leans towards the fullest tier (docs/stability.md)."""
COST_SKIN_SHARE = {1.0: 0.1327, 0.0: 0.9591}
"""The paper preset's skin share (:func:`gloss_and_skin_shares`, light 45 degrees) at the
coverages the costs were measured at: a material's costs are interpolated by its share."""
EEVEE_COST_COMMAND = "python bench/eevee_tier.py --costs"
EEVEE_RELATIVE_COST = {
    1.0: dict(zip(EEVEE_CANDIDATES, (1.000, 0.684, 0.783, 0.757), strict=True)),
    0.0: dict(zip(EEVEE_CANDIDATES, (1.000, 1.001, 0.990, 0.797), strict=True)),
}
"""Render time per frame of the EEVEE tier's candidates relative to its fullest, by coverage,
in EEVEE (5.0.1 on software OpenGL, 64 px, 64 samples, light 45 degrees), as
:data:`EEVEE_COST_COMMAND` measures it: medians of three interleaved runs whose frames took
20-40 s, so differences under ~30% are not resolved (docs/stability.md, "The Auto tier")."""


def _by_share(table: dict, candidate: Candidate, skin_share: float) -> float:
    """Interpolate a per-coverage table of :data:`RELATIVE_COST`, :data:`EEVEE_RELATIVE_COST`
    or :data:`NOISE_K` to a skin share (held beyond the measured ones)."""
    shares = [COST_SKIN_SHARE[c] for c in (1.0, 0.0)]
    values = [table[c][candidate] for c in (1.0, 0.0)]
    return float(np.interp(skin_share, shares, values))


def relative_cost(candidate: Candidate, skin_share: float = COST_SKIN_SHARE[1.0]) -> float:
    """:data:`RELATIVE_COST` of ``candidate`` (:data:`EEVEE_RELATIVE_COST` for the EEVEE
    tier's) for a material whose skin share is ``skin_share`` (default: the paper's film)."""
    table = EEVEE_RELATIVE_COST if candidate.tier == "EEVEE" else RELATIVE_COST
    return _by_share(table, candidate, skin_share)


def noise(candidate: Candidate, samples: int, *, engine: str = "CYCLES",
          denoise: bool = False, skin_share: float = COST_SKIN_SHARE[1.0]) -> float:
    """One render's Monte Carlo noise (relative RMS): ``k / sqrt(samples)`` (Cycles without a
    denoiser; ``k`` of :data:`NOISE_K` at the material's ``skin_share``), else 0."""
    if engine != "CYCLES" or denoise:
        return 0.0
    return _by_share(NOISE_K, candidate, skin_share) / math.sqrt(max(int(samples), 1))


# --------------------------------------------------------------------------------------------
# The scene
# --------------------------------------------------------------------------------------------
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
    lights_deg: tuple = (45.0,)
    engine: str = "CYCLES"
    samples: int = 128
    denoise: bool = False

    def __post_init__(self):
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


# --------------------------------------------------------------------------------------------
# The material
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class MaterialTraits:
    """What the Auto tier needs of a made-up material at its coverage and absorption.

    ``tier_errors``: angular relative RMS per tier (:func:`lut_baker.closures.tiers.tier_errors`);
    ``radius_mm``, ``profile``: the normalised radial profile ``R(d)/Rd`` (1/mm^2, ``(n, 3)``)
    on distances (mm), the tables' ``radius_mm`` and ``profile``; ``profile_mismatch``: the
    fitted closure's relative edge-response error (:func:`profile_mismatch`);
    ``skin_share``, ``gloss_share``: per light angle (degrees), the share of the image that
    spreads under the skin and that the gloss lobes make (:func:`gloss_and_skin_shares`);
    ``subsurface_scale``, ``gloss_scale``: the artist's Subsurface Scale and Gloss (the
    group's inputs); ``gloss_omission``: per tier, per light angle, what Gloss 0 changes in
    a sphere's image (:func:`gloss_omissions`; None: ``gloss_share`` stands in for it).
    """

    tier_errors: dict
    radius_mm: np.ndarray
    profile: np.ndarray
    profile_mismatch: float
    skin_share: dict
    gloss_share: dict
    subsurface_scale: float = 1.0
    gloss_omission: dict | None = None
    gloss_scale: float = 1.0

    def share(self, name: str, light_deg: float) -> float:
        """``skin_share`` or ``gloss_share`` at a light angle (linear between the stored
        angles, held beyond them)."""
        return _at_angle(getattr(self, name), light_deg)

    def gloss_error(self, tier: str, light_deg: float) -> float:
        """What leaving out the gloss lobes changes in a sphere's image lit ``light_deg`` from
        the view: ``gloss_omission`` of ``tier`` if known, else ``gloss_share``."""
        if self.gloss_omission and tier in self.gloss_omission:
            return _at_angle(self.gloss_omission[tier], light_deg)
        return self.share("gloss_share", light_deg)

    def scaled(self, subsurface_scale: float, gloss_scale: float | None = None
               ) -> MaterialTraits:
        """The same material with the artist's Subsurface Scale (distances multiplied) and
        Gloss (default: unchanged)."""
        return replace(self, subsurface_scale=float(subsurface_scale),
                       gloss_scale=self.gloss_scale if gloss_scale is None
                       else float(gloss_scale))

    @property
    def mean_radius_mm(self) -> float:
        """:func:`profile_mean_radius_mm` with the Subsurface Scale applied."""
        return self.subsurface_scale * profile_mean_radius_mm(self.radius_mm, self.profile)

    def as_dict(self) -> dict:
        """Plain data (floats, lists, string keys), for a file; :meth:`from_dict` reads it."""
        def by_angle(table):
            return {repr(float(angle)): float(value) for angle, value in table.items()}

        return {
            "tier_errors": {tier: float(e) for tier, e in self.tier_errors.items()},
            "radius_mm": np.asarray(self.radius_mm, float).tolist(),
            "profile": np.asarray(self.profile, float).tolist(),
            "profile_mismatch": float(self.profile_mismatch),
            "skin_share": by_angle(self.skin_share),
            "gloss_share": by_angle(self.gloss_share),
            "subsurface_scale": float(self.subsurface_scale),
            "gloss_omission": None if self.gloss_omission is None else {
                tier: by_angle(table) for tier, table in self.gloss_omission.items()},
            "gloss_scale": float(self.gloss_scale),
        }

    @classmethod
    def from_dict(cls, data: dict) -> MaterialTraits:
        """The traits :meth:`as_dict` wrote (``KeyError``, ``TypeError`` or ``ValueError``
        when an entry is missing or malformed)."""
        def by_angle(table):
            return {float(angle): float(value) for angle, value in table.items()}

        omission = data["gloss_omission"]
        return cls(
            tier_errors={str(tier): float(e) for tier, e in data["tier_errors"].items()},
            radius_mm=np.asarray(data["radius_mm"], float),
            profile=np.asarray(data["profile"], float),
            profile_mismatch=float(data["profile_mismatch"]),
            skin_share=by_angle(data["skin_share"]),
            gloss_share=by_angle(data["gloss_share"]),
            subsurface_scale=float(data["subsurface_scale"]),
            gloss_omission=None if omission is None else {
                str(tier): by_angle(table) for tier, table in omission.items()},
            gloss_scale=float(data["gloss_scale"]),
        )


def _at_angle(table: dict, light_deg: float) -> float:
    """A per-light-angle table at ``light_deg`` (linear between its angles, held beyond)."""
    angles = sorted(table)
    return float(np.interp(light_deg, angles, [table[a] for a in angles]))


def profile_mean_radius_mm(radius_mm, profile) -> float:
    """Mean distance (mm) between where light enters and leaves: ``Int d P(d) 2 pi d dd`` of
    the normalised profile ``P = R/Rd`` (largest over channels)."""
    d = np.asarray(radius_mm, float)
    p = np.reshape(np.asarray(profile, float), (d.size, -1))
    w = trapezoid_weights(d)
    mass = w @ (p * (2.0 * np.pi * d)[:, None])
    mean = w @ (p * (2.0 * np.pi * d * d)[:, None])
    return float(np.max(mean / np.maximum(mass, 1e-300)))


def gloss_and_skin_shares(tables, light_deg: float, coverage=None, absorption=None, *,
                          resolution: int = 48) -> tuple[float, float]:
    """``(gloss share, skin share)`` of a sphere's image under one distant light
    ``light_deg`` from the view (orthographic, the reference's framing): relative RMS over
    the lit pixels of the gloss lobes' radiance (film, path-3 and skin gloss at the coverage
    and absorption) and of the skin's diffuse part (what spreads), against the total radiance
    ``f cos(theta_i)`` from the tables."""
    _, wi, wo = sphere_directions(resolution, light_deg)
    w, a = tables.coverage_and_absorption(coverage, absorption)
    weights = coverage_weights(w, a)
    cos_i = wi[:, 2:3]
    total = tables.made_up_reflection(wi, wo, w, a) * cos_i
    gloss = combine(weights, top=tables.angular("film_gloss", wi, wo),
                    twice=tables.angular("path3_gloss", wi, wo),
                    bare=tables.angular("skin_gloss", wi, wo)) * cos_i
    t_i = tables.directional("film_transmittance", polar_angle_deg(wi))
    t_o = tables.directional("film_transmittance", polar_angle_deg(wo))
    skin = combine(weights, twice=tables.skin_diffuse * t_i * t_o,
                   bare=tables.skin_diffuse) * cos_i
    norm = np.sqrt(np.mean(total**2))
    if not norm > 0:
        return 0.0, 0.0
    return float(np.sqrt(np.mean(gloss**2)) / norm), float(np.sqrt(np.mean(skin**2)) / norm)


def gloss_omission_error(tables, fit, tier: str, light_deg: float, coverage=None,
                         absorption=None, *, resolution: int = 48) -> float:
    """Relative RMS change of a sphere's image (orthographic, one distant light ``light_deg``
    from the view, the lit pixels) when ``tier``'s Gloss input goes from 1 to 0: the tier's
    replica (:data:`lut_baker.closures.tiers.TIER_REPLICAS` with the closure fit ``fit``) with
    and without its gloss lobes, over the RMS of the tables' radiance ``f cos(theta_i)``, at
    the coverage and absorption (default: the tables')."""
    _, wi, wo = sphere_directions(resolution, light_deg)
    w, a = tables.coverage_and_absorption(coverage, absorption)
    cos_i = wi[:, 2:3]
    norm = np.sqrt(np.mean((tables.made_up_reflection(wi, wo, w, a) * cos_i) ** 2))
    if not norm > 0:
        return 0.0
    replica = TIER_REPLICAS[tier]
    kept, left_out = (replica(fit, tables, w, a, gloss, (wi, wo)) for gloss in (1.0, 0.0))
    return float(np.sqrt(np.mean(((kept - left_out) * cos_i) ** 2)) / norm)


def gloss_omissions(tables, fit, coverage=None, absorption=None, *,
                    lights_deg=None) -> dict:
    """:func:`gloss_omission_error` of every tier at ``lights_deg`` (default
    :data:`SHARE_LIGHTS_DEG`): ``{tier: {light angle: error}}``."""
    lights = SHARE_LIGHTS_DEG if lights_deg is None else lights_deg
    return {tier: {float(light): gloss_omission_error(tables, fit, tier, light, coverage,
                                                      absorption)
                   for light in lights} for tier in TIERS}


def profile_mismatch(tables, fit_error) -> float:
    """Relative error of a fitted subsurface closure's blur: ``fit_error`` (per channel, the
    RMS difference of its edge response and the tables', a fraction of the lit level:
    :class:`lut_baker.closures.profiles.ProfileFit` ``error``) over the RMS of the tables' edge
    response's departure from a sharp edge, largest over channels."""
    r_max = float(tables.radius_mm[-1])
    r = profile_grid(r_max)
    s = np.linspace(0.0, r_max, 48)
    reference = edge_response(r, tables.radial(r), s)
    departure = np.sqrt(np.mean(reference**2, axis=0))  # the sharp edge is 0 inside
    return float(np.max(np.asarray(fit_error, float) / np.maximum(departure, 1e-12)))


SHARE_LIGHTS_DEG = (0.0, 45.0, 75.0, 89.0)
"""Light angles (degrees from the view) at which :func:`traits_from_tables` measures the
shares."""


def traits_from_tables(tables, fit, coverage=None, absorption=None, *,
                       lights_deg=SHARE_LIGHTS_DEG, method: str | None = None,
                       errors: dict | None = None) -> MaterialTraits:
    """:class:`MaterialTraits` of baked ``tables`` and their
    :class:`lut_baker.closures.closure_fit.ClosureFit` ``fit`` at a coverage and absorption
    (default:
    the tables'); ``errors``: the fit's :func:`lut_baker.closures.tiers.tier_errors` there,
    if already measured."""
    w, a = tables.coverage_and_absorption(coverage, absorption)
    errors = tier_errors(fit, tables, w, a) if errors is None else errors
    shares = {float(angle): gloss_and_skin_shares(tables, angle, w, a) for angle in lights_deg}
    return MaterialTraits(
        tier_errors={tier: float(e.rms) for tier, e in errors.items()},
        radius_mm=np.asarray(tables.radius_mm, float),
        profile=np.asarray(tables.profile, float),
        profile_mismatch=profile_mismatch(
            tables, fit.profiles[method or fit.subsurface_method].error),
        skin_share={angle: value[1] for angle, value in shares.items()},
        gloss_share={angle: value[0] for angle, value in shares.items()},
        gloss_omission=gloss_omissions(tables, fit, w, a, lights_deg=lights_deg),
    )


TRAITS_COMMAND = "python bench/stability_sweep.py --traits"
PAPER_TIER_ERRORS = {"PRINCIPLED": 0.0769, "LAYERED": 0.0476, "EEVEE": 0.0888}
PAPER_MISMATCH = 0.0475
PAPER_SKIN_SHARE = {0.0: 0.1361, 45.0: 0.1327, 75.0: 0.1233, 89.0: 0.1141}
PAPER_GLOSS_SHARE = {0.0: 0.1825, 45.0: 0.1904, 75.0: 0.2274, 89.0: 0.2758}
PAPER_GLOSS_OMISSION = {"PRINCIPLED": {0.0: 0.1602, 45.0: 0.1877, 75.0: 0.2533, 89.0: 0.3074},
                        "LAYERED": {0.0: 0.1743, 45.0: 0.1869, 75.0: 0.2435, 89.0: 0.3022},
                        "EEVEE": {0.0: 0.1676, 45.0: 0.1795, 75.0: 0.2245, 89.0: 0.2789}}
"""The paper preset's traits (foundation paper_natural on paper_bioplate, coverage 1,
absorption 0, default bake, closure fit with Burley) as :data:`TRAITS_COMMAND` prints them:
what the Auto tier assumes of a material it has no tables for yet."""


def _paper_traits() -> MaterialTraits:
    """The constants above with the paper dipole's profile on the bake's
    radial grid (exact and cheap to recompute)."""
    dipole = made_up_skin("paper_natural", "paper_bioplate").dipole
    res = RESOLUTIONS["default"]
    radius = radius_nodes(res.n_radius, res.radius_spacing, profile_radius(dipole))
    profile = np.reshape(dipole_profile(radius, dipole), (radius.size, -1))
    profile = profile / np.atleast_1d(dipole_total_reflectance(dipole)) * np.ones(3)
    return MaterialTraits(tier_errors=dict(PAPER_TIER_ERRORS), radius_mm=radius,
                          profile=profile, profile_mismatch=PAPER_MISMATCH,
                          skin_share=dict(PAPER_SKIN_SHARE), gloss_share=dict(PAPER_GLOSS_SHARE),
                          gloss_omission={tier: dict(by_light) for tier, by_light
                                          in PAPER_GLOSS_OMISSION.items()})


@lru_cache(maxsize=1)
def paper_traits() -> MaterialTraits:
    """The paper preset's :class:`MaterialTraits` (the constants above; built once)."""
    return _paper_traits()


# --------------------------------------------------------------------------------------------
# The pixel-footprint blur argument
# --------------------------------------------------------------------------------------------
SUPERSAMPLE = 4
"""Cells per pixel side in :func:`subsurface_omission_error`."""
MAX_CELLS = 384
"""Largest grid side (cells) of :func:`subsurface_omission_error`: bigger objects are modelled
with coarser cells (never coarser than a pixel of the real image when it fits)."""
KERNEL_SUBSAMPLES = 4
"""Sub-samples per cell side when integrating the profile over a kernel cell."""


def blur_kernel(cell_mm: float, radius_mm, profile) -> np.ndarray:
    """The normalised profile integrated over square cells of ``cell_mm``: ``(2h+1, 2h+1, C)``
    weights summing to 1 per channel, ``h`` cells reaching the profile's last distance.  The
    centre cell takes what the others leave (the profile's peak at 0 is integrable but not
    sampleable)."""
    d = np.asarray(radius_mm, float)
    p = np.reshape(np.asarray(profile, float), (d.size, -1))
    h = int(min(math.ceil(d[-1] / cell_mm), MAX_CELLS))
    offsets = (np.arange(KERNEL_SUBSAMPLES) + 0.5) / KERNEL_SUBSAMPLES - 0.5
    centres = np.arange(-h, h + 1, dtype=float)
    x = (centres[:, None] + offsets[None, :]).ravel() * cell_mm
    r = np.hypot(x[:, None], x[None, :])
    values = np.stack([np.interp(r, d, p[:, c], right=0.0) for c in range(p.shape[1])], -1)
    n = 2 * h + 1
    cells = values.reshape(n, KERNEL_SUBSAMPLES, n, KERNEL_SUBSAMPLES, -1).mean(axis=(1, 3))
    cells *= cell_mm**2
    cells[h, h] = 0.0
    cells = np.minimum(cells, 1.0)
    total = cells.sum(axis=(0, 1))
    scale = np.where(total > 1.0, 1.0 / np.maximum(total, 1e-300), 1.0)
    cells = cells * scale
    cells[h, h] = 1.0 - cells.sum(axis=(0, 1))
    return cells


def _convolve(image: np.ndarray, kernel: np.ndarray) -> np.ndarray:
    """``image`` (m, m) convolved with ``kernel`` (k, k), same size, zero outside (FFT)."""
    m, k = image.shape[0], kernel.shape[0]
    size = m + k - 1
    spectrum = np.fft.rfft2(image, (size, size)) * np.fft.rfft2(kernel, (size, size))
    full = np.fft.irfft2(spectrum, (size, size))
    h = k // 2
    return full[h:h + m, h:h + m]


def subsurface_omission_error(footprint_mm: float, object_size_mm: float, light_deg: float,
                              radius_mm, profile, skin_share: float = 1.0) -> float:
    """Relative RMS change of a sphere's image (diameter ``object_size_mm``, pixels of
    ``footprint_mm``, one distant light ``light_deg`` from the view) when the part of its
    radiance that spreads under the skin (``skin_share`` of it) stays where it entered
    instead of spreading with the normalised ``profile`` on ``radius_mm`` (mm).

    The shading is Lambertian (``max(0, N.L)``) on cells of a pixel / :data:`SUPERSAMPLE`
    (coarser for objects over :data:`MAX_CELLS` cells), blurred in the image plane with
    :func:`blur_kernel` renormalised to the object's disk (light stays on the surface), both
    images averaged over each pixel (the pixel footprint) before they are compared.  A
    spread under half a pixel mostly stays inside the pixel it entered."""
    radius_obj = 0.5 * float(object_size_mm)
    cell = max(footprint_mm / SUPERSAMPLE, object_size_mm / MAX_CELLS)
    per_pixel = max(int(round(footprint_mm / cell)), 1)
    pixels = max(int(math.ceil(object_size_mm / (cell * per_pixel))), 1)
    m = pixels * per_pixel
    normals, inside = sphere_normals(m, 0.5 * m * cell / radius_obj)
    disk = inside.astype(float)
    x, z = normals[..., 0], normals[..., 2]
    a = math.radians(light_deg)
    shading = np.clip(x * math.sin(a) + z * math.cos(a), 0.0, None) * disk
    if not np.any(shading > 0):
        return 0.0
    kernel = blur_kernel(cell, radius_mm, profile)

    def pixel_mean(image):
        return image.reshape(pixels, per_pixel, pixels, per_pixel).mean(axis=(1, 3))

    seen = pixel_mean(disk) > 0.0
    sharp = pixel_mean(shading)
    errors = []
    for c in range(kernel.shape[-1]):
        spread = _convolve(shading, kernel[..., c])
        reach = _convolve(disk, kernel[..., c])
        blurred = np.where(disk > 0, spread / np.maximum(reach, 1e-12), 0.0)
        errors.append(pixel_mean(blurred)[seen] - sharp[seen])
    difference = np.stack(errors)
    return float(skin_share * np.sqrt(np.mean(difference**2)) / np.sqrt(np.mean(sharp[seen]**2)))


# --------------------------------------------------------------------------------------------
# Prediction and choice
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Prediction:
    """A candidate's predicted error in a scene: ``error`` (total, relative RMS), its parts
    ``angle``, ``subsurface``, ``gloss``, ``noise`` (see the module docstring), and ``cost``
    (render time relative to :data:`FULLEST`)."""

    candidate: Candidate
    error: float
    angle: float
    subsurface: float
    gloss: float
    noise: float
    cost: float


OMISSION_CACHE_SIZE = 256
_OMISSIONS = LRUCache(OMISSION_CACHE_SIZE)


def _omission(scene: SceneDescription, traits: MaterialTraits) -> float:
    """The largest :func:`subsurface_omission_error` over the scene's lights, remembered by
    everything it depends on (the same material read again from a file is the same)."""
    scale = traits.subsurface_scale
    radius = np.asarray(traits.radius_mm, float)
    profile = np.asarray(traits.profile, float)

    def at(light_deg):
        share = traits.share("skin_share", light_deg)
        key = (scene.footprint_mm, scene.object_size_mm, light_deg, scale, share,
               radius.tobytes(), profile.tobytes())
        return _OMISSIONS.get_or_compute(key, lambda: subsurface_omission_error(
            scene.footprint_mm, scene.object_size_mm, light_deg, scale * radius,
            profile / scale**2, share))

    return max(at(float(light)) for light in scene.lights_deg)


def predict(candidate: Candidate, scene: SceneDescription, traits: MaterialTraits,
            omission: float | None = None) -> Prediction:
    """:class:`Prediction` of ``candidate`` in ``scene`` for a material of ``traits``
    (``omission``: :func:`subsurface_omission_error` if already known)."""
    angle = float(traits.tier_errors[candidate.tier])
    if traits.subsurface_scale <= 0.0:
        omission = 0.0
    elif omission is None:
        omission = _omission(scene, traits)
    subsurface = omission * (min(traits.profile_mismatch, 1.0) if candidate.subsurface else 1.0)
    # Gloss kept: only what the artist's Gloss under 1 already leaves out.
    kept = traits.gloss_scale if candidate.gloss else 0.0
    gloss = (1.0 - min(max(kept, 0.0), 1.0)) * max(
        traits.gloss_error(candidate.tier, light) for light in scene.lights_deg)
    share = _skin_share(scene, traits)
    grain = noise(candidate, scene.samples, engine=scene.engine, denoise=scene.denoise,
                  skin_share=share)
    error = math.sqrt(angle**2 + subsurface**2 + gloss**2 + grain**2)
    return Prediction(candidate=candidate, error=error, angle=angle, subsurface=subsurface,
                      gloss=gloss, noise=grain, cost=relative_cost(candidate, share))


def _skin_share(scene: SceneDescription, traits: MaterialTraits) -> float:
    """The material's skin share, averaged over the scene's lights."""
    return float(np.mean([traits.share("skin_share", light) for light in scene.lights_deg]))


@dataclass(frozen=True)
class Choice:
    """The Auto tier's decision: ``chosen`` (a :class:`Prediction`), ``predictions`` of every
    candidate considered (cheapest first), ``tolerance``, ``best_error`` and ``reasons``
    (lines for a report)."""

    chosen: Prediction
    predictions: tuple
    tolerance: float
    best_error: float
    reasons: tuple = field(default_factory=tuple)

    @property
    def candidate(self) -> Candidate:
        return self.chosen.candidate

    def prediction(self, candidate: Candidate) -> Prediction | None:
        """The prediction of ``candidate``, if it was considered."""
        return next((p for p in self.predictions if p.candidate == candidate), None)


def needs_subsurface(scene: SceneDescription, traits: MaterialTraits) -> bool:
    """Whether the scene resolves the skin's subsurface spread: its mean radius
    (:attr:`MaterialTraits.mean_radius_mm`, the Subsurface Scale applied) is at least half a
    pixel.  Below that a shadow edge, where subsurface scattering shows most, moves by less
    than half a pixel.  (The sphere images of :func:`subsurface_omission_error` have no
    shadow edge, so their small error alone would drop the closure at any distance.)"""
    return traits.subsurface_scale > 0.0 and traits.mean_radius_mm >= 0.5 * scene.footprint_mm


def choose(scene: SceneDescription, traits: MaterialTraits | None = None, *,
           tolerance: float = DEFAULT_TOLERANCE, candidates=None) -> Choice:
    """The cheapest candidate whose predicted error is within ``tolerance`` of the best one's,
    among ``candidates`` (default: :data:`CANDIDATES` and :data:`EEVEE_CANDIDATES`) made for
    the scene's engine (:data:`ENGINE_TIERS`), keep
    the subsurface closure if :func:`needs_subsurface` (and drop it when the Subsurface
    Scale is 0: Cycles then shades no spread anyway; likewise the gloss lobes when the
    artist's Gloss is 0).  ``traits`` default to the paper preset's (:func:`paper_traits`)."""
    if not tolerance >= 0:
        raise ValueError(f"tolerance must be >= 0, got {tolerance}")
    traits = paper_traits() if traits is None else traits
    needed = needs_subsurface(scene, traits)
    pool = [c for c in (candidates or CANDIDATES + EEVEE_CANDIDATES)
            if c.tier in ENGINE_TIERS[scene.engine]
            and not (needed and not c.subsurface)
            and not (traits.subsurface_scale <= 0.0 and c.subsurface)
            and not (traits.gloss_scale <= 0.0 and c.gloss)]
    if not pool:
        raise ValueError(f"no candidate runs in {scene.engine} with what the scene needs")
    omission = 0.0 if traits.subsurface_scale <= 0.0 else _omission(scene, traits)
    predictions = sorted((predict(c, scene, traits, omission) for c in pool),
                         key=lambda p: (p.cost, p.error))
    best = min(p.error for p in predictions)
    chosen = next(p for p in predictions if p.error <= best + tolerance)
    radius = traits.mean_radius_mm
    grain = noise(FULLEST, scene.samples, engine=scene.engine, denoise=scene.denoise,
                  skin_share=_skin_share(scene, traits))
    tier = chosen.candidate.tier
    gloss = max(traits.gloss_error(tier, light) for light in scene.lights_deg)
    reasons = (
        f"object {scene.object_pixels:.0f} px across at {scene.footprint_mm:.3g} mm per px",
        f"subsurface mean radius {radius:.3g} mm = {radius / scene.footprint_mm:.2g} px: "
        + ("needed (half a pixel or more)" if needed else
           f"not needed (under half a pixel; leaving it out errs {100 * omission:.2f}%)"),
        f"gloss lobes {100 * gloss:.1f}% of the image ({Candidate(tier).name}), noise of the "
        f"fullest tier at {scene.samples} samples {100 * grain:.1f}%: "
        + ("kept" if chosen.candidate.gloss else "left out (Gloss 0)"),
        f"{chosen.candidate.name}: predicted error {100 * chosen.error:.1f}% (best "
        f"{100 * best:.1f}% + tolerance {100 * tolerance:.0f}%), cost {chosen.cost:.2f} of "
        f"the fullest tier's",
    )
    return Choice(chosen=chosen, predictions=tuple(predictions), tolerance=tolerance,
                  best_error=best, reasons=reasons)
