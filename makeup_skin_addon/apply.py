"""Apply, step by step; Revert; Check Tables.

Apply (:func:`apply_to_object`) takes these steps, each a call into the module that does it:

1. Refuse data linked from a library (:func:`refuse_linked`); take the object's material, or
   give it a new one.
2. Read the artist's shader (:func:`.artist_skin.read_material`): over it the skin under the
   film takes its roughness, index and subsurface method (:func:`_follow_shader`).
3. A shade never chosen: match the skin (:func:`.matching.first_shade`), the artist's first
   step.
4. The settings as the model and its bake record (:func:`.skin_model.skin_from_settings`,
   :func:`.bakes.bake_record`), at preview resolution first when asked.
5. The group: found and reused, or baked, fitted and built (:func:`.groups.group_for` with a
   :class:`.bakes.Bake`, which bakes and fits only when asked); Tier Auto chooses from the
   fit's measurement (:mod:`.tier_choice`).
6. The group made the material's surface, the artist's tree converted in place
   (:func:`.groups.setup_material`, :func:`.convert.install`), the measurement kept on the
   material.
7. The report: what was converted and carried over, what was not, the engine's tier.

- :func:`apply_to_object` -- the Apply operator's work; :class:`Report` its sentences.
- :func:`revert_material` -- Revert's.
- :func:`preview_first` -- whether a rebuild goes at preview resolution first (no group of
  the settings' bake yet).
- :func:`engine_note` -- the report's sentence when a tier is not made for the scene's engine.
- :func:`refuse_linked` -- :class:`LinkedDataError` for data linked from a library.
- :func:`check_material` -- verify a made-up material against its bake record, repair it
  (from a re-bake, or from the settings: :func:`.rebuild.rebuild_from_settings`).
- :func:`clear_cache` -- forget every session cache (the add-on's unregister calls it).
"""

from __future__ import annotations

from typing import Any

import bpy

from . import (
    artist_skin,
    bakes,
    convert,
    groups,
    matching,
    nodes,
    rebuild,
    shade,
    skin_model,
    skin_sampling,
    storage,
    surface_values,
    tier_choice,
)
from .bakes import Bake
from .core import auto_tier, tier_registry
from .keys import MATERIAL_NAME, SETTINGS_VERSION
from .progress import Progress, progress_bar

__all__ = [
    "PREVIEW",
    "LinkedDataError",
    "refuse_linked",
    "Report",
    "apply_to_object",
    "preview_first",
    "engine_note",
    "revert_material",
    "check_material",
    "clear_cache",
]

PREVIEW = "preview"
"""The resolution an Apply bakes at first when asked to (``preview_first``), and the live
preview's."""


class LinkedDataError(ValueError):
    """The data Apply or Fit to Scene would change is linked from a library."""


def refuse_linked(obj: Any, material: Any) -> None:
    """Raise :class:`LinkedDataError` (naming the library and how to make the data local) if
    ``material``, its Made-up Skin group, or (when Apply must add a material) ``obj``'s mesh is
    linked: changes to linked data are lost when the file is saved."""
    node = convert.group_node(material)
    checks = [(material, "material"), (node.node_tree if node else None, "node group")]
    if material is None and obj is not None:
        checks.append((obj.data, "mesh"))
    for datablock, kind in checks:
        reason = convert.linked_library(datablock, kind)
        if reason is not None:
            raise LinkedDataError(reason)


class Report(list):
    """The sentences of an Apply, in order; ``warnings``: those that say what could not be
    carried over (the operator reports them as warnings); ``refine``: the resolution the
    group is still to be rebuilt at (an Apply at preview first), or None."""

    def __init__(self) -> None:
        super().__init__()
        self.warnings: list[str] = []
        self.refine: str | None = None

    def warn(self, sentence: str) -> None:
        self.append(sentence)
        self.warnings.append(sentence)


# -- Apply, step by step ----------------------------------------------------------------------

def _material_for(obj: Any) -> tuple[Any, bool]:
    """``(material, created)``: the object's active material, or a new one in its active slot
    (the object had none)."""
    material = obj.active_material
    if material is not None:
        return material, False
    material = bpy.data.materials.new(MATERIAL_NAME)
    if obj.material_slots:
        obj.active_material = material
    else:
        obj.data.materials.append(material)
    return material, True


