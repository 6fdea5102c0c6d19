"""Stability where the methods fail: a sweep over the regimes that break them.

The regimes (:data:`REGIMES`): grazing light (80-89 degrees from the view) and the silhouette
(view 80-89 degrees from the normal); a 1 mm sphere (the subsurface spread is larger than the
sphere) and a 2 m one (the spread is under a pixel); the film's gloss lobe at both ends of the
panel's range (5 and 60 degrees) and beyond (2 and 90); indices of refraction near 1; coverage 0
and 1; full absorption.  In each, :func:`check_regime` runs the methods that compute made-up
skin without Blender and measures what must always hold and how far each is from its reference:

- ``model``: the exact evaluator (:func:`lut_baker.evaluate.made_up.made_up_reflection`) at
  directions of the regime: finite, non-negative; its directional albedo (white furnace) at most 1;
- ``bake``: the tables (:func:`bake.bake`): finite, non-negative, albedo at most 1, and their
  error against the exact evaluator (:func:`.table_accuracy.table_error`);
- ``reference``: the sphere image (:func:`reference.sphere_image`, local and, where the entry
  samples stay affordable, spread): finite, non-negative, and the spread image's total at most
  the local one's (spreading moves light, it does not make it);
- ``tiers`` (``fit=True``): the closure fits' angular and albedo errors against the tables
  (:func:`lut_baker.closures.tiers.tier_errors`) at the regime's coverage and absorption;
- ``auto``: the Auto tier's choice for the regime's scene (:func:`lut_baker.auto_tier.choose`).

Functions and types
-------------------
- :class:`Regime`, :data:`REGIMES`, :func:`regime` -- the sweep's regimes.
- :func:`with_film` -- a made-up skin with the film's lobe width and index overridden (what the
  add-on's Override Film does).
- :func:`regime_skin` -- the :class:`MadeUpSkin` of a regime.
- :func:`regime_directions` -- the ``(wi, wo)`` pairs a regime evaluates the model at.
- :func:`summary` -- finite / minimum / maximum of an array, as plain floats.
- :func:`spread_energy_ratio` -- light the spread reference returns over light that entered.
- :func:`auto_choice` -- the Auto tier's choice for a regime's sphere.
- :func:`check_regime`, :func:`sweep` -- the measurements (dicts of plain floats).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...auto_tier import SceneDescription, choose
from ...bake import bake
from ...closures.fitting import fit_closures
from ...closures.tiers import tier_errors
from ...evaluate.made_up import directional_albedo, made_up_reflection
from ...model.made_up_skin import MadeUpSkin
from ...model.presets import made_up_skin
from ...numerics.geometry import direction, light_direction
from .reference import (
    default_samples,
    local_diffuse,
    sphere_image,
    sphere_points,
    spread_diffuse,
)
from .table_accuracy import table_error

__all__ = [
    "Regime",
    "REGIMES",
    "regime",
    "with_film",
    "regime_skin",
    "regime_directions",
    "summary",
    "check_regime",
    "auto_choice",
    "sweep",
    "spread_energy_ratio",
    "MAX_SPREAD_SAMPLES",
    "FURNACE_TOLERANCE",
]

MAX_SPREAD_SAMPLES = 200_000
"""Entry samples above which the sweep does not spread the reference (the 2 m sphere would
need ~3e10: the reference's cost grows with the sphere's area in mean free paths)."""
FURNACE_TOLERANCE = 1e-3
"""Directional albedos may exceed 1 by this much (quadrature and interpolation)."""
DEFAULT_ANGLES_DEG = (0.0, 45.0, 80.0, 89.0, 89.9)
GRAZING_ANGLES_DEG = (80.0, 83.0, 86.0, 88.0, 89.0, 89.9)


@dataclass(frozen=True)
class Regime:
    """One regime of the sweep.

    ``key``, ``name``: identifier and the docs' wording; ``film_width_deg``, ``film_ior``,
    ``skin_ior``: overrides of the paper preset's film lobe (1/e half-width, degrees) and the
    film's and skin's indices (the skin's surface and its dipole); ``coverage``,
    ``absorption``; the sphere: ``radius_mm``, ``resolution`` (px), ``lights_deg`` (degrees
    from the view); ``incidence_deg``/``view_deg``: the polar angles (degrees) the model is
    evaluated at, light and view (:func:`regime_directions`)."""

    key: str
    name: str
    film_width_deg: float | None = None
    film_ior: float | None = None
    skin_ior: float | None = None
    coverage: float = 1.0
    absorption: float = 0.0
    radius_mm: float = 10.0
    resolution: int = 16
    lights_deg: tuple = (45.0,)
    incidence_deg: tuple = DEFAULT_ANGLES_DEG
    view_deg: tuple = DEFAULT_ANGLES_DEG

    @property
    def exact_affordable(self) -> bool:
        """Whether the exact evaluator is affordable at every pixel: not for film lobes under
        10 degrees (at 5 degrees it takes ~8 s and 2.4 GB per direction pair, bpy 5.0.1 venv
        on this machine), so there the sweep evaluates it at two pairs and draws no
        reference image."""
        return self.film_width_deg is None or self.film_width_deg >= 10.0


REGIMES = (
    Regime("grazing", "grazing light (80-89 deg from the view)", lights_deg=(80.0, 85.0, 89.0),
           incidence_deg=GRAZING_ANGLES_DEG),
    Regime("silhouette", "silhouette (view 80-89.9 deg from the normal)", lights_deg=(0.0,),
           view_deg=GRAZING_ANGLES_DEG),
    Regime("tiny", "1 mm sphere, bare skin (subsurface spread larger than the sphere)",
           radius_mm=1.0, coverage=0.0),
    Regime("huge", "2 m sphere, bare skin (subsurface spread under a pixel)", radius_mm=2000.0,
           coverage=0.0),
    Regime("sharp", "film lobe 5 deg (the panel's smallest)", film_width_deg=5.0),
    Regime("sharper", "film lobe 2 deg (beyond the panel)", film_width_deg=2.0),
    Regime("rough", "film lobe 60 deg (the panel's largest)", film_width_deg=60.0),
    Regime("rougher", "film lobe 90 deg (beyond the panel)", film_width_deg=90.0),
    Regime("eta1", "indices near 1 (film 1.001, skin 1.001)", film_ior=1.001, skin_ior=1.001),
    Regime("coverage0", "coverage 0 (bare skin)", coverage=0.0),
    Regime("coverage1", "coverage 1 (full film)", coverage=1.0),
    Regime("absorbed", "full absorption (A = 1)", absorption=1.0),
)
"""The regimes where a method breaks (the paper preset otherwise: 10 mm sphere, light 45 deg,
16 px for the reference images; the sphere-size regimes on bare skin, where the subsurface
is most of the image)."""


def regime(key: str) -> Regime:
    """The regime of :data:`REGIMES` with this ``key``."""
    for item in REGIMES:
        if item.key == key:
            return item
    raise ValueError(f"unknown regime {key!r}; known: {[r.key for r in REGIMES]}")


def with_film(skin: MadeUpSkin, width_deg: float | None = None,
              ior: float | None = None) -> MadeUpSkin:
    """``skin`` with the film's reflection lobe ``width_deg`` wide (1/e half-width, degrees:
    ``n = 1/width``), the transmission lobe scaled alike, and the film's index ``ior``; the
    other parameters (``P_s`` included) kept, as the add-on's Override Film does."""
    film, film_transmission = skin.film, skin.film_transmission
    if width_deg is not None:
        if not width_deg > 0:
            raise ValueError(f"width_deg must be > 0 (degrees), got {width_deg}")
        ratio = (1.0 / width_deg) / float(np.max(film.n))
        film, film_transmission = film.scaled(n=ratio), film_transmission.scaled(n=ratio)
    if ior is not None:
        film = film.scaled(eta=ior / float(np.max(film.eta)))
        film_transmission = film_transmission.scaled(eta=ior / float(np.max(film_transmission.eta)))
    return skin.replace(film=film, film_transmission=film_transmission)


