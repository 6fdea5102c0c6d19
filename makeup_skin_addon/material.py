"""Apply: bake, fit, build or reuse the node group, and make it the surface of the artist's
own material (converted in place, :mod:`.convert`); Revert and Check Tables.

A bake is named by its record's key (:func:`.storage.bake_record`: the settings' parameters and
resolution, hashed; no bake needed to know it) and a group by its tier, key and forced
subsurface method (:func:`.nodes.group_name`).  Apply with settings it has seen before finds the
group by name and bakes, fits and hashes nothing; otherwise it bakes and fits once per session
(:mod:`.fits`).  Tier = Auto decides from what the fit of the foundation being applied measured
(kept in the group's record), so the same settings in the same scene give the same tier.

- :func:`skin_from_settings` -- the panel's settings as a :class:`MadeUpSkin` (coverage 1,
  absorption 0: those two are socket values, applied after the bake; :mod:`.shade`).
- :func:`resolve_tier` -- the tier for the settings and scene (Auto: from a measurement).
- :func:`fitted_tiers` -- the tiers Apply fits: the scene engine's and the settings' own.
- :func:`engine_note` -- the report's sentence when a tier is not made for the scene's engine.
- :func:`socket_values` -- the settings' group-node socket values; :func:`update_sockets`
  sets them on a material's group node.
- :func:`refuse_linked` -- :class:`LinkedDataError` for data linked from a library.
- :func:`group_for_tables` -- the group for baked tables (tests and tools; reused when the same
  tables, tier and method were built before and its images are intact).
- :func:`apply_to_object` -- the Apply operator's work; :func:`revert_material` Revert's.
- :func:`rebuild_from_settings` -- a rebuild from the settings at once; :class:`Rebuild`,
  :func:`prepare_rebuild`, :func:`finish_rebuild` -- the same in steps, its costly one on a
  worker thread (the live preview's).
- :func:`check_material` -- verify a made-up material against its bake record, repair it.
"""

from __future__ import annotations

import json

import bpy

from . import artist_skin, convert, fits, matching, nodes, scene_fit, shade, skin_sampling, storage
from .core import auto_tier, params_file, tier_registry, tiers
from .keys import AUTO_KEY, ERRORS_KEY, MATERIAL_NAME, SETTINGS_VERSION
from .nodes import group_name
from .scene_fit import units_per_mm
from .shade import ROUGHNESS_MAX, SKIN_ROUGHNESS_MIN, skin_from_settings

__all__ = [
    "LinkedDataError",
    "refuse_linked",
    "revert_material",
    "rebuild_from_settings",
    "Rebuild",
    "prepare_rebuild",
    "finish_rebuild",
    "skin_from_settings",
    "resolve_tier",
    "engine_note",
    "forced_method",
    "fitted_tiers",
    "group_for_tables",
    "group_of",
    "apply_to_object",
    "setup_material",
    "check_material",
    "clear_cache",
    "update_sockets",
    "socket_values",
]


def resolve_tier(settings, scene, measured=None) -> str:
    """The tier to build: the settings' own, or for Auto the one
    :func:`.scene_fit.choose_with` picks in ``scene`` for a material whose fit measured
    ``measured`` (:func:`.fits.measure`; default: what the material's group keeps, never a new
    bake; in EEVEE the EEVEE tier)."""
    if settings.tier != "AUTO":
        return settings.tier
    return _auto_choice(settings.id_data, scene, measured)[0]


def _auto_choice(material, scene, measured) -> tuple[str, dict]:
    """``(tier, record for the panel)`` of the Auto choice for ``material`` in ``scene``."""
    traits = fits.traits(measured) if measured is not None else None
    if traits is None:
        traits = scene_fit.material_traits(material, may_fit=False, scene=scene)
    choice, _ = scene_fit.choose_with(traits, material, scene)
    chosen = choice.chosen
    return chosen.candidate.tier, {"tier": chosen.candidate.tier, "error": chosen.error,
                                   "engine": scene.render.engine}