def _follow_shader(settings: Any, reading: Any, report: Report) -> None:
    """Take from the artist's shader (``reading``) what the bake needs of the skin under the
    film: its roughness (within the panel's range), index and subsurface method, and its mean
    body colour (the skin the film covers, where a slab's fit is made)."""
    with shade.assigning():
        settings.over_shader = True
        settings.skin_body = [float(b) for b in reading.body]
        if reading.roughness is not None:
            value = min(max(reading.roughness, shade.SKIN_ROUGHNESS_MIN), shade.ROUGHNESS_MAX)
            if abs(value - reading.roughness) > 1e-6:
                report.append(
                    f"The skin under the film has Skin Roughness {value:.3f}, the shader's "
                    f"{reading.roughness:.3f} clamped to the panel's range (its gloss is seen "
                    f"through the film's transmission, which spreads it over about 29 degrees;"
                    f" the bare skin keeps the shader's).")
            settings.skin_roughness = value
        if reading.ior is not None:
            settings.skin_ior = min(max(reading.ior, 1.01), 2.5)
        if reading.method in {"BURLEY", "RANDOM_WALK", "RANDOM_WALK_SKIN"}:
            settings.subsurface_method = reading.method


def _first_match(context: Any, material: Any, reading: Any, resolution: str,
                 report: Report) -> None:
    """A shade never chosen: match the skin (the artist's first step), before the fit
    measures the tiers at the absorption; on the tables Apply bakes (``resolution``)."""
    settings = material.makeup_skin
    with progress_bar(getattr(context, "window_manager", None)):
        film, result = matching.first_shade(material, reading, resolution)
    if film is not None:
        with shade.assigning():
            settings.foundation = film
            settings.film_roughness = shade.foundation_roughness(film)
    matching.assign(settings, result, "MATCH")
    report += result.sentences
    for note in reading.notes if reading is not None else ():
        if surface_values.assumed(note):
            report.warn(f"Not followed by the match: {note} (the shade is matched as if so; "
                        f"the made-up skin renders the shader as it is)")


def _record(settings: Any, resolution: str) -> dict:
    """The settings' bake record at ``resolution`` (:func:`.bakes.bake_record`)."""
    return bakes.bake_record(skin_model.skin_from_settings(settings), resolution,
                             skin_model.film_of(settings), skin_model.skin_under_of(settings),
                             skin_model.skin_albedo_of(settings))


def _has_group(settings: Any, record: dict, over: bool) -> bool:
    return groups.has_group(record, tier_choice.forced_method(settings), over)


def preview_first(material: Any) -> bool:
    """Whether a rebuild of ``material``'s settings goes at preview resolution first: the
    settings' resolution is finer and the file has no group of that bake yet (one it has is
    swapped in at once)."""
    settings = material.makeup_skin
    over = settings.over_shader and convert.artist_tree(material) is not None
    return (settings.resolution != PREVIEW
            and not _has_group(settings, _record(settings, settings.resolution), over))


def _bake_record(settings: Any, target: str, quick: bool, over: bool, report: Report) -> dict:
    """The settings' bake record at ``target``, or (``quick``, and the file has no group of
    that bake) at preview resolution, the refinement to ``target`` noted in ``report``."""
    record = _record(settings, target)
    if quick and not _has_group(settings, record, over):
        record = _record(settings, PREVIEW)
        report.refine = target
        report.append(f"Baked at preview resolution first: the {target} tables follow in "
                      f"the background.")
    return record


def _users(material: Any) -> list:
    """Objects whose slots hold ``material``."""
    return [obj for obj in bpy.data.objects
            if any(slot.material == material for slot in getattr(obj, "material_slots", ()))]


def _conversion_sentences(material: Any, installed: convert.Installed, created: bool,
                          obj: Any) -> Report:
    """The report's sentences about a first conversion: what was kept, carried over, not
    carried over (warnings), and the film's normal."""
    report = Report()
    if created:
        report.append(f"{obj.name!r} had no material: created {material.name!r} with the skin "
                      f"preset's Skin Color.")
        return report
    if installed.over_shader:
        kept = ("its own shader stays the bare skin (Coverage 0 renders as before Apply) and "
                "gives the skin under the film")
    elif convert.can_revert(material):
        kept = ("it had no shader of the artist's (Blender's default Principled BSDF, kept "
                "framed and disconnected): the skin is the skin preset's")
    else:
        kept = "it had no surface before: the skin is the skin preset's"
    linked = f"; linked {', '.join(installed.carried)}" if installed.carried else ""
    report.append(f"Converted {material.name!r} in place: {kept}{linked}.")
    if installed.film_normal:
        report.append(installed.film_normal + ".")
    return report


