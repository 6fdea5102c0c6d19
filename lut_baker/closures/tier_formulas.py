"""Each tier's formulas, written once for numpy and for Blender's nodes.

A tier is a set of closures whose colours and weights are arithmetic on the node group's inputs
(Coverage ``w``, Foundation Absorption ``A``, Skin Color ``S``, Gloss ``g``), on constants of
the :class:`~lut_baker.closures.closure_fit.ClosureFit` and on the view-angle image's rows,
assembled into one shader: closures weighted, each side of the coverage mix summed, the sides
mixed by coverage as areas.  The functions here compute them from those values with Python's
operators and the few functions of an *algebra* (:class:`Algebra` for values,
:class:`ShaderAlgebra` for shaders), so the same code runs on two kinds of value:

- numpy arrays (:class:`NumpyAlgebra`; shaders as BRDFs, the replicas of
  :mod:`lut_baker.closures.tiers`): the tiers' errors, the Auto tier;
- node sockets (the add-on's node algebra, makeup_skin_addon/node_algebra.py): the node group
  is generated from these functions, so it cannot drift from what is measured.

Scalars (Coverage, Gloss, weights) and colours (RGB) mix freely, as they do in numpy (scalars
broadcast) and in nodes (a float socket linked to a colour input is grey).  Every mix of the
made-up skin's parts goes through :func:`lut_baker.model.made_up_skin.coverage_weights`,
:func:`~lut_baker.model.made_up_skin.mix_slots` and
:func:`~lut_baker.model.made_up_skin.combine` (docs/model.md §4).

- :class:`TierInputs` -- the group's inputs.
- :func:`skin_through_film` -- the skin's diffuse light through the film (the paper's, or
  the film as a slab with every return from its underside); :func:`under_film` -- the skin's
  albedo under the film.
- :func:`principled_sockets` -- one Principled BSDF's sockets; :func:`principled_shader` --
  that BSDF as a tier's shader.
- :func:`view_weighted_closures` -- Glossy, Diffuse and Subsurface closures with view-angle
  weights, by side of the coverage mix; :func:`view_weighted_shader` -- assembled.
- :func:`assemble` -- closures by side into one shader: summed, mixed by coverage.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from ..model.made_up_skin import combine, coverage_weights, mix_slots
from .view_image import row_reader

__all__ = ["Algebra", "ShaderAlgebra", "NumpyAlgebra", "TierInputs", "Closure",
           "ViewWeightedClosures", "principled_sockets", "principled_shader",
           "view_weighted_closures", "view_weighted_shader", "assemble", "SPECULAR_IOR",
           "ROW_SURFACE", "THROUGH_WEIGHT_FLOOR", "skin_through_film", "under_film"]

SPECULAR_IOR = 1.5
"""The Principled BSDF's IOR in the PRINCIPLED tier (its specular level carries the fit)."""
ROW_SURFACE = {"skin_gloss": "skin"}
"""The surface whose normal gives the view angle a row is read at: the skin's own gloss
against the skin's normal, every other row (the film and the light through it) against the
film's (``"film"``)."""
THROUGH_WEIGHT_FLOOR = 1e-6
"""Below this strongest channel the skin seen through the film keeps its colour's scale (no
division by a vanishing weight)."""


class Algebra(Protocol):
    """What a formula needs beyond ``+ - * /`` and ``** 2``: each call takes scalars or colours
    of the algebra's kind (or plain numbers) and returns one."""

    def maximum(self, a: Any, b: Any) -> Any: ...
    def minimum(self, a: Any, b: Any) -> Any: ...
    def floor(self, a: Any) -> Any: ...
    def lerp(self, t: Any, a: Any, b: Any) -> Any: ...
    def channel_mean(self, colour: Any) -> Any: ...
    def channel_max(self, colour: Any) -> Any: ...
    def row(self, name: str) -> Any: ...


