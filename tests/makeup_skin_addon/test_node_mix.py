"""The node group's formulas, evaluated by Cycles, against the same formulas in numpy.

Each tier's formulas are written once (:mod:`lut_baker.closures.tier_formulas`); the add-on
emits them as nodes (makeup_skin_addon/node_algebra.py) and the replicas evaluate them with
numpy.  These tests read what the built group computes at random coverages, absorptions,
Skin Colors, Gloss values and view angles, and compare it with the numpy evaluation: any
operation the node algebra emits wrongly, or a closure wired to the wrong colour, weight or
mix, shows.

How a value is read: each probe is a COPY of the built group (the built group itself is never
changed) in which one closure is replaced by an Emission shader of the same colour, in the same
place of the shader tree (Add and Mix Shaders kept), and the copy's other closures are removed:

- PRINCIPLED: the Emission's colour is the socket feeding one Principled input (Base Color,
  Subsurface Weight, Specular IOR Level, Coat Weight, Roughness), so the pixel is that input;
- LAYERED and EEVEE: the Emission replaces one closure (film gloss, path-3 gloss, skin gloss,
  film diffuse, skin through the film, bare skin), so the pixel is that closure's colour times
  every Mix Shader factor above it: its weight in the tier, as the replica adds it (each tier
  with its own view-angle image; the LAYERED tier's skin through the film has a weight of its
  own, probed too).

Every (probe, case) pair is one face of one plane, with its own material, tilted by the case's
view angle about the x axis so that it fills a 3x3-pixel cell of an orthographic camera looking
down (1 pixel per unit): the LAYERED tier reads its view-angle rows at that angle's cosine.
Cycles CPU, 1 sample, box filter, no light, film exposure 1 (neutral), view exposure 0, view
transform Standard; the float32 OpenEXR it writes holds the emitted values unchanged, and the
centre pixel of each face is compared with numpy's value.
"""

import dataclasses

import numpy as np
import pytest
from support import group_probes

from lut_baker.bake import bake
from lut_baker.closures import fitting as cf
from lut_baker.closures import tier_formulas, tier_registry, tiers
from lut_baker.model import presets

CELL = 3
"""Pixels (and scene units) per side of each probe's cell."""
RTOL, ATOL = 1e-5, 1e-6
"""Cycles evaluates the nodes in float32 (the differences seen are below 1e-6)."""


def _cases(count=14, seed=7):
    """``(coverage, absorption RGB, gloss, skin colour RGB, view angle in degrees)``: random
    ones, plus bare skin, full coverage and Gloss 0 (where a product of Coverage and Gloss
    differs from, e.g., their minimum)."""
    rng = np.random.default_rng(seed)
    cases = [(float(rng.uniform()), tuple(rng.uniform(0.0, 1.0, 3)), float(rng.uniform()),
              tuple(rng.uniform(0.05, 0.95, 3)), float(rng.uniform(0.0, 75.0)))
             for _ in range(count)]
    return [*cases, (0.0, (0.2, 0.4, 0.6), 1.0, (0.7, 0.5, 0.4), 30.0),
            (1.0, (0.0, 0.0, 0.0), 1.0, (0.8, 0.6, 0.5), 60.0),
            (0.5, (0.1, 0.4, 0.8), 0.0, (0.6, 0.4, 0.3), 0.0)]


CASES = _cases()
PRINCIPLED_PROBES = ("Base Color", "Subsurface Weight", "Specular IOR Level", "Coat Weight",
                     "Roughness")
LAYERED_PROBES = ("film gloss", "path3 gloss", "skin gloss", "film diffuse",
                  "skin through film", "bare skin", "skin through film weight")
"""The LAYERED group's closures by node label (nodes.py), and the weight of the one that has
its own."""
CLOSURES = {"BSDF_PRINCIPLED", "BSDF_GLOSSY", "BSDF_ANISOTROPIC", "BSDF_DIFFUSE",
            "SUBSURFACE_SCATTERING"}