def engine_note(material, tier: str, scene, measured: dict | None = None) -> str | None:
    """The report's sentence when ``tier`` is not made for the engine ``scene`` renders with
    (:data:`lut_baker.auto_tier.ENGINE_TIERS`), naming the tier that is and its angular error
    at the material's coverage (``measured``: :func:`.fits.measure`); None when it is.  The
    group renders in either engine: nothing is changed."""
    engine = scene_fit.render_engine(scene)
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


def forced_method(settings):
    """The subsurface method the settings force, or None (Auto: the fit's best)."""
    return None if settings.subsurface_method == "AUTO" else settings.subsurface_method


class LinkedDataError(ValueError):
    """The data Apply or Fit to Scene would change is linked from a library."""


def refuse_linked(obj, material) -> None:
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


class _Progress:
    """``window_manager.progress_*`` from 0 to 100 over Apply's stages (does nothing
    headless); ``stage(start, end)`` maps a stage's own 0..1 onto its share."""

    def __init__(self, context):
        self.wm = getattr(context, "window_manager", None)

    def __enter__(self):
        if self.wm is not None:
            self.wm.progress_begin(0, 100)
        return self

    def stage(self, start: float, end: float):
        def report(fraction: float, message: str = "") -> None:
            if self.wm is not None:
                self.wm.progress_update(int(100 * (start + (end - start) * fraction)))
        return report

    def __exit__(self, *exc):
        if self.wm is not None:
            self.wm.progress_end()
        return False


PREVIEW = "preview"
"""The resolution an Apply bakes at first when asked to (``preview_first``), and the live
preview's."""
BAKE_SHARE = 0.15
"""Share of Apply's progress bar the bake takes (the closure fit and its measurement take the
rest)."""
MEASURE_SHARE = 0.85
"""Where on Apply's progress bar the fit ends and its measurement begins."""


def _stage(progress, start, end):
    return progress.stage(start, end) if progress is not None else None


def _reusable(group, key: str, tier: str, method, messages: list) -> bool:
    """Whether ``group`` was built from this bake, tier and method by this version and its
    images are intact; a damaged image is reported in ``messages``."""
    meta = nodes.read_meta(group)
    if (meta.get("key"), meta.get("tier"), meta.get("forced_method")) != (key, tier, method):
        return False
    if not nodes.has_interface(group) or "parameters" not in meta:  # an older add-on's
        return False
    problems = storage.image_problems(meta.get("images", []))
    for problem in problems:
        messages.append(f"Group {group.name!r}: {problem}; rebuilt it.")
    return not problems


def fitted_tiers(settings, scene, also=()) -> tuple:
    """The tiers Apply fits for ``settings`` in ``scene``: those made for the scene's engine
    (:data:`lut_baker.auto_tier.ENGINE_TIERS`, among which Tier Auto chooses), the settings'
    tier when it is fixed to another, and ``also``; in :data:`lut_baker.closures.tiers.TIERS`
    order.  A tier asked for later (another tier or engine chosen) is fitted then."""
    wanted = {*auto_tier.ENGINE_TIERS[scene_fit.render_engine(scene)], *also}
    if settings.tier in tiers.TIERS:
        wanted.add(settings.tier)
    return tuple(tier for tier in tiers.TIERS if tier in wanted)


