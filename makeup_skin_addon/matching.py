"""The shade that matches the skin: Match Skin, Lighter / Darker and the first Apply's match.

Matching means the artist's render: the shade is solved so that the skin under the film, the
film over it included, has under uniform white light the colour the artist's own shader has
there (:class:`SkinTarget`, from :mod:`.artist_skin`: a Principled BSDF's layering and its
random walk included), so that at any coverage the face keeps the tone it had before Apply;
on a mesh whose hollows hide part of the sky, each part of both colours weighed by what it
keeps of it (:func:`seen_target`: the artist's gloss loses more there than the film).
A material without a shader of the artist's (the skin preset's made-up skin) matches its own
bare skin instead.  The covered colour is the model's
(:func:`lut_baker.tables.uniform_light.covered_colour`), solved per channel in closed form
(:func:`lut_baker.tables.uniform_light.matching_absorption`); a colour beyond the film's reach
is matched as far as it goes and the report says so.

With the film at a thickness (the Film setting, docs/model.md "Made-up skin at a thickness")
the covered colour is the slab's, every inter-reflection in, solved on its exact order-0
evaluation (:func:`lut_baker.model.slab_skin.matching_shade`, at the Gloss of 1 it is baked
with): Match Skin changes the foundation's absorption; only where even full absorption leaves
the made-up skin too light (a sheer film whose surface gloss adds more than its pigment can
take away) is the skin under the film darkened (``skin_under``, relative to Skin Color, baked
into the group; the bare skin stays the artist's), and the report says by how much.

Lighter and Darker step the covered colour's target by :data:`SHADE_STEP` from where the last
match (or the current shade) put it, counting steps (``shade_steps``), so that Lighter then
Darker returns to exactly the same shade, clamped or not.

- :class:`SkinTarget` -- the colour to match and the skin under the film's body colour.
- :func:`skin_target` -- both for a material, with where they came from.
- :class:`Shade` -- a solved shade.
- :func:`matched` -- Match Skin; :func:`first_shade` -- the first Apply's;
  :func:`seen_target` -- the colour to match as the mesh's hollows render it;
  :func:`stepped` -- Lighter / Darker; :func:`assign` -- store a shade on the settings.
- :func:`light_for` -- the settings' made-up skin under uniform light (cached per bake);
  :class:`SlabLight` -- with the film at a thickness (the exact closed form);
  :func:`bare_light` -- the bare skin alone (its gloss), without a bake.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import artist_skin, bakes, shade, skin_colour, skin_model, sky_visibility
from .core import albedo, bake, cache, film_slab, presets, quadrature, slab_skin, uniform_light

__all__ = ["SHADE_STEP", "MATTE_FILM", "SkinTarget", "Shade", "SlabLight", "skin_target",
           "light_for", "bare_light", "seen_target",
           "matched", "first_shade", "stepped", "assign", "clear_cache"]

SHADE_STEP = 1.1
"""One shade step of Lighter / Darker: the covered skin's colour times this (10% in
luminance)."""
MATTE_FILM = "clarins_103"
"""The matte film a first Apply turns to when the skin is darker than the default film's own
gloss (any matte product's film is the same: no surface gloss; this is the first)."""
CHANNELS = ("Red", "Green", "Blue")
_LIGHT = cache.LRUCache(8)


@dataclass
class SkinTarget:
    """What a shade is matched to: ``target``, the colour the skin has before Apply under
    uniform light (RGB, its gloss included), ``body``, the body colour of the skin under the
    film (RGB, the model's skin diffuse albedo ``a``), and ``source``, the end of a sentence
    saying where they came from; over the artist's shader ``glosses`` and ``sky``."""

    target: np.ndarray
    body: np.ndarray
    source: str
    glosses: list = field(default_factory=list)
    sky: sky_visibility.SkyVisibility | None = None
    """Over the artist's shader: its gloss parts (RGB, roughness) and what a uniform sky
    leaves to the surface (:func:`seen_target` weighs them)."""


def light_for(settings, foundation: str | None = None, resolution: str | None = None):
    """The settings' made-up skin (with ``foundation``'s film instead, if given) under uniform
    light (:func:`lut_baker.tables.uniform_light.uniform_light` of their tables, re-baked once
    per session) at ``resolution`` (default the settings': the colours move by about 1e-4
    between resolutions)."""
    skin = skin_model.skin_from_settings(settings, foundation).replace(absorption=0.0)
    record = bakes.bake_record(skin, resolution or settings.resolution)
    return _LIGHT.get_or_compute(record["key"],
                                 lambda: uniform_light.uniform_light(bakes.rebake(record)))


def bare_light(settings) -> uniform_light.UniformLight:
    """The settings' bare skin under uniform light: its gloss layer's directional albedo
    averaged over incidence (:func:`lut_baker.model.albedo.bihemispherical` of
    :func:`lut_baker.bake.gloss_albedos`, without the tables: what :func:`skin_target` needs
    with the film at a thickness, where the shade is solved on :class:`SlabLight`), the
    film's parts 0 (they weigh nothing at coverage 0).  Within 1e-4 of the gloss
    :func:`light_for`'s tables give (their directional table interpolated)."""
    layer = skin_model.skin_from_settings(settings).skin_reflection
    gloss = np.asarray(albedo.bihemispherical(
        lambda theta_deg: bake.gloss_albedos((layer,), theta_deg)[0]), float)
    zeros = np.zeros(3)
    return uniform_light.UniformLight(film_gloss=zeros, film_diffuse=zeros,
                                      path3_gloss=zeros, through_film=zeros, skin_gloss=gloss)


def skin_target(material, reading=None, light=None, resolution: str | None = None
                ) -> SkinTarget:
    """What the material's shade matches: over the artist's shader its colour under uniform
    light and its body colour (``reading``: :class:`.artist_skin.SkinReading`, read now if not
    given); the skin preset's made-up skin matches its own bare skin (Skin Color, or the mean
    of the image feeding it, with the preset's gloss, ``light``: default the settings' at
    ``resolution``)."""
    settings = material.makeup_skin
    if reading is None:
        reading = artist_skin.read_material(material)
    if reading is not None and reading.dominant is not None:
        notes = "".join(f"; {note}" for note in reading.notes)
        where = f" {reading.where}" if reading.where else ""
        return SkinTarget(np.asarray(reading.target, float), np.asarray(reading.body, float),
                          f"the artist's shader under uniform light{where}{notes}",
                          list(reading.glosses), reading.sky)
    skin = skin_colour.skin_colour(material)
    if light is None:
        light = (light_for(settings, resolution=resolution)
                 if skin_model.film_of(settings) == "paper" else bare_light(settings))
    bare = uniform_light.bare_colour(light, skin.rgb, float(settings.gloss))
    return SkinTarget(np.asarray(bare, float), np.asarray(skin.rgb, float),
                      f"its diffuse albedo {_rgb(skin.rgb)} with the skin preset's gloss; the "
                      f"albedo is {skin.source}")


@dataclass
class Shade:
    """A shade solved for the covered skin to have ``target``: ``absorption`` and
    ``clamped`` per channel, the covered colour ``reached``, the skin ``skin``
    (:class:`SkinTarget`), the report's ``sentences``, and the step count and its base that
    Lighter / Darker keep (``steps``, ``base``); with the film at a thickness, ``under``: the
    skin's albedo under the film that would match where full absorption does not (else the
    skin's own)."""

    absorption: np.ndarray
    clamped: np.ndarray
    target: np.ndarray
    reached: np.ndarray
    skin: SkinTarget
    sentences: list = field(default_factory=list)
    steps: int = 0
    base: np.ndarray | None = None
    under: np.ndarray | None = None

    def skin_under(self) -> np.ndarray:
        """The skin's albedo under the film relative to its own (``under`` over the body
        colour; 1 where unchanged or without a thickness)."""
        if self.under is None:
            return np.ones(3)
        body = np.asarray(self.skin.body, float)
        return np.where(self.under < body, self.under / np.maximum(body, 1e-12), 1.0)

    def note(self) -> str:
        """The panel's short line about channels out of reach, or ""."""
        out = [name for name, c in zip(CHANNELS, self.clamped, strict=True) if c]
        if not out:
            return ""
        return (f"{' and '.join(out)} out of the film's reach: "
                + ", ".join(f"{name[0]} {r:.3f} for {t:.3f}" for name, r, t, c in
                            zip(CHANNELS, self.reached, self.target, self.clamped, strict=True)
                            if c))


class SlabLight:
    """The settings' made-up skin with the film at a thickness under uniform light: the
    model's layers (``skin``, with ``foundation``'s film if given), the thickness and the
    bake's quadrature at ``resolution`` (the slab is derived on it, docs/baking.md): the
    named one refined for a narrow skin gloss as the bake refines it
    (:meth:`lut_baker.bake.Resolution.for_lobe`), so that the colour matched is the tables'."""

    def __init__(self, settings, foundation: str | None = None, resolution: str | None = None):
        self.skin = skin_model.skin_from_settings(settings, foundation)
        self.thickness_um = float(skin_model.film_of(settings))
        res = bake.resolution(resolution or settings.resolution).for_lobe(
            bake.path3_width_deg(self.skin))
        self.grid = quadrature.hemisphere_panels(res.quad_panels, res.quad_points,
                                                 res.quad_phi)
        self.film_gloss = uniform_light_gloss(self.skin, self.grid)

    def covered(self, absorption, body, under=None) -> np.ndarray:
        """The covered colour at ``absorption`` on a skin of albedo ``body`` (RGB; times
        ``under`` under the film, if given)."""
        if under is not None:
            body = np.asarray(body, float) * np.asarray(under, float)
        return slab_skin.channel_colours(
            self.skin.film, self.skin.film_transmission, self.skin.skin_reflection, body,
            self.thickness_um, self.grid, absorption)

    def solve(self, target, body):
        """``(A, a, clamped, colour)``: :func:`lut_baker.model.slab_skin.matching_shade` (the
        covered colour at ``A`` and ``a`` its search's own)."""
        return slab_skin.matching_shade(target, self.skin.film, self.skin.film_transmission,
                                        self.skin.skin_reflection, body, self.thickness_um,
                                        self.grid)


def uniform_light_gloss(skin, grid) -> np.ndarray:
    """The film surface's gloss under uniform light (RGB): the covered colour's floor."""
    albedo = film_slab.face_albedo(skin.film, grid)
    return np.asarray(film_slab.bihemispherical_on_grid(albedo, grid), float).reshape(-1) \
        * np.ones(3)


def _light(settings, foundation: str | None = None, resolution: str | None = None):
    """What a shade is solved on: :class:`SlabLight` with the film at a thickness, else the
    paper film's uniform-light parts (:func:`light_for`)."""
    if skin_model.film_of(settings) != "paper":
        return SlabLight(settings, foundation, resolution)
    return light_for(settings, foundation, resolution)


def _covered(light, settings, absorption, body, under=None) -> np.ndarray:
    if isinstance(light, SlabLight):
        return light.covered(absorption, body, under)
    return uniform_light.covered_colour(light, absorption, body, float(settings.gloss))


def _solve(settings, light, target, skin: SkinTarget) -> Shade:
    if isinstance(light, SlabLight):
        absorption, under, clamped, reached = light.solve(target, skin.body)
        result = Shade(np.asarray(absorption, float), np.asarray(clamped, bool),
                       np.asarray(target, float), reached, skin, under=np.asarray(under, float))
        # The colour reached by the shade as the settings keep it (single precision): what
        # the panel's shade renders, and what the next step finds kept as its current colour.
        result.reached = light.covered(_as_kept(result.absorption), skin.body,
                                       _as_kept(result.skin_under()))
        return result
    gloss = float(settings.gloss)
    absorption, clamped = uniform_light.matching_absorption(light, target, skin.body, gloss)
    reached = uniform_light.covered_colour(light, absorption, skin.body, gloss)
    return Shade(absorption, clamped, np.asarray(target, float), reached, skin)


def _as_kept(values) -> np.ndarray:
    """``values`` as a float vector property keeps them: single precision."""
    return np.asarray(values, np.float32).astype(float)


def _reach_sentences(shade_: Shade, light, gloss: float) -> list[str]:
    sentences = []
    for c, name in enumerate(CHANNELS):
        if isinstance(light, SlabLight) and shade_.under is not None and \
                shade_.under[c] < shade_.skin.body[c] and shade_.absorption[c] == 1.0:
            sentences.append(
                f"{name}: at {light.thickness_um:g} um the film's gloss adds more than full "
                f"absorption takes away; the skin under the film darkened to "
                f"{shade_.under[c] / shade_.skin.body[c]:.3f} of its own to match.")
            continue
        if not shade_.clamped[c]:
            continue
        if shade_.absorption[c] == 0.0:
            sentences.append(
                f"{name} is out of reach: the film over this skin reflects at most "
                f"{shade_.reached[c]:.3f} (no absorption) against {shade_.target[c]:.3f}: the "
                f"made-up skin is that much darker where the film covers it.")
        else:
            floor = (float(light.film_gloss[c]) if isinstance(light, SlabLight)
                     else gloss * float(light.film_gloss[c]))
            sentences.append(
                f"{name} is out of reach: the film's own gloss reflects {floor:.3f} and the "
                f"covered skin at least {shade_.reached[c]:.3f} (full absorption) against "
                f"{shade_.target[c]:.3f}; a matte product (no gloss: Clarins 103, 108) comes "
                f"closer.")
    return sentences


def seen_target(skin: SkinTarget, film_gloss, film_roughness: float
                ) -> tuple[np.ndarray, str]:
    """``(target, sentence)``: the covered colour under uniform light that renders on this
    mesh as the artist's shader does, and what the sentence says of it (or ``skin.target``
    and "" without ``skin.sky``).  Under a uniform sky each part of a colour keeps what the
    mesh leaves it (:meth:`.sky_visibility.SkyVisibility.kept`): the artist's glosses their
    lobes', the rest a diffuse surface's; so does the film's own gloss (``film_gloss``, RGB,
    at Blender ``film_roughness``), and what the film lets through of the skin is counted as
    diffuse."""
    if skin.sky is None:
        return np.asarray(skin.target, float), ""
    target = np.asarray(skin.target, float)
    film_gloss = np.asarray(film_gloss, float) * np.ones(3)
    glossy_film = bool(np.any(film_gloss > 0.0))  # a matte film: no lobe to measure
    diffuse, skies = skin.sky.seen(*(r for _, r in skin.glosses),
                                   *([film_roughness] if glossy_film else []))
    if not glossy_film:
        skies = [*skies, 1.0]
    kept = skin.sky.kept
    gloss = sum((np.asarray(g, float) for g, _ in skin.glosses), np.zeros(3))
    rendered = kept(diffuse, target) * (target - gloss) + sum(
        (kept(sky, target) * np.asarray(g, float)
         for (g, _), sky in zip(skin.glosses, skies[:-1], strict=True)), np.zeros(3))
    seen = film_gloss + (rendered - kept(skies[-1], target) * film_gloss) \
        / kept(diffuse, target)
    lobes = ", ".join(f"a gloss at roughness {r:.2g} {sky:.0%}" for (_, r), sky in zip(
        skin.glosses, skies[:-1], strict=True))
    film = f", the film's gloss {skies[-1]:.0%}" if glossy_film else ""
    return seen, (f"On this mesh a diffuse surface sees {diffuse:.0%} of a uniform sky"
                  f"{', ' + lobes if lobes else ''}{film} (its hollows, as the camera sees "
                  f"them): matched to {_rgb(seen)} under uniform light, which renders here as "
                  f"the artist's shader does.")


def _film_gloss(settings, light, foundation: str | None) -> tuple[np.ndarray, float]:
    """The film surface's own gloss under uniform light (RGB) and its Blender roughness."""
    roughness = (float(settings.film_roughness) if foundation is None
                 else shade.foundation_roughness(foundation))
    if isinstance(light, SlabLight):
        return light.film_gloss, roughness
    return float(settings.gloss) * np.asarray(light.film_gloss, float), roughness


def matched(material, foundation: str | None = None, skin: SkinTarget | None = None,
            resolution: str | None = None) -> Shade:
    """The shade whose covered skin has the skin's colour before Apply under uniform light
    (:func:`skin_target`), so that the made-up skin has it at any coverage, with the report's
    sentences; ``foundation``: on that preset's film instead of the settings'; ``skin``: the
    target if known; ``resolution``: of the tables (default the settings')."""
    settings = material.makeup_skin
    light = _light(settings, foundation, resolution)
    if skin is None:
        skin = skin_target(material, resolution=resolution, light=None if isinstance(
            light, SlabLight) else light)
    target, seen = seen_target(skin, *_film_gloss(settings, light, foundation))
    # aimed at as the settings keep it (Shade Base), so that steps back to it find this
    # search again (kept per channel, slab_skin.channel_colours)
    target = _as_kept(target)
    result = _solve(settings, light, target, skin)
    result.base = result.target
    result.sentences.append(
        f"Matched the shade to the skin's color before Apply ({_rgb(skin.target)}: "
        f"{skin.source}; under the film the skin's body color is {_rgb(skin.body)}): "
        f"absorption {_rgb(result.absorption)}, in the bottle "
        f"{_rgb(shade.colour_seen(result.absorption, shade.slab_foundation(settings)))}.")
    if seen:
        result.sentences.append(seen)
    result.sentences += _reach_sentences(result, light, float(settings.gloss))
    return result


def _shortfall(result: Shade) -> float:
    """How far a shade misses the skin, relative, summed over channels: its covered colour
    against its target, and with the film at a thickness how far it darkened the skin under
    the film to get there (a sheer film's gloss that full absorption cannot take away)."""
    return float(np.sum(np.abs(result.reached - result.target)
                        / np.maximum(result.target, 1e-6))
                 + np.sum(1.0 - result.skin_under()))


def first_shade(material, reading=None, resolution: str | None = None
                ) -> tuple[str | None, Shade]:
    """The first Apply's shade (docs/addon.md, "A first Apply"): :func:`matched` on the
    settings' film; when the skin is darker than that film's own gloss in some channel
    (clamped at full absorption, or with the film at a thickness the skin under the film
    darkened to reach it) and the matte film (:data:`MATTE_FILM`) reaches it better,
    matched on that instead, and its name returned (else None).  ``reading``: the artist's
    skin (:class:`.artist_skin.SkinReading`), if read; ``resolution``: of the tables (default
    the settings': Apply's own, so that the match's bake is Apply's)."""
    settings = material.makeup_skin
    skin = skin_target(material, reading, resolution=resolution)
    result = matched(material, skin=skin, resolution=resolution)
    too_dark = np.any(result.clamped & (result.absorption == 1.0)) or np.any(
        result.skin_under() < 1.0)
    if not too_dark or settings.foundation == MATTE_FILM:
        return None, result
    matte = matched(material, MATTE_FILM, skin, resolution)
    if _shortfall(matte) >= _shortfall(result):
        return None, result
    label = presets.FOUNDATIONS[MATTE_FILM]["label"]
    matte.sentences.insert(0, f"Chose {label}'s matte film: this skin is darker than the "
                              f"{presets.FOUNDATIONS[settings.foundation]['label']} film's own "
                              f"gloss reaches.")
    return MATTE_FILM, matte


def stepped(material, steps: int) -> Shade:
    """The shade ``steps`` shade steps lighter (positive) or darker than the current one: the
    covered skin's target times :data:`SHADE_STEP` per step, counted from the last match (or
    from the current shade's covered colour when it was set otherwise), so that steps undone
    give back exactly the shade they started from."""
    settings = material.makeup_skin
    light = _light(settings)
    skin = skin_target(material, light=None if isinstance(light, SlabLight) else light)
    gloss = float(settings.gloss)
    current = _covered(light, settings, list(settings.absorption), skin.body,
                       tuple(settings.skin_under))
    if settings.shade_source == "MATCH" and settings.is_property_set("shade_base"):
        base, count = np.asarray(settings.shade_base, float), int(settings.shade_steps)
    else:
        base, count = current, 0
    count += int(steps)
    result = _solve(settings, light, base * SHADE_STEP ** count, skin)
    result.steps, result.base = count, base
    word = "lighter" if steps > 0 else "darker"
    result.sentences.append(
        f"One shade {word}: the covered skin {_rgb(current)} -> {_rgb(result.reached)}, "
        f"absorption {_rgb(result.absorption)}, in the bottle "
        f"{_rgb(shade.colour_seen(result.absorption, shade.slab_foundation(settings)))}.")
    result.sentences += _reach_sentences(result, light, gloss)
    return result


def _rgb(values) -> str:
    return "(" + ", ".join(f"{float(v):.3f}" for v in values) + ")"


def assign(settings, result: Shade, source: str) -> None:
    """Store ``result`` on the settings: the absorption, its colour seen, the panel's note,
    where the shade came from (``source``: ``"MATCH"``) and the steps' count and base."""
    with shade.assigning():
        settings.absorption = [float(a) for a in result.absorption]
        settings.shade_colour = [float(c) for c in shade.colour_seen(
            result.absorption, shade.slab_foundation(settings))]
        settings.shade_note = result.note()
        settings.shade_source = source
        if result.base is not None:
            settings.shade_base = [float(b) for b in result.base]
        settings.shade_steps = int(result.steps)
        settings.skin_under = [float(u) for u in result.skin_under()]


def clear_cache() -> None:
    """Forget the session's uniform-light parts and the surfaces' sky (the add-on's
    unregister calls it)."""
    _LIGHT.clear()
    sky_visibility.clear_cache()

