"""The "Made-up Skin" node groups: closures fitted to baked tables (lut_baker.closures.fitting).

Every tier shares one interface, so a material keeps its links when the tier changes:

- inputs: ``Coverage`` (0..1, paintable with a texture), ``Foundation Absorption`` (colour:
  the fraction of light the film's pigment absorbs per channel), ``Skin Color`` (the skin's
  diffuse albedo, default the skin preset's: link the character's albedo texture),
  ``Normal`` and ``Film Normal`` (the skin's and the film's shading normals; unlinked, the
  surface's), ``Subsurface Scale`` (artist multiplier of the fitted radius), ``Gloss`` (0..1,
  multiplies the gloss lobes: at 0 Cycles allocates none of them, which the Auto tier uses
  when the gloss is below the noise), ``Units per mm`` (scene units in one millimetre; the
  add-on sets it from the scene's unit scale);
- output: ``Shader``.

Every skin closure is linear in Skin Color: the tables' skin diffuse term enters the model's
first-order paths (bare skin, and path 3 through the film) as a factor, and the view-angle rows
are per unit albedo, so a texture scales them exactly.  What stays the preset's: the subsurface
radius (fitted to the skin's profile), the skin's gloss and the film.

Each tier is a :class:`lut_baker.closures.tier_registry.Tier`: its shader, written over the
tier formulas' algebra (:mod:`lut_baker.closures.tier_formulas`), is emitted here as nodes
(:class:`.node_algebra.NodeShaders`: closures, Add and Mix Shaders, Math and Vector Math
nodes), so the group computes exactly what the replicas (and so the measured errors and the
Auto tier) compute, and no tier is spelled here.  Gloss scales the gloss closures: at 0 none is
allocated (a Glossy closure of colour 0, ``bsdf_alloc``; a Principled BSDF's coat and specular,
``svm_node_closure_bsdf``).  Coverage mixes the two sides as areas (a Mix Shader), so a
painted coverage fades out without fringe or halo.

A tier's view-angle rows (:attr:`~lut_baker.closures.tier_registry.Tier.image`) are read by
:func:`_read_rows` as :func:`lut_baker.closures.view_image.read_row` reads them: two Closest
lookups at neighbouring texel centres mixed linearly, which is what a Linear lookup gives in
Cycles; EEVEE samples a Linear image through mipmaps and anisotropic filtering, which mixes the
image's rows wherever ``cos(theta_o)`` changes quickly across the screen (docs/addon.md, "Why
the Layered tier breaks in EEVEE").

- :func:`build_group` -- create or rebuild (in place) a group from a fit and its bake record,
  named by :func:`group_name` (tier, tables key, a forced subsurface method); a group
  rebuilt with the same structure keeps its nodes, only values and links set anew
  (:class:`.node_algebra.Builder` ``reuse``).
- :func:`read_meta` -- a group's record (bake, fit summary, image hashes).
- :func:`set_inputs` -- socket values on a group node from the panel's settings.
"""

from __future__ import annotations

import json

import bpy
import numpy as np

from . import keys, storage
from .core import tier_formulas, tier_registry, view_image
from .group_parts import parts_of, remove_parts
from .keys import FIT_KEY, LEGACY_TABLES_REF, view_image_name
from .node_algebra import Builder, Mismatch, NodeAlgebra, NodeShaders, NodeValue, socket

__all__ = ["INPUTS", "OVER_SHADER_INPUTS", "NORMAL_INPUTS", "build_group", "group_name",
           "read_meta",
           "write_measured", "set_inputs", "socket", "has_interface", "over_shader",
           "inputs_of"]