@pytest.fixture(scope="module")
def baked():
    """``(skin, tables, fit)``: preview tables of a tinted skin, and a fit in which every term
    of the mix is non-zero (a specular lobe through the film and a tinted film albedo, which
    this preset's fit leaves at 0 and grey; a tinted film transmittance, which measured
    foundations have), so that each weight reaches some probe and every channel its own."""
    skin = presets.made_up_skin("paper_natural", "jensen_skin2", coverage=1.0, absorption=0.0)
    tables = bake(skin, "preview")
    fit = cf.fit_closures(tables)
    fit = dataclasses.replace(
        fit,
        specular_film=dataclasses.replace(fit.specular_film, level=0.4, roughness=0.3),
        specular_albedo_mean=(fit.specular_albedo_mean[0], 0.03),
        gloss_to_diffuse=np.full(3, 0.02),
        film_albedo=fit.film_albedo * np.array([1.0, 0.9, 0.8]),
        transmittance_mean=fit.transmittance_mean * np.array([1.0, 0.95, 0.8]))
    return skin, tables, fit


@pytest.fixture(scope="module")
def baked_slab():
    """``(skin, tables, fit)`` of the film as a slab (9.6 um, absorption baked in), the skin
    under the film darkened per channel (``skin_under``): the factor ``1 / (1 - S c)`` and the
    film body's row reach the probes."""
    skin = presets.made_up_skin("paper_natural", "jensen_skin2", coverage=1.0,
                                absorption=[0.1, 0.3, 0.5])
    tables = bake(skin, "preview", film=9.6)
    fit = cf.fit_closures(tables)
    fit = dataclasses.replace(fit, slab=dataclasses.replace(
        fit.slab, below=fit.slab.below * np.array([1.0, 1.2, 1.5]),
        skin_under=np.array([1.0, 0.9, 0.7])))
    return skin, tables, fit


def _group(tier, baked):
    from makeup_skin_addon import bakes, nodes

    skin, tables, fit = baked
    film = "paper" if fit.slab is None else fit.slab.thickness_um
    return nodes.build_group(tier, bakes.bake_record(skin, "preview", film), fit)


def _source(target):
    """``(linked socket or None, default value)`` feeding the input socket ``target``."""
    if target.is_linked:
        return target.links[0].from_socket, None
    return None, target.default_value


def _emission(tree, target_input):
    """An Emission node in ``tree`` whose Color is what feeds ``target_input``."""
    emission = tree.nodes.new("ShaderNodeEmission")
    emission.inputs["Strength"].default_value = 1.0
    linked, value = _source(target_input)
    if linked is not None:
        tree.links.new(linked, emission.inputs["Color"])
    else:
        emission.inputs["Color"].default_value = (*value[:3], 1.0)
    return emission


def _principled_probe(group, name):
    """A copy of the PRINCIPLED ``group`` whose output is the Principled input ``name``."""
    from makeup_skin_addon import group_parts, nodes

    probe = group_probes.copy_with_parts(group, f"probe {name}")
    bsdf = next(node for node in group_parts.nodes_of(probe)
                if node.type == "BSDF_PRINCIPLED")
    emission = _emission(bsdf.id_data, nodes.socket(bsdf.inputs, name))
    bsdf.id_data.nodes.remove(bsdf)
    group_probes.to_output(probe, emission.outputs[0])
    return probe


def _layered_probe(group, label):
    """A copy of the LAYERED ``group`` in which the closure labelled ``label`` is an Emission
    of its colour, in its place, and every other closure is gone."""
    from makeup_skin_addon import group_parts, nodes

    probe = group_probes.copy_with_parts(group, f"probe {label}")
    closures = [node for node in group_parts.nodes_of(probe) if node.type in CLOSURES]
    assert label in {node.label for node in closures}
    for node in closures:
        tree = node.id_data
        if node.label == label:
            emission = _emission(tree, nodes.socket(node.inputs, "Color"))
            for link in list(node.outputs[0].links):
                tree.links.new(emission.outputs[0], link.to_socket)
        tree.nodes.remove(node)
    return probe


