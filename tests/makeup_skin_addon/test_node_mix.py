"""The node group's coverage/absorption mix, evaluated by Cycles, against the closure fits.

:func:`lut_baker.model.made_up_skin.coverage_weights` is the one rule that mixes coverage and
absorption; :func:`lut_baker.closures.fitting.principled_inputs`,
:func:`~lut_baker.closures.fitting.layered_weights` and
:func:`~lut_baker.closures.fitting.eevee_weights` apply it, and the add-on's node group
(makeup_skin_addon/nodes.py) rebuilds it from math nodes.  These tests read what the group
computes and compare it with those functions at several coverages, absorptions (grey and RGB)
and one Gloss below 1.

How a value is read: each probe is a COPY of the built group (the built group itself is never
changed) in which one closure is replaced by an Emission shader of the same colour, in the same
place of the shader tree (Add and Mix Shaders kept), and the copy's other closures are removed:

- PRINCIPLED: the Emission's colour is the socket feeding one Principled input (Base Color,
  Subsurface Weight, Specular IOR Level, Coat Weight, Roughness), so the pixel is that input;
- LAYERED and EEVEE: the Emission replaces one closure (film gloss, path-3 gloss, skin gloss,
  film diffuse, skin through the film, bare skin), so the pixel is that closure's colour times
  every Mix Shader factor above it: its weight in the tier, as ``layered_tier_reflection`` and
  ``eevee_tier_reflection`` add it (each with its own view-angle image).

Every (probe, case) pair is one 3x3-pixel face of one plane, with its own material, seen
head-on by an orthographic camera (1 pixel per unit): Cycles CPU, 1 sample, box filter, no
light, film exposure 1 (neutral), view exposure 0, view transform Standard; the float32
OpenEXR it writes holds the emitted values unchanged, and the centre pixel of each face is
compared with numpy's value.  The view is along the normal, so the LAYERED tier's view-angle
rows are read at ``cos(theta_o) = 1`` (:func:`~lut_baker.closures.fitting.sample_lut`).
"""

import dataclasses

import numpy as np
import pytest

from lut_baker.bake import bake
from lut_baker.closures import fitting as cf
from lut_baker.model import presets

CELL = 3
"""Pixels (and scene units) per side of each probe's face."""
RTOL, ATOL = 1e-5, 1e-6
"""Cycles evaluates the nodes in float32 (the differences seen are below 1e-7)."""
RGB = (0.1, 0.4, 0.8)
CASES = [*((coverage, absorption, 1.0) for coverage in (0.0, 0.3, 1.0)
           for absorption in ((0.0,) * 3, (0.5,) * 3, RGB)),
         (0.3, RGB, 0.5)]
"""``(coverage, absorption, gloss)``: every weight at both ends of coverage and between, and
Gloss below 1 (where a product of Coverage and Gloss differs from, e.g., their minimum)."""
PRINCIPLED_PROBES = ("Base Color", "Subsurface Weight", "Specular IOR Level", "Coat Weight",
                     "Roughness")
LAYERED_PROBES = ("film gloss", "path3 gloss", "skin gloss", "film diffuse",
                  "skin through film", "bare skin")
"""The LAYERED group's closures by node label (nodes.py)."""
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


def _group(tier, baked):
    from makeup_skin_addon import nodes, storage

    skin, tables, fit = baked
    return nodes.build_group(tier, storage.bake_record(skin, "preview"), fit)


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
    from makeup_skin_addon import nodes

    probe = group.copy()
    probe.name = f"probe {name}"
    bsdf = next(node for node in probe.nodes if node.type == "BSDF_PRINCIPLED")
    emission = _emission(probe, nodes.socket(bsdf.inputs, name))
    output = next(node for node in probe.nodes if node.type == "GROUP_OUTPUT")
    probe.nodes.remove(bsdf)
    probe.links.new(emission.outputs[0], output.inputs["Shader"])
    return probe


