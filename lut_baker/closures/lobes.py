"""Lobes fitted to an angular part of the tables: the Principled coat and specular, and the
Glossy closures of the view-weighted tiers with their view-angle rows.

Fits run on a :class:`lut_baker.closures.view_grid.ViewGrid` sized by the lobe (a 1-degree
gloss costs what a 30-degree one does); the error is the relative RMS of the radiance
``L = f cos(theta_i)`` (docs/baking.md, "Errors").  Every search is Brent's, converged far
enough (:data:`FIT_XTOL`) that a fitted number follows its data continuously.

- :class:`LobeFit` -- a fitted lobe.
- :func:`fit_coat`, :func:`fit_specular` -- the Principled BSDF's coat (the film's gloss) and
  specular (the skin's gloss, bare or through the film).
- :func:`fit_glossy` -- a Glossy BSDF, its distribution, roughness and view-angle row (and, for
  a broad lobe, its Lambertian companion's row), as Cycles renders it or as EEVEE does
  (:data:`EEVEE_GLOSSY`, :func:`glossy_lobe`, :func:`glossy_albedo`).
- :func:`fit_glossy_pair` -- two of EEVEE's Glossy lobes and a Lambertian companion sharing a
  table's albedo (the EEVEE tier's film gloss).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from functools import lru_cache
from typing import TypedDict

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..numerics.optimise import brent_minimum, scanned_least_squares
from . import cycles as cc
from . import eevee
from .tier_formulas import SPECULAR_IOR
from .view_grid import ViewGrid
from .view_image import DEFAULT_IMAGE_SIZE, sample_row, texel_centres

__all__ = ["LobeFit", "fit_coat", "fit_specular", "fit_glossy", "ROUGHNESS_RANGE",
           "FIT_XTOL", "DISTRIBUTION_MARGIN", "COAT_IOR_RANGE", "SPECULAR_LEVEL_RANGE",
           "SEARCH_QUADRATURE", "FINAL_QUADRATURE", "PREVIEW_QUADRATURE", "NO_LOBE_ERROR",
           "EEVEE_GLOSSY",
           "glossy_lobe", "glossy_albedo", "fit_glossy_pair", "PAIR_RATIO", "PAIR_ALBEDO_SLACK",
           "PAIR", "SHARE_RIDGE"]

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
NO_LOBE_ERROR = 0.9
"""A specular fit erring more than this (relative RMS; leaving the lobe out errs 1.0) is
dropped and its albedo moved to the base colour."""
EEVEE_GLOSSY = "EEVEE_GGX"
"""The closure name :func:`fit_glossy` gives EEVEE's Glossy BSDF under a lamp
(:func:`lut_baker.closures.eevee.glossy_from_cosines`); the node is a GGX Glossy BSDF."""
SPECULAR_LEVEL_RANGE = (0.0, 8.0)
"""Specular IOR Level searched (0.5 leaves IOR 1.5 as it is; F0 = 0.04 * 2 level)."""


@dataclass(frozen=True)
class LobeFit:
    """A GGX lobe fitted to an angular part of the tables.

    ``roughness``: Blender's Roughness; ``ior``: Coat IOR (coat) or the IOR whose F0 the
    Specular IOR Level sets (specular), None for a Glossy BSDF; ``level``: Specular IOR Level
    (specular only; 0 when no lobe beats leaving the gloss out); ``weights``: the Glossy weight per
    view-angle texel, ``(size, 3)`` (Glossy only); ``distribution``: ``GGX``, ``BECKMANN`` or
    ``ASHIKHMIN_SHIRLEY`` (Glossy only; the Principled BSDF is GGX); ``diffuse_weights``: the
    weight of its Lambertian companion per texel, ``(size, 3)``, or None (:func:`fit_glossy`);
    ``error``: relative RMS of this lobe against its target (module docstring);
    ``searched``: each Glossy distribution's error in the search, by name (Glossy only: what
    the choice of distribution compares).
    """

    roughness: float
    error: float
    ior: float | None = None
    level: float | None = None
    weights: np.ndarray | None = None
    distribution: str = "GGX"
    diffuse_weights: np.ndarray | None = None
    searched: dict | None = None


def _grey(values: ArrayLike) -> NDArray[np.float64]:
    """Per-pair values ``(V, A, P[, C])`` with their channels averaged, ``(V, A, P)``."""
    array = np.asarray(values, float)
    return np.mean(array, axis=-1) if array.ndim == 4 else array


def _minimise_roughness(error_of: Callable[[float], float]) -> tuple[float, float]:
    """``(roughness, error)``: ``error_of(roughness)`` minimised over :data:`ROUGHNESS_RANGE`,
    in ``log(roughness)`` (a lobe's width goes as roughness squared)."""
    log_r, error = brent_minimum(lambda x: error_of(float(np.exp(x))),
                                 *np.log(ROUGHNESS_RANGE), coarse=ROUGHNESS_SCAN, xtol=FIT_XTOL)
    return float(np.exp(log_r)), error


LobeTimes = Callable[[float], Callable[[float], NDArray[np.float64]]]
"""``lobe_times(roughness)(second)``: the factor per pair a GGX lobe is multiplied by."""


def _per_value(compute: Callable[[float], NDArray[np.float64]]
               ) -> Callable[[float], NDArray[np.float64]]:
    """``compute`` remembered by its argument: the scan of :func:`_fit_roughness_and` asks for
    the same :data:`SECOND_SCAN` values of the second parameter at every roughness."""
    found: dict[float, NDArray[np.float64]] = {}

    def once(value: float) -> NDArray[np.float64]:
        value = float(value)
        if value not in found:
            found[value] = compute(value)
        return found[value]
    return once


def _fit_roughness_and(grid: ViewGrid, target: ArrayLike, lobe_times: LobeTimes,
                       second_range: tuple[float, float]) -> tuple[float, float, float]:
    """``(roughness, second, error)``: a GGX lobe times ``lobe_times(roughness)(second)`` (a
    factor per pair) fitted to ``target`` (channels averaged).  A scan of
    :data:`ROUGHNESS_SCAN` roughnesses by :data:`SECOND_SCAN` values of the second parameter
    finds the start; bounded Levenberg-Marquardt on ``(log(roughness), second)`` converges
    from it (:func:`lut_baker.numerics.optimise.least_squares`, to :data:`FIT_XTOL`)."""
    grey = _grey(target)
    root_weight = np.sqrt(grid.weight) * grid.cos_i
    scale = 1.0 / max(float(np.sqrt(np.sum(np.square(root_weight * grey)))), 1e-300)

    # the lobe and its factor's set-up, once per roughness tried
    per_roughness: dict[float, tuple[NDArray[np.float64],
                                     Callable[[float], NDArray[np.float64]]]] = {}

    def model(x: NDArray[np.float64]) -> NDArray[np.float64]:
        roughness = float(np.exp(x[0]))
        if roughness not in per_roughness:
            per_roughness[roughness] = (grid.lobe(roughness), lobe_times(roughness))
        lobe, factor = per_roughness[roughness]
        return lobe * factor(float(x[1]))

    def residuals(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return (scale * root_weight * (model(x) - grey)).ravel()

    low, high = np.log(ROUGHNESS_RANGE)
    x, cost, _ = scanned_least_squares(
        residuals, (np.linspace(low, high, ROUGHNESS_SCAN),
                    np.linspace(second_range[0], second_range[1], SECOND_SCAN)), xtol=FIT_XTOL)
    return float(np.exp(x[0])), float(x[1]), float(np.sqrt(cost))


def _search_average_albedo(grid: ViewGrid, albedo: NDArray[np.float64]) -> float:
    """The coat search's ``E_avg = 2 Int E(mu) mu dmu`` (Cycles' ``ggx_Eavg``,
    :func:`lut_baker.closures.cycles.ggx_average_albedo`) from the albedo ``E`` it has at
    ``grid``'s views, the midpoints of ``cos(theta_o)`` in [0, 1]: the midpoint rule, within
    1.5e-3 of the 32-node one (the search's ``E`` is within 2%)."""
    return float(2.0 * np.mean(albedo * grid.cos_view))


def fit_coat(grid: ViewGrid, target: ArrayLike) -> LobeFit:
    """Coat Roughness and Coat IOR of a GGX coat (weight 1, dielectric Fresnel, Cycles'
    energy compensation) fitted to ``target`` (the film's gloss on ``grid``, ``(V, A, P[, 3])``,
    channels averaged).  ``level`` is the coat's weight per unit coverage: 1, or 0 when the
    film has no gloss (a matte product) or no coat does much better than none
    (:data:`NO_LOBE_ERROR`)."""
    if not np.any(np.asarray(target, float)):
        return LobeFit(roughness=ROUGHNESS_RANGE[1], ior=COAT_IOR_RANGE[0], level=0.0,
                       error=0.0)
    fresnel = _per_value(lambda ior: cc.dielectric_fresnel(grid.cos_hi, ior))

    def lobe_times(roughness: float) -> Callable[[float], NDArray[np.float64]]:
        albedo = glossy_albedo(grid.cos_view, roughness, "GGX", final=False)
        average = _search_average_albedo(grid, albedo)

        def factor(ior: float) -> NDArray[np.float64]:
            scale = cc.ggx_energy_scale(albedo, average, float(cc.dielectric_fss(ior)))[0]
            return fresnel(ior) * scale[:, None, None]
        return factor

    roughness, ior, error = _fit_roughness_and(grid, target, lobe_times, COAT_IOR_RANGE)
    if error >= NO_LOBE_ERROR:
        return LobeFit(roughness=roughness, ior=ior, level=0.0, error=1.0)
    return LobeFit(roughness=roughness, ior=ior, level=1.0, error=error)


def _specular_fresnel(cos_hi: NDArray[np.float64], level: float) -> NDArray[np.float64]:
    """The Principled specular's Fresnel at IOR :data:`SPECULAR_IOR` and a Specular IOR
    Level."""
    f0 = float(cc.f0_from_ior(SPECULAR_IOR)) * 2.0 * level
    eta = float(cc.ior_from_f0(f0)) if level != 0.5 else SPECULAR_IOR
    return cc.schlick_ior_fresnel(cos_hi, eta, f0)


def fit_specular(grid: ViewGrid, target: ArrayLike,
                 attenuation: ArrayLike | None = None) -> LobeFit:
    """Roughness and Specular IOR Level (at IOR :data:`SPECULAR_IOR`) of the Principled
    specular fitted to ``target`` ``(V, A, P[, 3])`` (channels averaged).  ``attenuation``:
    the factor the layers above apply to it per view ``(V,)`` (the coat's ``1 - E_coat``), or
    None."""
    scale: float | NDArray[np.float64] = (1.0 if attenuation is None
                                          else np.asarray(attenuation, float)[:, None, None])

    fresnel = _per_value(lambda level: scale * _specular_fresnel(grid.cos_hi, level))

    def lobe_times(roughness: float) -> Callable[[float], NDArray[np.float64]]:
        return fresnel

    roughness, level, error = _fit_roughness_and(grid, target, lobe_times,
                                                 SPECULAR_LEVEL_RANGE)
    if error >= NO_LOBE_ERROR:  # no lobe does much better than none: leave it to the diffuse
        return LobeFit(roughness=roughness, ior=SPECULAR_IOR, level=0.0, error=1.0)
    return LobeFit(roughness=roughness, ior=SPECULAR_IOR, level=level, error=error)


class AlbedoQuadrature(TypedDict):
    """Nodes of :func:`lut_baker.closures.cycles.microfacet_albedo`: ``n_u`` over the facet
    distribution, ``n_phi`` in azimuth."""

    n_u: int
    n_phi: int


SEARCH_QUADRATURE: AlbedoQuadrature = {"n_u": 24, "n_phi": 12}
"""Closure-albedo quadrature of the coat's search, at the grid's views (within 2%; its
energy compensation's mean albedo from them, :func:`_search_average_albedo`); the Glossy
weights use :data:`FINAL_QUADRATURE` (within 0.1%) at every texel (while searching, the
grid's own integral: :func:`_search_glossy_albedo`)."""
FINAL_QUADRATURE: AlbedoQuadrature = {"n_u": 96, "n_phi": 64}
PREVIEW_QUADRATURE: AlbedoQuadrature = {"n_u": 48, "n_phi": 32}
"""The Glossy weights' closure albedo in a preview's fit (:func:`fit_glossy`'s ``preview``):
within 0.5% of :data:`FINAL_QUADRATURE`, a quarter of its cost."""


def _texel_albedo(albedo_table: np.ndarray, theta_deg: np.ndarray,
                  cos_view: NDArray[np.float64]) -> NDArray[np.float64]:
    """A directional albedo table ``(n_theta, 3)`` on ``theta_deg`` at view cosines
    ``cos_view`` ``(K,)``: ``(K, 3)``."""
    theta = np.degrees(np.arccos(np.clip(cos_view, 0.0, 1.0)))
    return np.stack([np.interp(theta, theta_deg, albedo_table[:, c]) for c in range(3)], -1)


def _companion_share(grid: ViewGrid, table_albedo: np.ndarray, target: np.ndarray
                     ) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """``share(lobe, closure_albedo)``: the share ``s`` (per view of ``grid``, in [0, 1]) of
    a table's albedo ``A`` that the Glossy lobe carries when a Lambertian companion carries
    the rest: weights ``a = s A / E`` (Glossy, ``E`` its albedo) and ``b = (1 - s) A``
    (Diffuse), so ``a E + b = A`` at every view.  ``s`` minimises ``|a lobe cos_i + b cos_i /
    pi - target cos_i|`` over the lights of each view (closed form).  ``lobe`` and ``target``
    grey ``(V, A, P)``, the albedos at the views ``(V,)``; what depends on the table alone is
    computed once (a search tries many lobes)."""
    a = table_albedo[:, None, None]
    lam = grid.cos_i / np.pi
    v = target * grid.cos_i - a * lam
    w = grid.weight

    def share(lobe: np.ndarray, closure_albedo: np.ndarray) -> np.ndarray:
        e = closure_albedo[:, None, None]
        u = a / np.maximum(e, 1e-6) * (lobe * grid.cos_i - e * lam)
        weighted = w * u
        num = np.sum(weighted * v, axis=(1, 2))
        den = np.sum(weighted * u, axis=(1, 2))
        return np.clip(np.where(den > 0.0, num / np.where(den > 0.0, den, 1.0), 1.0), 0.0, 1.0)
    return share


def glossy_lobe(grid: ViewGrid, roughness: float, closure: str) -> np.ndarray:
    """A white Glossy closure's BRDF at ``grid``'s pairs, ``(V, A, P)``: Cycles' distribution
    ``closure`` (:data:`lut_baker.closures.cycles.GLOSSY_DISTRIBUTIONS`) or, for
    :data:`EEVEE_GLOSSY`, EEVEE's GGX under a lamp."""
    if closure == EEVEE_GLOSSY:
        return eevee.glossy_from_cosines(grid.wi, grid.cos_o, roughness)
    return grid.lobe(roughness, closure)


def glossy_albedo(cos_view: ArrayLike, roughness: float, closure: str, *,
                  final: bool = True, preview: bool = False) -> NDArray[np.float64]:
    """The albedo of :func:`glossy_lobe`'s closure at view cosines: by quadrature over
    normals for Cycles' (:data:`FINAL_QUADRATURE`, :data:`PREVIEW_QUADRATURE` for a
    ``preview``, or :data:`SEARCH_QUADRATURE` while searching), in closed form for EEVEE's."""
    if closure == EEVEE_GLOSSY:
        return eevee.glossy_albedo(cos_view, roughness)
    if not final:
        views = np.ascontiguousarray(cos_view, float)
        return _search_albedo(views.tobytes(), views.shape, float(roughness), closure)
    return cc.microfacet_albedo(cos_view, roughness, distribution=closure,
                                **(PREVIEW_QUADRATURE if preview else FINAL_QUADRATURE))


SEARCH_ALBEDOS = 256
"""Closure albedos at :data:`SEARCH_QUADRATURE` kept for the session (0.1 kB each): every
coat search starts on the same roughnesses at the same views (:data:`ROUGHNESS_SCAN`,
:data:`lut_baker.closures.view_grid.FIT_VIEWS`)."""


@lru_cache(maxsize=SEARCH_ALBEDOS)
def _search_albedo(views: bytes, shape: tuple, roughness: float,
                   closure: str) -> NDArray[np.float64]:
    """:func:`glossy_albedo` while searching, by the views' bytes (read-only: shared)."""
    albedo = cc.microfacet_albedo(np.frombuffer(views).reshape(shape), roughness,
                                  distribution=closure, **SEARCH_QUADRATURE)
    albedo.setflags(write=False)
    return albedo


def _search_glossy_albedo(grid: ViewGrid, lobe: NDArray[np.float64], roughness: float,
                          closure: str) -> NDArray[np.float64]:
    """A Glossy closure's albedo at ``grid``'s views while :func:`fit_glossy` searches: the
    grid's own integral of its ``lobe`` (:meth:`ViewGrid.view_albedo`, a sum over pairs the
    search has at hand) for Cycles' distributions, so that each weighted lobe carries the
    table's albedo on the grid that measures it; EEVEE's closed form
    (:func:`glossy_albedo`).  A lobe narrower than the grid resolves gets an albedo far off,
    and so errs far more than the lobes the grid is sized for: the search never ends there."""
    if closure == EEVEE_GLOSSY:
        return glossy_albedo(grid.cos_view, roughness, closure)
    return grid.view_albedo(lobe)


def fit_glossy(grid: ViewGrid, target: ArrayLike, albedo_table: np.ndarray,
               theta_deg: np.ndarray, size: int = DEFAULT_IMAGE_SIZE, *, companion: bool = False,
               closures: tuple[str, ...] = cc.GLOSSY_DISTRIBUTIONS,
               preview: bool = False) -> LobeFit:
    """Distribution (:data:`lut_baker.closures.cycles.GLOSSY_DISTRIBUTIONS`) and roughness of a
    Glossy BSDF whose view-dependent weight (table albedo / closure albedo, read from a
    ``size``-texel image by ``cos(theta_o)``) best reproduces ``target`` ``(V, A, P[, 3])``;
    ``albedo_table`` ``(n_theta, 3)`` on ``theta_deg``.

    ``companion``: the albedo is shared with a Lambertian companion, in the proportion that
    fits each view best (:func:`_companion_share`); the weights are then ``weights`` (Glossy) and
    ``diffuse_weights`` (Diffuse), whose albedos still add up to the table's at every view.  A
    broad lobe whose radiance keeps a ``cos(theta_i)`` factor (the paper's film gloss) is
    part Lambertian, which no Glossy closure alone reproduces.

    ``closures``: the Glossy closures to choose from (:func:`glossy_lobe`): Cycles'
    distributions (default), or ``(EEVEE_GLOSSY,)`` for the EEVEE tier.  The first of them
    (GGX) is chosen unless another one's error is lower by more than
    :data:`DISTRIBUTION_MARGIN` (relative): a near tie never flips the choice.  The fit's
    ``distribution`` is the Glossy node's (``GGX`` for EEVEE's closure).

    ``preview``: a preview's fit, soon replaced by a refined one: the weights' closure albedo
    by :data:`PREVIEW_QUADRATURE` (the searches to :data:`FIT_XTOL` as every fit's, so that a
    preview's fit too moves continuously with its data)."""
    values = np.asarray(target, float)
    values = values if values.ndim == 4 else values[..., None]
    values = values * np.ones(3)
    grey = _grey(values)
    if not np.any(albedo_table):  # no gloss (a matte film): weights 0, nothing to fit
        zeros = np.zeros((size, 3))
        return LobeFit(roughness=ROUGHNESS_RANGE[1], error=0.0, weights=zeros,
                       diffuse_weights=zeros.copy() if companion else None)
    texels = texel_centres(size)
    tables = {False: _texel_albedo(albedo_table, theta_deg, grid.cos_view),
              True: _texel_albedo(albedo_table, theta_deg, texels)}
    shares = (_companion_share(grid, np.mean(tables[False], axis=-1), grey) if companion
              else None)
    error_of = grid.error_to(values)

    def weights(roughness: float, distribution: str, final: bool
                ) -> tuple[NDArray[np.float64], NDArray[np.float64] | None,
                           NDArray[np.float64]]:
        """``(glossy, diffuse_weights or None, value on the grid)`` for one lobe: while searching
        (``final`` False) the weights sit at the grid's views, the closure's albedo the grid's
        own integral of the lobe (:func:`_search_glossy_albedo`); the final ones at the
        image's texels, sampled as Blender samples them."""
        shape = glossy_lobe(grid, roughness, distribution)
        closure = (glossy_albedo(texels, roughness, distribution, preview=preview) if final
                   else _search_glossy_albedo(grid, shape, roughness, distribution))
        table = tables[final]
        glossy = table / np.maximum(closure, 1e-6)[:, None]
        diffuse = None
        if shares is not None:
            e_views = np.interp(grid.cos_view, texels, closure) if final else closure
            share = shares(shape, e_views)
            share = np.interp(texels, grid.cos_view, share) if final else share
            diffuse = (1.0 - share)[:, None] * table
            glossy = share[:, None] * glossy
        rows = ((lambda row: sample_row(row, grid.cos_o)) if final
                else (lambda row: row[:, None, None, :]))
        value = shape[..., None] * rows(glossy)
        if diffuse is not None:
            value = value + rows(diffuse) / np.pi
        return glossy, diffuse, value

    def search(distribution: str) -> tuple[float, float]:
        return _minimise_roughness(lambda r: error_of(weights(r, distribution, False)[2]))

    searched = {distribution: search(distribution) for distribution in closures}
    distribution = min(searched, key=lambda d: searched[d][1])
    if searched[distribution][1] >= (1.0 - DISTRIBUTION_MARGIN) * searched[closures[0]][1]:
        distribution = closures[0]
    roughness = searched[distribution][0]
    glossy, diffuse, value = weights(roughness, distribution, True)
    node = "GGX" if distribution == EEVEE_GLOSSY else distribution
    return LobeFit(roughness=roughness, error=error_of(value), weights=glossy,
                   distribution=node, diffuse_weights=diffuse,
                   searched={("GGX" if name == EEVEE_GLOSSY else name): float(found[1])
                             for name, found in searched.items()})


PAIR_RATIO = 1.26
"""The ratio of :func:`fit_glossy_pair`'s two roughnesses: where a fit of both roughnesses
lands on the paper film (0.516 and 0.651).  Fitted freely, the pair moves by 2e-6 when the
tables move by 1e-9 (a valley the data hardly determine), so the ratio is held."""
PAIR_ALBEDO_SLACK = 0.05
"""How far (relative) :func:`fit_glossy_pair`'s closures may move the film gloss's albedo
from the table's at a view, to follow its shape closer."""
PAIR = "GGX x2"
"""The name :func:`fit_glossy_pair` gives two lobes in a fit's ``searched`` errors (beside
``GGX``, one lobe): the choice between them is kept as a distribution choice is."""
SHARE_RIDGE = 1e-3
"""Ridge (relative to the mean diagonal of the normal equations) on :func:`_albedo_shares`:
two lobes of similar width are nearly collinear, and without it their split would amplify a
change of the data a thousandfold."""


def _spd_solve(matrix: np.ndarray, right: np.ndarray) -> np.ndarray:
    """``x`` with ``matrix x = right`` per view (``(V, n, n)`` symmetric positive definite,
    ``(V, n, m)``): Gaussian elimination without pivoting, in element-wise arithmetic only, so
    that the result does not depend on the BLAS library or its threads."""
    a, b = matrix.astype(float).copy(), right.astype(float).copy()
    n = a.shape[-1]
    for k in range(n):
        for i in range(k + 1, n):
            factor = a[:, i, k] / a[:, k, k]
            a[:, i, k:] -= factor[:, None] * a[:, k, k:]
            b[:, i] -= factor[:, None] * b[:, k]
    x = np.zeros_like(b)
    for k in range(n - 1, -1, -1):
        x[:, k] = (b[:, k] - np.einsum("vj,vjm->vm", a[:, k, k + 1:], x[:, k + 1:])) \
            / a[:, k, k, None]
    return x


def _face_minimum(gram: np.ndarray, right: np.ndarray,
                  total: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
    """Per view, the non-negative ``f`` ``(V, K)`` that minimises ``f G f - 2 r f`` (``gram``
    ``(V, K, K)``, positive definite; ``right`` ``(V, K)``), with ``sum(f) = total`` ``(V,)``
    if given: a convex quadratic, minimised exactly (the optimum on every face of the orthant,
    the best feasible one), so that ``f`` follows the data continuously.  On a face the
    optimum is ``G^-1 r`` plus, with the sum held, the multiple of ``G^-1 1`` that meets it."""
    views, count = right.shape
    faces = [np.flatnonzero([(mask >> k) & 1 for k in range(count)])
             for mask in range(1, 2 ** count)]
    # Every face's optimum, the faces of one size solved together (their views stacked).
    candidates = np.zeros((len(faces), views, count))
    for size in range(1, count + 1):
        group = [i for i, face in enumerate(faces) if face.size == size]
        grams = np.concatenate([gram[:, faces[i]][:, :, faces[i]] for i in group])
        both = np.concatenate([np.stack([right[:, faces[i]], np.ones((views, size))], axis=-1)
                               for i in group])
        solved = _spd_solve(grams, both).reshape(len(group), views, size, 2)
        solution = solved[..., 0]
        if total is not None:
            ones = solved[..., 1]
            solution = solution + ((np.asarray(total, float) - solution.sum(axis=-1))
                                   / ones.sum(axis=-1))[..., None] * ones
        for j, i in enumerate(group):
            candidates[i][:, faces[i]] = solution[j]
    cost = (np.einsum("fvk,vkj,fvj->fv", candidates, gram, candidates)
            - 2.0 * np.einsum("vk,fvk->fv", right, candidates))
    feasible = np.all(candidates >= 0.0, axis=-1) & ~np.isnan(cost)
    ranked = np.where(feasible, cost, np.inf)
    if total is None:  # f = 0 is feasible, at cost 0
        ranked = np.concatenate([np.zeros((1, views)), ranked])
        candidates = np.concatenate([np.zeros((1, views, count)), candidates])
    # The first face, in the order above, of the least cost (a tie keeps the earlier one).
    best = np.argmin(ranked, axis=0)
    shares = candidates[best, np.arange(views)]
    shares[~np.isfinite(ranked[best, np.arange(views)])] = 0.0  # no feasible face
    return shares


def _albedo_shares(grid: ViewGrid, models: list, target: np.ndarray,
                   slack: float) -> np.ndarray:
    """Per view of ``grid``, the shares ``f`` ``(V, K)`` (non-negative) that minimise
    ``|sum_k f_k m_k cos_i - target cos_i|`` over the lights (the grid's measure, with a
    :data:`SHARE_RIDGE`), ``models`` the closures' BRDFs ``(V, A, P)`` when each carries the
    whole table albedo, with ``|sum(f) - 1| <= slack``: the closures' albedo within ``slack``
    (relative) of the table's at every view.  Convex: the optimum without the albedo bound
    where it keeps the bound, else on the bound's nearer side (:func:`_face_minimum`)."""
    weight = grid.weight * np.square(grid.cos_i)
    stacked = np.stack(models, axis=1)  # (V, K, A, P)
    gram = np.einsum("vkap,vjap,vap->vkj", stacked, stacked, weight)
    # The ridge keeps every view solvable, one where the table's albedo is 0 as well.
    diagonal = np.maximum(np.einsum("vkk->vk", gram).mean(axis=1), 1e-300)
    gram = gram + SHARE_RIDGE * diagonal[:, None, None] * np.eye(len(models))
    right = np.einsum("vkap,vap,vap->vk", stacked, target, weight)
    free = _face_minimum(gram, right)
    total = np.clip(free.sum(axis=1), 1.0 - slack, 1.0 + slack)
    bounded = _face_minimum(gram, right, total)
    return np.where((np.abs(free.sum(axis=1) - 1.0) <= slack)[:, None], free, bounded)


def fit_glossy_pair(grid: ViewGrid, target: ArrayLike, albedo_table: np.ndarray,
                    theta_deg: np.ndarray,
                    size: int = DEFAULT_IMAGE_SIZE, *,
                    slack: float = PAIR_ALBEDO_SLACK,
                    ratio: float = PAIR_RATIO) -> tuple[LobeFit, LobeFit]:
    """One or two of EEVEE's Glossy lobes (:data:`EEVEE_GLOSSY`) and a Lambertian companion
    sharing the table's albedo ``A`` view by view (the EEVEE tier's film gloss): weights
    ``a_k = f_k A / E_k`` (``E_k`` the lobes' albedos) and ``b = f_c A``, the shares ``f``
    non-negative and adding up to within ``slack`` of 1 (:func:`_albedo_shares`), so that the
    closures' albedo stays that close to the table's at every view.  Two lobes have
    roughnesses ``r / sqrt(ratio)`` and ``r sqrt(ratio)`` (:data:`PAIR_RATIO`), both within
    :data:`ROUGHNESS_RANGE`; one lobe's roughness or two lobes' ``r`` is found by Brent's
    search.  The pair is kept when it errs less than the one lobe by more than
    :data:`DISTRIBUTION_MARGIN` (relative); else the second lobe has weight 0 and the first's
    roughness.

    Returns ``(first, second)``: the first holds its row and the companion's (``weights``,
    ``diffuse_weights``) and, in ``searched``, both errors (``GGX`` and :data:`PAIR`); the second
    its row.  EEVEE draws only GGX and drops a closure of negative colour, so no lobe can cut
    another's tail: a broad gloss whose radiance keeps ``cos(theta_i)`` (the paper film's) is
    followed closer by two lobes of different widths than by one, and a short-tailed narrow
    one (Clarins 112's) by a lobe whose albedo may give a little (docs/addon.md, "The EEVEE
    tier")."""
    if not np.any(albedo_table):  # no gloss (a matte film): weights 0, nothing to fit
        zeros = np.zeros((size, 3))
        empty = LobeFit(roughness=ROUGHNESS_RANGE[1], error=0.0, weights=zeros)
        return replace(empty, diffuse_weights=zeros.copy()), replace(empty, weights=zeros.copy())
    values = np.asarray(target, float)
    values = (values if values.ndim == 4 else values[..., None]) * np.ones(3)
    grey = _grey(values)
    texels = texel_centres(size)
    at_views = np.mean(_texel_albedo(albedo_table, theta_deg, grid.cos_view), axis=-1)
    lambert = np.broadcast_to(1.0 / np.pi, grid.cos_i.shape) * at_views[:, None, None]
    root_weight = np.sqrt(grid.weight) * grid.cos_i
    scale = 1.0 / max(float(np.sqrt(np.sum(np.square(root_weight * grey)))), 1e-300)

    # a lobe carrying the table's albedo, once per roughness tried
    carrying: dict[float, NDArray[np.float64]] = {}

    def models(roughnesses: Sequence[float]) -> list[NDArray[np.float64]]:
        for r in roughnesses:
            if r not in carrying:
                albedo = glossy_albedo(grid.cos_view, r, EEVEE_GLOSSY)
                carrying[r] = (glossy_lobe(grid, r, EEVEE_GLOSSY)
                               * (at_views / np.maximum(albedo, 1e-6))[:, None, None])
        return [carrying[r] for r in roughnesses] + [lambert]

    def residuals_of(roughnesses: Sequence[float]) -> NDArray[np.float64]:
        found = models(roughnesses)
        shares = _albedo_shares(grid, found, grey, slack)
        value = sum(shares[:, k, None, None] * m for k, m in enumerate(found))
        return (scale * root_weight * (value - grey)).ravel()

    def pair(r: float) -> list:
        return [float(r / np.sqrt(ratio)), float(r * np.sqrt(ratio))]

    table = _texel_albedo(albedo_table, theta_deg, texels)

    def result(roughnesses: Sequence[float]) -> tuple[float, list, np.ndarray]:
        """The error on the grid, the Glossy rows and the companion's row."""
        shares = _albedo_shares(grid, models(roughnesses), grey, slack)
        at_texels = np.stack([np.interp(texels, grid.cos_view, shares[:, k])
                              for k in range(len(roughnesses) + 1)], -1)
        rows = [at_texels[:, k, None] * table
                / np.maximum(glossy_albedo(texels, r, EEVEE_GLOSSY), 1e-6)[:, None]
                for k, r in enumerate(roughnesses)]
        companion = at_texels[:, -1, None] * table
        fitted = (sum(glossy_lobe(grid, r, EEVEE_GLOSSY)[..., None]
                      * sample_row(row, grid.cos_o)
                      for r, row in zip(roughnesses, rows, strict=True))
                  + sample_row(companion, grid.cos_o) / np.pi)
        return grid.error(fitted, values), rows, companion

    def cost(roughnesses: Sequence[float]) -> float:  # np.sum, not BLAS: same everywhere
        return float(np.sqrt(np.sum(np.square(residuals_of(roughnesses)))))

    one = [_minimise_roughness(lambda r: cost([r]))[0]]
    # r within the range that keeps both lobes' roughness in ROUGHNESS_RANGE.
    low, high = np.log(ROUGHNESS_RANGE) + np.array([0.5, -0.5]) * np.log(ratio)
    log_r, _ = brent_minimum(lambda x: cost(pair(np.exp(x))), low, high,
                             coarse=ROUGHNESS_SCAN, xtol=FIT_XTOL)
    two = pair(float(np.exp(log_r)))
    (one_error, one_rows, one_companion), (two_error, two_rows, two_companion) = (
        result(one), result(two))
    searched = {"GGX": one_error, PAIR: two_error}
    if two_error >= (1.0 - DISTRIBUTION_MARGIN) * one_error:
        first = LobeFit(roughness=one[0], error=one_error, weights=one_rows[0],
                        diffuse_weights=one_companion, searched=searched)
        return first, LobeFit(roughness=one[0], error=one_error, weights=np.zeros((size, 3)))
    first = LobeFit(roughness=two[0], error=two_error, weights=two_rows[0],
                    diffuse_weights=two_companion, searched=searched)
    return first, LobeFit(roughness=two[1], error=two_error, weights=two_rows[1])
