"""The Auto tier's candidates, what each costs to render and how noisy one render is.

The candidates are the registered tiers' (:mod:`lut_baker.closures.tier_registry`), each with
and without its subsurface and its gloss; a tier's engines say where it is a candidate, and its
costs come from ``measured.json`` or, for a tier not measured there, from its own
:class:`~lut_baker.closures.tier_registry.Costs`.

- :class:`Candidate`, :func:`candidates` (an engine's, read from the registry),
  :data:`CANDIDATES` (Cycles' measured ones), :data:`EEVEE_CANDIDATES`, :data:`FULLEST`,
  :data:`ENGINES`, :data:`ENGINE_TIERS`, :data:`DEFAULT_TOLERANCE`.
- :data:`RELATIVE_COST`, :data:`NOISE_K`, :data:`COST_SKIN_SHARE`,
  :data:`EEVEE_RELATIVE_COST` -- measured (:mod:`.measured`); :func:`relative_cost`,
  :func:`noise` -- at a material's skin share.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass

import numpy as np

from ..closures.tier_registry import engine_tiers, tier
from .measured import by_candidate, by_number, load

__all__ = ["Candidate", "candidates", "CANDIDATES", "EEVEE_CANDIDATES", "FULLEST", "ENGINES",
           "ENGINE_TIERS",
           "DEFAULT_TOLERANCE", "RELATIVE_COST", "NOISE_K", "COST_SKIN_SHARE",
           "EEVEE_RELATIVE_COST", "COST_COMMAND", "EEVEE_COST_COMMAND", "relative_cost",
           "noise"]

_MEASURED = load()


@dataclass(frozen=True)
class Candidate:
    """One way to shade made-up skin: a registered ``tier`` (by name) with or without its
    subsurface closure and its gloss lobes.  The add-on
    realises ``subsurface=False`` with Subsurface Scale 0 (Cycles then turns subsurface
    closures into diffuse ones) and ``gloss=False`` with the group's Gloss input at 0 (Cycles
    then allocates no Glossy closure, coat or specular, and EEVEE picks none: their weights
    are 0)."""

    tier: str
    subsurface: bool = True
    gloss: bool = True

    @property
    def name(self) -> str:
        parts = [tier(self.tier).label]
        if not self.subsurface:
            parts.append("no subsurface")
        if not self.gloss:
            parts.append("no gloss")
        return ", ".join(parts)


ENGINES = ("CYCLES", "EEVEE")


class _EngineTiers(Mapping[str, tuple[str, ...]]):
    """``{engine: tier names}`` read live from the registry, the fullest first."""

    def __getitem__(self, engine: str) -> tuple[str, ...]:
        if engine not in ENGINES:
            raise KeyError(engine)
        return engine_tiers(engine)

    def __iter__(self) -> Iterator[str]:
        return iter(ENGINES)

    def __len__(self) -> int:
        return len(ENGINES)


ENGINE_TIERS: Mapping[str, tuple[str, ...]] = _EngineTiers()
"""Tiers per engine (:attr:`~lut_baker.closures.tier_registry.Tier.engines`), the fullest
first: each engine gets the tiers made for it.  The Layered tier's fits choose
Ashikhmin-Shirley and Beckmann lobes that EEVEE renders as GGX, and EEVEE renders GGX itself
through a linearly transformed cosine (:mod:`lut_baker.closures.eevee`); the EEVEE tier is
fitted to that, and Cycles renders its GGX lobes exactly, which they were not fitted to."""


def candidates(engine: str, *, measured: bool = False) -> tuple[Candidate, ...]:
    """Every candidate of the tiers made for ``engine`` (:data:`ENGINE_TIERS`), the fullest
    first: per tier, with and without gloss, each with and without subsurface; ``measured``:
    only the tiers whose costs ``measured.json`` holds."""
    return tuple(Candidate(name, subsurface, gloss) for name in ENGINE_TIERS[engine]
                 if not (measured and tier(name).costs is not None)
                 for gloss in (True, False) for subsurface in (True, False))


CANDIDATES = candidates("CYCLES", measured=True)
"""Every measured candidate of the Cycles tiers, the fullest first."""
EEVEE_CANDIDATES = candidates("EEVEE", measured=True)
"""Every measured candidate of the EEVEE tiers, the fullest first."""
FULLEST = CANDIDATES[0]
"""The fullest Cycles tier with subsurface and gloss: the most accurate, the costliest."""
DEFAULT_TOLERANCE = 0.02
"""Error a cheaper candidate may add to the best one's (relative RMS)."""