class ShaderAlgebra(Algebra, Protocol):
    """An :class:`Algebra` that also makes shaders: one :class:`Closure` (its weight applied),
    one Principled BSDF from its sockets (:func:`principled_sockets`), their sum, and the areal
    mix of two by a coverage (``bare`` where it is 0, ``covered`` where 1)."""

    def closure(self, closure: Closure) -> Any: ...
    def principled(self, sockets: dict[str, Any]) -> Any: ...
    def add(self, *shaders: Any) -> Any: ...
    def mix(self, coverage: Any, bare: Any, covered: Any) -> Any: ...


class NumpyAlgebra:
    """The numpy algebra: scalars are arrays with a trailing axis of 1, colours of 3 (any
    leading shape, broadcast), rows read at ``cos_view`` (``(...,)``) from ``rows`` (name ->
    ``(size, 3)``) as Blender's Image Texture samples them (their texels at ``cos_view`` found
    once per size, :func:`lut_baker.closures.view_image.row_reader`).  ``read``: the rows
    already read from ``rows`` at ``cos_view`` by name (read-only), which this algebra fills as
    it reads: algebras of the same rows and view share them."""

    def __init__(self, rows: dict[str, Any] | None = None, cos_view: Any = None,
                 read: dict[str, Any] | None = None) -> None:
        self._rows = rows or {}
        self._cos = None if cos_view is None else np.asarray(cos_view, float)
        self._readers: dict[int, Any] = {}
        self._read = {} if read is None else read

    maximum = staticmethod(np.maximum)
    minimum = staticmethod(np.minimum)
    floor = staticmethod(np.floor)

    @staticmethod
    def lerp(t: Any, a: Any, b: Any) -> Any:
        return a + t * (b - a)

    @staticmethod
    def channel_mean(colour: Any) -> Any:
        return np.mean(np.asarray(colour, float) * np.ones(3), axis=-1, keepdims=True)

    @staticmethod
    def channel_max(colour: Any) -> Any:
        return np.max(np.asarray(colour, float) * np.ones(3), axis=-1, keepdims=True)

    def row(self, name: str) -> Any:
        if self._cos is None:
            raise ValueError(f"row {name!r} asked of an algebra without view angles")
        if name not in self._read:
            row = np.asarray(self._rows[name], float)
            size = row.shape[0]
            if size not in self._readers:
                self._readers[size] = row_reader(self._cos, size)
            value = self._readers[size](row)
            value.setflags(write=False)
            self._read[name] = value
        return self._read[name]


@dataclass(frozen=True)
class TierInputs:
    """The node group's inputs a tier's formulas read: ``coverage`` ``w`` (scalar),
    ``absorption`` ``A`` (colour), ``skin_color`` ``S`` (colour, the skin's diffuse albedo),
    ``gloss`` ``g`` (scalar, 0..1)."""

    coverage: Any
    absorption: Any
    skin_color: Any
    gloss: Any = 1.0

    @classmethod
    def numpy(cls, coverage: Any, absorption: Any, skin_color: Any,
              gloss: Any = 1.0) -> TierInputs:
        """Inputs as the numpy algebra takes them: scalars with a trailing axis of 1, colours
        of 3 (a scalar absorption is grey)."""
        def scalar(x: Any) -> Any:
            return np.asarray(x, float)[..., None]

        def colour(x: Any) -> Any:
            return np.asarray(x, float) * np.ones(3)

        return cls(scalar(coverage), colour(absorption), colour(skin_color), scalar(gloss))


def _weights(fit: Any, x: TierInputs) -> Any:
    """The coverage mix's weights: with the film as a slab its absorption is in the fit
    (``once`` and ``twice`` 1), else the Foundation Absorption input's."""
    return coverage_weights(x.coverage, 0.0 if _slab(fit) is not None else x.absorption)


def _slab(fit: Any) -> Any:
    return getattr(fit, "slab", None)