class _Bake:
    """One bake record's tables, fit and measurement, made when first asked for (a group that
    can be reused needs none of them): the fit of ``tiers``, for a group over the artist's
    shader if ``over``.  Nothing here touches bpy: a worker thread may make them
    (:mod:`.live`), and the group is built from them on the main thread."""

    def __init__(self, record: dict, method, coverage: float, absorption, progress=None, *,
                 tiers=tiers.TIERS, over: bool = False):
        self.record, self.method = record, method
        self.coverage, self.absorption = float(coverage), [float(a) for a in absorption]
        self.progress = progress
        self.tiers, self.over = tuple(tiers), bool(over)
        self._measured: dict | None = None
        self._fitted: tuple | None = None

    def fitted(self, tier: str | None = None):
        """``(tables, fit)`` (:func:`.fits.baked`), the fit holding :attr:`tiers` (and
        ``tier``, added to them if need be)."""
        if tier is not None and tier not in self.tiers:
            self.tiers = tuple(t for t in tiers.TIERS if t in {*self.tiers, tier})
        if self._fitted is None or not set(self.tiers) <= set(self._fitted[1].tiers):
            self._fitted = fits.baked(
                self.record, method=self.method, tiers=self.tiers, over_shader=self.over,
                errors_at=(self.coverage, self.absorption),
                bake_progress=_stage(self.progress, 0.0, BAKE_SHARE),
                fit_progress=_stage(self.progress, BAKE_SHARE, MEASURE_SHARE))
        return self._fitted

    def adopt(self, measured: dict | None) -> None:
        """Take a measurement a group's record kept at this coverage and absorption."""
        if measured is not None:
            self._measured = measured

    def measured(self, *, with_traits: bool = False) -> dict:
        """What the fit measures at the coverage and absorption (baking and fitting if need
        be), the Auto tier's traits too if ``with_traits``."""
        if self._measured is None or (with_traits and not self._measured["traits"]):
            tables, fit = self.fitted()
            measured = fits.measure(tables, fit, self.coverage, self.absorption,
                                    self.method or fit.subsurface_method,
                                    with_traits=with_traits, over_shader=self.over)
            self._measured = measured
            report = _stage(self.progress, MEASURE_SHARE, 1.0)
            if report is not None:
                report(1.0, "measured")
            return measured
        return self._measured


def _existing(record: dict, tier: str, method, messages: list, over: bool):
    """The group of this bake, tier, method and kind (``over`` the artist's shader or not) if
    the file has it intact, else None."""
    group = bpy.data.node_groups.get(group_name(tier, record["key"], method, over))
    if group is not None and nodes.over_shader(group) == over and \
            _reusable(group, record["key"], tier, method, messages):
        return group
    return None


def _stored_measurement(work: _Bake):
    """What any group of this bake (any tier) keeps measured at the coverage and absorption,
    of the tiers fitted, with the Auto tier's traits, or None."""
    for tier in tiers.TIERS:
        group = bpy.data.node_groups.get(group_name(tier, work.record["key"], work.method,
                                                    work.over))
        if group is not None:
            measured = fits.measured_at(nodes.read_meta(group), work.coverage, work.absorption,
                                        with_traits=True, tiers=work.tiers)
            if measured is not None:
                return measured
    return None


def _build(work: _Bake, tier: str, group=None):
    """The group of ``tier`` built from the bake (rebuilt in place when ``group`` is given),
    its record keeping the measurement; over the artist's shader if ``work.over``."""
    _, fit = work.fitted(tier)
    return nodes.build_group(tier, work.record, fit, group, method=work.method,
                             measured=work.measured(), over=work.over)


def _group_for(material, settings, scene, work: _Bake, messages: list, group=None):
    """``(group, measured, tier, auto record or None)`` for the settings: the existing group
    of the tier reused when intact (nothing baked or fitted), else built (``group`` given:
    rebuilt in place, always); over the artist's shader if ``work.over``."""
    auto = None
    tier = settings.tier
    over = work.over
    if tier == "AUTO":
        work.adopt(_stored_measurement(work))
        tier, auto = _auto_choice(material, scene, work.measured(with_traits=True))
    existing = None if group is not None else _existing(work.record, tier, work.method,
                                                        messages, over)
    if existing is not None:
        stored = fits.measured_at(nodes.read_meta(existing), work.coverage, work.absorption,
                                  tiers=work.tiers)
        if stored is None:  # the group was built at another coverage or absorption
            nodes.write_measured(existing, work.measured())
        return existing, stored or work.measured(), tier, auto
    if group is None:
        group = bpy.data.node_groups.get(group_name(tier, work.record["key"], work.method,
                                                    over))
    return _build(work, tier, group), work.measured(), tier, auto


