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

PRINCIPLED: one Principled BSDF (GGX, coat = the film, specular and base/subsurface = the skin)
whose inputs follow :func:`lut_baker.closures.fitting.principled_inputs` in math nodes (Gloss
scales Coat Weight and Specular IOR Level: at 0 ``svm_node_closure_bsdf`` skips the coat,
``coat_weight > CLOSURE_WEIGHT_CUTOFF``, and the specular, ``eta != 1``).
LAYERED: Glossy, Diffuse and Subsurface closures weighted as
:func:`lut_baker.closures.fitting.layered_weights` (Gloss scales the three Glossy colours: a closure
of weight 0 is never allocated, ``bsdf_alloc``), view-dependent factors read from one float image
(rows :data:`lut_baker.closures.fitting.LUT_ROWS`) at ``u = cos(theta_o)``, and a Mix Shader by
Coverage between bare skin and made-up skin: an areal mix of closures, so a painted coverage
fades out without fringe or halo.
EEVEE: the LAYERED tier's closures and mix with their weights from
:func:`lut_baker.closures.fitting.eevee_weights`, every Glossy BSDF GGX (fitted as EEVEE renders
it), its own view-angle image (``fit.eevee_lut``), subsurface Christensen-Burley.

The view-angle rows are read by :func:`_lut_rows`: two Closest lookups at neighbouring texel
centres mixed linearly, which is what a Linear lookup gives in Cycles
(:func:`lut_baker.closures.fitting.sample_lut`); EEVEE samples a Linear image through mipmaps
and anisotropic filtering, which mixes the image's five rows wherever ``cos(theta_o)`` changes
quickly across the screen (docs/addon.md, "Why the Layered tier breaks in EEVEE").

- :func:`build_group` -- create or rebuild (in place) a group from a fit and its bake record,
  named by :func:`.keys.group_name` (tier, tables key, a forced subsurface method).
- :func:`read_meta` -- a group's record (bake, fit summary, image hashes).
- :func:`set_inputs` -- socket values on a group node from the panel's settings.
"""

from __future__ import annotations

import json

import bpy
import numpy as np

from . import storage
from .core import fitting
from .keys import FIT_KEY, LEGACY_TABLES_REF, group_name, lut_image_name

__all__ = ["INPUTS", "NORMAL_INPUTS", "build_group", "read_meta", "write_measured",
           "set_inputs", "socket", "has_interface"]

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
NORMAL_INPUTS = ("Normal", "Film Normal")
"""Vector inputs whose value is hidden: unlinked, a closure's Normal is the shading normal
(Blender leaves a hidden-value group input unlinked inside the group), and the view-angle
lookups use the Geometry node's normal instead (:func:`_normal_or_shading`)."""


def socket(sockets, identifier: str):
    """A node socket by identifier (display names differ between Blender versions)."""
    for item in sockets:
        if item.identifier == identifier:
            return item
    raise KeyError(identifier)