def _weight_probe(group, label):
    """A copy of the LAYERED ``group`` in which the Mix Shader weighting the closure
    labelled ``label`` is an Emission of its factor, in its place, and every closure is
    gone: the pixel is the weight times the coverage mix above it."""
    from makeup_skin_addon import group_parts, nodes

    probe = group_probes.copy_with_parts(group, f"probe {label} weight")
    mix = next(node for node in group_parts.nodes_of(probe)
               if node.label == f"{label} (weight)")
    emission = _emission(mix.id_data, nodes.socket(mix.inputs, "Fac"))
    for link in list(mix.outputs[0].links):
        mix.id_data.links.new(emission.outputs[0], link.to_socket)
    for node in [n for n in group_parts.nodes_of(probe) if n.type in CLOSURES] + [mix]:
        node.id_data.nodes.remove(node)
    return probe


def _layered_or_weight_probe(group, name):
    if name.endswith(" weight"):
        return _weight_probe(group, name.removesuffix(" weight"))
    return _layered_probe(group, name)


def _material(probe, coverage, absorption, gloss, skin_colour, view_deg):
    import bpy

    material = bpy.data.materials.new(f"{probe.name} {coverage} {absorption} {view_deg}")
    if material.node_tree is None:  # Blender 4.5 (5.0 gives every material a tree)
        material.use_nodes = True
    tree = material.node_tree
    tree.nodes.clear()
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = probe
    for name, value in (("Coverage", coverage), ("Foundation Absorption", (*absorption, 1.0)),
                        ("Gloss", gloss), ("Skin Color", (*skin_colour, 1.0))):
        node.inputs[name].default_value = value
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(node.outputs["Shader"], output.inputs["Surface"])
    return material