def regime_skin(item: Regime) -> MadeUpSkin:
    """The paper preset with the regime's overrides, coverage and absorption."""
    skin = made_up_skin("paper_natural", "paper_bioplate", coverage=item.coverage,
                        absorption=item.absorption)
    skin = with_film(skin, item.film_width_deg, item.film_ior)
    if item.skin_ior is not None:
        skin = skin.replace(skin_reflection=replace(skin.skin_reflection, eta=item.skin_ior),
                            dipole=replace(skin.dipole, eta=item.skin_ior))
    return skin


def regime_directions(item: Regime):
    """``(wi, wo)`` ``(N, 3)``: every incidence x view angle of the regime at relative azimuths
    0, 90 and 180 degrees (mirror, side and back)."""
    ti, to, phi = np.meshgrid(np.radians(item.incidence_deg), np.radians(item.view_deg),
                              np.radians([0.0, 90.0, 180.0]), indexing="ij")
    return direction(ti.ravel(), phi.ravel()), direction(to.ravel(), np.zeros(to.size))


def summary(values) -> dict:
    """``{"finite", "min", "max"}`` of an array (min and max over its finite entries)."""
    values = np.asarray(values, float)
    finite = np.isfinite(values)
    good = values[finite]
    return {"finite": bool(np.all(finite)),
            "min": float(good.min()) if good.size else float("nan"),
            "max": float(good.max()) if good.size else float("nan")}