def group_for_tables(tables, tier: str, *, resolution: str = "default", group=None,
                     errors_at=None, method=None, messages=None):
    """``(group, fit or None)`` of ``tier`` for baked ``tables`` baked at ``resolution`` (tests
    and tools that bake themselves; Apply goes through the settings).

    A group already built from the same bake, tier and ``method`` (a forced subsurface method,
    or None for the fit's choice) whose images are intact is reused (no fit) unless ``group``
    is given, which is then rebuilt in place.  ``errors_at``: ``(coverage, absorption)`` at
    which to measure (default: the bake's).  ``messages``: a list that gets a sentence for
    each damaged image found (then rebuilt)."""
    messages = [] if messages is None else messages
    skin = params_file.skin_from_dict(tables.parameters)
    record = storage.bake_record(skin, resolution)
    storage.remember(record, tables)
    coverage, absorption = errors_at if errors_at is not None else \
        tables.coverage_and_absorption()
    work = _Bake(record, method, coverage, absorption)
    existing = None if group is not None else _existing(record, tier, method, messages,
                                                        False)
    if existing is not None:
        return existing, None
    if group is None:
        group = bpy.data.node_groups.get(group_name(tier, record["key"], method))
    return _build(work, tier, group), work.fitted()[1]


def clear_cache() -> None:
    """Forget the session's fits and re-baked tables (the add-on's unregister calls it)."""
    fits.clear()
    storage.clear_cache()
    shade.clear_cache()
    matching.clear_cache()
    skin_sampling.clear_cache()


def group_of(material):
    """The made-up group node of a material, or None."""
    return convert.group_node(material)


def setup_material(material, group, scene, reading=None):
    """Make ``group`` the surface of ``material`` (:func:`convert.install`: the artist's tree is
    converted in place; over the artist's shader, ``reading``
    (:class:`.artist_skin.SkinReading`) gives the skin under the film) and set the group
    node's inputs from the settings.  Returns what was carried over
    (:class:`.convert.Installed`)."""
    settings = material.makeup_skin
    installed = convert.install(material, group, over_shader=nodes.over_shader(group),
                                reading=reading, film_strength=settings.film_normal_strength,
                                film_follows=settings.film_follows_pores)
    nodes.set_inputs(group_of(material), {"Units per mm": units_per_mm(scene)})
    update_sockets(material)
    return installed


def socket_values(settings) -> dict:
    """Group-node socket values of the settings (by socket name; over the artist's shader the
    skin's colour comes from the shader, not from Skin Color)."""
    values = {
        "Coverage": settings.coverage,
        "Foundation Absorption": tuple(settings.effective_absorption()),
        "Skin Color": tuple(settings.skin_colour),
        "Subsurface Scale": settings.subsurface_scale,
        "Gloss": settings.gloss,
    }
    if settings.over_shader:
        del values["Skin Color"]
    return values


def update_sockets(material) -> None:
    """Copy the material's socket-level settings onto its group node, and the film's normal
    settings onto its normal node (:func:`.convert.set_film_normal`)."""
    node = group_of(material)
    if node is not None:
        settings = material.makeup_skin
        nodes.set_inputs(node, socket_values(settings))
        convert.set_film_normal(material, settings.film_follows_pores,
                                settings.film_normal_strength)


def _users(material) -> list:
    """Objects whose slots hold ``material``."""
    return [obj for obj in bpy.data.objects
            if any(slot.material == material for slot in getattr(obj, "material_slots", ()))]


def _material_for(obj) -> tuple:
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


class Report(list):
    """The sentences of an Apply, in order; ``warnings``: those that say what could not be
    carried over (the operator reports them as warnings); ``refine``: the resolution the
    group is still to be rebuilt at (an Apply at preview first), or None."""

    def __init__(self):
        super().__init__()
        self.warnings: list[str] = []
        self.refine: str | None = None

    def warn(self, sentence: str) -> None:
        self.append(sentence)
        self.warnings.append(sentence)


