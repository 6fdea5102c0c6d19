"""The choice: each candidate's predicted error and cost in a scene, and the cheapest one
within a tolerance of the best.

- :class:`Prediction`, :func:`predict` -- one candidate's error and cost.
- :func:`needs_subsurface` -- whether the scene resolves the skin's spread.
- :class:`Choice`, :func:`choose` -- every candidate's prediction and the one chosen.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..numerics.cache import LRUCache
from .blur import subsurface_omission_error
from .candidates import (
    DEFAULT_TOLERANCE,
    ENGINE_TIERS,
    FULLEST,
    Candidate,
    noise,
    relative_cost,
)
from .candidates import candidates as engine_candidates
from .material import MaterialTraits, paper_traits
from .scene import SceneDescription

__all__ = ["Prediction", "predict", "needs_subsurface", "Choice", "choose"]


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
    everything it depends on but the skin's share, which it is proportional to (the same
    scene and skin under another foundation, or read again from a file, is the same)."""
    scale = traits.subsurface_scale
    radius = np.asarray(traits.radius_mm, float)
    profile = np.asarray(traits.profile, float)

    def at(light_deg: float) -> float:
        key = (scene.footprint_mm, scene.object_size_mm, light_deg, scale,
               radius.tobytes(), profile.tobytes())
        whole = _OMISSIONS.get_or_compute(key, lambda: subsurface_omission_error(
            scene.footprint_mm, scene.object_size_mm, light_deg, scale * radius,
            profile / scale**2))
        return traits.share("skin_share", light_deg) * whole

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
    predictions: tuple[Prediction, ...]
    tolerance: float
    best_error: float
    reasons: tuple[str, ...] = field(default_factory=tuple)

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
           tolerance: float = DEFAULT_TOLERANCE,
           candidates: Sequence[Candidate] | None = None) -> Choice:
    """The cheapest candidate whose predicted error is within ``tolerance`` of the best one's,
    among ``candidates`` (default: every registered tier's,
    :func:`~lut_baker.auto_tier.candidates.candidates`) made for the scene's engine
    (:data:`ENGINE_TIERS`), keep
    the subsurface closure if :func:`needs_subsurface` (and drop it when the Subsurface
    Scale is 0: Cycles then shades no spread anyway; likewise the gloss lobes when the
    artist's Gloss is 0).  ``traits`` default to the paper preset's (:func:`paper_traits`)."""
    if not tolerance >= 0:
        raise ValueError(f"tolerance must be >= 0, got {tolerance}")
    traits = paper_traits() if traits is None else traits
    needed = needs_subsurface(scene, traits)
    pool = [c for c in (candidates or engine_candidates(scene.engine))
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