def skin_through_film(fit: Any, x: TierInputs) -> Any:
    """The skin's diffuse light through the film under uniform light, unabsorbed (``twice``
    applies the paper film's absorption): ``S T_mean^2``; with the film as a slab every return
    from the film's underside too, ``S t_mean^2 / (1 - S c)`` (docs/model.md "Made-up skin at
    a thickness"), per pixel since ``S`` is the Skin Color input."""
    slab = _slab(fit)
    if slab is None:
        return x.skin_color * fit.transmittance_mean**2
    skin = under_film(fit, x)
    return skin * fit.transmittance_mean**2 / (1.0 - skin * slab.below)


def under_film(fit: Any, x: TierInputs) -> Any:
    """The skin's albedo under the film: Skin Color, times the fit's ``slab.skin_under``
    where Match Skin darkened it (the film at a thickness only)."""
    slab = _slab(fit)
    if slab is None or slab.skin_under is None:
        return x.skin_color
    return x.skin_color * slab.skin_under


def principled_sockets(fit: Any, x: TierInputs, ops: Algebra) -> dict[str, Any]:
    """The PRINCIPLED tier's Principled BSDF sockets (by name) at inputs ``x``:

    - Coat Weight ``g w c`` (``c`` the coat's level: 1, or 0 without a coat), Coat
      Roughness/IOR fitted;
    - Roughness ``mix(r_bare, r_film, w)``, Specular IOR Level
      ``g [(1 - w) l_bare + w l_film mean((1 - A)^2)]``;
    - Base Color: the diffuse albedo ``combine(once: pi P_d,f, twice: S T_mean^2 + g
      gloss_to_diffuse, bare: S + g bare_to_diffuse)`` divided by the mean attenuation of the
      layers above it,
      ``(1 - g w c E_coat) (1 - g E_spec(w))``, ``E_spec(w) = mix(E_bare, E_film, w)``, and
      clipped to [0, 1] (Cycles clamps the colour its subsurface closure takes to 1, not its
      diffuse one: clipped, both take the same);
    - Subsurface Weight: the skin's share of the diffuse albedo (channel mean; the bare
      skin's, ``bare_to_diffuse`` included, is all of it).

    ``g`` (the group's Gloss input, 0..1) scales the gloss lobes: at 0 the coat weight and the
    specular level are 0, so Cycles allocates neither closure (``coat_weight >
    CLOSURE_WEIGHT_CUTOFF`` and ``eta != 1`` guard them in ``svm_node_closure_bsdf``), and the
    base colour is the diffuse albedo alone.  Between 0 and 1 the layer attenuation is taken
    linear in ``g`` (exact at both ends)."""
    weights = _weights(fit, x)
    g = x.gloss
    bare_gloss = None if fit.bare_to_diffuse is None else g * fit.bare_to_diffuse
    skin = combine(weights, **mix_slots(through_film=skin_through_film(fit, x),
                                        skin_gloss=bare_gloss, skin=x.skin_color))
    total = skin + combine(weights, **mix_slots(film_diffuse=fit.film_albedo,
                                                path3_gloss=g * fit.gloss_to_diffuse))
    e_spec = combine(weights, top=fit.specular_albedo_mean[1], bare=fit.specular_albedo_mean[0])
    coat = g * weights.covered * fit.coat.level
    base = total / ((1.0 - coat * fit.coat_albedo_mean) * (1.0 - g * e_spec))
    return {
        "Base Color": ops.minimum(ops.maximum(base, 0.0), 1.0),
        "Roughness": combine(weights, top=fit.specular_film.roughness,
                             bare=fit.specular_bare.roughness),
        "IOR": SPECULAR_IOR,
        "Specular IOR Level": g * combine(
            weights, top=fit.specular_film.level * ops.channel_mean(weights.twice),
            bare=fit.specular_bare.level),
        "Coat Weight": coat,
        "Coat Roughness": fit.coat.roughness,
        "Coat IOR": fit.coat.ior,
        "Subsurface Weight": ops.channel_mean(skin / ops.maximum(total, 1e-12)),
    }