def _render_grid(scene, materials, views_deg, tmp_path):
    """Render ``materials`` (rows of columns, column ``j`` seen at ``views_deg[j]`` degrees)
    as the faces of one plane and return each face's centre pixel, ``(rows, columns, 3)``."""
    import bpy

    rows, columns = len(materials), len(materials[0])
    vertices, faces = [], []
    for row in range(rows):
        for column in range(columns):
            x, y = CELL * column, CELL * row
            rise = CELL * np.tan(np.radians(views_deg[column]))  # normal at the view angle
            start = len(vertices)
            vertices += [(x, y, 0.0), (x + CELL, y, 0.0), (x + CELL, y + CELL, rise),
                         (x, y + CELL, rise)]
            faces.append(tuple(range(start, start + 4)))
    mesh = bpy.data.meshes.new("probes")
    mesh.from_pydata(vertices, [], faces)
    for material in (m for row in materials for m in row):
        mesh.materials.append(material)
    mesh.polygons.foreach_set("material_index", np.arange(rows * columns))
    mesh.update()
    scene.collection.objects.link(bpy.data.objects.new("probes", mesh))

    width, height = CELL * columns, CELL * rows
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = max(width, height)
    camera.data.sensor_fit = "AUTO"
    camera.location = (width / 2, height / 2, 100.0)  # looking down -Z at the plane
    scene.collection.objects.link(camera)
    scene.camera = camera

    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 1
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.cycles.film_exposure = 1.0
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.filter_width = 1.0
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = str(tmp_path / "probes.exr")
    bpy.ops.render.render(write_still=True)

    image = bpy.data.images.load(scene.render.filepath, check_existing=False)
    try:
        assert tuple(image.size) == (width, height)
        pixels = np.empty(width * height * 4, np.float32)
        image.pixels.foreach_get(pixels)
    finally:
        bpy.data.images.remove(image)
    pixels = pixels.reshape(height, width, 4)[..., :3]  # row 0 at the bottom
    return pixels[CELL // 2::CELL, CELL // 2::CELL]


class _Recording(tier_formulas.NumpyAlgebra):
    """The shader algebra as a list of ``(share, closure)``: each closure with its side's
    share of the coverage mix."""

    def closure(self, closure):
        return [(1.0, closure)]

    def add(self, *shaders):
        return [item for shader in shaders for item in shader]

    def mix(self, coverage, bare, covered):
        return ([((1.0 - coverage) * share, c) for share, c in bare]
                + [(coverage * share, c) for share, c in covered])


def _numpy(fit, case, name="LAYERED"):
    """The tier formulas' inputs and algebra for one case, as the replicas take them (the
    image of tier ``name``)."""
    coverage, absorption, gloss, skin_colour, view_deg = case
    x = tier_formulas.TierInputs.numpy(coverage, absorption, skin_colour, gloss)
    image = tier_registry.tier(name).image(fit)
    rows = dict(zip(image.rows, image.texels, strict=True))
    return x, _Recording(rows, np.cos(np.radians(view_deg)))


def _principled_expected(fit, case):
    x, algebra = _numpy(fit, case)
    sockets = tier_formulas.principled_sockets(fit, x, algebra)
    return {name: np.broadcast_to(np.ravel(sockets[name]), (3,)) for name in PRINCIPLED_PROBES}


def _layered_expected(fit, case, eevee=False):
    """Each closure's colour times its weight and its side's share of the coverage mix."""
    name = "EEVEE" if eevee else "LAYERED"
    x, algebra = _numpy(fit, case, name)
    out = {}
    for share, closure in tier_registry.held(fit, name).shader(fit, x, algebra, None):
        weight = 1.0 if closure.weight is None else closure.weight
        out[closure.name.replace("_", " ")] = np.ravel(share * closure.colour * weight)
        if closure.weight is not None:
            out[f"{closure.name} weight"] = np.broadcast_to(np.ravel(share * weight), (3,))
    return out


@pytest.mark.parametrize("film", ["paper", "slab"])
@pytest.mark.parametrize("tier", tiers.TIERS)
def test_node_group_follows_the_tier_formulas(blank_scene, baked, baked_slab, tmp_path, tier,
                                              film):
    """Every probe of ``tier`` in every case equals numpy's value to a relative 1e-5, with the
    paper's film and with the film as a slab (docs/model.md, "The tiers at a thickness")."""
    baked = baked if film == "paper" else baked_slab
    fit = baked[2]
    group = _group(tier, baked)
    probes, make_probe, expected_of = {
        "PRINCIPLED": (PRINCIPLED_PROBES, _principled_probe, _principled_expected),
        "LAYERED": (LAYERED_PROBES, _layered_or_weight_probe, _layered_expected),
        "EEVEE": (("film gloss", "film gloss 2", "path3 gloss", "skin gloss", "film diffuse",
                   "skin"), _layered_probe,
                  lambda fit, case: _layered_expected(fit, case, eevee=True)),
    }[tier]
    copies = [make_probe(group, name) for name in probes]
    materials = [[_material(copy, *case) for case in CASES] for copy in copies]
    measured = _render_grid(blank_scene, materials, [case[4] for case in CASES], tmp_path)
    expected = np.array([[expected_of(fit, case)[name] for case in CASES] for name in probes])
    assert np.ptp(expected) > 0.1  # the cases give the probes different values
    excess = np.abs(measured - expected) / (ATOL + RTOL * np.abs(expected))
    worst = np.unravel_index(np.argmax(excess), excess.shape)
    assert excess.max() <= 1.0, (
        f"{tier} {probes[worst[0]]} at (coverage, absorption, gloss, skin, view) = "
        f"{CASES[worst[1]]}: node group {measured[worst[:2]]}, numpy {expected[worst[:2]]}")


def test_the_principled_base_colour_is_clipped_in_both(blank_scene, baked, tmp_path):
    """A diffuse albedo the layers above would push past 1 (a white skin under a strong coat)
    is clipped to 1 by the formulas, so numpy and the nodes agree, and Cycles' own clamp of
    the colour its subsurface closure takes changes nothing."""
    skin, tables, fit = baked
    bright = dataclasses.replace(fit, coat_albedo_mean=0.6)
    case = (1.0, (0.0, 0.0, 0.0), 1.0, (1.0, 1.0, 1.0), 0.0)
    x, algebra = _numpy(bright, case)
    unclipped = tier_formulas.principled_sockets(bright, x, algebra)
    assert np.max(unclipped["Base Color"]) == 1.0
    group = _group("PRINCIPLED", (skin, tables, bright))
    material = _material(_principled_probe(group, "Base Color"), *case)
    # 2 x 2 cells: Blender renders no image under 4 pixels a side
    measured = _render_grid(blank_scene, [[material] * 2] * 2, [0.0, 0.0], tmp_path)[0, 0]
    np.testing.assert_allclose(measured, np.ravel(unclipped["Base Color"]), rtol=RTOL,
                               atol=ATOL)
