"""The node group for a bake: found in the file and reused when intact, else built from the
bake's fit; and made a material's surface, its sockets set from the settings.

A group is named by its tier, its bake's key, the forced subsurface method and its kind (over
the artist's shader or not, :func:`.nodes.group_name`).  A group of that name built by this
version, whose images are intact, is reused: nothing is baked, fitted or hashed.  Otherwise
the :class:`.bakes.Bake` is asked for its fit (baked and fitted once per session) and the group
is built (:func:`.nodes.build_group`), in place of one of the same name.  Tier Auto decides
from what the fit of the foundation being applied measured (kept in the group's record), so
the same settings in the same scene give the same tier.

- :func:`group_for` -- ``(group, measured, tier, auto record)`` for a material's settings.
- :func:`build` -- the group of a tier built from a bake; :func:`has_group` -- whether the
  file has a group of a bake (any tier).
- :func:`group_for_tables` -- the group for baked tables (tests and tools).
- :func:`group_of` -- a material's group node; :func:`setup_material` -- a group made its
  surface; :func:`socket_values`, :func:`update_sockets` -- the settings' socket values.
- :func:`record_measurement` -- the tier errors and the Auto choice kept on the material.
"""

from __future__ import annotations

import json
from typing import Any

import bpy

from . import bakes, convert, nodes, storage, tier_choice
from .bakes import Bake
from .core import params_file, table_set, tiers
from .keys import AUTO_KEY, ERRORS_KEY
from .nodes import group_name

__all__ = ["group_for", "build", "has_group", "group_for_tables", "group_of", "setup_material",
           "socket_values", "update_sockets", "record_measurement"]


def _reusable(group: Any, key: str, tier: str, method: str | None, messages: list) -> bool:
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


def _named(record: dict, tier: str, method: str | None, over: bool) -> Any:
    """The file's group of this bake, tier, method and kind, intact or not, or None."""
    return bpy.data.node_groups.get(group_name(tier, record["key"], method, over))


def _existing(record: dict, tier: str, method: str | None, messages: list, over: bool) -> Any:
    """The group of this bake, tier, method and kind (``over`` the artist's shader or not) if
    the file has it intact, else None."""
    group = _named(record, tier, method, over)
    if group is not None and nodes.over_shader(group) == over and \
            _reusable(group, record["key"], tier, method, messages):
        return group
    return None


def has_group(record: dict, method: str | None, over: bool) -> bool:
    """Whether the file has a group of this bake (any tier)."""
    return any(_named(record, tier, method, over) for tier in tiers.TIERS)


def _stored_measurement(work: Bake) -> dict | None:
    """What any group of this bake (any tier) keeps measured at the coverage and absorption,
    of the tiers fitted, with the Auto tier's traits, or None."""
    for tier in tiers.TIERS:
        group = _named(work.record, tier, work.method, work.over)
        if group is not None:
            measured = bakes.measured_at(nodes.read_meta(group), work.coverage,
                                         work.absorption, with_traits=True, tiers=work.tiers)
            if measured is not None:
                return measured
    return None


def build(work: Bake, tier: str, group: Any = None, *, measured: bool = True) -> Any:
    """The group of ``tier`` built from the bake (rebuilt in place when ``group`` is given),
    its record keeping the measurement (none if not ``measured``: a Thickness move's, measured
    after it is swapped in, :mod:`.live`); over the artist's shader if ``work.over``."""
    _, fit = work.fitted(tier)
    return nodes.build_group(tier, work.record, fit, group, method=work.method,
                             measured=work.measured() if measured else None, over=work.over)


def group_for(material: Any, settings: Any, scene: Any, work: Bake, messages: list,
              group: Any = None) -> tuple[Any, dict, str, dict | None]:
    """``(group, measured, tier, auto record or None)`` for the settings: the existing group
    of the tier reused when intact (nothing baked or fitted), else built (``group`` given:
    rebuilt in place, always); over the artist's shader if ``work.over``.  ``messages`` gets
    a sentence for each damaged image found."""
    auto = None
    tier = settings.tier
    if tier == "AUTO":
        work.adopt(_stored_measurement(work))
        tier, auto = tier_choice.auto_choice(material, scene, work.measured(with_traits=True))
    existing = None if group is not None else _existing(work.record, tier, work.method,
                                                        messages, work.over)
    if existing is not None:
        stored = bakes.measured_at(nodes.read_meta(existing), work.coverage, work.absorption,
                                   tiers=work.tiers)
        if stored is None:  # the group was built at another coverage or absorption
            nodes.write_measured(existing, work.measured())
        return existing, stored or work.measured(), tier, auto
    if group is None:
        group = _named(work.record, tier, work.method, work.over)
    return build(work, tier, group), work.measured(), tier, auto