def _conversion_sentences(material, installed, created: bool, obj, report: Report) -> None:
    """The report's sentences about a first conversion: what was kept, carried over, not
    carried over (warnings), and the film's normal."""
    if created:
        report.append(f"{obj.name!r} had no material: created {material.name!r} with the skin "
                      f"preset's Skin Color.")
        return
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


def _follow_shader(settings, reading, report: Report) -> None:
    """Take from the artist's shader (``reading``) what the bake needs of the skin under the
    film: its roughness (within the panel's range), index and subsurface method."""
    with shade.assigning():
        settings.over_shader = True
        if reading.roughness is not None:
            value = min(max(reading.roughness, SKIN_ROUGHNESS_MIN), ROUGHNESS_MAX)
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


def _record_errors(material, measured: dict, key: str) -> None:
    """The measurement's tier errors and gloss omissions on the material
    (:data:`.keys.ERRORS_KEY`), for the panel and the Auto tier."""
    omission = (measured.get("traits") or {}).get("gloss_omission") or {}
    material[ERRORS_KEY] = json.dumps({
        tier: {"rms": e["rms"], "albedo": e["albedo"], "coverage": measured["coverage"],
               "absorption": list(measured["absorption"]),
               "gloss_omission": omission.get(tier, {}), "key": key}
        for tier, e in measured["errors"].items()})


def _record_auto(material, auto) -> None:
    """What Tier = Auto chose (:data:`.keys.AUTO_KEY`), or nothing kept for a fixed tier."""
    if auto is not None:
        material[AUTO_KEY] = json.dumps(auto)
    elif AUTO_KEY in material:
        del material[AUTO_KEY]


def _has_group(record: dict, method, over: bool) -> bool:
    """Whether the file has a group of this bake (any tier)."""
    return any(bpy.data.node_groups.get(group_name(tier, record["key"], method, over))
               for tier in tiers.TIERS)


def apply_to_object(context, obj, *, resolution=None, preview_first: bool = False) -> tuple:
    """Find or build the group for the settings of ``obj``'s active material and make it the
    material's surface, converted in place (:func:`setup_material`); an object without a
    material gets a new one.  Returns ``(material, report)``: the report's sentences
    (:class:`Report`: what was carried over, what was not as warnings, how many objects
    share the material).

    ``resolution``: of the bake (default the settings').  ``preview_first``: when the file
    has no group of that bake, bake and fit at preview resolution instead (about a quarter of
    the bake's time, and the first Apply's match with it) and say so in ``report.refine``
    (the resolution to rebuild at, which the caller does on a worker thread:
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
    refuse_linked(obj, obj.active_material)
    material, created = _material_for(obj)
    settings = material.makeup_skin
    first = not settings.is_made_up or group_of(material) is None
    scene = context.scene
    report = Report()
    with skin_sampling.progress_bar(getattr(context, "window_manager", None)):
        reading = None if created else artist_skin.read_material(material, scene)
    if reading is not None:
        _follow_shader(settings, reading, report)
    else:
        with shade.assigning():
            settings.over_shader = False
    target = resolution or settings.resolution
    quick = preview_first and target != PREVIEW
    if first and settings.shade_source == "DEFAULT":
        # A shade never chosen: match the skin (the artist's first step), before the fit
        # measures the tiers at the absorption; on the tables Apply bakes.
        with skin_sampling.progress_bar(getattr(context, "window_manager", None)):
            film, result = matching.first_shade(material, reading,
                                                PREVIEW if quick else target)
        if film is not None:
            with shade.assigning():
                settings.foundation = film
                settings.film_roughness = shade.foundation_roughness(film)
        matching.assign(settings, result, "MATCH")
        report += result.sentences
    record = storage.bake_record(skin_from_settings(settings), target)
    if quick and not _has_group(record, forced_method(settings), reading is not None):
        record = storage.bake_record(skin_from_settings(settings), PREVIEW)
        report.refine = target
        report.append(f"Baked at preview resolution first: the {target} tables follow in "
                      f"the background.")
    with _Progress(context) as progress:
        work = _Bake(record, forced_method(settings), settings.coverage,
                     settings.effective_absorption(), progress,
                     tiers=fitted_tiers(settings, scene), over=reading is not None)
        group, measured, tier, auto = _group_for(material, settings, scene, work, report)
    _record_errors(material, measured, record["key"])
    _record_auto(material, auto)
    installed = setup_material(material, group, scene, reading)
    note = engine_note(material, tier, scene, measured)
    if note is not None:
        report.append(note)
    settings.is_made_up = True
    settings.settings_version = SETTINGS_VERSION
    if installed.first or created:
        head = Report()
        _conversion_sentences(material, installed, created, obj, head)
        report[:0] = head
    for sentence in installed.missing:
        report.warn(f"Not carried over: {sentence}.")
    users = len(_users(material))
    if users > 1:
        report.append(f"{material.name!r} is shared by {users} objects: all of them show "
                      f"the made-up skin.")
    return material, report


def revert_material(material) -> str:
    """Give ``material`` back the surface it had before Apply (:func:`convert.revert`); its
    Made-up Skin settings stay for a later Apply.  Returns the report's sentence."""
    reason = convert.linked_library(material, "material")
    if reason is not None:
        raise LinkedDataError(reason)
    restored = convert.revert(material)
    material.makeup_skin.is_made_up = False
    with shade.assigning():
        material.makeup_skin.over_shader = False
    return f"Reverted {material.name!r}: {restored}."