def principled_shader(fit: Any, x: TierInputs, ops: ShaderAlgebra,
                      subsurface_weight: Any = None) -> Any:
    """One Principled BSDF of :func:`principled_sockets` (``subsurface_weight``: the share of
    the skin under the film that scatters below its surface, the artist's, multiplying the
    fitted one; None: all of it)."""
    sockets = principled_sockets(fit, x, ops)
    if subsurface_weight is not None:
        sockets["Subsurface Weight"] = sockets["Subsurface Weight"] * subsurface_weight
    return ops.principled(sockets)


@dataclass(frozen=True)
class Closure:
    """One closure of a view-weighted tier: ``kind`` (``"glossy"``, ``"diffuse"`` or
    ``"subsurface"``), ``name`` (a glossy lobe's key in the fit, else a label), ``colour``,
    ``weight`` (a scalar factor, or None), ``surface`` (whose normal it takes: ``"film"`` or
    ``"skin"``)."""

    kind: str
    name: str
    colour: Any
    surface: str
    weight: Any = None

    @property
    def product(self) -> Any:
        """What the closure carries: its colour times its weight (if it has one)."""
        return self.colour if self.weight is None else self.colour * self.weight


@dataclass(frozen=True)
class ViewWeightedClosures:
    """A view-weighted tier's closures: ``covered`` (where the film is) and ``bare`` (bare
    skin), mixed by ``coverage`` as areas (a Mix Shader), and ``shared`` closures added to
    that mix, their colours mixed by coverage already."""

    covered: tuple[Closure, ...]
    bare: tuple[Closure, ...]
    coverage: Any
    shared: tuple[Closure, ...] = ()


def assemble(closures: ViewWeightedClosures, ops: ShaderAlgebra) -> Any:
    """The one shader of a tier's closures: each side's closures summed (each weighted by
    :meth:`ShaderAlgebra.closure`), the sides mixed by coverage as areas, the shared closures
    added to the mix.  A coverage of exactly 1 (a group over the artist's shader, whose own
    mix with the Skin Shader is by Coverage) is the covered side alone."""
    covered = ops.add(*(ops.closure(c) for c in closures.covered))
    coverage = closures.coverage
    if isinstance(coverage, (int, float)) and coverage == 1.0:
        mixed = covered
    else:
        mixed = ops.mix(coverage, ops.add(*(ops.closure(c) for c in closures.bare)), covered)
    return ops.add(mixed, *(ops.closure(c) for c in closures.shared))