MODEL_CHUNK = 32
"""Direction pairs the exact evaluator gets at once (its memory grows with the batch)."""


def _model(item: Regime, skin: MadeUpSkin, points: int | None, albedo: bool) -> dict:
    wi, wo = regime_directions(item)
    if points is not None and points < wi.shape[0]:
        pick = np.unique(np.round(np.linspace(0, wi.shape[0] - 1, points)).astype(int))
        wi, wo = wi[pick], wo[pick]
    chunk = MODEL_CHUNK if item.exact_affordable else 1
    values = np.concatenate([made_up_reflection(wi[i:i + chunk], wo[i:i + chunk], skin)
                             for i in range(0, wi.shape[0], chunk)])
    out = {"reflection": summary(values), "pairs": int(wi.shape[0]),
           "_values": (wi, wo, values)}
    if albedo and item.exact_affordable:
        theta = np.array(sorted(set(item.incidence_deg) & {0.0, 45.0, 89.0, 89.9}) or [0.0])
        out["albedo"] = summary(directional_albedo(theta, skin))
    return out


def _bake(item: Regime, skin: MadeUpSkin, resolution: str, error_points: int):
    tables = bake(skin, resolution)
    arrays = {name: summary(value) for name, value in tables.arrays.items()
              if name not in ("theta_deg", "phi_deg", "radius_mm")}
    out = {
        "finite": all(a["finite"] for a in arrays.values()),
        "min": min(a["min"] for a in arrays.values()),
        "albedo": summary(tables.directional_albedo(tables.theta_deg)),
    }
    if error_points:
        error = table_error(tables, skin, error_points)
        out["error"] = {k: error[k] for k in ("reflection", "albedo", "max", "worst")}
    return tables, out


def _reference(item: Regime, skin: MadeUpSkin, resolution: int, spread: bool) -> dict:
    samples = default_samples(skin, item.radius_mm)
    spread = spread and samples <= MAX_SPREAD_SAMPLES
    images = [sphere_image(skin, resolution=resolution, radius_mm=item.radius_mm,
                           light_angle_deg=light, spread=spread, samples=samples)
              for light in item.lights_deg]
    out = {"image": summary(np.stack(images)), "spread": spread, "entry_samples": int(samples)}
    if spread:
        out["spread_over_local"] = spread_energy_ratio(skin, item.radius_mm, resolution,
                                                       samples)
    return out