class _Checked:
    """A progress for :class:`_Bake` that reports nothing but calls ``check()`` at every step
    (which raises to stop the work)."""

    def __init__(self, check):
        self.check = check

    def stage(self, start: float, end: float):
        def report(fraction: float, message: str = "") -> None:
            self.check()
        return report


class Rebuild:
    """A rebuild of a material's group from its settings, in three steps so that the costly
    one runs off the main thread (:mod:`.live`): :func:`prepare_rebuild` reads the settings
    and the scene, :meth:`compute` makes the made-up skin, bakes, fits and measures (and
    makes the Auto tier's choice once, which leaves its costly part cached), touching no bpy,
    and :func:`finish_rebuild` builds the group from what was computed.  ``material``: the
    name, ``uid``: the material's ``session_uid`` (another file's material of the same name
    is not it); ``work``: the :class:`_Bake` (made by :meth:`compute`)."""

    def __init__(self, material, skin: shade.SkinSettings, resolution: str, bake: dict,
                 where):
        self.material, self.uid = material.name, material.session_uid
        self.skin, self.resolution, self.bake, self.where = skin, resolution, bake, where
        self.work: _Bake | None = None
        self.progress = None

    @property
    def key(self) -> str:
        """The bake's key (once :meth:`compute` made it)."""
        if self.work is None:
            raise AssertionError("the rebuild is not computed")
        return self.work.record["key"]

    def compute(self, check=None) -> _Bake:
        """Make the skin, bake, fit and measure (no bpy: any thread); ``check()``: called at
        every step of the bake and the fit, raises to stop them.  Returns :attr:`work`."""
        work = self.work
        if work is None:
            record = storage.bake_record(skin_from_settings(self.skin), self.resolution)
            work = self.work = _Bake(record, **self.bake)
        before = work.progress
        work.progress = self.progress if check is None else _Checked(check)
        try:
            work.fitted()
            measured = work.measured(with_traits=self.where is not None)
            if self.where is not None:
                traits = fits.traits(measured)
                if traits is not None:
                    self.where.choose(traits)
        finally:
            work.progress = before
        return work


