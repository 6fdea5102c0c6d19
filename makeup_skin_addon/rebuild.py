"""A material's group rebuilt from its settings, at once or in three steps so that the costly
one runs on a worker thread (the live preview's, :mod:`.live`): read the settings on the main
thread (:func:`prepare_rebuild`), make the skin, bake, fit and measure anywhere
(:meth:`Rebuild.compute`, no bpy), build the group on the main thread (:func:`finish_rebuild`).

- :class:`Rebuild` -- a rebuild and what it computed (measured, or not yet: a Thickness
  move's group swapped in first and measured by the rebuild that follows it).
- :func:`prepare_rebuild`, :func:`finish_rebuild` -- its first and last steps.
- :func:`rebuild_from_settings` -- the three at once (Check Tables' repair, the live preview
  without an event loop).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from . import bakes, convert, groups, nodes, skin_model, tier_choice
from .bakes import Bake
from .core import tier_registry
from .progress import Checked, Progress, Stages

__all__ = ["Rebuild", "prepare_rebuild", "finish_rebuild", "rebuild_from_settings"]


class Rebuild:
    """A rebuild of a material's group from its settings, in three steps so that the costly
    one runs off the main thread (:mod:`.live`): :func:`prepare_rebuild` reads the settings
    and the scene, :meth:`compute` makes the made-up skin, bakes, fits and measures (and
    makes the Auto tier's choice once, which leaves its costly part cached), touching no bpy,
    and :func:`finish_rebuild` builds the group from what was computed.  ``material``: the
    name, ``uid``: the material's ``session_uid`` (another file's material of the same name
    is not it); ``work``: the :class:`.bakes.Bake` (made by :meth:`compute`).
    ``unmeasured``: the tier of a rebuild that measures nothing (None: it measures, and Tier
    Auto chooses): the group of the material's tier now, swapped in at once (a Thickness
    move: its fit moved in milliseconds), then measured by a rebuild that follows it."""

    def __init__(self, material: Any, skin: skin_model.SkinSettings, resolution: str,
                 bake: dict, where: tier_choice.ChoiceScene | None,
                 unmeasured: str | None = None):
        self.material, self.uid = material.name, material.session_uid
        self.skin, self.resolution, self.bake, self.where = skin, resolution, bake, where
        self.unmeasured = unmeasured
        self.work: Bake | None = None
        self.progress: Stages | None = None

    @property
    def key(self) -> str:
        """The bake's key (once :meth:`compute` made it)."""
        if self.work is None:
            raise AssertionError("the rebuild is not computed")
        return self.work.key

    def compute(self, check: Callable[[], None] | None = None) -> Bake:
        """Make the skin, bake, fit and measure (no bpy: any thread); ``check()``: called at
        every step of the bake and the fit, raises to stop them.  Returns :attr:`work`."""
        work = self.work
        if work is None:
            record = bakes.bake_record(skin_model.skin_from_settings(self.skin),
                                       self.resolution, skin_model.film_of(self.skin),
                                       skin_model.skin_under_of(self.skin),
                                       skin_model.skin_albedo_of(self.skin))
            work = self.work = Bake(record, **self.bake)
        before = work.progress
        work.progress = self.progress if check is None else Checked(check)
        try:
            work.fitted(self.unmeasured)
            if self.unmeasured is not None:
                return work
            measured = work.measured(with_traits=self.where is not None)
            if self.where is not None:
                traits = bakes.traits(measured)
                if traits is not None:
                    self.where.choose(traits)
        finally:
            work.progress = before
        return work


def _tier_now(material: Any) -> str | None:
    """The tier of the material's group now (Tier Auto's last choice), or None."""
    node = groups.group_of(material)
    tier = nodes.read_meta(node.node_tree).get("tier") if node is not None else None
    return tier if tier in tier_registry.TIERS else None


def prepare_rebuild(context: Any, material: Any, resolution: str, *,
                    measure: bool = True, one_thickness: bool = False) -> Rebuild:
    """What the rebuild of ``material``'s group at ``resolution`` needs of Blender (main
    thread, a few milliseconds): its settings (:func:`.skin_model.skin_settings`), the tiers
    to fit (:func:`.tier_choice.fitted_tiers`), whether it goes over the artist's shader, and
    with Tier Auto the scene the choice judges in.  Not ``measure``: a rebuild of the tier the
    material has now that measures nothing (:attr:`Rebuild.unmeasured`; measured all the same
    if it has no group of a tier yet).  ``one_thickness``: the slab's tables at the film's
    thickness will do (a preview a refinement follows: :class:`.bakes.Bake`)."""
    settings = material.makeup_skin
    if not measure:
        tier = settings.tier if settings.tier != "AUTO" else _tier_now(material)
        if tier is not None:
            rebuild = prepare_rebuild(context, material, resolution,
                                      one_thickness=one_thickness)
            rebuild.where, rebuild.unmeasured = None, tier
            return rebuild
    over = settings.over_shader and convert.artist_tree(material) is not None
    bake = {"method": tier_choice.forced_method(settings), "coverage": settings.coverage,
            "absorption": list(settings.absorption),
            "tiers": tier_choice.fitted_tiers(settings, context.scene), "over": over,
            "one_thickness": one_thickness}
    where = (tier_choice.choice_scene(material, context.scene) if settings.tier == "AUTO"
             else None)
    return Rebuild(material, skin_model.skin_settings(settings), resolution, bake, where)


def finish_rebuild(context: Any, material: Any, group: Any, rebuild: Rebuild) -> None:
    """Rebuild ``group`` (the material's group, or a copy of it) in place from ``rebuild``
    (computed: nothing is baked or fitted again) and make it the material's surface."""
    settings = material.makeup_skin
    work = rebuild.work if rebuild.work is not None else rebuild.compute()
    if rebuild.unmeasured is not None:
        group = groups.build(work, rebuild.unmeasured, group, measured=False)
        groups.setup_material(material, group, context.scene)
        return
    group, measured, _, auto = groups.group_for(material, settings, context.scene, work, [],
                                                group=group)
    groups.record_measurement(material, measured, rebuild.key, auto)
    groups.setup_material(material, group, context.scene)


def rebuild_from_settings(context: Any, material: Any, group: Any, resolution: str) -> None:
    """Bake the material's settings at ``resolution``, rebuild ``group`` (its group, or a copy
    of it) in place and make it the material's surface, all at once: Check Tables' repair when
    the group's record cannot be used, and the live preview without an event loop."""
    rebuild = prepare_rebuild(context, material, resolution)
    with Progress(context) as progress:
        rebuild.progress = progress
        rebuild.compute()
        finish_rebuild(context, material, group, rebuild)
