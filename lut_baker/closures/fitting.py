"""Fitting Blender closure parameters to baked tables, and each tier's error against them.

A Cycles shader sees the view direction but not the light's, so the add-on's tiers are
closures (replicated in :mod:`lut_baker.closures.cycles`) whose parameters are fitted here to the
tables of :mod:`lut_baker.tables.table_set`, with weights that may depend on the view angle through
1-D lookup images.  Everything is numpy only (it runs inside Blender, which ships no scipy).

Tiers
-----
``PRINCIPLED``: one Principled BSDF.  Coat = the film's gloss (Coat Weight = coverage; none
for a film without gloss, or one no coat follows; Coat Roughness and Coat IOR fitted);
specular = the skin's gloss, bare or through the film (Roughness and Specular IOR Level
fitted per case, mixed by coverage); base colour = the
diffuse albedo (film diffuse + skin seen through the film, or bare skin), divided by the mean
attenuation of the layers above it; Subsurface Weight = the skin's share of it.
``LAYERED``: closures added with view-dependent weights: film gloss, path-3 gloss and skin gloss
(Glossy GGX, roughness fitted, weight = table albedo / closure albedo read from a 1-D image by
``cos(theta_o)``; the film gloss shares its albedo with a Lambertian companion, its own
row), film diffuse plus that companion (one Diffuse), the skin through the film and bare
(Subsurface, colour ``(1 - A)^2 skin_diffuse pi T_mean T(theta_o)`` and ``skin_diffuse pi``),
mixed by coverage.
``EEVEE``: the LAYERED tier's closures and mix (:func:`eevee_weights`), made for EEVEE: every
Glossy lobe is GGX (EEVEE renders no other distribution) fitted to the tables as EEVEE renders
it under a lamp, a linearly transformed cosine (:mod:`lut_baker.closures.eevee`), with its own
view-angle rows; subsurface Christensen-Burley (EEVEE's screen-space method).
Both take the group's Gloss input ``g`` (0..1): it scales the gloss lobes (coat weight and
specular level; the Glossy colours), and at 0 Cycles allocates none of them.  The replicas
below take it as ``gloss``, so the Auto tier predicts a gloss-free candidate from the same
formulas as the node group (:func:`lut_baker.auto_tier.gloss_omission_error`).

Grids and errors
----------------
Fits and errors run on direction pairs organised by view, the lights around each view's mirror
direction through their half vector (:mod:`lut_baker.closures.view_grid`), in panels sized by
the narrowest lobe involved: a 1-degree film gloss costs what a 30-degree one does.  The
surfaces' gloss is evaluated in closed form there, path 3 looked up in its table.  With ``f``
the BRDF and ``L = f cos(theta_i)`` the radiance under a unit-irradiance light, the error is the
relative RMS of ``L`` over lights uniform over the hemisphere and views weighted by the area a
sphere's image gives them (``cos(theta_o) dw_o``), and the largest relative error of the view
albedo ``Int f cos(theta_i) dw_i``.  Every search is Brent's, converged far enough
(:data:`FIT_XTOL`) that a fitted number follows its data continuously.

Functions and types
-------------------
- :func:`fit_coat`, :func:`fit_specular`, :func:`fit_glossy` -- lobes fitted to an angular
  part on a :class:`lut_baker.closures.view_grid.ViewGrid`.
- :func:`edge_response` -- a radial profile's response to a straight shadow edge, on the
  radii of :func:`profile_grid`.
- :func:`fit_profile`, :func:`fit_profiles` -- Subsurface Radius per channel for a Blender
  subsurface method, fitted to the radial profile's edge response.
- :func:`lut_nodes`, :func:`sample_lut` -- the 1-D image's texel centres and its sampling.
- :class:`LobeFit`, :class:`ProfileFit`, :class:`TierError`, :class:`ClosureFit`.
- :func:`fit_closures` -- every fit of one set of tables.
- :func:`principled_inputs`, :func:`principled_tier_reflection` -- the PRINCIPLED tier at a
  coverage, absorption and Gloss; :func:`layered_weights`, :func:`layered_tier_reflection` --
  the LAYERED tier; :func:`eevee_weights`, :func:`eevee_tier_reflection` -- the EEVEE tier;
  :data:`TIER_REPLICAS` -- all by name; :func:`tier_errors` -- all against the tables.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, replace

import numpy as np

from ..model.made_up_skin import combine, coverage_weights
from ..numerics.cache import LRUCache
from ..numerics.optimise import brent_minimum, scanned_least_squares
from ..numerics.quadrature import trapezoid_weights
from ..tables.table_set import Tables
from . import cycles as cc
from . import eevee
from .view_grid import ERROR_VIEWS, FIT_VIEWS, ViewGrid, view_grid

__all__ = [
    "TIERS",
    "LUT_ROWS",
    "DEFAULT_LUT_SIZE",
    "lut_nodes",
    "sample_lut",
    "LobeFit",
    "ProfileFit",
    "TierError",
    "ClosureFit",
    "fit_coat",
    "fit_specular",
    "fit_glossy",
    "edge_response",
    "profile_grid",
    "fit_profile",
    "fit_profiles",
    "subsurface_ior",
    "fit_closures",
    "diffuse_albedo",
    "principled_inputs",
    "principled_tier_reflection",
    "layered_weights",
    "layered_tier_reflection",
    "eevee_weights",
    "eevee_tier_reflection",
    "EEVEE_GLOSSY",
    "EEVEE_SUBSURFACE_METHOD",
    "TIER_REPLICAS",
    "tier_errors",
    "lobe_widths_deg",
]

TIERS = ("PRINCIPLED", "LAYERED", "EEVEE")
"""The node group's tiers: the two made for Cycles, cheapest first, then the one made for
EEVEE."""
LUT_ROWS = ("film_gloss", "path3_gloss", "skin_gloss", "film_transmittance",
            "film_gloss_diffuse")
"""Rows of the LAYERED and EEVEE tiers' view-angle images: three Glossy weights, the film's
transmittance ``T(theta_o)`` and the film gloss's Lambertian companion (:func:`fit_glossy`)."""
EEVEE_GLOSSY = "EEVEE_GGX"
"""The closure name :func:`fit_glossy` gives EEVEE's Glossy BSDF under a lamp
(:func:`lut_baker.closures.eevee.glossy_from_cosines`); the node is a GGX Glossy BSDF."""
EEVEE_SUBSURFACE_METHOD = "BURLEY"
"""The EEVEE tier's subsurface method: EEVEE's screen-space subsurface is Burley's profile
whatever the node asks for, and Cycles renders the same method when the file is rendered
there."""
DEFAULT_LUT_SIZE = 64
"""Texels per row of the view-angle image (linear filtering between texel centres)."""
ROUGHNESS_RANGE = (0.02, 1.0)
"""Roughness (Blender's socket, alpha = roughness^2) searched by the fits: from a lobe about
0.03 degrees wide to the broadest; searched in ``log(roughness)``."""
ROUGHNESS_SCAN = 7
"""Evenly spaced ``log(roughness)`` samples that bracket the minimum before Brent's search."""
SECOND_SCAN = 5
"""Samples that bracket the second parameter (Coat IOR, Specular IOR Level)."""
FIT_XTOL = 1e-7
"""Absolute tolerance of the searches (``log(roughness)``, IOR, level): far below what a render
shows and far above rounding, so that a fit moves continuously with its data (a 1e-9 change of
the tables moves it by about 1e-9, never by a search's tolerance)."""
DISTRIBUTION_MARGIN = 0.02
"""A Glossy distribution other than GGX is chosen only when its error is this much (relative)
lower than GGX's: a near tie keeps GGX, so the choice does not flip with rounding."""
COAT_IOR_RANGE = (1.01, 4.0)
"""Coat IOR searched (the socket's range in Blender)."""
SPECULAR_LEVEL_RANGE = (0.0, 8.0)
"""Specular IOR Level searched (0.5 leaves IOR 1.5 as it is; F0 = 0.04 * 2 level)."""
SPECULAR_IOR = 1.5
"""The Principled IOR the specular fits assume (Specular IOR Level scales its F0)."""
REPLICA_EDGE_ERROR = {"BURLEY": 0.0035, "RANDOM_WALK": 0.0068, "RANDOM_WALK_SKIN": 0.0067}
"""RMS difference (fraction of the lit level) between a rendered edge response and the
replica's at albedo 0.8 (tools/calibrate_subsurface.py, Cycles 5.0.1 and 4.5.15, 256 samples):
Burley's is the Monte Carlo noise; the random walks add the mismatch of their Burley-shaped
replica (0.6-1.3% over albedos 0.2-0.95)."""
NO_LOBE_ERROR = 0.9
"""A specular fit erring more than this (relative RMS; leaving the lobe out errs 1.0) is
dropped and its albedo moved to the base colour."""


