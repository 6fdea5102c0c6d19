"""The run-time fits audited: does a 1e-9 change of the inputs move what they ship by less
than 1e-6, and how far is each discrete choice from flipping?

Used by the perturbation tests (tests/test_fit_stability.py) and printed by
``python bench/fit_stability.py`` (the table of docs/stability.md, "How far the fits move").

- :data:`CASES` -- the made-up skins audited: the paper preset, a hand shade, the four
  measured products.
- :func:`case_tables`, :func:`case_fit` -- a case's skin, its tables and their closure fit.
- :func:`criterion` -- whether a quantity's movement is measured relative to its size or
  absolutely (errors: they are already fractions, and a small error's relative change is
  large for no reason that reaches a render).
- :func:`fit_movement` -- the largest movement of every shipped output when the skin (through
  the bake) or the tables are perturbed.
- :class:`SearchRecorder` -- every search of a closure fit, with its scan: the margin between
  separated minima, and the two-parameter fits' errors.
- :func:`decision_margins` -- the margins of the fits' discrete choices: distribution per
  Glossy lobe, the subsurface method, keeping the coat or a specular lobe
  (:data:`NO_LOBE_ERROR`), the bake's node counts, the scans' minimum.
- :func:`choice_margins` -- the Auto tier's margins (error threshold, cost order, the
  half-pixel subsurface rule).
"""

from __future__ import annotations

import math
from contextlib import contextmanager
from functools import lru_cache

import numpy as np

from lut_baker import auto_tier, bake
from lut_baker.closures import fitting, lobes, profiles
from lut_baker.model import presets

from .perturbation import movement, perturbed

__all__ = ["CASES", "case_skin", "case_tables", "case_fit", "criterion",
           "fit_movement",
           "SearchRecorder", "recorded_searches", "decision_margins", "count_margin",
           "distribution_margin",
           "SCENES", "choice_margins"]

CASES = {
    "paper": ("paper_natural", "paper_bioplate", 1.0),
    "medium_beige+jensen_skin1": ("medium_beige", "jensen_skin1", 1.0),
    "clarins_103": ("clarins_103", "paper_bioplate", 1.0),
    "clarins_105": ("clarins_105", "paper_bioplate", 1.0),
    "clarins_108": ("clarins_108", "paper_bioplate", 1.0),
    "clarins_112": ("clarins_112", "paper_bioplate", 1.0),
}
"""Audited skins: ``name -> (foundation, skin, coverage)``; the measured products on the
paper's bio-plate."""
ABSOLUTE = ("error", "max_error", "rms", "albedo")
"""Last name parts of error measures (relative RMS, largest albedo error, edge-response
error): their movement is absolute (:func:`criterion`)."""


def case_skin(name: str):
    foundation, skin, coverage = CASES[name]
    return presets.made_up_skin(foundation, skin, coverage=coverage)


def case_tables(name: str, resolution: str = "preview"):
    """``(skin, tables)`` of a case."""
    skin = case_skin(name)
    return skin, bake.bake(skin, resolution)


@lru_cache(maxsize=8)
def case_fit(name: str, resolution: str = "preview"):
    """``(skin, tables, closure fit)`` of a case (kept: a fit takes 1-14 s), fitted as the
    add-on fits tables of that resolution (:func:`shipped_fit`)."""
    skin, tables = case_tables(name, resolution)
    return skin, tables, shipped_fit(tables, resolution)


def shipped_fit(tables, resolution: str = "preview"):
    """The closure fit the add-on makes of ``tables`` baked at ``resolution``: a preview's at
    preview resolution (``makeup_skin_addon.bakes``), the full one otherwise."""
    return fitting.fit_closures(tables, preview=resolution == "preview")


def criterion(name: str) -> str:
    """``"abs"`` for an error measure of a fit (the last part of ``name`` in
    :data:`ABSOLUTE`, under ``errors``, or ending ``error``), ``"rel"`` for the rest."""
    last = name.rsplit("/", 1)[-1]
    if last.endswith("error") or (last in ABSOLUTE and "/errors/" in f"/{name}"):
        return "abs"
    return "rel"


def _worst(into: dict, changes: dict) -> None:
    for name, change in changes.items():
        value = change.abs if criterion(name) == "abs" else change.rel
        into[name] = max(into.get(name, 0.0), value)