def _closing_sentences(material: Any, installed: convert.Installed, created: bool, obj: Any,
                       report: Report) -> None:
    """What the conversion did (first), what was not carried over (warnings), and who else
    shows the material."""
    if installed.first or created:
        report[:0] = _conversion_sentences(material, installed, created, obj)
    for sentence in installed.missing:
        report.warn(f"Not carried over: {sentence}.")
    users = len(_users(material))
    if users > 1:
        report.append(f"{material.name!r} is shared by {users} objects: all of them show "
                      f"the made-up skin.")


def apply_to_object(context: Any, obj: Any, *, resolution: str | None = None,
                    preview_first: bool = False) -> tuple[Any, Report]:
    """Find or build the group for the settings of ``obj``'s active material and make it the
    material's surface, converted in place (:func:`.groups.setup_material`); an object
    without a material gets a new one.  Returns ``(material, report)``: the report's
    sentences (:class:`Report`: what was carried over, what was not as warnings, how many
    objects share the material).

    ``resolution``: of the bake (default the settings').  ``preview_first``: when the file
    has no group of that bake, bake and fit at preview resolution instead (about a quarter of
    the bake's time, and the first Apply's match with it; with the film at a thickness the
    slab's tables at that thickness only, :func:`.bakes.rebake`) and say so in
    ``report.refine`` (the resolution to rebuild at, which the caller does on a worker thread:
    :func:`.live.refine`); else ``report.refine`` is None.

    Over the artist's shader (:func:`.convert.artist_tree`) the skin under the film is read
    from it again at every Apply (:func:`.artist_skin.read_material`).  Settings Apply has
    seen before (the same bake, tier and method, in this file) reuse their group: nothing is
    baked, fitted or hashed.

    Raises
    ------
    LinkedDataError
        If the material, its group, or the mesh that would get a new material is linked from
        a library (nothing is changed).
    """
    # 1. The material, refused if linked.
    refuse_linked(obj, obj.active_material)
    material, created = _material_for(obj)
    settings = material.makeup_skin
    first = not settings.is_made_up or groups.group_of(material) is None
    scene = context.scene
    report = Report()
    # 2. The artist's shader, followed.
    with progress_bar(getattr(context, "window_manager", None)):
        reading = None if created else artist_skin.read_material(material, scene)
    if reading is not None:
        _follow_shader(settings, reading, report)
    else:
        with shade.assigning():
            settings.over_shader = False
    target = resolution or settings.resolution
    quick = preview_first and target != PREVIEW
    # 3. A shade never chosen, matched.
    if first and settings.shade_source == "DEFAULT":
        _first_match(context, material, reading, PREVIEW if quick else target, report)
    # 4. The model's bake record.
    record = _bake_record(settings, target, quick, reading is not None, report)
    # 5. The group, reused or built.
    with Progress(context) as progress:
        work = Bake(record, tier_choice.forced_method(settings), settings.coverage,
                    settings.absorption, progress,
                    tiers=tier_choice.fitted_tiers(settings, scene), over=reading is not None,
                    one_thickness=report.refine is not None)
        group, measured, tier, auto = groups.group_for(material, settings, scene, work, report)
    # 6. The material's surface.
    groups.record_measurement(material, measured, record["key"], auto)
    installed = groups.setup_material(material, group, scene, reading)
    settings.is_made_up = True
    settings.settings_version = SETTINGS_VERSION
    # 7. The report.
    note = engine_note(material, tier, scene, measured)
    if note is not None:
        report.append(note)
    _closing_sentences(material, installed, created, obj, report)
    return material, report


