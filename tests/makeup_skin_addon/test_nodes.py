"""The Made-up Skin node groups (makeup_skin_addon.nodes): Normal, Film Normal and Skin Color
reach every closure (Cycles and EEVEE), an albedo texture in Skin Color renders as a bake
at that albedo, a forced subsurface method gets its own group, and the view-angle rows read
in EEVEE as in Cycles."""

import dataclasses
import json

import numpy as np
import pytest
from support import group_probes, sphere_scene
from support.addon_steps import HEAD_PX, apply_operator, apply_pipeline, group_node, render


def _unlinked_against_no_normal_links(head, tmp_path, tier):
    """``(render with Normal and Film Normal unlinked, render of the same group with no link
    from those inputs inside)``: the second is the group before it had the inputs."""
    material = apply_operator(head, tier)
    node = group_node(material)
    for name in ("Normal", "Film Normal", "Skin Color"):
        for link in list(node.inputs[name].links):
            material.node_tree.links.remove(link)
    node.inputs["Skin Color"].default_value = (0.6, 0.45, 0.4, 1.0)
    with_inputs = render(tmp_path, f"{tier}_inputs")
    bare = node.node_tree.copy()
    group_input = next(n for n in bare.nodes if n.type == "GROUP_INPUT")
    for name in ("Normal", "Film Normal"):
        for link in list(group_input.outputs[name].links):
            bare.links.remove(link)
    node.node_tree = bare
    return with_inputs, render(tmp_path, f"{tier}_bare")


@pytest.mark.slow  # renders compared
def test_unlinked_normals_render_as_the_shading_normal(head, tmp_path):
    """Leaving Normal and Film Normal unlinked renders exactly as a group whose closures have
    no Normal link at all, in every tier (Cycles)."""
    for tier in ("LAYERED", "PRINCIPLED", "EEVEE"):
        with_inputs, bare = _unlinked_against_no_normal_links(head, tmp_path, tier)
        np.testing.assert_array_equal(bare, with_inputs)


@pytest.mark.slow
def test_unlinked_normals_in_eevee(head, tmp_path):
    """The same in EEVEE, EEVEE tier (the one Auto gives EEVEE): a hidden-value group input
    stays unlinked inside the group, where a visible one would hand the BSDF a zero normal
    (flat shading in EEVEE 5.0)."""
    import bpy

    scene = bpy.context.scene
    scene.render.engine = "BLENDER_EEVEE" if bpy.app.version >= (5, 0, 0) else \
        "BLENDER_EEVEE_NEXT"
    scene.eevee.taa_render_samples = 4
    for light in (obj.data for obj in scene.objects if obj.type == "LIGHT"):
        light.use_shadow = False  # software OpenGL: ~45 s a render with shadows
    render(tmp_path, "warm_up")  # a process's first EEVEE render differs (by up to 0.03)
    with_inputs, bare = _unlinked_against_no_normal_links(head, tmp_path, "EEVEE")
    assert with_inputs.mean() > 0.1
    np.testing.assert_allclose(bare, with_inputs, atol=1e-4)  # a zero normal: ~0.5


@pytest.mark.slow  # renders compared
def test_every_closure_reads_a_normal_input(head, tmp_path):
    from makeup_skin_addon import group_parts, nodes

    for tier in ("LAYERED", "PRINCIPLED", "EEVEE"):
        group = group_node(apply_operator(head, tier)).node_tree
        closures = [n for n in group_parts.nodes_of(group)
                    if n.type.startswith(("BSDF", "SUBSURFACE"))]
        assert closures
        for closure in closures:
            sources = {link.from_socket.name for name in ("Normal", "Coat Normal")
                       if name in closure.inputs for link in closure.inputs[name].links}
            assert sources and sources <= set(nodes.NORMAL_INPUTS), closure.name
    # A bump on the film changes the render; on neither input it does not.
    material = head.active_material
    node = group_node(material)
    smooth = render(tmp_path, "smooth")
    material.node_tree.links.new(node.inputs["Normal"].links[0].from_socket,
                                 node.inputs["Film Normal"])
    assert np.abs(render(tmp_path, "bumped") - smooth).max() > 1e-3