def _layered_probe(group, label):
    """A copy of the LAYERED ``group`` in which the closure labelled ``label`` is an Emission
    of its colour, in its place, and every other closure is gone."""
    from makeup_skin_addon import nodes

    probe = group.copy()
    probe.name = f"probe {label}"
    closures = [node for node in probe.nodes if node.type in CLOSURES]
    assert label in {node.label for node in closures}
    for node in closures:
        if node.label == label:
            emission = _emission(probe, nodes.socket(node.inputs, "Color"))
            for link in list(node.outputs[0].links):
                probe.links.new(emission.outputs[0], link.to_socket)
        probe.nodes.remove(node)
    return probe


def _material(probe, coverage, absorption, gloss, skin_colour):
    import bpy

    material = bpy.data.materials.new(f"{probe.name} {coverage} {absorption} {gloss}")
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


def _render_grid(scene, materials, tmp_path):
    """Render ``materials`` (rows of columns) as the faces of one plane and return each face's
    centre pixel, ``(rows, columns, 3)``."""
    import bpy

    rows, columns = len(materials), len(materials[0])
    vertices, faces = [], []
    for row in range(rows):
        for column in range(columns):
            x, y = CELL * column, CELL * row
            start = len(vertices)
            vertices += [(x, y, 0.0), (x + CELL, y, 0.0), (x + CELL, y + CELL, 0.0),
                         (x, y + CELL, 0.0)]
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
    camera.location = (width / 2, height / 2, 10.0)  # looking down -Z at the plane
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


def _principled_expected(fit, coverage, absorption, gloss):
    inputs, subsurface_weight = cf.principled_inputs(fit, coverage, absorption, gloss)
    assert max(inputs.base_color) < 1.0  # the node group does not clip it; the fit does
    values = {"Base Color": inputs.base_color, "Subsurface Weight": subsurface_weight,
              "Specular IOR Level": inputs.specular_ior_level,
              "Coat Weight": inputs.coat_weight, "Roughness": inputs.roughness}
    return {name: np.broadcast_to(np.asarray(value, float), (3,)) for name, value in
            values.items()}


def _layered_expected(fit, coverage, absorption, gloss, *, weights_of=cf.layered_weights,
                      lut=None):
    weights = weights_of(fit, coverage, absorption, gloss)
    lut = fit.lut if lut is None else lut
    rows = {name: cf.sample_lut(row, 1.0) for name, row in zip(cf.LUT_ROWS, lut, strict=True)}
    return {
        "film gloss": weights["film_gloss"] * rows["film_gloss"],
        "path3 gloss": weights["path3_gloss"] * rows["path3_gloss"],
        "skin gloss": weights["skin_gloss"] * rows["skin_gloss"],
        "film diffuse": (weights["film_diffuse"]
                         + weights["film_gloss_diffuse"] * rows["film_gloss_diffuse"]),
        "skin through film": weights["skin_through"] * rows["film_transmittance"],
        "bare skin": weights["skin_bare"],
    }


@pytest.mark.parametrize("tier", cf.TIERS)
def test_node_group_mix_follows_coverage_weights(blank_scene, baked, tmp_path, tier):
    """Every probe of ``tier`` in every case equals the fit's value to a relative 1e-5."""
    fit = baked[2]
    group = _group(tier, baked)
    probes, make_probe, expected_of = {
        "PRINCIPLED": (PRINCIPLED_PROBES, _principled_probe, _principled_expected),
        "LAYERED": (LAYERED_PROBES, _layered_probe, _layered_expected),
        "EEVEE": (LAYERED_PROBES, _layered_probe, lambda *case: _layered_expected(
            *case, weights_of=cf.eevee_weights, lut=case[0].eevee_lut)),
    }[tier]
    copies = [make_probe(group, name) for name in probes]
    materials = [[_material(copy, *case, fit.skin_albedo) for case in CASES]
                 for copy in copies]
    measured = _render_grid(blank_scene, materials, tmp_path)
    expected = np.array([[expected_of(fit, *case)[name] for case in CASES]
                         for name in probes])
    assert np.ptp(expected) > 0.1  # the cases give the probes different values
    excess = np.abs(measured - expected) / (ATOL + RTOL * np.abs(expected))
    worst = np.unravel_index(np.argmax(excess), excess.shape)
    assert excess.max() <= 1.0, (
        f"{tier} {probes[worst[0]]} at (coverage, absorption, gloss) = {CASES[worst[1]]}: "
        f"node group {measured[worst[:2]]}, fit {expected[worst[:2]]}")