COST_COMMAND = _MEASURED["cycles_costs"]["command"]
RELATIVE_COST = by_candidate(_MEASURED["cycles_costs"]["relative_cost"], CANDIDATES)
"""Render time per sample relative to :data:`FULLEST`, by coverage (1: the paper's film, 0:
bare skin), then by candidate, as :data:`COST_COMMAND` measures it into ``measured.json``
(:mod:`.measured`; Cycles CPU, adaptive sampling off).  How it was measured and how far the
runs spread (up to 0.15, so differences under ~10% are not resolved): docs/stability.md, "The
Auto tier"."""
NOISE_K = by_candidate(_MEASURED["cycles_costs"]["noise_k"], CANDIDATES)
"""Noise coefficient ``k`` by coverage and candidate: one render's relative RMS deviation from
the converged image is ``k / sqrt(samples)`` (:data:`COST_COMMAND`, two seeds at 272 samples).
A sun is assumed: area lights and environments add noise to every candidate alike, so the
choice then leans towards the fullest tier (docs/stability.md)."""
COST_SKIN_SHARE = by_number(_MEASURED["cycles_costs"]["skin_share"])
"""The paper preset's skin share (light 45 degrees) at the
coverages the costs were measured at: a material's costs are interpolated by its share
(:func:`lut_baker.auto_tier.material.gloss_and_skin_shares`)."""
EEVEE_COST_COMMAND = _MEASURED["eevee_costs"]["command"]
EEVEE_RELATIVE_COST = by_candidate(_MEASURED["eevee_costs"]["relative_cost"], EEVEE_CANDIDATES)
"""Render time per frame of the EEVEE tier's candidates relative to its fullest, by coverage,
in EEVEE (5.0.1 on software OpenGL, 64 px, 64 samples, light 45 degrees), as
:data:`EEVEE_COST_COMMAND` measures it: medians of three interleaved runs whose frames took
20-40 s, so differences under ~30% are not resolved (docs/stability.md, "The Auto tier")."""


def _by_share(table: dict[float, dict[Candidate, float]], candidate: Candidate,
              skin_share: float) -> float:
    """Interpolate a per-coverage table of :data:`RELATIVE_COST`, :data:`EEVEE_RELATIVE_COST`
    or :data:`NOISE_K` to a skin share (held beyond the measured ones)."""
    shares = [COST_SKIN_SHARE[c] for c in (1.0, 0.0)]
    values = [table[c][candidate] for c in (1.0, 0.0)]
    return float(np.interp(skin_share, shares, values))


def relative_cost(candidate: Candidate, skin_share: float = COST_SKIN_SHARE[1.0]) -> float:
    """:data:`RELATIVE_COST` of ``candidate`` (:data:`EEVEE_RELATIVE_COST` for the EEVEE
    tiers') for a material whose skin share is ``skin_share`` (default: the paper's film);
    for a tier not measured, its own :class:`~lut_baker.closures.tier_registry.Costs`."""
    costs = tier(candidate.tier).costs
    if costs is not None:
        return costs.relative_cost
    table = EEVEE_RELATIVE_COST if candidate in EEVEE_RELATIVE_COST[1.0] else RELATIVE_COST
    return _by_share(table, candidate, skin_share)


def noise(candidate: Candidate, samples: int, *, engine: str = "CYCLES",
          denoise: bool = False, skin_share: float = COST_SKIN_SHARE[1.0]) -> float:
    """One render's Monte Carlo noise (relative RMS): ``k / sqrt(samples)`` (Cycles without a
    denoiser; ``k`` of :data:`NOISE_K` at the material's ``skin_share``), else 0."""
    if engine != "CYCLES" or denoise:
        return 0.0
    costs = tier(candidate.tier).costs
    k = costs.noise_k if costs is not None else _by_share(NOISE_K, candidate, skin_share)
    return k / math.sqrt(max(int(samples), 1))
