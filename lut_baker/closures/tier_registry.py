"""The tiers: one :class:`Tier` object per way of shading the made-up skin, and one registry.

A tier says what it fits (its parts of a :class:`~lut_baker.closures.closure_fit.ClosureFit`),
how its shader is made of closures (a function over a
:class:`~lut_baker.closures.tier_formulas.ShaderAlgebra`: evaluated by numpy it is the tier's
replica, :mod:`lut_baker.closures.tiers`; emitted as nodes it is the add-on's node group), its
Glossy lobes and view-angle image, how its renderer draws a Glossy lobe, its label, the
engines it is made for and its cost traits.  Everything that lists or tells tiers apart reads
them here: the panel's Tier items, the Auto tier's candidates
(:mod:`lut_baker.auto_tier.candidates`), the fit (:func:`lut_baker.closures.fitting.
fit_closures`), the replicas and the node group.  A new tier is one :class:`Tier` passed to
:func:`register` (docs/architecture.md, "How to add a tier").

- :class:`Tier`, :class:`ViewImage`, :class:`Costs`.
- :func:`register`, :func:`unregister`, :func:`tier` (by name), :func:`held` (by name, of a
  fit that holds it), :data:`TIERS` (the names, live, in registration order),
  :func:`engine_tiers` (an engine's, fullest first).
- :data:`PRINCIPLED`, :data:`LAYERED`, :data:`EEVEE` -- the built-in tiers;
  :data:`UNRECORDED` -- the tier of a group whose record names none (the first add-on's).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import cycles as cc
from . import eevee
from .lobes import LobeFit
from .tier_formulas import TierInputs, principled_shader, view_weighted_shader
from .tier_parts import FitTargets, eevee_parts, image_rows, layered_parts, principled_parts
from .view_image import EEVEE_IMAGE_ROWS, IMAGE_ROWS

__all__ = ["Tier", "ViewImage", "Costs", "register", "unregister", "tier", "held", "TIERS",
           "engine_tiers", "PRINCIPLED", "LAYERED", "EEVEE", "UNRECORDED"]


@dataclass(frozen=True)
class ViewImage:
    """A tier's view-angle image: ``texels`` ``(len(rows), size, 3)``, its rows named ``rows``
    (:mod:`lut_baker.closures.view_image`)."""

    rows: tuple[str, ...]
    texels: NDArray[np.float64]


@dataclass(frozen=True)
class Costs:
    """A tier's render cost relative to its engine's fullest tier (``relative_cost``) and its
    noise coefficient (``noise_k``, one render's relative RMS deviation times
    ``sqrt(samples)``), for a tier ``lut_baker/auto_tier/measured.json`` does not measure."""

    relative_cost: float
    noise_k: float = 0.0


def _no_lobes(fit: Any) -> dict[str, LobeFit]:
    return {}


def _no_image(fit: Any) -> ViewImage | None:
    return None


def _cycles_glossy(pairs: cc.DirectionPairs, lobe: LobeFit) -> NDArray[np.float64]:
    """Cycles' Glossy BSDF of a fitted lobe, white (:func:`lut_baker.closures.cycles.
    microfacet_reflection`)."""
    return cc.pair_reflection(pairs, lobe.roughness, distribution=lobe.distribution)


def _eevee_glossy(pairs: cc.DirectionPairs, lobe: LobeFit) -> NDArray[np.float64]:
    """EEVEE's Glossy BSDF of a fitted lobe under a lamp, white
    (:func:`lut_baker.closures.eevee.glossy_reflection`)."""
    return eevee.glossy_reflection(pairs.wi, pairs.wo, lobe.roughness)


@dataclass(frozen=True)
class Tier:
    """One way of shading made-up skin.

    - ``name``: its identifier (kept in users' files and settings); ``label``: its name in the
      panel and in group and image names; ``description``: the panel's tooltip; ``number``:
      the Tier setting's stored value (files keep it; never reused).
    - ``engines``: the renderers it is made for (``"CYCLES"``, ``"EEVEE"``); ``fullness``:
      its rank among an engine's tiers for the Auto tier, 0 the fullest (the most accurate);
      ``costs``: its cost traits where measured.json has none (None: measured there).
    - ``fit(targets, over_shader)``: its parts, fitted (:class:`~lut_baker.closures.
      tier_parts.FitTargets`): ClosureFit fields, a tier of its own keeping them in
      ``{"extra": {name: ...}}``; ``fit_share``: its rough share of a full fit's time;
      ``holds(fit)``: whether a fit has its parts.
    - ``shader(fit, inputs, ops, subsurface_weight)``: its shader over a
      :class:`~lut_baker.closures.tier_formulas.ShaderAlgebra` (``subsurface_weight``: the
      artist's, over their shader, else None); ``lobes(fit)``: its Glossy lobes by closure
      name; ``image(fit)``: its :class:`ViewImage` or None; ``glossy(pairs, lobe)``: a white
      Glossy lobe as its renderer draws it at :class:`lut_baker.closures.cycles.
      DirectionPairs` (the replica's; the pairs' cosines shared by its lobes);
      ``with_image(lobes, texels)``: the fit's fields that hold its lobes and image (a fit
      moved to another thickness,
      :func:`lut_baker.closures.fitting.at_thickness`, writes them back; a tier with an
      image has one).
    - ``subsurface_method``: the method its renderer always uses (None: the fit's choice).
    """

    name: str
    label: str
    description: str
    number: int
    engines: tuple[str, ...]
    fit: Callable[[FitTargets, bool], dict[str, Any]]
    holds: Callable[[Any], bool]
    shader: Callable[[Any, TierInputs, Any, Any], Any]
    lobes: Callable[[Any], dict[str, LobeFit]] = _no_lobes
    image: Callable[[Any], ViewImage | None] = _no_image
    glossy: Callable[[cc.DirectionPairs, LobeFit], NDArray[np.float64]] = _cycles_glossy
    with_image: Callable[[dict[str, LobeFit], NDArray[np.float64]],
                         dict[str, Any]] | None = None
    subsurface_method: str | None = None
    fullness: int = 0
    fit_share: float = 0.3
    costs: Costs | None = None


_REGISTRY: dict[str, Tier] = {}


class _Names(Sequence[str]):
    """The registered tiers' names, in registration order, read live."""

    def __getitem__(self, index: Any) -> Any:
        return tuple(_REGISTRY)[index]

    def __len__(self) -> int:
        return len(_REGISTRY)

    def __iter__(self) -> Iterator[str]:
        return iter(tuple(_REGISTRY))

    def __contains__(self, name: object) -> bool:
        return name in _REGISTRY

    def __repr__(self) -> str:
        return repr(tuple(_REGISTRY))


TIERS: Sequence[str] = _Names()
"""The registered tiers' names in registration order (the built-in ones: the two made for
Cycles, cheapest first, then the one made for EEVEE), read live."""


def register(new: Tier) -> Tier:
    """Add ``new`` to the registry (``ValueError`` if its name or number is taken)."""
    if new.name in _REGISTRY:
        raise ValueError(f"a tier named {new.name!r} is registered already")
    if any(other.number == new.number for other in _REGISTRY.values()) or new.number == 0:
        raise ValueError(f"tier number {new.number} is taken (0 is the Auto tier's)")
    _REGISTRY[new.name] = new
    return new


def unregister(name: str) -> None:
    """Remove the tier ``name`` from the registry."""
    del _REGISTRY[name]


def tier(name: str) -> Tier:
    """The tier named ``name`` (``ValueError`` if none is registered)."""
    try:
        return _REGISTRY[name]
    except KeyError:
        raise ValueError(f"tier must be one of {TIERS}, got {name!r}") from None


def held(fit: Any, name: str) -> Tier:
    """The tier ``name`` of a fit that holds its parts (``ValueError`` if it does not)."""
    found = tier(name)
    if not found.holds(fit):
        raise ValueError(f"the fit holds no {name} tier (it has {', '.join(fit.tiers)}): fit "
                         f"it with fit_closures(..., tiers=...)")
    return found


def engine_tiers(engine: str) -> tuple[str, ...]:
    """The names of the tiers made for ``engine``, the fullest first."""
    made = [t for t in _REGISTRY.values() if engine in t.engines]
    return tuple(t.name for t in sorted(made, key=lambda t: t.fullness))


def _eevee_film_lobes(fit: Any) -> tuple[str, ...]:
    """The film gloss's second lobe is a closure only where its fit kept two."""
    second = np.any(fit.eevee_glossy["film_gloss_2"].weights)
    return ("film_gloss", "film_gloss_2") if second else ("film_gloss",)


def _eevee_shader(fit: Any, x: TierInputs, ops: Any, subsurface_weight: Any = None) -> Any:
    """The Layered tier's closures with the EEVEE tier's lobes, the plain colour EEVEE's
    subsurface takes, one Subsurface closure for both sides (EEVEE picks one Diffuse or
    Subsurface closure per sample, and fewer are less noise)."""
    return view_weighted_shader(fit, x, ops, subsurface_weight, tinted_subsurface=False,
                                film_lobes=_eevee_film_lobes(fit), one_subsurface=True)


PRINCIPLED = register(Tier(
    name="PRINCIPLED", label="Principled", number=1,
    description="One Principled BSDF: coat = film, subsurface = skin; cheapest, no images",
    engines=("CYCLES",), fullness=1, fit_share=0.25,
    fit=principled_parts, holds=lambda fit: fit.coat is not None, shader=principled_shader))
"""One Principled BSDF (GGX): coat = the film's gloss, specular = the skin's (bare or through
the film), base colour and subsurface = the diffuse albedo
(:func:`~lut_baker.closures.tier_formulas.principled_sockets`)."""

LAYERED = register(Tier(
    name="LAYERED", label="Layered", number=2,
    description="Glossy, Diffuse and Subsurface closures with view-angle weights from a "
                "lookup image; closest to the tables in Cycles",
    engines=("CYCLES",), fullness=0, fit_share=0.35,
    fit=layered_parts, holds=lambda fit: fit.glossy is not None,
    shader=partial(view_weighted_shader, tinted_subsurface=True, film_lobes=("film_gloss",)),
    lobes=lambda fit: fit.glossy,
    image=lambda fit: ViewImage(image_rows(IMAGE_ROWS, fit.slab is not None), fit.view_rows),
    with_image=lambda lobes, texels: {"glossy": lobes, "view_rows": texels}))
"""Glossy (film gloss, path-3 gloss, skin gloss; weights read from a view-angle image),
Diffuse and Subsurface closures mixed by coverage
(:func:`~lut_baker.closures.tier_formulas.view_weighted_closures`); the skin through the film
tinted and weighted as Cycles' random walk needs."""

EEVEE = register(Tier(
    name="EEVEE", label="EEVEE", number=3,
    description="The Layered closures fitted as EEVEE renders them (GGX lobes, its own lookup "
                "image, Burley subsurface); closest to the tables in EEVEE",
    engines=("EEVEE",), fullness=0, fit_share=0.4,
    fit=eevee_parts, holds=lambda fit: fit.eevee_glossy is not None, shader=_eevee_shader,
    lobes=lambda fit: fit.eevee_glossy, image=lambda fit: ViewImage(
        image_rows(EEVEE_IMAGE_ROWS, fit.slab is not None), fit.eevee_view_rows),
    with_image=lambda lobes, texels: {"eevee_glossy": lobes, "eevee_view_rows": texels},
    glossy=_eevee_glossy, subsurface_method="BURLEY"))
"""The Layered tier's closures and mix made for EEVEE: every Glossy lobe GGX fitted as EEVEE
renders it under a lamp (a linearly transformed cosine, :mod:`lut_baker.closures.eevee`), the
film's gloss in two, its own view-angle image; subsurface Christensen-Burley (EEVEE's
screen-space subsurface is Burley's profile whatever the node asks for, and Cycles renders the
same method when the file is rendered there)."""

UNRECORDED = LAYERED.name
"""The tier of a group whose record names none (the add-on's first version built only it)."""
