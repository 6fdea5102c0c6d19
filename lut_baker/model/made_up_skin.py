"""From the paper's pixel counts to albedo units, the made-up skin bundle and its mixing rule
(docs/model.md §4).

The paper's fitted values are 16-bit counts at two shutter times.  Dividing each layer by its
shutter time puts them on one scale (counts per second); dividing by one constant ``K`` makes
them albedos.  ``K`` is chosen so that the film as measured is lossless where it is brightest:
``K = max over theta_i of [reflection albedo (counts/s) + transmission albedo (counts/s)]``.

Functions and types
-------------------
- :func:`normalisation_constant` -- ``K`` from the film's two measured layers (docs/model.md
  §4).
- :func:`per_second` -- a layer divided by its shutter time.
- :class:`MadeUpSkin` -- the bundle in albedo units: film, skin, dipole, coverage, absorption.
- :func:`from_paper_counts` -- build a :class:`MadeUpSkin` from layers in pixel counts.
- :func:`coverage_weights` -- the weights of coverage and absorption: how bare skin, the film
  and the skin seen through the film are mixed; :func:`mix_slots` -- which part goes to which
  slot of the mix; :func:`combine` -- the mix itself, written once.
- :func:`film_reflection_layer`, :func:`film_transmission_layer` -- the film with its pigment
  absorption applied.

The made-up skin's reflection and albedo, which sum these parts, are evaluated in
:mod:`lut_baker.evaluate.made_up`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, NamedTuple, TypeVar

import numpy as np

from ..numerics.optimise import golden_minimum
from .albedo import reflection_albedo, transmission_albedo
from .layers import Dipole, ReflectionLayer, TransmissionLayer, check_parameter

__all__ = [
    "REFLECTION_SHUTTER_S",
    "TRANSMISSION_SHUTTER_S",
    "normalisation_constant",
    "per_second",
    "MadeUpSkin",
    "from_paper_counts",
    "CoverageWeights",
    "coverage_weights",
    "mix_slots",
    "combine",
    "film_reflection_layer",
    "film_transmission_layer",
]

REFLECTION_SHUTTER_S = 3.0
"""Shutter time of the paper's reflection measurements (4.1.1, 4.2.1), seconds."""
TRANSMISSION_SHUTTER_S = 10.0
"""Shutter time of the paper's transmission measurement (4.1.2), seconds."""


_Scaled = TypeVar("_Scaled", ReflectionLayer, TransmissionLayer)


def per_second(layer: _Scaled, shutter_s: float) -> _Scaled:
    """``layer`` with its intensity scales (``P_d``, ``P_s``/``P_t``) divided by ``shutter_s``."""
    if not shutter_s > 0:
        raise ValueError(f"shutter_s must be > 0 seconds, got {shutter_s!r}")
    lobe = "P_s" if isinstance(layer, ReflectionLayer) else "P_t"
    return layer.scaled(P_d=1.0 / shutter_s, **{lobe: 1.0 / shutter_s})


def normalisation_constant(film_reflection: ReflectionLayer,
                           film_transmission: TransmissionLayer) -> tuple[float, float]:
    """``K`` (docs/model.md §4): the largest total directional albedo of the film over incidence.

    Both layers in the same unit per second (see :func:`per_second`).  Returns ``(K,
    theta_max_deg)``, where ``theta_max_deg`` is the incidence at which the film is brightest.
    For RGB layers the brightest channel sets ``K``.
    """

    def total(theta_deg: float) -> float:
        value = reflection_albedo(theta_deg, film_reflection) + transmission_albedo(
            theta_deg, film_transmission
        )
        return float(np.max(value))

    theta, value = golden_minimum(lambda t: -total(t), 0.0, 89.9, tol=1e-5, coarse=91)
    return float(-value), float(theta)