def view_weighted_closures(fit: Any, x: TierInputs, ops: Algebra, *,
                           tinted_subsurface: bool = True,
                           film_lobes: Sequence[str] = ("film_gloss",),
                           one_subsurface: bool = False,
                           subsurface_weight: Any = None) -> ViewWeightedClosures:
    """The LAYERED tier's closures at inputs ``x``, their view-dependent factors read from the
    image rows (``ops.row``, :data:`lut_baker.closures.view_image.IMAGE_ROWS`):

    - where the film is: its gloss (a Glossy per lobe of ``film_lobes``, ``g`` times the row
      of its name: ``film_gloss``, and ``film_gloss_2`` in the EEVEE tier), its diffuse and
      the gloss's Lambertian companion (one Diffuse, ``(1 - A) pi P_d,f + g`` row
      ``film_gloss_diffuse``), the skin's gloss through it (Glossy, ``g (1 - A)^2`` row
      ``path3_gloss``), the skin through it (Subsurface, ``(1 - A)^2 T(theta_o) T_mean S``);
    - bare skin: its gloss (Glossy, ``g`` row ``skin_gloss``) and its subsurface (``S``).

    With the film as a slab (``fit.slab``, docs/model.md "The tiers at a thickness") the
    absorption is in the fit: the film's Diffuse is its body's row ``film_body`` (plus the
    gloss's companion), ``path3_gloss`` is the skin's gloss through the film every order, and
    the skin through the film ``t(theta_o) t_mean S / (1 - S c)``.

    ``g`` (the group's Gloss input) scales the Glossy colours: at 0 no Glossy closure is
    allocated.  ``tinted_subsurface``: the skin through the film keeps the skin's own
    (bright) colour, tinted by ``(1 - A)^2 T(theta_o) T_mean`` relative to its strongest
    channel, and that channel weights the closure (a dark colour would make Cycles' random
    walk both noisy, 14% against 1% at 32 samples, and wrongly short); else its colour is the
    product itself (EEVEE's screen-space subsurface and Burley take it as it is).  Both give
    the same product.

    ``one_subsurface``: the two Subsurface closures (the skin through the film and bare; one
    radius, one normal) are one, shared by both sides, its colour their areal mix.  EEVEE
    renders a pixel's Diffuse and Subsurface closures by picking one per sample (in
    proportion to weight times luminance, ``closure_select`` in eevee_nodetree_lib.glsl), so
    closures of different hues in one pixel are noise that samples average away slowly: a
    matte film at coverage 0.5 errs 3.4% at 16 samples against 0.6% at 256 with three such
    closures; with two, as at full coverage, 1.4%.

    ``subsurface_weight`` (a scalar, or None): the share of the skin through the film that
    scatters below its surface, the rest a Diffuse closure of the same product (a skin whose
    shader has a Subsurface Weight, docs/addon.md "Over the artist's skin"); None: all of
    it."""
    weights = _weights(fit, x)
    g = x.gloss
    slab = _slab(fit)
    transmitted = weights.twice * ops.row("film_transmittance") * fit.transmittance_mean
    skin = under_film(fit, x)
    if slab is not None:  # every return from the film's underside, per pixel
        transmitted = transmitted / (1.0 - skin * slab.below)
    if tinted_subsurface:
        strongest = ops.channel_max(transmitted)
        through = Closure("subsurface", "skin through film",
                          transmitted * skin / ops.maximum(strongest, THROUGH_WEIGHT_FLOOR),
                          "skin", weight=strongest)
    else:
        through = Closure("subsurface", "skin through film", transmitted * skin, "skin")
    diffuse_through: tuple[Closure, ...] = ()
    if subsurface_weight is not None:
        diffuse_through = (Closure("diffuse", "skin through film (diffuse)",
                                   transmitted * skin, "skin",
                                   weight=1.0 - subsurface_weight),)
        through = Closure(through.kind, through.name, through.colour, through.surface,
                          weight=subsurface_weight if through.weight is None
                          else through.weight * subsurface_weight)
    covered = (
        *(Closure("glossy", name, g * ops.row(name), "film") for name in film_lobes),
        Closure("diffuse", "film diffuse",
                (weights.once * fit.film_albedo if slab is None else ops.row("film_body"))
                + g * ops.row("film_gloss_diffuse"), "film"),
        Closure("glossy", "path3_gloss", g * ops.row("path3_gloss") * weights.twice, "skin"),
        through,
        *diffuse_through,
    )
    bare = (
        Closure("glossy", "skin_gloss", g * ops.row("skin_gloss"), "skin"),
        Closure("subsurface", "bare skin", x.skin_color, "skin"),
    )
    if not one_subsurface:
        return ViewWeightedClosures(covered=covered, bare=bare, coverage=x.coverage)
    skin = Closure("subsurface", "skin", combine(coverage_weights(x.coverage, 0.0),
                                                 top=through.product, bare=x.skin_color), "skin")
    return ViewWeightedClosures(covered=covered[:-1], bare=bare[:-1], coverage=x.coverage,
                                shared=(skin,))


def view_weighted_shader(fit: Any, x: TierInputs, ops: ShaderAlgebra,
                         subsurface_weight: Any = None, *, tinted_subsurface: bool = True,
                         film_lobes: Sequence[str] = ("film_gloss",),
                         one_subsurface: bool = False) -> Any:
    r""":func:`view_weighted_closures` :func:`assemble`\ d; over the artist's shader (a
    ``subsurface_weight``) the bare side is theirs, so nothing is shared with it."""
    return assemble(view_weighted_closures(
        fit, x, ops, tinted_subsurface=tinted_subsurface, film_lobes=film_lobes,
        one_subsurface=one_subsurface and subsurface_weight is None,
        subsurface_weight=subsurface_weight), ops)