INPUTS = (
    # name, socket type, default, min, max, subtype, description
    ("Coverage", "NodeSocketFloat", 1.0, 0.0, 1.0, "FACTOR",
     "Foundation coverage: 0 bare skin, 1 full film (paint it with a texture)"),
    ("Foundation Absorption", "NodeSocketColor", (0.0, 0.0, 0.0, 1.0), None, None, None,
     "Fraction of the light crossing the film's pigment that it absorbs, per channel"),
    ("Skin Color", "NodeSocketColor", (0.8, 0.8, 0.8, 1.0), None, None, None,
     "The skin's diffuse albedo (link the character's albedo texture here); every skin "
     "closure scales with it, under the film and bare"),
    ("Normal", "NodeSocketVector", (0.0, 0.0, 0.0), None, None, None,
     "Normal of the skin's closures (link a Normal Map or Bump node with pore detail); "
     "unlinked: the surface's shading normal"),
    ("Film Normal", "NodeSocketVector", (0.0, 0.0, 0.0), None, None, None,
     "Normal of the foundation film's closures (a softer bump than the skin's: foundation "
     "fills pores); unlinked: the surface's shading normal"),
    ("Subsurface Scale", "NodeSocketFloat", 1.0, 0.0, 100.0, "NONE",
     "Multiplies the subsurface radius fitted to the skin's profile"),
    ("Gloss", "NodeSocketFloat", 1.0, 0.0, 1.0, "FACTOR",
     "Multiplies the gloss lobes (film, skin through the film, bare skin): 0 leaves them out "
     "and Cycles then allocates none (cheaper; Fit to Scene does it when the gloss is below "
     "the noise)"),
    ("Units per mm", "NodeSocketFloat", 0.001, 0.0, 1e6, "NONE",
     "Scene units in one millimetre (set from the scene's unit scale on Apply)"),
)
OVER_SHADER_INPUTS = (
    ("Skin Shader", "NodeSocketShader", None, None, None, None,
     "The artist's own skin shader: rendered as it is where the film does not cover "
     "(Coverage 0 renders exactly as before Apply)"),
    INPUTS[0], INPUTS[1],
    ("Skin Color", "NodeSocketColor", (0.8, 0.8, 0.8, 1.0), None, None, None,
     "The body colour of the skin under the film: what the artist's shader renders of its "
     "Base Color (Apply links it); every closure of the skin under the film scales with it"),
    INPUTS[3], INPUTS[4],
    ("Subsurface Radius", "NodeSocketVector", (0.005, 0.001, 0.0005), None, None, None,
     "The subsurface radius of the skin under the film per channel, in scene units (Apply "
     "links the artist's Subsurface Radius times Subsurface Scale)"),
    ("Subsurface Weight", "NodeSocketFloat", 1.0, 0.0, 1.0, "FACTOR",
     "Share of the skin under the film that scatters below its surface (the artist's "
     "Subsurface Weight); the rest is diffuse"),
    ("Subsurface Scale", "NodeSocketFloat", 1.0, 0.0, 100.0, "NONE",
     "Multiplies the subsurface radius of the skin under the film"),
    INPUTS[6],
)
"""The inputs of a group built over the artist's shader (:func:`over_shader`): the bare skin
is the Skin Shader input, the skin under the film's radius and weight are the artist's."""
NORMAL_INPUTS = ("Normal", "Film Normal")
"""Vector inputs whose value is hidden: unlinked, a closure's Normal is the shading normal
(Blender leaves a hidden-value group input unlinked inside the group), and the view-angle
lookups use the Geometry node's normal instead (:func:`_normal_or_shading`)."""


def group_name(tier: str, key: str, method: str | None = None, over: bool = False) -> str:
    """The name of ``tier``'s group of the tables ``key`` (:func:`.keys.group_name` with the
    tier's label)."""
    return keys.group_name(tier_registry.tier(tier).label, key, method, over)


def _input_names(group) -> list[str]:
    return [item.name for item in group.interface.items_tree
            if getattr(item, "item_type", "SOCKET") == "SOCKET"
            and getattr(item, "in_out", "INPUT") == "INPUT"]


def inputs_of(over: bool) -> tuple:
    """The inputs of a group over the artist's shader (:data:`OVER_SHADER_INPUTS`) or of the
    skin preset's (:data:`INPUTS`)."""
    return OVER_SHADER_INPUTS if over else INPUTS


def over_shader(group) -> bool:
    """Whether ``group`` goes over the artist's shader (its bare skin is its Skin Shader
    input)."""
    return group is not None and "Skin Shader" in _input_names(group)