@dataclass(frozen=True, eq=False)
class MadeUpSkin:
    """Made-up skin in albedo units (1/sr): the film over the skin, plus coverage and absorption.

    ``film``: the film's top-surface reflection (path 1); ``film_transmission``: the film's
    transmission (paths 3 and 4); ``skin_reflection``: the skin surface's Torrance-Sparrow
    reflection; ``dipole``: the skin's subsurface scattering (its profile shape spreads the
    skin's diffuse light); ``coverage`` in [0, 1]: 0 bare skin, 1 the full two-layer result,
    areal mix between;
    ``absorption`` in [0, 1] per channel: the fraction of light crossing the film's pigment
    (its diffuse reflection and its transmission) that is absorbed; ``K``: the normalisation
    constant these values were divided by (counts per second per unit albedo), if any.
    """

    film: ReflectionLayer
    film_transmission: TransmissionLayer
    skin_reflection: ReflectionLayer
    dipole: Dipole
    coverage: float = 1.0
    absorption: Any = 0.0
    K: float | None = None
    name: str = field(default="custom")

    def __post_init__(self) -> None:
        coverage = check_parameter("coverage", self.coverage, 0.0, 1.0,
                                   low_open=False, high_open=False)
        if coverage.shape != ():
            raise ValueError("coverage must be a float in [0, 1]")
        object.__setattr__(self, "coverage", float(coverage))
        absorption = check_parameter("absorption", self.absorption, 0.0, 1.0,
                                     low_open=False, high_open=False)
        object.__setattr__(self, "absorption", absorption)
        for name, kind in (("film", ReflectionLayer), ("film_transmission", TransmissionLayer),
                           ("skin_reflection", ReflectionLayer), ("dipole", Dipole)):
            if not isinstance(getattr(self, name), kind):
                raise ValueError(f"{name} must be a {kind.__name__}")

    def replace(self, **changes: Any) -> MadeUpSkin:
        """A copy with some fields changed (validated again)."""
        values = {name: getattr(self, name) for name in self.__dataclass_fields__}
        values.update(changes)
        return MadeUpSkin(**values)


def from_paper_counts(film: ReflectionLayer, film_transmission: TransmissionLayer,
                      skin: ReflectionLayer, dipole: Dipole, *,
                      reflection_shutter_s: float = REFLECTION_SHUTTER_S,
                      transmission_shutter_s: float = TRANSMISSION_SHUTTER_S,
                      **options: Any) -> MadeUpSkin:
    """Layers in the paper's pixel counts -> :class:`MadeUpSkin` in albedo units
    (docs/model.md §4)."""
    film_s = per_second(film, reflection_shutter_s)
    transmission_s = per_second(film_transmission, transmission_shutter_s)
    skin_s = per_second(skin, reflection_shutter_s)
    k, _ = normalisation_constant(film_s, transmission_s)
    return MadeUpSkin(
        film=film_s.scaled(P_d=1 / k, P_s=1 / k),
        film_transmission=transmission_s.scaled(P_d=1 / k, P_t=1 / k),
        skin_reflection=skin_s.scaled(P_d=1 / k, P_s=1 / k),
        dipole=dipole,
        K=k,
        **options,
    )


class CoverageWeights(NamedTuple):
    """The weights of :func:`coverage_weights`."""

    bare: float
    """``1 - w``: the bare skin's share of the area."""
    covered: float
    """``w``: the film's share of the area."""
    once: np.ndarray
    """``1 - A``: what is left of light that crosses the film's pigment once."""
    twice: np.ndarray
    """``(1 - A)^2``: what is left of light that crosses it twice (paths 3 and 4)."""


def coverage_weights(coverage: Any, absorption: Any) -> CoverageWeights:
    """The mixing weights of coverage ``w`` and absorption ``A`` (docs/model.md §4, dimensionless;
    ``A`` per channel).  The made-up skin is::

        f = covered [f_gloss,c + once P_d,c + twice f_cs] + bare f_r,s

    with ``covered = w``, ``bare = 1 - w``, ``once = 1 - A`` (the film's diffuse reflection
    crosses its pigment once; its gloss ``f_gloss,c`` does not cross it) and ``twice =
    (1 - A)^2`` (the skin seen through the film, path 3 ``f_cs`` with the film unabsorbed,
    crosses it twice; so does path 4).  Every mix of the made-up skin's parts uses these
    weights: the exact evaluator, the tables, the closures' tiers, the Auto tier and the
    reference images.  The add-on's node group (makeup_skin_addon/nodes.py) builds the same mix
    from math nodes and must follow it.  ``coverage`` and ``absorption``: numbers and arrays,
    or a node group's sockets.

    >>> weights = coverage_weights(0.6, [0.2, 0.5, 0.8])
    >>> print(round(weights.bare, 6), weights.covered, weights.once, np.round(weights.twice, 4))
    0.4 0.6 [0.8 0.5 0.2] [0.64 0.25 0.04]
    """
    if isinstance(absorption, (list, tuple)):
        absorption = np.asarray(absorption, dtype=float)
    # Plain arithmetic: the weights of numpy arrays are arrays, those of a node group's sockets
    # are sockets (lut_baker.closures.tier_formulas).
    once = 1.0 - absorption
    return CoverageWeights(bare=1.0 - coverage, covered=coverage, once=once, twice=once**2)