def group_for_tables(tables: table_set.Tables, tier: str, *, resolution: str = "default",
                     group: Any = None, errors_at: tuple[float, Any] | None = None,
                     method: str | None = None, messages: list | None = None) -> tuple:
    """``(group, fit or None)`` of ``tier`` for baked ``tables`` baked at ``resolution`` (tests
    and tools that bake themselves; Apply goes through the settings).  Tables baked with a film
    thickness get the record of the film as a slab at it, as Apply's would
    (:func:`.bakes.bake_record`): their own key, the slab's tiers.

    A group already built from the same bake, tier and ``method`` (a forced subsurface method,
    or None for the fit's choice) whose images are intact is reused (no fit) unless ``group``
    is given, which is then rebuilt in place.  ``errors_at``: ``(coverage, absorption)`` at
    which to measure (default: the bake's).  ``messages``: a list that gets a sentence for
    each damaged image found (then rebuilt)."""
    messages = [] if messages is None else messages
    skin = params_file.skin_from_dict(tables.parameters)
    thickness = tables.parameters.get("film_thickness_um")  # the film as a slab, if baked so
    record = bakes.bake_record(skin, resolution, "paper" if thickness is None else thickness)
    bakes.remember(record, tables)
    coverage, absorption = errors_at if errors_at is not None else \
        tables.coverage_and_absorption()
    work = Bake(record, method, coverage, absorption)
    existing = None if group is not None else _existing(record, tier, method, messages,
                                                        False)
    if existing is not None:
        return existing, None
    if group is None:
        group = _named(record, tier, method, False)
    return build(work, tier, group), work.fitted()[1]


def group_of(material: Any) -> Any:
    """The made-up group node of a material, or None."""
    return convert.group_node(material)


def socket_values(settings: Any) -> dict:
    """Group-node socket values of the settings (by socket name; over the artist's shader the
    skin's colour comes from the shader, not from Skin Color)."""
    values = {
        "Coverage": settings.coverage,
        "Foundation Absorption": tuple(settings.absorption),
        "Skin Color": tuple(settings.skin_colour),
        "Subsurface Scale": settings.subsurface_scale,
        "Gloss": settings.gloss,
    }
    if settings.over_shader:
        del values["Skin Color"]
    return values


def update_sockets(material: Any) -> None:
    """Copy the material's socket-level settings onto its group node, and the film's normal
    settings onto its normal node (:func:`.convert.set_film_normal`)."""
    node = group_of(material)
    if node is not None:
        settings = material.makeup_skin
        nodes.set_inputs(node, socket_values(settings))
        convert.set_film_normal(material, settings.film_follows_pores,
                                settings.film_normal_strength)


def setup_material(material: Any, group: Any, scene: Any, reading: Any = None
                   ) -> convert.Installed:
    """Make ``group`` the surface of ``material`` (:func:`.convert.install`: the artist's tree
    is converted in place; over the artist's shader, ``reading``
    (:class:`.artist_skin.SkinReading`) gives the skin under the film) and set the group
    node's inputs from the settings.  Returns what was carried over
    (:class:`.convert.Installed`)."""
    settings = material.makeup_skin
    installed = convert.install(material, group, over_shader=nodes.over_shader(group),
                                reading=reading, film_strength=settings.film_normal_strength,
                                film_follows=settings.film_follows_pores)
    nodes.set_inputs(group_of(material), {"Units per mm": tier_choice.units_per_mm(scene)})
    update_sockets(material)
    return installed


def record_measurement(material: Any, measured: dict, key: str, auto: dict | None) -> None:
    """Keep on the material the measurement's tier errors and gloss omissions
    (:data:`.keys.ERRORS_KEY`, for the panel and the Auto tier) and what Tier Auto chose
    (:data:`.keys.AUTO_KEY`; nothing kept for a fixed tier, ``auto`` None)."""
    omission = (measured.get("traits") or {}).get("gloss_omission") or {}
    material[ERRORS_KEY] = json.dumps({
        tier: {"rms": e["rms"], "albedo": e["albedo"], "coverage": measured["coverage"],
               "absorption": list(measured["absorption"]),
               "gloss_omission": omission.get(tier, {}), "key": key}
        for tier, e in measured["errors"].items()})
    if auto is not None:
        material[AUTO_KEY] = json.dumps(auto)
    elif AUTO_KEY in material:
        del material[AUTO_KEY]
