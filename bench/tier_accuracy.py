"""The tiers' errors against the exact made-up skin, per foundation preset, for any checkout (a
benchmark, not a test).

    python bench/tier_accuracy.py --repo CHECKOUT [--json FILE] [--presets A B ...]
                                  [--coverages 1 0.5] [--cache DIR] [--no-refine]
    python bench/tier_accuracy.py --before FILE --after FILE

For each foundation of the checkout's ``lut_baker.model.presets.FOUNDATIONS`` on the skin
``paper_bioplate``: bake and fit as Apply does (``bake(made_up_skin(foundation, skin, coverage=1,
absorption=0), "default")``, ``fit_closures(tables)``), then compare each tier's BRDF replica
(``closures.tiers.tier_replica(fit, tables, tier, coverage, absorption, 1, directions)``) with
the exact made-up skin (``evaluate.made_up.made_up_reflection`` of ``made_up_skin(foundation,
skin, coverage=w, absorption=the preset's)``) at coverages 1 and 0.5.

The measures are those of ``closures.fitting`` (``relative_rms``, ``albedo_error``), with the
integrals taken by a quadrature that resolves the narrowest lobe instead of on the tables' grid:

- ``rms`` -- relative RMS of the radiance ``f cos(theta_i)``, weighted by ``sin(theta_i)``
  (light directions uniform over the hemisphere) times ``cos(theta_o) dw_o`` (the view measure),
  channels pooled;
- ``albedo`` -- the largest relative error of the view albedo ``Int f cos(theta_i) dw_i`` over
  the view angles :data:`ALBEDO_ANGLES_DEG` (0 to 89 degrees) and channels.

The quadrature (:class:`HalfVectorQuadrature`): incidence ``theta_i`` on Gauss-Legendre panels
over [0, 89] degrees (``wi`` at azimuth 0); ``wo`` through the half vector ``h`` (``wo`` =
``2 (wi.h) h - wi``, ``dw_o = 4 (wi.h) dw_h``), its polar angle on Gauss-Legendre panels
concentrated within five widths of the preset's narrowest lobe (``1/n`` degrees over the film,
its transmission and the skin: the facet distribution of eq. 2 is ``exp(-(alpha n)^2)`` in the
half vector's polar angle ``alpha``) and panels of at most 15 degrees beyond, cut at 45 -
theta_i/2 and ending at 45 + theta_i/2 degrees (where ``wo`` begins and ends to cross the
horizon); its azimuth (from ``wi``'s; the BRDFs are even in it, so one half turn counted twice) by
Gauss-Legendre from 0 to where ``wo`` meets the horizon (:func:`horizon_azimuth`), so that no
node falls below it and the integrand has no kink.  The view albedo is integrated the same
way with the roles of ``wi`` and ``wo`` swapped, at fixed view angles.  Checked per preset: the
errors with twice the nodes on every axis (``refined``: their relative change), and known
integrals: ``Int cos(theta_o) dw_o = pi``, the film's (or for a film without gloss the skin's)
eq. 2 gloss albedo against ``model.albedo.reflection_albedo`` (levels 0 and 1) and the exact
model's directional albedo against ``evaluate.made_up.directional_albedo``, all at
:data:`ALBEDO_ANGLES_DEG`.

The exact values: ``made_up_reflection`` costs ~17 ms per direction pair (path 3 by Fourier
matrices on its own grid), too slow for 10^5 pairs.  Its path 3 is evaluated here from the same
Fourier matrices (``evaluate.two_layer.layered_fourier_matrices`` on ``model.albedo.grid_for``'s
grid, level 0, as ``made_up_reflection`` uses) at the quadrature's incidences and 181 view angles
(0.5 degrees apart; a cubic spline between them, within 1e-9 of the matrices), summed over the
azimuth orders, and paths 1 and bare skin in closed form, mixed by ``coverage_weights``; each
computation is checked against ``made_up_reflection`` itself at 64 random pairs of the
quadrature (largest difference in the JSON; more than 1e-6 of the peak stops the run), and so
is its reciprocity (the view albedo uses ``f(wi, wo) = f(wo, wi)``).  They are cached per preset
and coverage in ``--cache`` (default bench/results/exact_cache/, not committed), keyed by the
made-up skin's parameters and the quadrature, so a later run (another checkout) reuses them.

``--before``/``--after``: the Markdown table of two ``--json`` files.
Run with the venv's python (``$(tools/venv.sh)/bin/python``).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import resource
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from checkout import (  # bench/checkout.py
    commit,
    machine_load,
    packages_commit,
    use_checkout,
    write_figures,
)

HERE = Path(__file__).resolve()
SKIN = "paper_bioplate"
COVERAGES = (1.0, 0.5)
DEFAULT_CACHE = HERE.parent / "results" / "exact_cache"
THETA_I_EDGES_DEG = (0.0, 30.0, 60.0, 80.0, 89.0)
"""Panels of the incidence angle (Gauss-Legendre), degrees."""
LOBE_EDGES = (0.0, 0.5, 1.0, 2.0, 3.0, 5.0)
"""Panels of the half vector's polar angle near the normal, in widths of the narrowest lobe."""
WIDEST_PANEL_DEG = 15.0
ALBEDO_ANGLES_DEG = (0.0, 15.0, 30.0, 45.0, 60.0, 70.0, 75.0, 80.0, 85.0, 87.0, 89.0)
"""View angles of the view-albedo error (and incidences of the known integrals), degrees."""
VIEW_NODES = 181
"""View angles (uniform on [0, 90] degrees) at which path 3's Fourier matrices are computed."""
CHECK_PAIRS = 64
CHECK_LIMIT = 1e-6
"""Largest difference (fraction of the peak) allowed between the exact values computed here and
``made_up_reflection`` at the check pairs."""