# --------------------------------------------------------------------------------------------
# The view-angle image
# --------------------------------------------------------------------------------------------
def lut_nodes(size: int = DEFAULT_LUT_SIZE) -> np.ndarray:
    """``cos(theta_o)`` at the texel centres ``(i + 0.5) / size`` of a view-angle image."""
    return (np.arange(size) + 0.5) / size


def sample_lut(lut, cos_view) -> np.ndarray:
    """What Blender's Image Texture (Linear, EXTEND) returns for a row ``lut`` ``(size[, C])``
    at ``u = cos_view``: linear between texel centres, the edge texel beyond them."""
    lut = np.asarray(lut, float)
    nodes = lut_nodes(lut.shape[0])
    cos_view = np.asarray(cos_view, float)
    if lut.ndim == 1:
        return np.interp(cos_view, nodes, lut)
    return np.stack([np.interp(cos_view, nodes, lut[:, c]) for c in range(lut.shape[1])], -1)


# --------------------------------------------------------------------------------------------
# Lobe fits
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class LobeFit:
    """A GGX lobe fitted to an angular part of the tables.

    ``roughness``: Blender's Roughness; ``ior``: Coat IOR (coat) or the IOR whose F0 the
    Specular IOR Level sets (specular), None for a Glossy BSDF; ``level``: Specular IOR Level
    (specular only; 0 when no lobe beats leaving the gloss out); ``lut``: the Glossy weight per
    view-angle texel, ``(size, 3)`` (Glossy only); ``distribution``: ``GGX``, ``BECKMANN`` or
    ``ASHIKHMIN_SHIRLEY`` (Glossy only; the Principled BSDF is GGX); ``diffuse_lut``: the
    weight of its Lambertian companion per texel, ``(size, 3)``, or None (:func:`fit_glossy`);
    ``error``: relative RMS of this lobe against its target (module docstring);
    ``searched``: each Glossy distribution's error in the search, by name (Glossy only: what
    the choice of distribution compares).
    """

    roughness: float
    error: float
    ior: float | None = None
    level: float | None = None
    lut: np.ndarray | None = None
    distribution: str = "GGX"
    diffuse_lut: np.ndarray | None = None
    searched: dict | None = None


def _grey(values) -> np.ndarray:
    """Per-pair values ``(V, A, P[, C])`` with their channels averaged, ``(V, A, P)``."""
    values = np.asarray(values, float)
    return np.mean(values, axis=-1) if values.ndim == 4 else values


def _minimise_roughness(error_of) -> tuple[float, float]:
    """``(roughness, error)``: ``error_of(roughness)`` minimised over :data:`ROUGHNESS_RANGE`,
    in ``log(roughness)`` (a lobe's width goes as roughness squared)."""
    log_r, error = brent_minimum(lambda x: error_of(float(np.exp(x))),
                                 *np.log(ROUGHNESS_RANGE), coarse=ROUGHNESS_SCAN, xtol=FIT_XTOL)
    return float(np.exp(log_r)), error


def _fit_roughness_and(grid: ViewGrid, target, lobe_times, second_range):
    """``(roughness, second, error)``: a GGX lobe times ``lobe_times(roughness)(second)`` (a
    factor per pair) fitted to ``target`` (channels averaged).  A scan of
    :data:`ROUGHNESS_SCAN` roughnesses by :data:`SECOND_SCAN` values of the second parameter
    finds the start; bounded Levenberg-Marquardt on ``(log(roughness), second)`` converges
    from it (:func:`lut_baker.numerics.optimise.least_squares`, to :data:`FIT_XTOL`)."""
    target = _grey(target)
    root_weight = np.sqrt(grid.weight) * grid.cos_i
    scale = 1.0 / max(float(np.sqrt(np.sum(np.square(root_weight * target)))), 1e-300)

    per_roughness = {}  # the lobe and its factor's set-up, once per roughness tried

    def model(x):
        roughness = float(np.exp(x[0]))
        if roughness not in per_roughness:
            per_roughness[roughness] = (grid.lobe(roughness), lobe_times(roughness))
        lobe, factor = per_roughness[roughness]
        return lobe * factor(float(x[1]))

    def residuals(x):
        return (scale * root_weight * (model(x) - target)).ravel()

    x, cost, _ = scanned_least_squares(
        residuals, (np.linspace(*np.log(ROUGHNESS_RANGE), ROUGHNESS_SCAN),
                    np.linspace(*second_range, SECOND_SCAN)), xtol=FIT_XTOL)
    return float(np.exp(x[0])), float(x[1]), float(np.sqrt(cost))