@pytest.mark.slow  # renders compared
@pytest.mark.parametrize("tier", ["LAYERED", "PRINCIPLED", "EEVEE"])
def test_skin_colour_texture_matches_a_bake_at_that_albedo(addon, blank_scene, tmp_path, tier):
    """An albedo texture in Skin Color renders as the tables baked with that albedo: the skin's
    diffuse term is linear, so the texture scales every skin closure exactly."""
    import bpy

    from lut_baker import bake
    from lut_baker.model import presets
    from makeup_skin_addon import groups

    colour = np.array([0.62, 0.41, 0.33])
    obj = sphere_scene.add_sphere(blank_scene, 0.03, light_deg=40.0, size=HEAD_PX, samples=16)
    skin = presets.made_up_skin("medium_beige", "jensen_skin2", absorption=0.0)
    tables = bake.bake(skin, "preview")
    material = sphere_scene.made_up_material(obj, tables, tier, coverage=0.7,
                                              absorption=[0.1, 0.24, 0.42])
    texture = material.node_tree.nodes.new("ShaderNodeTexImage")
    texture.image = bpy.data.images.new("flat albedo", 4, 4, float_buffer=True)
    texture.image.colorspace_settings.name = "Non-Color"
    texture.image.pixels.foreach_set(np.tile([*colour, 1.0], 16).astype(np.float32))
    material.node_tree.links.new(texture.outputs["Color"],
                                 groups.group_of(material).inputs["Skin Color"])
    textured = render(tmp_path, "textured")

    own = skin.replace(skin_reflection=dataclasses.replace(skin.skin_reflection,
                                                           P_d=colour / np.pi))
    # recorded at the default resolution as made_up_material records its tables, so that both
    # are fitted alike (a preview record's fit takes the preview's shortcuts)
    group, _ = groups.group_for_tables(bake.bake(own, "preview"), tier)
    material.node_tree.nodes.remove(texture)
    groups.group_of(material).node_tree = group
    groups.group_of(material).inputs["Skin Color"].default_value = (*colour, 1.0)
    baked = render(tmp_path, "baked")
    assert np.abs(textured - baked).max() < 1e-5 * max(baked.max(), 1.0)


def test_forced_subsurface_method_gets_its_own_group(sphere):
    from makeup_skin_addon import group_parts

    material, _ = apply_pipeline(sphere, "PRINCIPLED")
    auto = material.node_tree.nodes["Made-up Skin"].node_tree
    material, _ = apply_pipeline(sphere, "PRINCIPLED", subsurface_method="RANDOM_WALK_SKIN")
    group = material.node_tree.nodes["Made-up Skin"].node_tree
    assert group != auto and " RW Skin " in group.name
    principled = next(n for n in group_parts.nodes_of(group) if n.type == "BSDF_PRINCIPLED")
    assert principled.subsurface_method == "RANDOM_WALK_SKIN"
    meta = json.loads(group["makeup_skin_fit"])
    radius = meta["profiles"]["RANDOM_WALK_SKIN"]["radius_mm"]
    assert tuple(next(s for s in principled.inputs if s.identifier == "Subsurface Radius")
                 .default_value) == pytest.approx(radius)



def test_tables_with_the_film_as_a_slab_get_the_slabs_group(addon, blank_scene):
    """Tables baked with a film thickness give a group of the film as a slab at it (the record
    Apply's Film "At a Thickness" makes, its own key, the slab's fit), never the paper film's
    group of the same skin."""
    from lut_baker import bake
    from lut_baker.model import presets
    from makeup_skin_addon import bakes, groups, nodes

    skin = presets.paper()
    slab = bake.bake(skin, "preview", film=9.6)
    group, fit = groups.group_for_tables(slab, "LAYERED", resolution="preview")
    meta = nodes.read_meta(group)
    assert meta["film_thickness_um"] == pytest.approx(9.6)
    assert meta["key"] == bakes.bake_record(skin, "preview", 9.6)["key"]
    assert meta["key"] != bakes.bake_record(skin, "preview")["key"]
    assert fit is not None and fit.slab is not None
    assert fit.slab.thickness_um == pytest.approx(9.6)