def _gauss_panels(edges_deg, points: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights (radians) of Gauss-Legendre panels between consecutive ``edges_deg``."""
    x, w = np.polynomial.legendre.leggauss(points)
    nodes, weights = [], []
    for start, stop in zip(np.radians(edges_deg[:-1]), np.radians(edges_deg[1:]), strict=True):
        half = (stop - start) / 2.0
        nodes.append(start + half * (x + 1.0))
        weights.append(half * w)
    return np.concatenate(nodes), np.concatenate(weights)


def half_vector_edges(lobe_deg: float) -> np.ndarray:
    """Panel edges (degrees) of the half vector's polar angle: :data:`LOBE_EDGES` widths of the
    lobe, then panels of at most :data:`WIDEST_PANEL_DEG` up to 90."""
    inner = [e * lobe_deg for e in LOBE_EDGES if e * lobe_deg < 90.0]
    start = inner[-1]
    count = max(1, int(np.ceil((90.0 - start) / WIDEST_PANEL_DEG)))
    return np.concatenate([inner, np.linspace(start, 90.0, count + 1)[1:]])


@dataclass(frozen=True)
class HalfVectorQuadrature:
    """Direction pairs and weights that resolve a lobe of ``lobe_deg`` (module docstring).

    ``points_i``, ``points_h``: Gauss-Legendre nodes per panel of theta_i and of the half
    vector's polar angle; ``points_phi``: Gauss-Legendre nodes of its azimuth between 0 and
    :func:`horizon_azimuth` (beyond it ``wo`` is below the horizon)."""

    lobe_deg: float
    points_i: int = 6
    points_h: int = 8
    points_phi: int = 24

    def refined(self) -> HalfVectorQuadrature:
        """Twice the nodes on every axis."""
        return HalfVectorQuadrature(self.lobe_deg, 2 * self.points_i, 2 * self.points_h,
                                    2 * self.points_phi)

    def spec(self) -> dict:
        return {"lobe_deg": self.lobe_deg, "points_i": self.points_i, "points_h": self.points_h,
                "points_phi": self.points_phi, "theta_i_edges_deg": THETA_I_EDGES_DEG,
                "half_vector_edges_deg": half_vector_edges(self.lobe_deg).round(6).tolist()}

    def build(self) -> dict:
        """The error measure's pairs: ``wi``, ``wo`` ``(P, 3)``; ``theta_i`` (radians) the
        incidence nodes and ``node`` (P,) each pair's index into them; ``d_wo`` (P,) the solid
        angle of each pair's ``wo`` times ``cos(theta_o)`` (sums to integrals over the view
        hemisphere); ``weight`` (P,) that times ``sin(theta_i) dtheta_i``."""
        return _pairs(*_gauss_panels(THETA_I_EDGES_DEG, self.points_i), self)

    def build_albedo(self) -> dict:
        """Pairs as :meth:`build` at the fixed incidences :data:`ALBEDO_ANGLES_DEG` (no
        ``weight``): directional integrals there, the same for any node count."""
        return _pairs(np.radians(ALBEDO_ANGLES_DEG), None, self)


def horizon_azimuth(theta_i, theta_h) -> np.ndarray:
    """The half vector's largest azimuth (radians, from ``wi``'s) whose ``wo`` stays above
    the horizon: ``wo_z = 2 (wi.h) h_z - wi_z > 0`` is ``cos(phi_h) > -cot(theta_i)
    cot(2 theta_h)``; pi where every azimuth is, 0 where none is."""
    num = -np.cos(theta_i) * np.cos(2.0 * theta_h)
    den = np.sin(theta_i) * np.sin(2.0 * theta_h)
    with np.errstate(divide="ignore", invalid="ignore"):
        bound = np.where(den > 0.0, num / np.where(den > 0.0, den, 1.0),
                         np.where(num < 0.0, -np.inf, np.inf))
    return np.arccos(np.clip(bound, -1.0, 1.0))


def _half_vector_panels(theta_i: float, lobe_deg: float, points: int):
    """Nodes and weights (radians) of the half vector's polar angle for incidence ``theta_i``
    (radians): :func:`half_vector_edges`, cut at 45 - theta_i/2 degrees (beyond it part of
    the azimuths put ``wo`` below the horizon, a kink in the azimuth integral) and ending at
    45 + theta_i/2 (beyond it every azimuth does)."""
    half = np.degrees(theta_i) / 2.0
    edges = np.append(half_vector_edges(lobe_deg), [45.0 - half, 45.0 + half])
    edges = np.unique(edges[edges <= 45.0 + half])
    edges = edges[np.append(True, np.diff(edges) > 1e-9)]
    return _gauss_panels(edges, points)


def _pairs(theta_i, w_i, quadrature: HalfVectorQuadrature) -> dict:
    x, w = np.polynomial.legendre.leggauss(quadrature.points_phi)
    parts = []
    for index, a in enumerate(theta_i):
        theta_h, w_h = _half_vector_panels(a, quadrature.lobe_deg, quadrature.points_h)
        t = np.repeat(theta_h, x.size)
        top = horizon_azimuth(a, t)  # Gauss-Legendre on [0, top]: no kink at the horizon
        phi = top * (np.tile(x, theta_h.size) + 1.0) / 2.0
        # dw_h = sin(t) dt dphi; the azimuth's other half turn counted twice, by symmetry
        d_h = np.repeat(w_h * np.sin(theta_h), x.size) * top * np.tile(w, theta_h.size)
        parts.append((np.full(t.size, index), t, phi, d_h))
    node, t, phi, d_h = (np.concatenate(p) for p in zip(*parts, strict=True))
    a = theta_i[node]
    wi = np.stack([np.sin(a), np.zeros_like(a), np.cos(a)], axis=-1)
    h = np.stack([np.sin(t) * np.cos(phi), np.sin(t) * np.sin(phi), np.cos(t)], axis=-1)
    wi_h = np.sum(wi * h, axis=-1)
    wo = 2.0 * wi_h[:, None] * h - wi
    wo = wo / np.linalg.norm(wo, axis=-1, keepdims=True)
    keep = (d_h > 0.0) & (wo[:, 2] > 0.0)  # rounding at the bounds
    d_wo = 4.0 * wi_h * d_h * wo[:, 2]
    out = {"theta_i": theta_i, "wi": wi[keep], "wo": wo[keep], "node": node[keep],
           "d_wo": d_wo[keep]}
    if w_i is not None:
        out["weight"] = (d_wo * np.sin(a) * w_i[node])[keep]
    return out


# -- measures --------------------------------------------------------------------------------

def relative_rms(f_fit, f_ref, pairs) -> float:
    """Relative RMS of ``f cos(theta_i)`` with the quadrature's weights, channels pooled (the
    measure of ``lut_baker.closures.view_grid.ViewGrid.error``)."""
    w = (pairs["weight"] * pairs["wi"][:, 2] ** 2)[:, None]
    return float(np.sqrt(np.sum(w * (f_fit - f_ref) ** 2) / np.sum(w * f_ref**2)))


def directional_sums(f, pairs) -> np.ndarray:
    """``Int f(wi, wo) cos(theta_o) dw_o`` at each incidence node, ``(n_theta_i, C)``."""
    out = np.zeros((pairs["theta_i"].size, f.shape[-1]))
    np.add.at(out, pairs["node"], f * pairs["d_wo"][:, None])
    return out


def view_albedo_error(f_fit_swapped, f_ref, pairs) -> float:
    """Largest relative error of the view albedo ``Int f cos(theta_i) dw_i`` over the view
    angles (``pairs``' incidences with the roles swapped: ``f_fit_swapped`` is the replica at
    ``(wo, wi)``; the exact model is reciprocal, so its view albedo is its directional sum)."""
    fit, ref = directional_sums(f_fit_swapped, pairs), directional_sums(f_ref, pairs)
    return float(np.max(np.abs(fit - ref) / np.maximum(np.abs(ref), 1e-12)))


# -- the exact model -------------------------------------------------------------------------

def _rgb(values) -> np.ndarray:
    values = np.asarray(values, float)
    return values if values.ndim == 2 else np.repeat(values[:, None], 3, axis=1)


def exact_reflection(skin, pairs) -> np.ndarray:
    """``made_up_reflection(wi, wo, skin)`` at every pair, ``(P, 3)``: paths 1 and bare skin in
    closed form, path 3 from its Fourier matrices (module docstring), mixed by coverage."""
    from scipy.interpolate import CubicSpline

    from lut_baker.evaluate.two_layer import layered_fourier_matrices
    from lut_baker.model.albedo import grid_for
    from lut_baker.model.made_up_skin import (
        coverage_weights,
        film_reflection_layer,
        film_transmission_layer,
    )
    from lut_baker.model.microfacet import ts_reflection

    wi, wo, node = pairs["wi"], pairs["wo"], pairs["node"]
    film_t = film_transmission_layer(skin)
    grid = grid_for(film_t, skin.skin_reflection)
    views = np.radians(np.linspace(0.0, 90.0, VIEW_NODES))
    matrices = layered_fourier_matrices(pairs["theta_i"], views, film_t, skin.skin_reflection, grid)
    orders = np.arange(matrices.shape[0])
    theta_o = np.arccos(np.clip(wo[:, 2], 0.0, 1.0))
    phi = np.arctan2(wo[:, 1], wo[:, 0])  # wi lies at azimuth 0
    path3 = np.empty((wi.shape[0], matrices.shape[-1]))
    for k in range(pairs["theta_i"].size):
        pick = np.nonzero(node == k)[0]
        coefficients = CubicSpline(views, matrices[:, k], axis=1)(theta_o[pick])  # (M, p, C)
        path3[pick] = np.einsum("mpc,mp->pc", coefficients,
                                np.cos(orders[:, None] * phi[None, pick]))
    path3 = np.maximum(path3, 0.0)  # (P, 1) or (P, 3)
    weights = coverage_weights(skin.coverage, skin.absorption)
    bare = _rgb(ts_reflection(wi, wo, skin.skin_reflection, check=False))
    top = _rgb(ts_reflection(wi, wo, film_reflection_layer(skin), check=False))
    return weights.bare * bare + weights.covered * (top + path3)


def check_exact(skin, pairs, exact, rng) -> dict:
    """``made_up_reflection`` itself at :data:`CHECK_PAIRS` random pairs against ``exact``, and
    swapped (reciprocity); its cost per pair."""
    from lut_baker.evaluate.made_up import made_up_reflection

    pick = rng.choice(pairs["wi"].shape[0], CHECK_PAIRS, replace=False)
    wi, wo = pairs["wi"][pick], pairs["wo"][pick]
    start = time.perf_counter()
    direct = made_up_reflection(wi, wo, skin)
    per_pair = (time.perf_counter() - start) / CHECK_PAIRS
    swapped = made_up_reflection(wo, wi, skin)
    peak = float(np.max(np.abs(direct)))
    return {"difference": float(np.max(np.abs(exact[pick] - direct)) / peak),
            "reciprocity": float(np.max(np.abs(swapped - direct)) / peak),
            "made_up_reflection_ms_per_pair": 1e3 * per_pair}


def _cache_key(skin, quadrature: HalfVectorQuadrature, pairs) -> str:
    from lut_baker.model.params_file import skin_to_dict

    data = {"skin": skin_to_dict(skin), "quadrature": quadrature.spec(),
            "theta_i": np.round(pairs["theta_i"], 12).tolist(), "view_nodes": VIEW_NODES,
            "version": 1}
    return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()[:20]


def cached_exact(skin, quadrature, pairs, cache: Path | None, label: str) -> tuple:
    """``(exact values (P, 3), facts)`` from the cache, or computed, checked and stored."""
    key = _cache_key(skin, quadrature, pairs)
    path = None if cache is None else cache / f"{label}_{key}.npz"
    if path is not None and path.is_file():
        with np.load(path) as stored:
            facts = json.loads(str(stored["facts"]))
            if stored["exact"].shape[0] == pairs["wi"].shape[0]:
                return stored["exact"], dict(facts, cached=True)
    start = time.perf_counter()
    exact = exact_reflection(skin, pairs)
    seconds = time.perf_counter() - start
    facts = {"seconds": seconds, "pairs": int(pairs["wi"].shape[0]),
             **check_exact(skin, pairs, exact, np.random.default_rng(0))}
    if facts["difference"] > CHECK_LIMIT or facts["reciprocity"] > CHECK_LIMIT:
        raise SystemExit(f"tier_accuracy: the exact values of {label} differ from "
                         f"made_up_reflection: {facts}")
    if path is not None:
        cache.mkdir(parents=True, exist_ok=True)
        np.savez_compressed(path, exact=exact, facts=json.dumps(facts))
    return exact, dict(facts, cached=False)


def known_integrals(skin, pairs) -> dict:
    """The quadrature against known integrals at its incidence nodes (largest relative
    difference): ``Int cos(theta_o) dw_o = pi``, a gloss lobe's eq. 2 albedo (the film's, or
    the skin's when the film has none) against ``reflection_albedo`` at levels 0 and 1."""
    from lut_baker.model.albedo import reflection_albedo
    from lut_baker.model.layers import ReflectionLayer
    from lut_baker.model.microfacet import ts_reflection

    layer = skin.film if np.any(skin.film.P_s) else skin.skin_reflection
    gloss = ReflectionLayer(P_d=0.0, P_s=layer.P_s, n=layer.n, eta=layer.eta)
    ours = directional_sums(_rgb(ts_reflection(pairs["wi"], pairs["wo"], gloss,
                                               check=False)), pairs)
    theta_deg = np.degrees(pairs["theta_i"])
    cosine = directional_sums(np.ones((pairs["wi"].shape[0], 1)), pairs)[:, 0]
    out = {"gloss_lobe": "film" if layer is skin.film else "skin",
           "gloss_lobe_deg": float(1.0 / np.max(layer.n)),
           "cosine_vs_pi": float(np.max(np.abs(cosine / np.pi - 1.0)))}
    for level in (0, 1):
        reference = _rgb(reflection_albedo(theta_deg, gloss, level=level))
        out[f"gloss_albedo_vs_level{level}"] = float(np.max(np.abs(ours - reference)
                                                            / np.abs(reference)))
    return out