class _Builder:
    """Adds nodes to a tree and links them; values may be sockets or constants."""

    def __init__(self, tree):
        self.tree = tree
        self.count = 0

    def node(self, kind: str, label: str = "", **props):
        node = self.tree.nodes.new(kind)
        node.location = (200 * (self.count // 10) - 400, -160 * (self.count % 10))
        self.count += 1
        if label:
            node.label = label
        for name, value in props.items():
            setattr(node, name, value)
        return node

    def feed(self, target, value):
        """Link a socket into ``target`` or set its default value."""
        if isinstance(value, bpy.types.NodeSocket):
            self.tree.links.new(value, target)
        elif target.type in ("VECTOR", "RGBA") and np.ndim(value) == 0:
            n = len(target.default_value)
            target.default_value = (float(value),) * n
        elif target.type == "RGBA" and len(value) == 3:
            target.default_value = (*map(float, value), 1.0)
        else:
            target.default_value = value if np.ndim(value) == 0 else tuple(map(float, value))

    def math(self, operation: str, a, b=0.0, label: str = ""):
        node = self.node("ShaderNodeMath", label, operation=operation)
        self.feed(node.inputs[0], a)
        self.feed(node.inputs[1], b)
        return node.outputs[0]

    def vector(self, operation: str, a, b=(0.0, 0.0, 0.0), label: str = ""):
        node = self.node("ShaderNodeVectorMath", label, operation=operation)
        self.feed(socket(node.inputs, "Vector"), a)
        self.feed(socket(node.inputs, "Vector_001"), b)
        return node.outputs["Value" if operation in ("DOT_PRODUCT", "LENGTH") else "Vector"]

    def scale(self, vector, factor, label: str = ""):
        """``vector * factor`` (a float)."""
        node = self.node("ShaderNodeVectorMath", label, operation="SCALE")
        self.feed(socket(node.inputs, "Vector"), vector)
        self.feed(socket(node.inputs, "Scale"), factor)
        return node.outputs["Vector"]

    def mix_float(self, factor, a, b, label: str = ""):
        """``a + factor (b - a)``, factor unclamped."""
        return self._mix("FLOAT", factor, a, b, label)

    def mix_vector(self, factor, a, b, label: str = ""):
        return self._mix("VECTOR", factor, a, b, label)

    def _mix(self, data_type: str, factor, a, b, label: str):
        node = self.node("ShaderNodeMix", label, data_type=data_type)
        node.clamp_factor = False
        suffix = "Float" if data_type == "FLOAT" else "Vector"
        self.feed(socket(node.inputs, "Factor_Float"), factor)
        self.feed(socket(node.inputs, "A_" + suffix), a)
        self.feed(socket(node.inputs, "B_" + suffix), b)
        return socket(node.outputs, "Result_" + suffix)


def _input_names(group) -> list[str]:
    return [item.name for item in group.interface.items_tree
            if getattr(item, "item_type", "SOCKET") == "SOCKET"
            and getattr(item, "in_out", "INPUT") == "INPUT"]


def _interface(group, skin_albedo) -> None:
    """Create the group's sockets if missing (existing ones keep their links and values); a
    socket added to a group built before it existed is moved to its place in :data:`INPUTS`,
    and inputs no longer in :data:`INPUTS` are removed.  ``skin_albedo`` (RGB) becomes Skin
    Color's default."""
    known = {name for name, *_ in INPUTS}
    for item in list(group.interface.items_tree):
        if (getattr(item, "item_type", "SOCKET") == "SOCKET" and item.in_out == "INPUT"
                and item.name not in known):
            group.interface.remove(item)
    existing = set(_input_names(group))
    for position, (name, kind, default, low, high, subtype, description) in enumerate(INPUTS):
        if name in existing:
            continue
        item = group.interface.new_socket(name=name, in_out="INPUT", socket_type=kind)
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
                          if other.name == INPUTS[position - 1][0])
            group.interface.move(item, before + 1)
    if not any(getattr(item, "in_out", "") == "OUTPUT" and item.name == "Shader"
               for item in group.interface.items_tree):
        group.interface.new_socket(name="Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
    colour = next(item for item in group.interface.items_tree
                  if getattr(item, "in_out", "") == "INPUT" and item.name == "Skin Color")
    colour.default_value = (*map(float, skin_albedo), 1.0)


def has_interface(group) -> bool:
    """Whether ``group``'s inputs are exactly :data:`INPUTS` (a group built by an older version
    of the add-on may lack one, e.g. Film Normal, and is then rebuilt)."""
    return _input_names(group) == [name for name, *_ in INPUTS]


def _normal_or_shading(build: _Builder, normal, geometry):
    """The Normal input where linked, else the Geometry node's shading normal: an unlinked
    hidden vector input reads (0, 0, 0) in math nodes, so a length below 0.5 means unlinked
    (a mix at factor 0 returns the shading normal exactly)."""
    linked = build.math("GREATER_THAN", build.vector("LENGTH", normal), 0.5)
    return build.mix_vector(linked, geometry.outputs["Normal"], normal, label="normal or shading")


def _texel_pair(build: _Builder, u, size: int, label: str):
    """``(u0, u1, t)`` for reading a row of ``size`` texels at ``u`` linearly: the texel
    centres ``(i + 0.5) / size`` around ``u`` (the edge texel twice beyond the centres) and
    the weight of the second, ``x = clamp(u size - 0.5, 0, size - 1)``, ``i = floor(x)``,
    ``t = x - i``."""
    x = build.math("MINIMUM", build.math("MAXIMUM", build.math(
        "MULTIPLY", u, float(size), label=f"{label}: u size"), 0.5), size - 0.5)
    x = build.math("SUBTRACT", x, 0.5, label=f"{label}: texel coordinate")
    index = build.math("FLOOR", x, label=f"{label}: texel")
    weight = build.math("SUBTRACT", x, index, label=f"{label}: t")
    u0 = build.math("DIVIDE", build.math("ADD", index, 0.5), float(size))
    u1 = build.math("DIVIDE", build.math("MINIMUM", build.math("ADD", index, 1.5),
                                         size - 0.5), float(size))
    return u0, u1, weight


def _lut_rows(build: _Builder, lut, coordinates: dict) -> dict:
    """Every row of the view-angle image ``lut`` (rows :data:`fitting.LUT_ROWS`), read at
    ``u = coordinates[name]`` (a socket per row name) linearly between texel centres and held
    beyond them, as :func:`lut_baker.closures.fitting.sample_lut` reads it: two Closest
    lookups mixed, so that EEVEE reads what Cycles does (its Linear filter goes through
    mipmaps, which mix rows).  The texel pair is built once per coordinate socket."""
    size = lut.size[0]
    pairs = {}
    rows = {}
    for j, name in enumerate(fitting.LUT_ROWS):
        u = coordinates[name]
        key = u.as_pointer()
        if key not in pairs:
            pairs[key] = _texel_pair(build, u, size, name)
        u0, u1, weight = pairs[key]
        samples = []
        for k, at in enumerate((u0, u1)):
            coordinate = build.node("ShaderNodeCombineXYZ", f"row {name}, texel {k}")
            build.feed(coordinate.inputs["X"], at)
            build.feed(coordinate.inputs["Y"], (j + 0.5) / len(fitting.LUT_ROWS))
            texture = build.node("ShaderNodeTexImage", name, image=lut,
                                 interpolation="Closest", extension="EXTEND")
            build.tree.links.new(coordinate.outputs[0], texture.inputs["Vector"])
            samples.append(texture.outputs["Color"])
        rows[name] = build.mix_vector(weight, *samples, label=f"row {name}")
    return rows


def _cos_view(build: _Builder, normal, geometry, label: str):
    """``max(0, I . N)``: the cosine of the view angle against ``normal``."""
    return build.math("MAXIMUM", build.vector("DOT_PRODUCT", geometry.outputs["Incoming"],
                                              _normal_or_shading(build, normal, geometry)),
                      0.0, label=label)


def _common(build: _Builder):
    """Group input/output nodes and the terms both tiers use."""
    inputs = build.node("NodeGroupInput")
    output = build.node("NodeGroupOutput")
    w = inputs.outputs["Coverage"]
    through = build.vector("SUBTRACT", (1.0, 1.0, 1.0), inputs.outputs["Foundation Absorption"],
                           label="1 - A")
    through2 = build.vector("MULTIPLY", through, through, label="(1 - A)^2")
    skin = inputs.outputs["Skin Color"]
    scale = build.math("MULTIPLY", inputs.outputs["Subsurface Scale"],
                       inputs.outputs["Units per mm"], label="subsurface scale")
    return inputs, output, w, through, through2, skin, scale, inputs.outputs["Gloss"]


def _build_principled(build: _Builder, fit, method: str, radius_mm, ior: float):
    inputs, output, w, through, through2, skin, scale, gloss = _common(build)
    coat_weight = build.math("MULTIPLY", build.math("MULTIPLY", w, gloss), fit.coat.level,
                             label="coat weight")
    made_skin = build.vector("MULTIPLY", build.vector("MULTIPLY", through2, skin),
                             tuple(fit.transmittance_mean**2), label="skin through film")
    made_total = build.vector("ADD", build.vector("MULTIPLY", through, tuple(fit.film_albedo)),
                              build.vector("ADD", made_skin, build.scale(build.vector(
                                  "MULTIPLY", through2, tuple(fit.gloss_to_diffuse)), gloss)))
    total = build.mix_vector(w, skin, made_total, label="diffuse albedo")
    skin_part = build.mix_vector(w, skin, made_skin, label="skin part")
    e_spec = build.mix_float(w, fit.specular_albedo_mean[0], fit.specular_albedo_mean[1])
    attenuation = build.math("MULTIPLY",
                             build.math("SUBTRACT", 1.0, build.math("MULTIPLY", coat_weight,
                                                                     fit.coat_albedo_mean)),
                             build.math("SUBTRACT", 1.0, build.math("MULTIPLY", e_spec, gloss)),
                             label="layer attenuation")
    base = build.scale(total, build.math("DIVIDE", 1.0, attenuation), label="base colour")
    share = build.vector("DOT_PRODUCT", build.vector("DIVIDE", skin_part, total),
                         (1 / 3, 1 / 3, 1 / 3), label="subsurface weight")
    mean_through2 = build.vector("DOT_PRODUCT", through2, (1 / 3, 1 / 3, 1 / 3))
    level = build.math("MULTIPLY", build.mix_float(
        w, fit.specular_bare.level, build.math("MULTIPLY", mean_through2,
                                               fit.specular_film.level)), gloss,
        label="specular level")
    roughness = build.mix_float(w, fit.specular_bare.roughness, fit.specular_film.roughness)

    bsdf = build.node("ShaderNodeBsdfPrincipled", "Made-up skin", distribution="GGX",
                      subsurface_method=method)
    values = {
        "Base Color": base, "Roughness": roughness, "IOR": fitting.SPECULAR_IOR,
        "Specular IOR Level": level, "Coat Weight": coat_weight,
        "Coat Roughness": fit.coat.roughness,
        "Coat IOR": fit.coat.ior, "Subsurface Weight": share,
        "Subsurface Radius": tuple(map(float, radius_mm)), "Subsurface Scale": scale,
        "Subsurface IOR": ior, "Normal": inputs.outputs["Normal"],
        "Coat Normal": inputs.outputs["Film Normal"],
    }
    for name, value in values.items():
        # By identifier: a socket the method leaves unavailable is not found by name in 5.0.
        build.feed(socket(bsdf.inputs, name), value)
    build.tree.links.new(bsdf.outputs[0], output.inputs["Shader"])


def _build_view_weighted(build: _Builder, glossy_fits: dict, lut, method: str, radius_mm,
                         ior: float, *, film_albedo, transmittance_mean,
                         tinted_subsurface: bool):
    """The LAYERED and EEVEE tiers' closures (their weights:
    :func:`lut_baker.closures.fitting.layered_weights`, :func:`~lut_baker.closures.fitting.
    eevee_weights`): Glossy lobes ``glossy_fits`` weighted by the rows of ``lut``, one Diffuse
    for the film, Subsurface for the skin, a Mix Shader by Coverage.  ``tinted_subsurface``:
    the skin through the film keeps the skin's own colour, tinted relative to its strongest
    channel, which weights the closure (Cycles' random walk: see below); else its colour is
    the product itself (EEVEE's screen-space Burley and Cycles' Burley take it as it is)."""
    inputs, output, w, through, through2, skin, scale, gloss = _common(build)
    geometry = build.node("ShaderNodeNewGeometry")
    film_normal, skin_normal = inputs.outputs["Film Normal"], inputs.outputs["Normal"]
    # Each row is read at the view angle against the normal of the surface it describes: the
    # skin's own gloss against the skin's, the film and the light through it against the film's.
    cos_film = _cos_view(build, film_normal, geometry, "cos theta_o (film)")
    cos_skin = _cos_view(build, skin_normal, geometry, "cos theta_o (skin)")
    rows = _lut_rows(build, lut, {name: cos_skin if name == "skin_gloss" else cos_film
                                  for name in fitting.LUT_ROWS})

    def glossy(name, colour, normal):
        lobe = glossy_fits[name]
        node = build.node("ShaderNodeBsdfGlossy", name.replace("_", " "),
                          distribution=lobe.distribution)
        # Gloss 0: colour 0, a closure Cycles does not allocate (bsdf_alloc's weight cutoff).
        build.feed(node.inputs["Color"], build.scale(colour, gloss, label=f"{name} x Gloss"))
        build.feed(node.inputs["Roughness"], lobe.roughness)
        build.feed(node.inputs["Normal"], normal)
        return node.outputs[0]

    def subsurface(colour, label):  # the skin's: its normal
        node = build.node("ShaderNodeSubsurfaceScattering", label, falloff=method)
        build.feed(socket(node.inputs, "Color"), colour)
        build.feed(socket(node.inputs, "Radius"), tuple(map(float, radius_mm)))
        build.feed(socket(node.inputs, "Scale"), scale)
        build.feed(socket(node.inputs, "IOR"), ior)
        build.feed(socket(node.inputs, "Normal"), skin_normal)
        return node.outputs[0]

    def add(a, b):
        node = build.node("ShaderNodeAddShader")
        build.tree.links.new(a, node.inputs[0])
        build.tree.links.new(b, node.inputs[1])
        return node.outputs[0]

    # The film's diffuse and the Lambertian companion of its gloss (closures.fitting.fit_glossy)
    # share one Diffuse closure: no extra closure to sample.
    film_diffuse = build.node("ShaderNodeBsdfDiffuse", "film diffuse")
    companion = build.scale(rows["film_gloss_diffuse"], gloss, label="gloss companion x Gloss")
    build.feed(film_diffuse.inputs["Color"],
               build.vector("ADD", build.vector("MULTIPLY", through, tuple(film_albedo)),
                            companion, label="film diffuse + gloss companion"))
    build.feed(film_diffuse.inputs["Normal"], film_normal)
    transmitted = build.vector("MULTIPLY", build.vector("MULTIPLY", through2,
                                                        rows["film_transmittance"]),
                               tuple(transmittance_mean), label="(1 - A)^2 T(theta_o) T_mean")
    if tinted_subsurface:
        # The skin seen through the film, per channel (1 - A)^2 T(theta_o) T_mean times the
        # skin: the closure's colour keeps the skin's own (bright) colour, tinted by that
        # product relative to its strongest channel, and the strongest channel weights the
        # closure.  A dark colour instead would make the random walk both noisy (14% against
        # 1% at 32 samples) and wrongly short.
        separate = build.node("ShaderNodeSeparateXYZ", "transmitted channels")
        build.feed(separate.inputs[0], transmitted)
        strongest = build.math("MAXIMUM", separate.outputs[0],
                               build.math("MAXIMUM", separate.outputs[1], separate.outputs[2]))
        through_colour = build.scale(build.vector("MULTIPLY", transmitted, skin),
                                     build.math("DIVIDE", 1.0, build.math("MAXIMUM", strongest,
                                                                          1e-6)),
                                     label="skin through film colour")
        weighted = build.node("ShaderNodeMixShader", "skin through film (weight)")
        build.feed(socket(weighted.inputs, "Fac"), strongest)
        build.tree.links.new(subsurface(through_colour, "skin through film"),
                             socket(weighted.inputs, "Shader_001"))
        skin_through = weighted.outputs[0]
    else:
        skin_through = subsurface(build.vector("MULTIPLY", transmitted, skin),
                                  "skin through film")
    made_up = add(add(glossy("film_gloss", rows["film_gloss"], film_normal),
                      film_diffuse.outputs[0]),
                  add(glossy("path3_gloss", build.vector("MULTIPLY", rows["path3_gloss"],
                                                         through2), skin_normal),
                      skin_through))
    bare = add(glossy("skin_gloss", rows["skin_gloss"], skin_normal),
               subsurface(skin, "bare skin"))
    mix = build.node("ShaderNodeMixShader", "coverage (areal mix)")
    build.feed(socket(mix.inputs, "Fac"), w)
    build.tree.links.new(bare, socket(mix.inputs, "Shader"))
    build.tree.links.new(made_up, socket(mix.inputs, "Shader_001"))
    build.tree.links.new(mix.outputs[0], output.inputs["Shader"])


def _build_layered(build: _Builder, fit, lut, method: str, radius_mm, ior: float):
    _build_view_weighted(build, fit.glossy, lut, method, radius_mm, ior,
                         film_albedo=fit.film_albedo,
                         transmittance_mean=fit.transmittance_mean, tinted_subsurface=True)


def _build_eevee(build: _Builder, fit, lut, method: str, radius_mm, ior: float):
    _build_view_weighted(build, fit.eevee_glossy, lut, method, radius_mm, ior,
                         film_albedo=fit.film_albedo,
                         transmittance_mean=fit.transmittance_mean, tinted_subsurface=False)


def build_group(tier: str, bake: dict, fit, group=None, *, method=None, measured=None):
    """Create (or, given ``group``, rebuild in place) the node group of ``tier`` from a
    :class:`ClosureFit` ``fit`` of the tables that ``bake`` describes (its record,
    :func:`storage.bake_record`).  ``method``: a subsurface method forced by the user, else the
    fit's choice.  The group's :data:`.keys.FIT_KEY` holds the bake record, the fit's summary,
    the SHA-256 of every image the group reads (:func:`storage.image_record`) and
    ``measured``, what the fit measured at the settings' coverage and absorption
    (:func:`.fits.measure`), if given."""
    if tier not in fitting.TIERS:
        raise ValueError(f"tier must be one of {fitting.TIERS}, got {tier!r}")
    key = bake["key"]
    name = group_name(tier, key, method)
    if group is None:
        group = bpy.data.node_groups.get(name) or bpy.data.node_groups.new(name,
                                                                           "ShaderNodeTree")
    elif group.name != name and bpy.data.node_groups.get(name) is None:
        group.name = name
    _interface(group, fit.skin_albedo)
    group.nodes.clear()
    build = _Builder(group)
    forced = method
    method = method or (fitting.EEVEE_SUBSURFACE_METHOD if tier == "EEVEE"
                        else fit.subsurface_method)
    radius = fit.profiles[method].radius_mm
    ior = fit.subsurface_ior
    images = []
    if tier == "PRINCIPLED":
        _build_principled(build, fit, method, radius, ior)
    else:
        rows = fit.eevee_lut if tier == "EEVEE" else fit.lut
        lut = storage.lut_image(lut_image_name(key, tier), rows)
        images.append(storage.image_record(lut))
        (_build_eevee if tier == "EEVEE" else _build_layered)(build, fit, lut, method, radius,
                                                              ior)
    group[FIT_KEY] = json.dumps({**bake, "tier": tier, "forced_method": forced,
                                 "images": images, **fit.summary(),
                                 "subsurface_method": method, "measured": measured},
                                default=float)
    if LEGACY_TABLES_REF in group:  # an older add-on kept the whole tables in the file
        del group[LEGACY_TABLES_REF]
    return group


def write_measured(group, measured: dict) -> None:
    """Replace the measurement a group's record keeps (:func:`.fits.measure`)."""
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