def _row_probe(group, row: str, linear: bool):
    """A copy of ``group`` whose output is an Emission of its view-angle row ``row``: read as
    the group reads it (two Closest texels mixed) or, ``linear``, by one Linear lookup at
    ``u = cos(theta_o)`` (what the Layered tier did before)."""
    from makeup_skin_addon import group_parts

    probe = group_probes.copy_with_parts(group, f"row probe {row} {linear}")
    every = group_parts.nodes_of(probe)
    if linear:
        cos = next(n for n in every if n.label == "cos theta_o (film)").outputs[0]
        texture = next(n for n in every if n.type == "TEX_IMAGE" and n.label == row)
        texel = next(n for n in every if n.label == f"row {row}, texel 0")  # its coordinate
        tree = cos.id_data
        coordinate = tree.nodes.new("ShaderNodeCombineXYZ")
        tree.links.new(cos, coordinate.inputs["X"])
        coordinate.inputs["Y"].default_value = texel.inputs["Y"].default_value
        lookup = tree.nodes.new("ShaderNodeTexImage")
        lookup.image, lookup.interpolation, lookup.extension = texture.image, "Linear", "EXTEND"
        tree.links.new(coordinate.outputs[0], lookup.inputs["Vector"])
        colour = lookup.outputs["Color"]
    else:
        mixed = next(n for n in every if n.label == f"row {row}")
        colour = next(s for s in mixed.outputs if s.enabled and s.is_linked)
    emission = colour.id_data.nodes.new("ShaderNodeEmission")
    colour.id_data.links.new(colour, emission.inputs["Color"])
    group_probes.to_output(probe, emission.outputs[0])
    return probe


@pytest.mark.slow  # EEVEE renders
def test_view_angle_rows_read_in_eevee_as_in_cycles(addon, paper_tables):
    """EEVEE samples a Linear image through mipmaps and anisotropic filtering, which mixes the
    view-angle image's rows wherever cos(theta_o) changes quickly across the screen (the
    Layered tier's bright patches in EEVEE, docs/addon.md).  The groups read each row from two
    Closest texels mixed: in EEVEE, a sphere of a row (the film's transmittance) equals
    :func:`lut_baker.closures.view_image.sample_row` at every pixel's cos(theta_o) within the
    image's half-float precision (and the mesh's normals), where one Linear lookup errs by tens
    of per cent."""
    import bpy
    from support import bench_scene as scene_module

    from lut_baker.closures import view_image
    from lut_baker.numerics.geometry import sphere_normals
    from lut_baker.offline.validation import compare
    from makeup_skin_addon import groups

    size = 48
    sphere = scene_module.sphere_scene(size=size, samples=1)
    scene = bpy.context.scene
    scene_module.use_eevee(scene, 1)
    group, fit = groups.group_for_tables(paper_tables, "EEVEE", resolution="preview")
    normals, mask = sphere_normals(size)
    expected = np.zeros((size, size, 3))
    row = "film_transmittance"  # non-zero at every view: the error is relative to it
    texels = fit.eevee_view_rows[view_image.EEVEE_IMAGE_ROWS.index(row)]
    expected[mask] = view_image.sample_row(texels, np.clip(normals[mask][:, 2], 0, 1))
    errors = {}
    for linear in (False, True):
        material = bpy.data.materials.new(f"row probe {linear}")
        if material.node_tree is None:
            material.use_nodes = True
        tree = material.node_tree
        tree.nodes.clear()
        node = tree.nodes.new("ShaderNodeGroup")
        node.node_tree = _row_probe(group, row, linear)
        tree.links.new(node.outputs["Shader"],
                       tree.nodes.new("ShaderNodeOutputMaterial").inputs["Surface"])
        scene_module.set_material(sphere, material)
        errors[linear] = compare.relative_rms(scene_module.render_image()[1], expected)
    print(f"{row} row in EEVEE: exact lookup {errors[False]:.2e}, Linear {errors[True]:.3f}")
    assert errors[False] < 5e-3  # measured 4.3e-4: half floats and the mesh normals
    assert errors[True] > 0.05


@pytest.mark.parametrize("tier", ["LAYERED", "EEVEE"])
def test_a_damaged_lookup_image_renders_wrong_but_bounded(sphere, tmp_path, tier):
    """The view-angle image overwritten with 1e20 (a file damaged where the add-on cannot
    repair it, on a render farm): every row is held within its own range as baked, so the
    sphere renders no brighter than the brightest the rows allow, and finite (unbounded, it
    rendered values up to 6e23)."""
    import bpy
    from support.addon_steps import view_images

    material, _ = apply_pipeline(sphere, tier)
    intact = render(tmp_path, "intact")
    image = view_images()[0]
    image.pixels.foreach_set(np.full(len(image.pixels), 1e20, np.float32))
    bpy.context.scene.cycles.samples = 4
    damaged = render(tmp_path, "damaged")
    assert np.all(np.isfinite(damaged))
    assert damaged.max() < 3.0 * intact.max() + 0.5, (damaged.max(), intact.max())