def fit_movement(name: str, seeds=(0, 1), resolution: str = "preview", *, rel: float = 1e-9,
                 via_bake: bool = True, via_tables: bool = True) -> dict:
    """The largest movement (:func:`criterion`) of every output, over ``seeds``: of the tables
    and the closure fit when the skin's parameters are perturbed by ``rel`` and baked again
    (``tables/...``, ``fit/...``), and of the closure fit when the tables themselves are
    perturbed (``fit_of_tables/...``)."""
    skin, tables, fit = case_fit(name, resolution)
    worst: dict = {}
    for seed in seeds:
        if via_bake:
            moved = bake.bake(perturbed(skin, rel, seed), resolution)
            _worst(worst, movement(tables, moved, "tables"))
            _worst(worst, movement(fit, shipped_fit(moved, resolution), "fit"))
        if via_tables:
            refit = shipped_fit(perturbed(tables, rel, 1000 + seed), resolution)
            _worst(worst, movement(fit, refit, "fit_of_tables"))
    return worst


# --------------------------------------------------------------------------------------------
# Discrete choices and their margins
# --------------------------------------------------------------------------------------------
def _separated_gap(samples) -> float:
    """Relative gap between the lowest of a scan's samples (along its first axis, the lowest
    over the others) and the lowest local minimum of the samples not next to it (inf when
    the scan has one valley, or is flat: a function the search cannot tell apart anywhere):
    how near the scan is to starting in another valley."""
    v = np.asarray(samples, float)
    v = v.reshape(v.shape[0], -1).min(axis=1)
    k = int(np.argmin(v))
    if np.all(v == v[0]) or not np.isfinite(v[k]):
        return math.inf
    minima = [i for i in range(v.size)
              if (i == 0 or v[i] <= v[i - 1]) and (i == v.size - 1 or v[i] <= v[i + 1])
              and abs(i - k) > 1]
    if not minima:
        return math.inf
    return float((min(v[i] for i in minima) - v[k]) / max(abs(v[k]), 1e-300))


class SearchRecorder:
    """Wraps the fits' two searches (``lobes.brent_minimum``'s coarse samples and
    ``lobes.scanned_least_squares``' grid of starts) to keep each call's scan, and the
    final errors of the two-parameter fits (``errors``: the relative RMS the lobe-or-no-lobe
    rule compares)."""

    def __init__(self):
        self.scans: list = []
        self.errors: list = []

    def brent(self, function, low, high, **options):
        samples = []
        coarse = options.get("coarse", 9)

        def recorded(x):
            value = function(x)
            if len(samples) < coarse:
                samples.append(float(value))
            return value

        result = BRENT(recorded, low, high, **options)
        self.scans.append(samples)
        return result

    def scanned(self, residuals, axes, **options):
        x, cost, scan = SCANNED(residuals, axes, **options)
        self.scans.append(scan)
        self.errors.append(math.sqrt(cost))
        return x, cost, scan


BRENT, SCANNED = lobes.brent_minimum, lobes.scanned_least_squares


@contextmanager
def recorded_searches():
    """``with recorded_searches() as recorder:`` every search of
    :mod:`lut_baker.closures.fitting` inside is kept by ``recorder``."""
    recorder = SearchRecorder()
    lobes.brent_minimum, lobes.scanned_least_squares = recorder.brent, recorder.scanned
    try:
        yield recorder
    finally:
        lobes.brent_minimum, lobes.scanned_least_squares = BRENT, SCANNED


def _relative_gap(values) -> float:
    """``(second lowest - lowest) / lowest`` of ``values``."""
    ordered = sorted(float(v) for v in values)
    return (ordered[1] - ordered[0]) / max(abs(ordered[0]), 1e-300)


def count_margin(width_deg: float, resolution: str = "preview") -> float:
    """The smallest relative change of a lobe width (1/e half-width, degrees) that changes the
    grids :meth:`lut_baker.bake.Resolution.for_lobe` gives it (steps of 10^(1/8))."""
    base = bake.RESOLUTIONS[resolution]
    grids = base.for_lobe(width_deg)
    for exponent in np.arange(-10.0, 0.01, 0.125):
        step = 10.0**exponent
        if any(base.for_lobe(width_deg * (1.0 + sign * step)) != grids for sign in (-1, 1)):
            return float(step)
    return math.inf


def distribution_margin(lobe) -> float:
    """How far a Glossy fit's choice of distribution is from flipping: ``|best other /
    GGX - (1 - DISTRIBUTION_MARGIN)|`` of the searched errors (the rule keeps GGX unless
    another errs that much less); inf for a lobe with nothing to fit (no gloss)."""
    if not lobe.searched:
        return math.inf
    others = [error for name, error in lobe.searched.items() if name != "GGX"]
    ggx = lobe.searched["GGX"]
    if ggx <= 0.0:
        return math.inf
    return abs(min(others) / ggx - (1.0 - lobes.DISTRIBUTION_MARGIN))