def engine_note(material: Any, tier: str, scene: Any, measured: dict | None = None
                ) -> str | None:
    """The report's sentence when ``tier`` is not made for the engine ``scene`` renders with
    (:data:`lut_baker.auto_tier.ENGINE_TIERS`), naming the tier that is and its angular error
    at the material's coverage (``measured``: :func:`.bakes.measure`); None when it is.  The
    group renders in either engine: nothing is changed."""
    engine = artist_skin.render_engine(scene)
    if tier in auto_tier.ENGINE_TIERS[engine]:
        return None
    suited = auto_tier.ENGINE_TIERS[engine][0]
    error = ((measured or {}).get("errors") or {}).get(suited, {}).get("rms")
    at = f" ({100 * error:.1f}% angular error here)" if error is not None else ""
    label, better, made_for = (*(tier_registry.tier(t).label for t in (tier, suited)),
                               tier_registry.tier(tier).engines[0])
    if engine == "EEVEE":
        why = ("EEVEE draws every Glossy lobe as GGX through its own approximation, which "
               "the Cycles tiers are not fitted to")
    else:
        why = "Cycles renders its GGX lobes exactly, which they are not fitted to"
    return (f"{material.name!r} uses the {label} tier, made for "
            f"{'EEVEE' if made_for == 'EEVEE' else 'Cycles'}, but the scene renders with "
            f"{'EEVEE' if engine == 'EEVEE' else 'Cycles'}: {why}; the {better} tier is "
            f"fitted to {'EEVEE' if engine == 'EEVEE' else 'Cycles'}{at}: choose it, or Tier "
            f"Auto.")


def revert_material(material: Any) -> str:
    """Give ``material`` back the surface it had before Apply (:func:`.convert.revert`); its
    Made-up Skin settings stay for a later Apply.  Returns the report's sentence."""
    reason = convert.linked_library(material, "material")
    if reason is not None:
        raise LinkedDataError(reason)
    restored = convert.revert(material)
    material.makeup_skin.is_made_up = False
    with shade.assigning():
        material.makeup_skin.over_shader = False
    return f"Reverted {material.name!r}: {restored}."


# -- Check Tables ------------------------------------------------------------------------------

def check_material(context: Any, material: Any) -> tuple[bool, str]:
    """Verify a made-up material: its group's bake record is readable and its own (its key
    is the hash of its parameters and resolution) and every image the render reads matches
    its recorded hash; repair what is not, from the record (or, if it is unusable, from the
    panel's settings).  Nothing is baked when all is intact.  Returns ``(intact, one
    sentence for the report)``."""
    name = material.name
    node = groups.group_of(material)
    if node is None or node.node_tree is None:
        return False, (f"{name!r}: its Made-up Skin node is gone from the node tree; Apply "
                       f"puts it back.")
    group = node.node_tree
    reason = convert.linked_library(group, "node group")
    if reason is not None:
        return False, f"{name!r}: not checked: {reason}."
    meta = nodes.read_meta(group)
    if "parameters" not in meta:
        rebuild.rebuild_from_settings(context, material, group,
                                      material.makeup_skin.resolution)
        return False, (f"{name!r}: its group's record is unreadable or from an older "
                       f"version; re-baked it from the panel's settings.")
    try:
        key = bakes.bake_key(meta["parameters"], meta.get("resolution", "default"),
                             meta.get("film_thickness_um"), meta.get("skin_under"),
                             meta.get("skin_albedo"))
    except (TypeError, ValueError):
        key = None
    if key != meta.get("key"):
        rebuild.rebuild_from_settings(context, material, group,
                                      material.makeup_skin.resolution)
        return False, (f"{name!r}: its group's bake record does not match its key; re-baked "
                       f"it from the panel's settings.")
    problems = storage.image_problems(meta.get("images", []))
    if not problems and nodes.has_interface(group):
        return True, f"{name!r}: intact."
    settings = material.makeup_skin
    tier = meta.get("tier", tier_registry.UNRECORDED)
    work = Bake({k: meta[k] for k in bakes.RECORD_FIELDS if k in meta},
                meta.get("forced_method"), settings.coverage, settings.absorption,
                tiers=tier_choice.fitted_tiers(settings, context.scene, (tier,)),
                over=nodes.over_shader(group))
    groups.build(work, tier, group)
    what = "; ".join(problems) if problems else "its inputs were of an older version"
    return False, f"{name!r}: {what}; rebuilt it from a re-bake."


def clear_cache() -> None:
    """Forget the session's bakes and fits, roughened layers, matches, points and images (the
    add-on's unregister calls it)."""
    bakes.clear()
    skin_model.clear_cache()
    matching.clear_cache()
    skin_sampling.clear_cache()