def mix_slots(*, film_gloss: Any = None, film_diffuse: Any = None, path3_gloss: Any = None,
              through_film: Any = None, skin_gloss: Any = None,
              skin: Any = None) -> dict[str, Any]:
    """The slots of :func:`combine` (``top``, ``once``, ``twice``, ``bare``) filled with the
    made-up skin's parts, the one place that says which part crosses the film's pigment how
    often (docs/model.md §4): the film's gloss none (``top``), its diffuse once, the skin's
    gloss through the film (path 3) and the skin's light through it (``through_film``) twice,
    the bare skin's gloss and light (``skin``) are the bare slot.  A part not given is no
    term; a slot with no part is None (no term of :func:`combine`).

    >>> slots = mix_slots(film_gloss=0.05, film_diffuse=0.3, path3_gloss=0.1,
    ...                   through_film=0.4, skin=0.4)
    >>> print(slots)
    {'top': 0.05, 'once': 0.3, 'twice': 0.5, 'bare': 0.4}
    """
    def total(first: Any, second: Any) -> Any:
        return first if second is None else second if first is None else first + second

    return {"top": film_gloss, "once": film_diffuse, "twice": total(path3_gloss, through_film),
            "bare": total(skin_gloss, skin)}


def combine(weights: CoverageWeights, *, top: Any = None, once: Any = None, twice: Any = None,
            bare: Any = None) -> Any:
    """The made-up skin's mix of its parts (docs/model.md §4, :func:`coverage_weights`)::

        covered [top + once (1 - A) + twice (1 - A)^2] + bare (1 - w)

    ``top``: what the film covers without crossing its pigment (its surface gloss, or parts
    whose layers hold the absorption already); ``once``: what crosses it once (its diffuse
    reflection); ``twice``: what crosses it twice (the skin seen through it, paths 3 and 4);
    ``bare``: the bare skin.  Any unit, any broadcasting shapes (RGB last); a part not given
    is no term at all, so a grey part stays a scalar (and a node group's Math node).

    >>> weights = coverage_weights(0.6, [0.2, 0.5, 0.8])
    >>> print(np.round(combine(weights, top=0.05, once=0.3, twice=0.5, bare=0.4), 4))
    [0.526 0.355 0.238]
    >>> round(combine(weights, bare=0.4), 6)  # a grey part alone stays a number
    0.16
    """
    def times(weight: Any, part: Any) -> Any:
        return None if part is None else weight * part

    def total(parts: list[Any]) -> Any:
        given = [part for part in parts if part is not None]
        return sum(given[1:], given[0]) if given else None

    covered = total([top, times(weights.once, once), times(weights.twice, twice)])
    mixed = total([times(weights.covered, covered), times(weights.bare, bare)])
    return 0.0 if mixed is None else mixed


def film_reflection_layer(skin: MadeUpSkin) -> ReflectionLayer:
    """The film's top reflection with pigment absorption on its diffuse part (docs/model.md §4:
    ``P_d`` times :func:`coverage_weights`' ``once``)."""
    return skin.film.scaled(P_d=coverage_weights(skin.coverage, skin.absorption).once)


def film_transmission_layer(skin: MadeUpSkin) -> TransmissionLayer:
    """The film's transmission with pigment absorption on all of it (docs/model.md §4: ``P_d``
    and ``P_t`` times :func:`coverage_weights`' ``once``; crossed twice, it gives ``twice``)."""
    once = coverage_weights(skin.coverage, skin.absorption).once
    return skin.film_transmission.scaled(P_d=once, P_t=once)