def prepare_rebuild(context, material, resolution: str) -> Rebuild:
    """What the rebuild of ``material``'s group at ``resolution`` needs of Blender (main
    thread, a few milliseconds): its settings (:func:`.shade.skin_settings`), the tiers to fit
    (:func:`fitted_tiers`), whether it goes over the artist's shader, and with Tier Auto the
    scene the choice judges in."""
    settings = material.makeup_skin
    over = settings.over_shader and convert.artist_tree(material) is not None
    bake = {"method": forced_method(settings), "coverage": settings.coverage,
            "absorption": settings.effective_absorption(),
            "tiers": fitted_tiers(settings, context.scene), "over": over}
    where = scene_fit.choice_scene(material, context.scene) if settings.tier == "AUTO" else None
    return Rebuild(material, shade.skin_settings(settings), resolution, bake, where)


def finish_rebuild(context, material, group, rebuild: Rebuild) -> None:
    """Rebuild ``group`` (the material's group, or a copy of it) in place from ``rebuild``
    (computed: nothing is baked or fitted again) and make it the material's surface."""
    settings = material.makeup_skin
    work = rebuild.work if rebuild.work is not None else rebuild.compute()
    group, measured, _, auto = _group_for(material, settings, context.scene, work, [],
                                          group=group)
    _record_errors(material, measured, rebuild.key)
    _record_auto(material, auto)
    setup_material(material, group, context.scene)


def rebuild_from_settings(context, material, group, resolution: str) -> None:
    """Bake the material's settings at ``resolution``, rebuild ``group`` (its group, or a copy
    of it) in place and make it the material's surface, all at once: Check Tables' repair when
    the group's record cannot be used, and the live preview without an event loop."""
    rebuild = prepare_rebuild(context, material, resolution)
    with _Progress(context) as progress:
        rebuild.progress = progress
        rebuild.compute()
        finish_rebuild(context, material, group, rebuild)


def check_material(context, material) -> tuple[bool, str]:
    """Verify a made-up material: its group's bake record is readable and its own (its key
    is the hash of its parameters and resolution) and every image the render reads matches
    its recorded hash; repair what is not, from the record (or, if it is unusable, from the
    panel's settings).  Nothing is baked when all is intact.  Returns ``(intact, one
    sentence for the report)``."""
    name = material.name
    node = group_of(material)
    if node is None or node.node_tree is None:
        return False, (f"{name!r}: its Made-up Skin node is gone from the node tree; Apply "
                       f"puts it back.")
    group = node.node_tree
    reason = convert.linked_library(group, "node group")
    if reason is not None:
        return False, f"{name!r}: not checked: {reason}."
    meta = nodes.read_meta(group)
    if "parameters" not in meta:
        rebuild_from_settings(context, material, group, material.makeup_skin.resolution)
        return False, (f"{name!r}: its group's record is unreadable or from an older "
                       f"version; re-baked it from the panel's settings.")
    try:
        key = storage.bake_key(meta["parameters"], meta.get("resolution", "default"))
    except (TypeError, ValueError):
        key = None
    if key != meta.get("key"):
        rebuild_from_settings(context, material, group, material.makeup_skin.resolution)
        return False, (f"{name!r}: its group's bake record does not match its key; re-baked "
                       f"it from the panel's settings.")
    problems = storage.image_problems(meta.get("images", []))
    if not problems and nodes.has_interface(group):
        return True, f"{name!r}: intact."
    settings = material.makeup_skin
    tier = meta.get("tier", tier_registry.UNRECORDED)
    work = _Bake({k: meta[k] for k in ("key", "parameters", "resolution")},
                 meta.get("forced_method"), settings.coverage, settings.effective_absorption(),
                 tiers=fitted_tiers(settings, context.scene, (tier,)),
                 over=nodes.over_shader(group))
    _build(work, tier, group)
    what = "; ".join(problems) if problems else "its inputs were of an older version"
    return False, f"{name!r}: {what}; rebuilt it from a re-bake."