def albedo_check(skin, pairs, exact) -> float:
    """Largest relative difference of the exact values' directional sums at ``pairs``'
    incidences from ``directional_albedo`` (level 0)."""
    from lut_baker.evaluate.made_up import directional_albedo

    reference = directional_albedo(np.degrees(pairs["theta_i"]), skin)
    return float(np.max(np.abs(directional_sums(exact, pairs) - reference) / reference))


# -- one preset ------------------------------------------------------------------------------

def narrowest_lobe_deg(skin) -> float:
    """The narrowest 1/e half-width (1/n degrees) of the film, its transmission and the skin."""
    return min(1.0 / float(np.max(layer.n)) for layer in (skin.film, skin.film_transmission,
                                                          skin.skin_reflection))


def _tier_errors(fit, tables, coverage, absorption, pairs, exact, albedo_pairs,
                 albedo_exact) -> dict:
    try:  # a checkout with the tier registry
        from lut_baker.closures.tiers import TIERS, tier_replica

        replicas = {tier: (lambda fit, tables, *rest, tier=tier, **options:
                           tier_replica(fit, tables, tier, *rest, **options))
                    for tier in TIERS}
    except ImportError:  # an older one
        from lut_baker.closures.fitting import TIER_REPLICAS as replicas

    out = {}
    for tier, replica in replicas.items():
        f = replica(fit, tables, coverage, absorption, 1.0, directions=(pairs["wi"], pairs["wo"]))
        swapped = replica(fit, tables, coverage, absorption, 1.0,
                          directions=(albedo_pairs["wo"], albedo_pairs["wi"]))
        out[tier] = {"rms": relative_rms(f, exact, pairs),
                     "albedo": view_albedo_error(swapped, albedo_exact, albedo_pairs)}
    return out