def spread_energy_ratio(skin: MadeUpSkin, radius_mm: float, resolution: int,
                        samples: int) -> float:
    """Light the spread reference returns over the visible hemisphere over the light that
    entered there, bare skin lit from the view: at most 1 (spreading moves light, it does not
    make it); below 1 by the profile's mass beyond the hemisphere (a sphere of the spread's
    size loses much).  Exit points are the image's pixel centres, each the surface area
    ``pixel / cos(theta_o)``."""
    bare = skin.replace(coverage=0.0)
    light = light_direction(0.0)
    _, normals, mask = sphere_points(resolution, radius_mm)
    points = normals[mask]
    area = 1.0 / np.maximum(points[:, 2:3], 1e-3)
    local = local_diffuse(points, light, bare)
    moved = spread_diffuse(points, light, bare, radius_mm=radius_mm, samples=samples)
    return float(np.sum(moved * area) / max(float(np.sum(local * area)), 1e-300))


def _tiers(item: Regime, tables) -> dict:
    fit = fit_closures(tables)
    errors = tier_errors(fit, tables, item.coverage, item.absorption)
    return {tier: {"rms": e.rms, "albedo": e.albedo} for tier, e in errors.items()}


def auto_choice(item: Regime, samples: int = 128):
    """The Auto tier's :class:`lut_baker.auto_tier.Choice` for the regime's sphere (``resolution``
    px across, its lights, Cycles at ``samples``) and skin (the paper preset's traits)."""
    diameter = 2.0 * item.radius_mm
    scene = SceneDescription(object_size_mm=diameter, footprint_mm=diameter / item.resolution,
                             lights_deg=item.lights_deg, samples=samples)
    return choose(scene)


def _auto(item: Regime) -> dict:
    choice = auto_choice(item)
    return {"choice": choice.candidate.name, "error": choice.chosen.error,
            "reasons": list(choice.reasons)}


def check_regime(item: Regime, *, bake_resolution: str = "preview", error_points: int = 0,
                 model_points: int | None = None, model_albedo: bool = True,
                 fit: bool = False, resolution: int | None = None,
                 spread: bool = True) -> dict:
    """Measurements of every method in one regime (module docstring), as plain data.

    ``model_points``: direction pairs of :func:`regime_directions` given to the exact evaluator
    (evenly picked; None: all; where it is not :attr:`Regime.exact_affordable`, at most 2;
    0: none, ``model`` is then None);
    ``model_albedo``: also its directional albedo (affordable regimes only);
    ``resolution``: of the reference images (default the regime's); ``spread``: spread
    their skin light where the entry samples are affordable (the first spread for a film
    layer tabulates its transmittance: 4-7 s);
    ``error_points``: random points of :func:`.table_accuracy.table_error` (0 or unaffordable:
    skipped);
    ``fit``: also the closure fits' tier errors (a few seconds)."""
    skin = regime_skin(item)
    affordable = item.exact_affordable
    tables, baked = _bake(item, skin, bake_resolution, error_points if affordable else 0)
    points = model_points if affordable or model_points == 0 else min(model_points or 2, 2)
    model = _model(item, skin, points, model_albedo) if points != 0 else None
    values = model.pop("_values") if model is not None else None
    if values is not None and not affordable:  # the bake's error at the pairs afforded
        wi, wo, exact = values
        peak = tables.node_values().reshape(-1, 3).max(axis=0)
        error = np.abs(tables.made_up_reflection(wi, wo) - exact) / np.maximum(
            np.abs(exact), 0.1 * peak)
        baked["error"] = {"reflection": float(error.max()), "pairs": int(wi.shape[0])}
    out = {"key": item.key, "name": item.name,
           "model": model,
           "bake": baked,
           "reference": (_reference(item, skin, resolution or item.resolution, spread)
                         if affordable else None),
           "auto": _auto(item)}
    if fit:
        out["tiers"] = _tiers(item, tables)
    return out


def sweep(regimes=REGIMES, **options) -> list[dict]:
    """:func:`check_regime` over ``regimes``."""
    return [check_regime(item, **options) for item in regimes]