def fit_coat(grid: ViewGrid, target) -> LobeFit:
    """Coat Roughness and Coat IOR of a GGX coat (weight 1, dielectric Fresnel, Cycles'
    energy compensation) fitted to ``target`` (the film's gloss on ``grid``, ``(V, A, P[, 3])``,
    channels averaged).  ``level`` is the coat's weight per unit coverage: 1, or 0 when the
    film has no gloss (a matte product) or no coat does much better than none
    (:data:`NO_LOBE_ERROR`)."""
    if not np.any(np.asarray(target, float)):
        return LobeFit(roughness=ROUGHNESS_RANGE[1], ior=COAT_IOR_RANGE[0], level=0.0,
                       error=0.0)
    def lobe_times(roughness):
        albedo = cc.microfacet_albedo(grid.cos_view, roughness, **SEARCH_QUADRATURE)
        average = cc.ggx_average_albedo(roughness)

        def factor(ior):
            scale = cc.ggx_energy_scale(albedo, average, float(cc.dielectric_fss(ior)))[0]
            return cc.dielectric_fresnel(grid.cos_hi, ior) * scale[:, None, None]
        return factor

    roughness, ior, error = _fit_roughness_and(grid, target, lobe_times, COAT_IOR_RANGE)
    if error >= NO_LOBE_ERROR:
        return LobeFit(roughness=roughness, ior=ior, level=0.0, error=1.0)
    return LobeFit(roughness=roughness, ior=ior, level=1.0, error=error)


def _specular_fresnel(cos_hi, level):
    """The Principled specular's Fresnel at IOR :data:`SPECULAR_IOR` and a Specular IOR
    Level."""
    f0 = float(cc.f0_from_ior(SPECULAR_IOR)) * 2.0 * level
    eta = float(cc.ior_from_f0(f0)) if level != 0.5 else SPECULAR_IOR
    return cc.schlick_ior_fresnel(cos_hi, eta, f0)


def fit_specular(grid: ViewGrid, target, attenuation=None) -> LobeFit:
    """Roughness and Specular IOR Level (at IOR :data:`SPECULAR_IOR`) of the Principled
    specular fitted to ``target`` ``(V, A, P[, 3])`` (channels averaged).  ``attenuation``:
    the factor the layers above apply to it per view ``(V,)`` (the coat's ``1 - E_coat``), or
    None."""
    scale = 1.0 if attenuation is None else np.asarray(attenuation, float)[:, None, None]

    def lobe_times(roughness):
        return lambda level: scale * _specular_fresnel(grid.cos_hi, level)

    roughness, level, error = _fit_roughness_and(grid, target, lobe_times,
                                                 SPECULAR_LEVEL_RANGE)
    if error >= NO_LOBE_ERROR:  # no lobe does much better than none: leave it to the diffuse
        return LobeFit(roughness=roughness, ior=SPECULAR_IOR, level=0.0, error=1.0)
    return LobeFit(roughness=roughness, ior=SPECULAR_IOR, level=level, error=error)


SEARCH_QUADRATURE = {"n_u": 24, "n_phi": 12}
"""Closure-albedo quadrature while searching, at the grid's views (within 2%); the final
weights use :data:`FINAL_QUADRATURE` (within 0.1%) at every texel."""
FINAL_QUADRATURE = {"n_u": 96, "n_phi": 64}


def _texel_albedo(albedo_table: np.ndarray, theta_deg: np.ndarray, cos_view) -> np.ndarray:
    """A directional albedo table ``(n_theta, 3)`` on ``theta_deg`` at view cosines
    ``cos_view`` ``(K,)``: ``(K, 3)``."""
    theta = np.degrees(np.arccos(np.clip(cos_view, 0.0, 1.0)))
    return np.stack([np.interp(theta, theta_deg, albedo_table[:, c]) for c in range(3)], -1)