def measure_preset(foundation: str, coverages, cache, refine: bool, progress=print) -> dict:
    from lut_baker.bake import bake
    from lut_baker.closures import fitting, tiers
    from lut_baker.model import presets

    entry = {"foundation": foundation}
    start = time.perf_counter()
    baked = presets.made_up_skin(foundation, SKIN, coverage=1.0, absorption=0.0)
    tables = bake(baked, "default")
    entry["bake_s"] = time.perf_counter() - start
    fit = fitting.fit_closures(tables)
    entry["bake_fit_s"] = time.perf_counter() - start
    entry["angular_grid"] = list(np.shape(getattr(tables, "film_gloss", tables.path3_gloss))[:3])
    absorption = presets.FOUNDATIONS[foundation]["absorption"]
    entry["absorption"] = list(absorption)
    exact_skin = presets.made_up_skin(foundation, SKIN, coverage=1.0)
    lobe = narrowest_lobe_deg(exact_skin)
    entry["lobe_deg"] = lobe
    quadratures = {"base": HalfVectorQuadrature(lobe)}
    if refine:
        quadratures["refined"] = quadratures["base"].refined()
    built = {name: (q.build(), q.build_albedo()) for name, q in quadratures.items()}
    entry["quadrature"] = {name: dict(q.spec(), pairs=int(built[name][0]["wi"].shape[0]),
                                      albedo_pairs=int(built[name][1]["wi"].shape[0]))
                           for name, q in quadratures.items()}
    entry["known_integrals"] = known_integrals(exact_skin, built["base"][1])
    entry["coverages"] = {}
    for coverage in coverages:
        skin = presets.made_up_skin(foundation, SKIN, coverage=coverage)
        result = {}
        for name, q in quadratures.items():
            pairs, albedo_pairs = built[name]
            label = f"{foundation}_w{coverage:g}_{name}"
            exact, facts = cached_exact(skin, q, pairs, cache, label)
            albedo_exact, albedo_facts = cached_exact(skin, q, albedo_pairs, cache,
                                                      label + "_albedo")
            result[name] = {"errors": _tier_errors(fit, tables, coverage, absorption, pairs,
                                                   exact, albedo_pairs, albedo_exact),
                            "exact": facts, "albedo_exact": albedo_facts}
            if name == "base":
                result[name]["directional_albedo_check"] = albedo_check(skin, albedo_pairs,
                                                                        albedo_exact)
        if hasattr(fitting, "tier_errors"):  # against the tables, as the add-on reports
            grid = tiers.tier_errors(fit, tables, coverage, absorption)
            result["table_grid"] = {tier: {"rms": e.rms, "albedo": e.albedo}
                                    for tier, e in grid.items()}
        if refine:
            result["refined_change"] = {
                tier: {m: abs(result["refined"]["errors"][tier][m]
                              - result["base"]["errors"][tier][m])
                       / result["base"]["errors"][tier][m] for m in ("rms", "albedo")}
                for tier in result["base"]["errors"]}
        entry["coverages"][f"{coverage:g}"] = result
        errors = result["base"]["errors"]
        progress(f"  {foundation} w={coverage:g}: Principled {errors['PRINCIPLED']['rms']:.4f}"
                 f", Layered {errors['LAYERED']['rms']:.4f} (lobe {lobe:.2f} deg, "
                 f"{entry['quadrature']['base']['pairs']} pairs)", flush=True)
    entry["seconds"] = time.perf_counter() - start
    entry["maxrss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return entry


# -- reports ---------------------------------------------------------------------------------

def _rows(results):
    for foundation, entry in results["presets"].items():
        for coverage, result in entry["coverages"].items():
            yield foundation, coverage, entry, result


def print_report(results: dict) -> None:
    print(f"\nTier errors against the exact model, skin {SKIN} -- checkout {results['repo']} at "
          f"{results['commit']} (packages last changed in {results['packages_commit'][:12]}); "
          f"load {results['load_start']} -> {results['load_end']}; "
          f"{results['seconds'] / 60:.1f} min")
    print("\nrelative RMS of f cos(theta_i) / largest view-albedo error; 'grid': the same "
          "against the tables on their own grid (closures.tiers.tier_errors); '2x': relative "
          "change of the RMS with twice the nodes\n")
    print("| preset | coverage | lobe deg | pairs | Principled RMS | Layered RMS "
          "| Principled albedo | Layered albedo | grid P / L RMS | 2x P / L | bake+fit s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for foundation, coverage, entry, result in _rows(results):
        e = result["base"]["errors"]
        grid = result.get("table_grid")
        grid_text = (f"{grid['PRINCIPLED']['rms']:.4f} / {grid['LAYERED']['rms']:.4f}"
                     if grid else "-")
        change = result.get("refined_change")
        change_text = (f"{change['PRINCIPLED']['rms']:.1e} / {change['LAYERED']['rms']:.1e}"
                       if change else "-")
        print(f"| {foundation} | {coverage} | {entry['lobe_deg']:.2f} "
              f"| {entry['quadrature']['base']['pairs']} | {e['PRINCIPLED']['rms']:.4f} "
              f"| {e['LAYERED']['rms']:.4f} | {e['PRINCIPLED']['albedo']:.4f} "
              f"| {e['LAYERED']['albedo']:.4f} | {grid_text} | {change_text} "
              f"| {entry['bake_fit_s']:.1f} |")
    print("\nChecks: exact values against made_up_reflection (fraction of the peak), "
          "reciprocity, Int cos dw vs pi, gloss albedo vs reflection_albedo level 0 / 1, "
          "directional albedo vs directional_albedo")
    for foundation, coverage, entry, result in _rows(results):
        facts = result["base"]["exact"]
        known = entry["known_integrals"]
        print(f"  {foundation} w={coverage}: {facts['difference']:.1e}, "
              f"{facts['reciprocity']:.1e}, {known['cosine_vs_pi']:.1e}, "
              f"{known['gloss_lobe']} gloss "
              f"{known['gloss_albedo_vs_level0']:.1e} / {known['gloss_albedo_vs_level1']:.1e}, "
              f"albedo {result['base']['directional_albedo_check']:.1e}"
              + ("" if facts.get("cached") else
                 f"; exact values {facts['seconds']:.1f} s for {facts['pairs']} pairs "
                 f"(made_up_reflection {facts['made_up_reflection_ms_per_pair']:.1f} ms/pair)"))


def markdown(before: dict, after: dict) -> str:
    """Before / after per preset and coverage (Markdown)."""
    lines = [f"Before: {before['packages_commit'][:12]}; after: {after['packages_commit'][:12]}"
             "; relative RMS of f cos(theta_i) against the exact model (view-albedo error in "
             "brackets).", "",
             "| preset | coverage | Principled before | Principled after | Layered before "
             "| Layered after |", "|---|---|---|---|---|---|"]
    keys = list(dict.fromkeys([(f, c) for f, c, _, _ in _rows(before)]
                              + [(f, c) for f, c, _, _ in _rows(after)]))

    def cell(results, foundation, coverage, tier):
        entry = results["presets"].get(foundation, {}).get("coverages", {}).get(coverage)
        if entry is None:
            return "-"
        e = entry["base"]["errors"][tier]
        return f"{e['rms']:.4f} ({e['albedo']:.4f})"

    for foundation, coverage in keys:
        lines.append(f"| {foundation} | {coverage} | "
                     + " | ".join(cell(r, foundation, coverage, tier)
                                  for tier in ("PRINCIPLED", "LAYERED")
                                  for r in (before, after)) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repo", type=Path, help="checkout whose lut_baker/ is measured")
    parser.add_argument("--presets", nargs="+", metavar="FOUNDATION",
                        help="foundations to measure (default: all of the checkout's)")
    parser.add_argument("--coverages", nargs="+", type=float, default=list(COVERAGES))
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE,
                        help="folder of the exact values (default: %(default)s)")
    parser.add_argument("--no-cache", action="store_true", help="neither read nor write it")
    parser.add_argument("--no-refine", action="store_true",
                        help="leave out the check with twice the nodes")
    parser.add_argument("--json", type=Path, help="write the figures here")
    parser.add_argument("--before", type=Path, help="a --json file of the old code")
    parser.add_argument("--after", type=Path, help="a --json file of the new code")
    args = parser.parse_args(argv)
    if args.before or args.after:
        if not (args.before and args.after):
            parser.error("--before and --after go together")
        print(markdown(*(json.loads(p.read_text()) for p in (args.before, args.after))))
        return 0
    if args.repo is None:
        parser.error("--repo is required")
    repo = args.repo.resolve()
    use_checkout(repo, ("lut_baker",), who="tier_accuracy")
    from lut_baker.model.presets import FOUNDATIONS

    foundations = args.presets or list(FOUNDATIONS)
    results = {"repo": str(repo), "commit": commit(repo, ("lut_baker",)),
               "packages_commit": packages_commit(repo, ("lut_baker",)), "skin": SKIN,
               "load_start": machine_load(),
               "started": time.strftime("%Y-%m-%d %H:%M:%S"), "presets": {}}
    start = time.perf_counter()
    for foundation in foundations:
        results["presets"][foundation] = measure_preset(
            foundation, args.coverages, None if args.no_cache else args.cache,
            not args.no_refine)
    results["load_end"] = machine_load()
    results["seconds"] = time.perf_counter() - start
    print_report(results)
    write_figures(args.json, results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