def decision_margins(tables, skin=None) -> dict:
    """Margins of the closure fit's discrete choices on ``tables`` (relative, unless said):

    - ``distribution/<lobe>``: :func:`distribution_margin` of each Glossy lobe;
    - ``subsurface_method``: gap between the best and second method's
      ``hypot(worst edge error, replica error)``;
    - ``no_lobe/<lobe>``: ``|error - NO_LOBE_ERROR|`` (absolute) of the coat's and each
      specular fit's error (the lobe is dropped at or above it; a film without gloss has no
      coat to fit: no margin);
    - ``coarse_valley``: the smallest separated gap (:func:`_separated_gap`) over every
      search's scan;
    - ``node_counts``: :func:`count_margin` of the widths path 3 goes through (with
      ``skin``).
    """
    margins: dict = {}
    with recorded_searches() as recorder:
        fit = shipped_fit(tables)
    for lobe, found in fit.glossy.items():
        margins[f"distribution/{lobe}"] = distribution_margin(found)
    # One EEVEE lobe or two for the film gloss: GGX against lobes.PAIR in its searched errors.
    margins["pair/film_gloss"] = distribution_margin(fit.eevee_glossy["film_gloss"])
    # The scanned fits in order: the coat (when the film has gloss), then the two speculars.
    names = (["coat"] if len(recorder.errors) == 3 else []) + ["specular_bare",
                                                               "specular_film"]
    for name, error in zip(names, recorder.errors, strict=True):
        margins[f"no_lobe/{name}"] = abs(error - lobes.NO_LOBE_ERROR)
    margins["subsurface_method"] = _relative_gap(
        np.hypot(p.worst_error, profiles.REPLICA_EDGE_ERROR[m]) for m, p in fit.profiles.items())
    margins["coarse_valley"] = min(_separated_gap(scan) for scan in recorder.scans)
    if skin is not None:
        margins["node_counts"] = min(count_margin(bake.path3_width_deg(skin), r)
                                     for r in ("preview", "default"))
    return margins


# --------------------------------------------------------------------------------------------
# The Auto tier
# --------------------------------------------------------------------------------------------
SCENES = {
    "close-up 0.2 mm/px, Cycles 16": auto_tier.SceneDescription(200.0, 0.2, samples=16),
    "close-up 0.2 mm/px, Cycles 64": auto_tier.SceneDescription(200.0, 0.2, samples=64),
    "close-up 0.2 mm/px, Cycles 256": auto_tier.SceneDescription(200.0, 0.2, samples=256),
    "full figure 3 mm/px, Cycles 128": auto_tier.SceneDescription(1800.0, 3.0, samples=128),
    "sphere 300 mm at 48 px, Cycles 256": auto_tier.SceneDescription(300.0, 6.25,
                                                                     samples=256),
    "grazing light 80, 1 mm/px, Cycles 128": auto_tier.SceneDescription(
        200.0, 1.0, lights_deg=(80.0,), samples=128),
    "close-up, EEVEE": auto_tier.SceneDescription(200.0, 0.2, engine="EEVEE"),
}
"""Scenes the Auto tier is audited in (those of docs/stability.md's table and a few more)."""


def choice_margins(choice, scene, traits) -> dict:
    """How far :func:`lut_baker.auto_tier.choose`'s ``choice`` is from flipping:

    - ``error``: the smallest distance (absolute, in predicted relative RMS) between the
      threshold ``best + tolerance`` and the predicted error of the chosen candidate or of a
      cheaper one (crossing it changes the choice);
    - ``cost``: the relative cost gap between the chosen candidate and the next one within
      the threshold (inf when none);
    - ``subsurface``: ``|mean radius / (half a pixel) - 1|``, the half-pixel rule's margin
      (:func:`lut_baker.auto_tier.needs_subsurface`; inf without the subsurface).
    """
    threshold = choice.best_error + choice.tolerance
    ordered = list(choice.predictions)
    at = ordered.index(choice.chosen)
    error = min(abs(p.error - threshold) for p in ordered[:at + 1])
    within = [p for p in ordered[at + 1:] if p.error <= threshold]
    cost = (min(p.cost for p in within) - choice.chosen.cost) / choice.chosen.cost \
        if within else math.inf
    subsurface = math.inf
    if traits.subsurface_scale > 0.0:
        subsurface = abs(traits.mean_radius_mm / (0.5 * scene.footprint_mm) - 1.0)
    return {"error": float(error), "cost": float(cost), "subsurface": float(subsurface)}