def _companion_share(grid: ViewGrid, lobe: np.ndarray, closure_albedo: np.ndarray,
                     table_albedo: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The share ``s`` (per view of ``grid``, in [0, 1]) of a table's albedo ``A`` that the
    Glossy lobe carries when a Lambertian companion carries the rest: weights ``a = s A / E``
    (Glossy, ``E`` its albedo) and ``b = (1 - s) A`` (Diffuse), so ``a E + b = A`` at every
    view.  ``s`` minimises ``|a lobe cos_i + b cos_i / pi - target cos_i|`` over the lights
    of each view (closed form).  ``lobe`` and ``target`` grey ``(V, A, P)``, the albedos at
    the views ``(V,)``."""
    e = closure_albedo[:, None, None]
    a = table_albedo[:, None, None]
    lam = grid.cos_i / np.pi
    u = a / np.maximum(e, 1e-6) * (lobe * grid.cos_i - e * lam)
    v = target * grid.cos_i - a * lam
    w = grid.weight
    num = np.sum(w * u * v, axis=(1, 2))
    den = np.sum(w * u * u, axis=(1, 2))
    return np.clip(np.where(den > 0.0, num / np.where(den > 0.0, den, 1.0), 1.0), 0.0, 1.0)


def glossy_lobe(grid: ViewGrid, roughness: float, closure: str) -> np.ndarray:
    """A white Glossy closure's BRDF at ``grid``'s pairs, ``(V, A, P)``: Cycles' distribution
    ``closure`` (:data:`lut_baker.closures.cycles.GLOSSY_DISTRIBUTIONS`) or, for
    :data:`EEVEE_GLOSSY`, EEVEE's GGX under a lamp."""
    if closure == EEVEE_GLOSSY:
        return eevee.glossy_from_cosines(grid.wi, grid.cos_o, roughness)
    return grid.lobe(roughness, closure)


def glossy_albedo(cos_view, roughness: float, closure: str, *, final: bool = True):
    """The albedo of :func:`glossy_lobe`'s closure at view cosines: by quadrature over
    normals for Cycles' (:data:`FINAL_QUADRATURE`, or :data:`SEARCH_QUADRATURE` while
    searching), in closed form for EEVEE's."""
    if closure == EEVEE_GLOSSY:
        return eevee.glossy_albedo(cos_view, roughness)
    return cc.microfacet_albedo(cos_view, roughness, distribution=closure,
                                **(FINAL_QUADRATURE if final else SEARCH_QUADRATURE))


def fit_glossy(grid: ViewGrid, target, albedo_table: np.ndarray, theta_deg: np.ndarray,
               size: int = DEFAULT_LUT_SIZE, *, companion: bool = False,
               closures: tuple = cc.GLOSSY_DISTRIBUTIONS) -> LobeFit:
    """Distribution (:data:`lut_baker.closures.cycles.GLOSSY_DISTRIBUTIONS`) and roughness of a
    Glossy BSDF whose view-dependent weight (table albedo / closure albedo, read from a
    ``size``-texel image by ``cos(theta_o)``) best reproduces ``target`` ``(V, A, P[, 3])``;
    ``albedo_table`` ``(n_theta, 3)`` on ``theta_deg``.

    ``companion``: the albedo is shared with a Lambertian companion, in the proportion that
    fits each view best (:func:`_companion_share`); the weights are then ``lut`` (Glossy) and
    ``diffuse_lut`` (Diffuse), whose albedos still add up to the table's at every view.  A
    broad lobe whose radiance keeps a ``cos(theta_i)`` factor (the paper's film gloss) is
    part Lambertian, which no Glossy closure alone reproduces.

    ``closures``: the Glossy closures to choose from (:func:`glossy_lobe`): Cycles'
    distributions (default), or ``(EEVEE_GLOSSY,)`` for the EEVEE tier.  The first of them
    (GGX) is chosen unless another one's error is lower by more than
    :data:`DISTRIBUTION_MARGIN` (relative): a near tie never flips the choice.  The fit's
    ``distribution`` is the Glossy node's (``GGX`` for EEVEE's closure)."""
    target = np.asarray(target, float)
    target = target if target.ndim == 4 else target[..., None]
    target = target * np.ones(3)
    grey = _grey(target)
    if not np.any(albedo_table):  # no gloss (a matte film): weights 0, nothing to fit
        zeros = np.zeros((size, 3))
        return LobeFit(roughness=ROUGHNESS_RANGE[1], error=0.0, lut=zeros,
                       diffuse_lut=zeros.copy() if companion else None)
    texels = lut_nodes(size)
    tables = {False: _texel_albedo(albedo_table, theta_deg, grid.cos_view),
              True: _texel_albedo(albedo_table, theta_deg, texels)}

    def weights(roughness, distribution, final: bool):
        """``(lut, diffuse_lut or None, value on the grid)`` for one lobe: while searching
        (``final`` False) the weights sit at the grid's views, with a coarser closure albedo;
        the final ones at the image's texels, sampled as Blender samples them."""
        shape = glossy_lobe(grid, roughness, distribution)
        nodes = texels if final else grid.cos_view
        closure = glossy_albedo(nodes, roughness, distribution, final=final)
        table = tables[final]
        lut = table / np.maximum(closure, 1e-6)[:, None]
        diffuse = None
        if companion:
            e_views = np.interp(grid.cos_view, texels, closure) if final else closure
            share = _companion_share(grid, shape, e_views, np.mean(tables[False], axis=-1),
                                     grey)
            share = np.interp(texels, grid.cos_view, share) if final else share
            diffuse = (1.0 - share)[:, None] * table
            lut = share[:, None] * lut
        rows = ((lambda row: sample_lut(row, grid.cos_o)) if final
                else (lambda row: row[:, None, None, :]))
        value = shape[..., None] * rows(lut)
        if diffuse is not None:
            value = value + rows(diffuse) / np.pi
        return lut, diffuse, value

    searched = {distribution: _minimise_roughness(lambda r, d=distribution: grid.error(
        weights(r, d, False)[2], target)) for distribution in closures}
    distribution = min(searched, key=lambda d: searched[d][1])
    if searched[distribution][1] >= (1.0 - DISTRIBUTION_MARGIN) * searched[closures[0]][1]:
        distribution = closures[0]
    roughness = searched[distribution][0]
    lut, diffuse, value = weights(roughness, distribution, True)
    node = "GGX" if distribution == EEVEE_GLOSSY else distribution
    return LobeFit(roughness=roughness, error=grid.error(value, target), lut=lut,
                   distribution=node, diffuse_lut=diffuse,
                   searched={("GGX" if name == EEVEE_GLOSSY else name): float(found[1])
                             for name, found in searched.items()})


# --------------------------------------------------------------------------------------------
# Radial profile fits
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ProfileFit:
    """Subsurface Radius (x Scale, in mm, per channel) of one Blender subsurface method fitted
    to the tables' normalised profile ``R(d)/Rd``.  ``error`` and ``max_error`` per channel: RMS
    and largest difference of the edge response (:func:`edge_response`, a fraction of the lit
    level) over distances up to the tables' last radius; ``albedo``: the colour assumed (the
    random walks' spread depends on it)."""

    method: str
    radius_mm: np.ndarray
    error: np.ndarray
    max_error: np.ndarray
    albedo: np.ndarray | None = None

    @property
    def worst_error(self) -> float:
        return float(np.max(self.error))


def edge_response(r_mm, profile, s_mm) -> np.ndarray:
    """The light a point ``s_mm`` inside a straight shadow edge receives from the lit
    half-plane, as a fraction of the lit level, for a radial profile ``profile`` (unit area,
    1/mm^2) sampled at ``r_mm``: ``ESF(s) = Int_s^inf P(r) 2 r arccos(s / r) dr`` (0.5 at the
    edge).  What a subsurface profile looks like in a render: the blur of a shadow edge.
    ``profile``: ``(n_r)`` or ``(n_r, C)``; the result ``(n_s)`` or ``(n_s, C)``."""
    r = np.asarray(r_mm, float)
    s = np.asarray(s_mm, float)[:, None]
    arc = np.where(r > s, 2.0 * np.arccos(np.clip(s / np.maximum(r, 1e-300), -1.0, 1.0)), 0.0)
    return (arc * (r * trapezoid_weights(r))) @ np.asarray(profile, float)


PROFILE_RADII = 600
"""Radii of :func:`profile_grid` (1200 moves the fitted radii by under 0.2%)."""


def profile_grid(r_max: float) -> np.ndarray:
    """Integration radii (mm) for :func:`edge_response`: geometric, to 40 x the table's end."""
    return np.concatenate([[0.0], np.geomspace(1e-5 * r_max, 40.0 * r_max, PROFILE_RADII)])


def fit_profile(tables: Tables, method: str, *, albedo=None) -> ProfileFit:
    """Fit the Subsurface Radius (mm, per channel) of ``method`` (``BURLEY``, ``RANDOM_WALK``,
    ``RANDOM_WALK_SKIN``) so that its edge response matches the tables' profile's (RMS over
    distances up to the tables' last radius).  ``albedo`` (per channel): the colour the random
    walk sees, default the skin's diffuse albedo ``pi skin_diffuse``."""
    if method not in cc.SUBSURFACE_METHODS:
        raise ValueError(f"method must be one of {cc.SUBSURFACE_METHODS}, got {method!r}")
    albedo = np.clip(np.pi * np.asarray(tables.skin_diffuse, float) if albedo is None
                     else np.broadcast_to(np.asarray(albedo, float), (3,)), 0.0, 1.0)
    r_max = float(tables.radius_mm[-1])
    r = profile_grid(r_max)
    s = np.linspace(0.0, r_max, 48)
    reference = edge_response(r, tables.radial(r), s)  # (48, 3)
    radii, errors, worst, done = [], [], [], {}
    for c in range(3):
        key = (reference[:, c].tobytes(), float(albedo[c]))
        if key in done:
            for values in (radii, errors, worst):
                values.append(values[done[key]])
            continue
        done[key] = c

        def difference(log_radius, c=c):
            model = cc.subsurface_profile(r, float(np.exp(log_radius)), albedo[c], method)
            return edge_response(r, model, s) - reference[:, c]

        def rms(log_radius):
            return float(np.sqrt(np.mean(np.square(difference(log_radius)))))

        # Half the reference's mean spread (mm) centres the search window (log radius).
        centre = np.log(max(float(np.mean(reference[:, c]) * r_max), 1e-6))
        log_radius, error = brent_minimum(rms, centre - 3.0, centre + 5.0, coarse=17,
                                          xtol=FIT_XTOL)
        radii.append(float(np.exp(log_radius)))
        errors.append(error)
        worst.append(float(np.max(np.abs(difference(log_radius)))))
    return ProfileFit(method=method, radius_mm=np.array(radii), error=np.array(errors),
                      max_error=np.array(worst), albedo=None if method == "BURLEY" else albedo)


PROFILE_FIT_CACHE_SIZE = 16
"""Profile fits kept in this process: they depend on the skin alone (its profile and diffuse
albedo), so every foundation on one skin shares them."""
_PROFILE_FITS = LRUCache(PROFILE_FIT_CACHE_SIZE)


def fit_profiles(tables: Tables, **options) -> dict[str, ProfileFit]:
    """:func:`fit_profile` for every Blender subsurface method, by method name; remembered by
    the tables' radial grid, profile, skin albedo and ``options`` (the fits read nothing
    else)."""
    key = (np.asarray(tables.radius_mm, float).tobytes(),
           np.asarray(tables.profile, float).tobytes(),
           np.asarray(tables.skin_diffuse, float).tobytes(),
           repr(sorted((name, np.asarray(value).tolist()) for name, value in options.items())))
    return _PROFILE_FITS.get_or_compute(key, lambda: {
        method: fit_profile(tables, method, **options) for method in cc.SUBSURFACE_METHODS})


# --------------------------------------------------------------------------------------------
# All fits of one set of tables
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class TierError:
    """A tier's error against the tables at one coverage and absorption: ``rms`` (relative RMS
    of ``f cos(theta_i)``) and ``albedo`` (largest relative view-albedo error)."""

    tier: str
    coverage: float
    absorption: tuple
    rms: float
    albedo: float


@dataclass(frozen=True, eq=False)
class ClosureFit:
    """Everything the node group needs from one set of tables (absorption 0).

    PRINCIPLED: ``coat`` (film gloss), ``specular_bare`` (skin gloss), ``specular_film`` (path-3
    gloss under the coat), ``coat_albedo_mean``, ``specular_albedo_mean`` (bare, film): the
    cosine-weighted mean layering albedos; ``gloss_to_diffuse`` (RGB): the path-3 gloss albedo
    the base colour carries when no specular lobe fits it (else 0).  LAYERED: ``glossy``
    (film_gloss, path3_gloss, skin_gloss: Glossy lobes with their weight rows).  Both:
    ``transmittance_mean`` (RGB, the cosine-weighted mean of T), ``film_albedo`` and
    ``skin_albedo`` (RGB, ``pi P_d``), ``profiles`` (by method) and ``subsurface_method``
    (the best-fitting one), ``subsurface_ior`` (the dipole's index, for the random walk and
    the profile fits), ``lut`` (``(len(LUT_ROWS), size, 3)``: the view-angle image),
    ``errors`` at the coverage and absorption the tables were baked for.  EEVEE:
    ``eevee_glossy`` (the same three lobes, GGX as EEVEE renders it) and ``eevee_lut`` (their
    view-angle image, rows :data:`LUT_ROWS`); its subsurface is Burley's
    (:data:`EEVEE_SUBSURFACE_METHOD`).
    """

    coat: LobeFit
    specular_bare: LobeFit
    specular_film: LobeFit
    coat_albedo_mean: float
    specular_albedo_mean: tuple
    gloss_to_diffuse: np.ndarray
    glossy: dict
    transmittance_mean: np.ndarray
    film_albedo: np.ndarray
    skin_albedo: np.ndarray
    profiles: dict
    subsurface_method: str
    subsurface_ior: float
    lut: np.ndarray
    eevee_glossy: dict
    eevee_lut: np.ndarray
    errors: dict = field(default_factory=dict)

    @property
    def subsurface_radius_mm(self) -> np.ndarray:
        """The chosen method's Subsurface Radius x Scale per channel, mm."""
        return self.profiles[self.subsurface_method].radius_mm

    def summary(self) -> dict:
        """Plain data (floats and lists) for metadata, the panel and the docs."""
        return {
            "coat": {"roughness": self.coat.roughness, "ior": self.coat.ior,
                     "level": self.coat.level, "error": self.coat.error},
            "specular_bare": {"roughness": self.specular_bare.roughness,
                              "level": self.specular_bare.level,
                              "error": self.specular_bare.error},
            "specular_film": {"roughness": self.specular_film.roughness,
                              "level": self.specular_film.level,
                              "error": self.specular_film.error},
            "glossy": {name: {"roughness": lobe.roughness, "error": lobe.error,
                              "distribution": lobe.distribution}
                       for name, lobe in self.glossy.items()},
            "eevee_glossy": {name: {"roughness": lobe.roughness, "error": lobe.error}
                             for name, lobe in self.eevee_glossy.items()},
            "subsurface_method": self.subsurface_method,
            "subsurface_ior": self.subsurface_ior,
            "profiles": {name: {"radius_mm": p.radius_mm.tolist(), "error": p.error.tolist(),
                                "max_error": p.max_error.tolist()}
                         for name, p in self.profiles.items()},
            "errors": {name: asdict(e) for name, e in self.errors.items()},
        }


def _cosine_mean(values: np.ndarray, theta_deg: np.ndarray) -> np.ndarray:
    """``2 Int v(mu) mu dmu`` of a directional table ``(n_theta[, C])`` (its hemispherical
    cosine-weighted mean), trapezoid in ``mu``, held at its last value beyond ``theta_max``."""
    mu = np.cos(np.radians(np.asarray(theta_deg, float)))[::-1]
    values = np.asarray(values, float)[::-1]
    mu = np.concatenate([[0.0], mu])
    values = np.concatenate([values[:1], values])
    w = trapezoid_weights(mu)
    return 2.0 * np.tensordot(w * mu, values, axes=(0, 0))


def _view_mean(albedo_of) -> float:
    """``2 Int a(mu) mu dmu``: the cosine-weighted mean over view angles of ``albedo_of(mu)``
    (trapezoid on 33 view cosines)."""
    mu = np.linspace(0.0, 1.0, 33)
    return float(2.0 * np.sum(trapezoid_weights(mu) * mu * albedo_of(mu)))


def _coat_layering_mean(roughness: float, ior: float) -> float:
    """:func:`_view_mean` of the coat's layering albedo
    (:func:`lut_baker.closures.cycles.coat_view_terms`)."""
    return _view_mean(lambda mu: cc.coat_view_terms(mu, roughness, ior)[1])


def _layering_mean(roughness: float, ior: float, f0=None) -> float:
    """:func:`_view_mean` of :func:`lut_baker.closures.cycles.layering_albedo` (its largest
    channel)."""
    return _view_mean(lambda mu: np.max(
        np.atleast_2d(cc.layering_albedo(mu, roughness, ior, f0).T).T, axis=-1))


def subsurface_ior(parameters: dict) -> float:
    """The skin dipole's relative index (the Subsurface IOR) from tables' ``parameters``;
    1.4 (Blender's default) if they do not say.  Clamped to Cycles' [1.01, 3.8]."""
    dipole = parameters.get("dipole", {}) if isinstance(parameters, dict) else {}
    eta = float(np.mean(dipole.get("eta", 1.4)))
    return float(np.clip(eta, 1.01, 3.8))


def lobe_widths_deg(tables: Tables) -> dict[str, float]:
    """The 1/e half-widths (degrees, 1/n of eq. 2's D) of the film's and the skin's gloss, by
    surface-gloss name; path 3 is at least as wide as the skin's (it is the skin's gloss seen
    through the film's broad transmission)."""
    return {name: 1.0 / float(np.max(tables.surface_layer(name).n))
            for name in ("film_gloss", "skin_gloss")}


def fit_closures(tables: Tables, *, lut_size: int = DEFAULT_LUT_SIZE,
                 subsurface_method: str | None = None, errors_at=None,
                 progress=None) -> ClosureFit:
    """Fit both tiers to ``tables`` and measure their errors at ``errors_at`` = ``(coverage,
    absorption)`` (default: those the tables were baked for).  ``subsurface_method``: force
    one (default: the method whose edge response, fitted error and replica error combined,
    is closest to the tables'; all three are fitted and reported).  ``progress(fraction,
    message)``: called as the fit advances (fraction 0..1).

    The film's gloss is fitted on a grid sized by its own lobe, the skin's gloss and path 3 on
    one sized by the skin's (:func:`lobe_widths_deg`, :func:`lut_baker.closures.view_grid.
    view_grid`), so the cost does not depend on how narrow either lobe is."""
    report = progress or (lambda fraction, message="": None)
    report(0.0, "fitting the Principled tier")
    widths = lobe_widths_deg(tables)
    film_grid = view_grid(widths["film_gloss"], FIT_VIEWS)
    skin_grid = view_grid(widths["skin_gloss"], FIT_VIEWS)
    film_gloss = tables.surface_gloss("film_gloss", *film_grid.directions)
    skin_gloss = tables.surface_gloss("skin_gloss", *skin_grid.directions)
    path3 = tables.angular("path3_gloss", *skin_grid.directions)

    coat = fit_coat(film_grid, film_gloss)
    e_coat = cc.coat_view_terms(skin_grid.cos_view, coat.roughness, coat.ior)[1]
    specular_bare = fit_specular(skin_grid, skin_gloss)
    specular_film = fit_specular(skin_grid, path3, attenuation=1.0 - e_coat)
    # The node group mixes the two roughnesses by coverage: a dropped lobe (level 0) takes the
    # other's, so that mixing never sharpens the remaining lobe.
    if specular_film.level == 0.0:
        specular_film = replace(specular_film, roughness=specular_bare.roughness)
    elif specular_bare.level == 0.0:
        specular_bare = replace(specular_bare, roughness=specular_film.roughness)

    theta_deg = np.asarray(tables.theta_deg, float)
    transmittance = np.asarray(tables.film_transmittance, float)
    mu = lut_nodes(lut_size)
    t_rows = np.stack([np.interp(np.degrees(np.arccos(mu)), theta_deg, transmittance[:, c])
                       for c in range(3)], -1)

    def view_weighted(closures):
        """The three Glossy lobes fitted with ``closures``, and their view-angle image."""
        lobes = {name: fit_glossy(grid, table, np.asarray(getattr(tables, name + "_albedo")),
                                  theta_deg, lut_size, companion=name == "film_gloss",
                                  closures=closures)
                 for name, grid, table in (("film_gloss", film_grid, film_gloss),
                                           ("path3_gloss", skin_grid, path3),
                                           ("skin_gloss", skin_grid, skin_gloss))}
        image = np.stack([lobes[name].lut for name in LUT_ROWS[:3]]
                         + [t_rows, lobes["film_gloss"].diffuse_lut])
        return lobes, image

    report(0.3, "fitting the Layered tier's gloss lobes")
    glossy, lut = view_weighted(cc.GLOSSY_DISTRIBUTIONS)
    report(0.45, "fitting the EEVEE tier's gloss lobes")
    eevee_glossy, eevee_lut = view_weighted((EEVEE_GLOSSY,))

    report(0.6, "fitting the subsurface profile")
    ior = subsurface_ior(tables.parameters)
    profiles = fit_profiles(tables)
    if subsurface_method is None:
        subsurface_method = min(cc.SUBSURFACE_METHODS, key=lambda m: np.hypot(
            profiles[m].worst_error, REPLICA_EDGE_ERROR[m]))
    elif subsurface_method not in cc.SUBSURFACE_METHODS:
        raise ValueError(f"subsurface_method must be one of {cc.SUBSURFACE_METHODS}, "
                         f"got {subsurface_method!r}")

    def specular_mean(lobe):
        if lobe.level == 0.0:
            return 0.0
        f0 = float(cc.f0_from_ior(SPECULAR_IOR)) * 2.0 * lobe.level
        return _layering_mean(lobe.roughness, float(cc.ior_from_f0(f0)), f0)

    fit = ClosureFit(
        coat=coat,
        specular_bare=specular_bare,
        specular_film=specular_film,
        coat_albedo_mean=_coat_layering_mean(coat.roughness, coat.ior),
        specular_albedo_mean=(specular_mean(specular_bare), specular_mean(specular_film)),
        gloss_to_diffuse=(_cosine_mean(np.asarray(tables.path3_gloss_albedo), theta_deg)
                          if specular_film.level == 0.0 else np.zeros(3)),
        glossy=glossy,
        transmittance_mean=_cosine_mean(transmittance, theta_deg),
        film_albedo=np.pi * np.asarray(tables.film_diffuse, float),
        skin_albedo=np.pi * np.asarray(tables.skin_diffuse, float),
        profiles=profiles,
        subsurface_method=subsurface_method,
        subsurface_ior=ior,
        lut=lut,
        eevee_glossy=eevee_glossy,
        eevee_lut=eevee_lut,
    )
    if errors_at is None:
        errors_at = (float(tables.parameters.get("coverage", 1.0)),
                     tables.parameters.get("absorption", 0.0))
    report(0.8, "measuring the tiers' errors")
    fit = replace(fit, errors=tier_errors(fit, tables, *errors_at))
    report(1.0, "fitted")
    return fit


# --------------------------------------------------------------------------------------------
# The tiers at a coverage and absorption (the node group's formulas)
# --------------------------------------------------------------------------------------------
def _absorption(absorption) -> np.ndarray:
    return np.broadcast_to(np.asarray(absorption, float), (3,)).copy()


def diffuse_albedo(fit: ClosureFit, coverage: float, absorption) -> tuple[np.ndarray, np.ndarray]:
    """``(total, skin part)`` of the diffuse albedo per channel at coverage ``w`` and
    absorption ``A``: ``(1 - w) pi P_d,s + w [(1 - A) pi P_d,f + (1 - A)^2 pi P_d,s T_mean^2]``
    (:func:`~lut_baker.model.made_up_skin.coverage_weights`) and its skin terms (which the
    subsurface closure carries)."""
    weights = coverage_weights(coverage, _absorption(absorption))
    skin = combine(weights, twice=fit.skin_albedo * fit.transmittance_mean**2,
                   bare=fit.skin_albedo)
    return skin + combine(weights, once=fit.film_albedo), skin


def principled_inputs(fit: ClosureFit, coverage: float, absorption, gloss: float = 1.0):
    """``(PrincipledInputs, subsurface_weight)`` of the PRINCIPLED tier (the node group's math):

    - Coat Weight ``g w c`` (``c`` the coat's level: 1, or 0 without a coat), Coat
      Roughness/IOR fitted;
    - Roughness ``mix(r_bare, r_film, w)``, Specular IOR Level
      ``g [(1 - w) l_bare + w l_film mean((1 - A)^2)]``;
    - Base Color = (:func:`diffuse_albedo` + ``g w (1 - A)^2 gloss_to_diffuse``) /
      ``((1 - g w E_coat) (1 - g E_spec(w)))`` with the mean layering albedos,
      ``E_spec(w) = mix(E_bare, E_film, w)``;
    - Subsurface Weight = the skin's share of the diffuse albedo (channel mean).

    ``gloss`` (the group's Gloss input, 0..1) scales the gloss lobes: at 0 the coat weight
    and the specular level are 0, so Cycles allocates neither closure (``coat_weight >
    CLOSURE_WEIGHT_CUTOFF`` and ``eta != 1`` guard them in ``svm_node_closure_bsdf``), and the
    base colour is the diffuse albedo alone.  Between 0 and 1 the layer attenuation is taken
    linear in ``g`` (exact at both ends).
    """
    w = float(coverage)
    g = float(gloss)
    weights = coverage_weights(w, _absorption(absorption))
    bare, covered = weights.bare, weights.covered
    through2 = float(np.mean(weights.twice))
    total, skin = diffuse_albedo(fit, w, absorption)
    total = total + combine(weights, twice=g * fit.gloss_to_diffuse)
    e_spec = bare * fit.specular_albedo_mean[0] + covered * fit.specular_albedo_mean[1]
    coat = g * covered * fit.coat.level
    base = total / ((1.0 - coat * fit.coat_albedo_mean) * (1.0 - g * e_spec))
    level = g * (bare * fit.specular_bare.level + covered * fit.specular_film.level * through2)
    inputs = cc.PrincipledInputs(
        base_color=tuple(np.clip(base, 0.0, 1.0)),
        roughness=bare * fit.specular_bare.roughness + covered * fit.specular_film.roughness,
        ior=SPECULAR_IOR,
        specular_ior_level=level,
        coat_weight=coat,
        coat_roughness=fit.coat.roughness,
        coat_ior=fit.coat.ior,
    )
    weight = float(np.mean(skin / np.maximum(total, 1e-12)))
    return inputs, weight


def principled_tier_reflection(fit: ClosureFit, tables: Tables, coverage: float, absorption,
                               gloss: float = 1.0, directions=None):
    """The PRINCIPLED tier's BRDF, ``(..., 3)``: at the angular nodes, or at ``directions``
    ``(wi, wo)`` (local unit vectors); ``gloss``: the group's Gloss input."""
    wi, wo = tables.node_directions() if directions is None else directions
    inputs, _ = principled_inputs(fit, coverage, absorption, gloss)
    return cc.principled_reflection(wi, wo, inputs)


def layered_weights(fit: ClosureFit, coverage: float, absorption, gloss: float = 1.0) -> dict:
    """The LAYERED tier's constant weights (RGB) at coverage ``w`` and absorption ``A``;
    view-dependent factors come from the image rows :data:`LUT_ROWS`:

    - ``film_gloss``: ``g w``; ``path3_gloss``: ``g w (1 - A)^2``; ``skin_gloss``: ``g (1 - w)``
      (each times its row; ``g`` the group's Gloss input: at 0 the Glossy colours are 0 and
      Cycles allocates no Glossy closure, ``bsdf_alloc``'s weight cutoff);
    - ``film_diffuse``: ``w (1 - A) pi P_d,f`` (Diffuse); ``film_gloss_diffuse``: ``g w`` times
      its row, the film gloss's Lambertian companion, in the same Diffuse closure;
    - ``skin_through``: ``w (1 - A)^2 pi P_d,s T_mean`` (times row ``T``); ``skin_bare``:
      ``(1 - w) pi P_d,s`` (Subsurface).
    """
    g = float(gloss)
    weights = coverage_weights(float(coverage), _absorption(absorption))
    bare, covered = weights.bare, weights.covered
    one = np.ones(3)
    return {
        "film_gloss": g * covered * one,
        "path3_gloss": g * covered * weights.twice,
        "skin_gloss": g * bare * one,
        "film_diffuse": covered * weights.once * fit.film_albedo,
        "film_gloss_diffuse": g * covered * one,
        "skin_through": covered * weights.twice * fit.skin_albedo * fit.transmittance_mean,
        "skin_bare": bare * fit.skin_albedo,
    }


def _view_weighted_reflection(weights: dict, lobes: dict, lut: np.ndarray, lobe_of,
                              directions) -> np.ndarray:
    """The BRDF ``(..., 3)`` of closures added with constant ``weights`` and view-angle
    rows ``lut`` (:data:`LUT_ROWS`, linear between texel centres): the three Glossy ``lobes``
    (``lobe_of(wi, wo, lobe)``, white), one Lambertian term for the rest."""
    wi, wo = directions
    cos_o = wo[..., 2]
    rows = dict(zip(LUT_ROWS, lut, strict=True))
    value = 0.0
    for name in LUT_ROWS[:3]:
        if not np.any(weights[name]):
            continue  # no closure of weight 0 is allocated (Cycles) or picked (EEVEE)
        lobe = lobe_of(wi, wo, lobes[name])[..., None]
        value = value + lobe * weights[name] * sample_lut(rows[name], cos_o)
    diffuse = (weights["film_diffuse"] + weights["skin_bare"]
               + weights["film_gloss_diffuse"] * sample_lut(rows["film_gloss_diffuse"], cos_o)
               + weights["skin_through"] * sample_lut(rows["film_transmittance"], cos_o))
    return value + cc.lambert_reflection(diffuse)


def layered_tier_reflection(fit: ClosureFit, tables: Tables, coverage: float, absorption,
                            gloss: float = 1.0, directions=None):
    """The LAYERED tier's BRDF, ``(..., 3)``, at the angular nodes or at ``directions``
    ``(wi, wo)``: every closure added with its weight and image row (linear texel
    interpolation, as Blender samples it); ``gloss``: the group's Gloss input."""
    return _view_weighted_reflection(
        layered_weights(fit, coverage, absorption, gloss), fit.glossy, fit.lut,
        lambda wi, wo, lobe: cc.microfacet_reflection(wi, wo, lobe.roughness,
                                                      distribution=lobe.distribution),
        tables.node_directions() if directions is None else directions)


def eevee_weights(fit: ClosureFit, coverage: float, absorption, gloss: float = 1.0) -> dict:
    """The EEVEE tier's constant weights (RGB) at coverage ``w`` and absorption ``A``, by the
    names of :func:`layered_weights` and with its values: the EEVEE tier keeps the LAYERED
    tier's closures and areal mix (its own lobes and view-angle rows, ``fit.eevee_glossy``
    and ``fit.eevee_lut``), so the mix of the model (eq. 9, docs/model.md §3) is the same;
    ``g`` (the group's Gloss input) scales the three Glossy colours, and EEVEE picks no
    closure of weight 0."""
    return layered_weights(fit, coverage, absorption, gloss)


def eevee_tier_reflection(fit: ClosureFit, tables: Tables, coverage: float, absorption,
                          gloss: float = 1.0, directions=None):
    """The EEVEE tier's BRDF as EEVEE renders it under lamps, ``(..., 3)``, at the angular
    nodes or at ``directions`` ``(wi, wo)``: its Glossy closures as EEVEE's GGX
    (:func:`lut_baker.closures.eevee.glossy_reflection`), weighted by :func:`eevee_weights`
    and the rows of ``fit.eevee_lut`` (the node group interpolates them exactly as
    :func:`sample_lut` does), its Diffuse and Subsurface closures Lambertian."""
    return _view_weighted_reflection(
        eevee_weights(fit, coverage, absorption, gloss), fit.eevee_glossy, fit.eevee_lut,
        lambda wi, wo, lobe: eevee.glossy_reflection(wi, wo, lobe.roughness),
        tables.node_directions() if directions is None else directions)


TIER_REPLICAS = {"PRINCIPLED": principled_tier_reflection, "LAYERED": layered_tier_reflection,
                 "EEVEE": eevee_tier_reflection}
"""Each tier's replica, ``(fit, tables, coverage, absorption, gloss=1, directions=None)``:
the Cycles tiers as Cycles renders them, the EEVEE tier as EEVEE does."""


def tier_errors(fit: ClosureFit, tables: Tables, coverage: float, absorption,
                gloss: float = 1.0) -> dict:
    """:class:`TierError` of every tier against the tables at one coverage and absorption
    (``gloss``: the group's Gloss input; at 0 the error includes all of the gloss left out),
    on a :class:`lut_baker.closures.view_grid.ViewGrid` of :data:`ERROR_VIEWS` views that
    resolves the narrower of the two surfaces' gloss lobes."""
    grid = view_grid(min(lobe_widths_deg(tables).values()), ERROR_VIEWS)
    directions = grid.directions
    reference = tables.made_up_reflection(*directions, coverage, absorption)
    out = {}
    for tier, replica in TIER_REPLICAS.items():
        f = replica(fit, tables, coverage, absorption, gloss, directions)
        out[tier] = TierError(tier=tier, coverage=float(coverage),
                              absorption=tuple(_absorption(absorption).tolist()),
                              rms=grid.error(f, reference),
                              albedo=grid.albedo_error(f, reference))
    return out