def _interface(group, skin_albedo, over: bool) -> None:
    """Create the group's sockets if missing (existing ones keep their links and values); a
    socket added to a group built before it existed is moved to its place in
    :func:`inputs_of` ``over``, and inputs no longer there are removed.  ``skin_albedo`` (RGB)
    becomes Skin Color's default."""
    specs = inputs_of(over)
    known = {name for name, *_ in specs}
    for item in list(group.interface.items_tree):
        if (getattr(item, "item_type", "SOCKET") == "SOCKET" and item.in_out == "INPUT"
                and item.name not in known):
            group.interface.remove(item)
    existing = set(_input_names(group))
    for position, (name, kind, default, low, high, subtype, description) in enumerate(specs):
        if name in existing:
            continue
        item = group.interface.new_socket(name=name, in_out="INPUT", socket_type=kind)
        if default is not None:
            item.default_value = default
        item.description = description
        if low is not None:
            item.min_value, item.max_value = low, high
        if subtype and hasattr(item, "subtype"):
            item.subtype = subtype
        if name in NORMAL_INPUTS:
            item.hide_value = True
        if existing and position:  # after its predecessor (outputs may come first)
            items = list(group.interface.items_tree)
            before = next(i for i, other in enumerate(items)
                          if other.name == specs[position - 1][0])
            group.interface.move(item, before + 1)
    if not any(getattr(item, "in_out", "") == "OUTPUT" and item.name == "Shader"
               for item in group.interface.items_tree):
        group.interface.new_socket(name="Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
    colour = next(item for item in group.interface.items_tree
                  if getattr(item, "in_out", "") == "INPUT" and item.name == "Skin Color")
    colour.default_value = (*map(float, skin_albedo), 1.0)


def has_interface(group) -> bool:
    """Whether ``group``'s inputs are exactly those of its kind (:func:`inputs_of`: a group
    built by an older version of the add-on may lack one, e.g. Film Normal, and is then
    rebuilt)."""
    return _input_names(group) == [name for name, *_ in inputs_of(over_shader(group))]


def _normal_or_shading(build: Builder, normal, geometry):
    """The Normal input where linked, else the Geometry node's shading normal: an unlinked
    hidden vector input reads (0, 0, 0) in math nodes, so a length below 0.5 means unlinked
    (a mix at factor 0 returns the shading normal exactly)."""
    linked = build.math("GREATER_THAN", build.vector("LENGTH", normal), 0.5)
    return build.mix_vector(linked, geometry.outputs["Normal"], normal, label="normal or shading")


def _cos_view(build: Builder, normal, geometry, label: str):
    """``max(0, I . N)``: the cosine of the view angle against ``normal``."""
    return build.math("MAXIMUM", build.vector("DOT_PRODUCT", geometry.outputs["Incoming"],
                                              _normal_or_shading(build, normal, geometry)),
                      0.0, label=label)


def _group_io(build: Builder, over: bool):
    """The group's input and output nodes, the tier formulas' inputs as node values
    (:class:`lut_baker.closures.tier_formulas.TierInputs`; over the artist's shader, at
    coverage 1: the film covers all of what the group computes, Coverage mixes it with the
    Skin Shader) and the subsurface ``(radius, scale)``: the fitted radius (mm) and Subsurface
    Scale x Units per mm, or over the artist's shader its Subsurface Radius (scene units) and
    Subsurface Scale."""
    inputs = build.node("NodeGroupInput")
    output = build.node("NodeGroupOutput")
    out = inputs.outputs
    x = tier_formulas.TierInputs(
        coverage=1.0 if over else NodeValue(build, out["Coverage"], False),
        absorption=NodeValue(build, out["Foundation Absorption"], True),
        skin_color=NodeValue(build, out["Skin Color"], True),
        gloss=NodeValue(build, out["Gloss"], False))
    if over:
        return inputs, output, x, (out["Subsurface Radius"], out["Subsurface Scale"])
    scale = build.math("MULTIPLY", out["Subsurface Scale"], out["Units per mm"],
                       label="subsurface scale")
    return inputs, output, x, (None, scale)


def _finish(build: Builder, inputs, output, shader, over: bool) -> None:
    """Link the group's shader to its output: over the artist's shader, mixed with the Skin
    Shader by Coverage (an areal mix; at Coverage 0 exactly the Skin Shader)."""
    if over:
        mix = build.node("ShaderNodeMixShader", "coverage (areal mix over the artist's shader)")
        build.feed(socket(mix.inputs, "Fac"), inputs.outputs["Coverage"])
        build.link(inputs.outputs["Skin Shader"], socket(mix.inputs, "Shader"))
        build.link(shader, socket(mix.inputs, "Shader_001"))
        shader = mix.outputs[0]
    build.link(shader, output.inputs["Shader"])


def _read_rows(build: Builder, datablock, names: tuple, coordinates: dict, bounds) -> dict:
    """Every row of the view-angle image ``datablock`` (rows named ``names``), read at
    ``u = coordinates[name]`` (a socket per row name) as
    :func:`lut_baker.closures.view_image.read_row` reads it: two Closest lookups mixed, so
    that EEVEE reads what Cycles does (its Linear filter goes through mipmaps, which mix
    rows).  The texel pair is built once per coordinate socket.  Each row is kept within its
    range as baked (``bounds``): an image damaged in a file read where the add-on cannot
    repair it (a render farm) renders wrong, not blown out.  Colour :class:`NodeValue` by row
    name."""
    size = datablock.size[0]
    algebra = NodeAlgebra(build)
    pairs: dict = {}
    rows = {}
    for j, name in enumerate(names):
        u = coordinates[name]
        if u.as_pointer() not in pairs:
            pairs[u.as_pointer()] = view_image.texel_pair(NodeValue(build, u, False), size,
                                                          algebra)
        u0, u1, weight = pairs[u.as_pointer()]

        def texel(at, k, j=j, name=name):
            coordinate = build.node("ShaderNodeCombineXYZ", f"row {name}, texel {k}")
            build.feed(coordinate.inputs["X"], at)
            build.feed(coordinate.inputs["Y"], (j + 0.5) / len(names))
            texture = build.node("ShaderNodeTexImage", name, image=datablock,
                                 interpolation="Closest", extension="EXTEND")
            build.link(coordinate.outputs[0], texture.inputs["Vector"])
            return NodeValue(build, texture.outputs["Color"], True)

        value = algebra.lerp(weight, texel(u0, 0), texel(u1, 1), label=f"row {name}")
        rows[name] = NodeValue(build, build.vector(
            "MINIMUM", build.vector("MAXIMUM", value.socket, (0.0, 0.0, 0.0)),
            tuple(map(float, bounds[j])), label=f"row {name} (bounded)"), True)
    return rows


def _build(build: Builder, tier, fit, image, datablock, method: str, radius_mm, ior: float,
           over: bool) -> None:
    """``tier``'s shader (:attr:`lut_baker.closures.tier_registry.Tier.shader`) emitted as
    nodes (:class:`.node_algebra.NodeShaders`): its view-angle ``image`` (or None) read from
    the image datablock ``datablock`` at the view angle against the normal of the surface each row
    describes; over the artist's shader at full coverage, its subsurface the artist's radius
    and weight, mixed with the Skin Shader by Coverage (:func:`_finish`)."""
    inputs, output, x, (radius, scale) = _group_io(build, over)
    normals = {"film": inputs.outputs["Film Normal"], "skin": inputs.outputs["Normal"]}
    rows = {}
    if image is not None:
        geometry = build.node("ShaderNodeNewGeometry")
        cosines = {surface: _cos_view(build, normal, geometry, f"cos theta_o ({surface})")
                   for surface, normal in normals.items()}
        rows = _read_rows(build, datablock, image.rows, {
            name: cosines[tier_formulas.ROW_SURFACE.get(name, "film")] for name in image.rows},
            np.max(np.asarray(image.texels, float), axis=1))
    shaders = NodeShaders(build, rows, lobes=tier.lobes(fit), normals=normals, subsurface=(
        method, radius if over else tuple(map(float, radius_mm)), scale, ior))
    weight = NodeValue(build, inputs.outputs["Subsurface Weight"], False) if over else None
    _finish(build, inputs, output, tier.shader(fit, x, shaders, weight), over)


def _emit(group, emit, reuse: bool) -> None:
    """Run ``emit(builder)`` on ``group``: over its nodes again when ``reuse`` (a group of the
    same tier and kind: the same structure, new values; :class:`.node_algebra.Builder`), or
    on a cleared group (at once, or when the structure turns out to differ)."""
    if reuse:
        build = Builder(group, reuse=True, parts=True)
        try:
            emit(build)
            build.finish()
            return
        except Mismatch:
            pass
    old = parts_of(group)
    group.nodes.clear()
    remove_parts(old)
    build = Builder(group, parts=True)
    emit(build)
    build.finish()


def build_group(tier: str, record: dict, fit, group=None, *, method=None, measured=None,
                over: bool = False):
    """Create (or, given ``group``, rebuild in place) the node group of ``tier`` from a
    :class:`ClosureFit` ``fit`` of the tables that the bake record ``record`` describes
    (:func:`.bakes.bake_record`).  ``method``: a subsurface method forced by the user, else the
    fit's choice.  The group's :data:`.keys.FIT_KEY` holds the bake record, the fit's summary,
    the SHA-256 of every image the group reads (:func:`storage.image_record`) and
    ``measured``, what the fit measured at the settings' coverage and absorption
    (:func:`.bakes.measure`), if given.  ``over``: a group over the artist's shader (its
    Skin Shader input is the bare skin, :data:`OVER_SHADER_INPUTS`), else the skin preset's
    made-up skin, bare skin included (:data:`INPUTS`)."""
    found = tier_registry.held(fit, tier)
    key = record["key"]
    name = group_name(tier, key, method, over)
    if group is None:
        group = bpy.data.node_groups.get(name) or bpy.data.node_groups.new(name,
                                                                           "ShaderNodeTree")
    elif group.name != name and bpy.data.node_groups.get(name) is None:
        group.name = name
    before = read_meta(group)
    reuse = (bool(group.nodes) and (before.get("tier"), before.get("over_shader")) == (tier, over)
             and has_interface(group))
    _interface(group, fit.skin_albedo, over)
    forced = method
    method = method or found.subsurface_method or fit.subsurface_method
    # Over the artist's shader the radius is theirs (a fit for it may have no profiles).
    radius = None if over else fit.profiles[method].radius_mm
    image, datablock, images = found.image(fit), None, []
    if image is not None:
        datablock = storage.view_image(view_image_name(key, found.label), image.texels)
        images.append(storage.image_record(datablock))

    def emit(build):
        _build(build, found, fit, image, datablock, method, radius, fit.subsurface_ior, over)
    _emit(group, emit, reuse)
    group[FIT_KEY] = json.dumps({**record, "tier": tier, "forced_method": forced,
                                 "over_shader": over,
                                 "images": images, **fit.summary(),
                                 "subsurface_method": method, "measured": measured},
                                default=float)
    if LEGACY_TABLES_REF in group:  # an older add-on kept the whole tables in the file
        del group[LEGACY_TABLES_REF]
    return group


def write_measured(group, measured: dict) -> None:
    """Replace the measurement a group's record keeps (:func:`.bakes.measure`)."""
    group[FIT_KEY] = json.dumps({**read_meta(group), "measured": measured}, default=float)


def read_meta(group) -> dict:
    """A group's :data:`.keys.FIT_KEY` record, or {} if it has none or it cannot be read."""
    try:
        meta = json.loads(group.get(FIT_KEY, "{}")) if group is not None else {}
    except (TypeError, ValueError):
        return {}
    return meta if isinstance(meta, dict) else {}


def set_inputs(node, values: dict) -> None:
    """Set a group node's input socket values by name (unknown names are ignored)."""
    for name, value in values.items():
        target = node.inputs.get(name)
        if target is None or target.is_linked:
            continue
        if target.type == "RGBA" and len(value) == 3:
            value = (*value, 1.0)
        target.default_value = value
