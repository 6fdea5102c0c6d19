"""A mesh's attribute at points of its surface (makeup_skin_addon.mesh_attributes), as an
Attribute or Color Attribute node reads it: a vertex's and a corner's value interpolated over
each point's triangle, a face's taken whole, byte colours linear, the render colour attribute
for an empty name; what it cannot read said; the skin's mean colour of a vertex-coloured skin
within its sampling error of the exact area-weighted mean."""

import numpy as np
import pytest
from support import exact_mean
from support.two_faces import build_two_faces, new_material

COUNT = 1 << 12


@pytest.fixture
def faces(addon, blank_scene):
    """``(object, material, points)``: the two faces of the skin slot and their points."""
    from makeup_skin_addon import surface_points

    skin = new_material("Skin")
    obj = build_two_faces(skin, new_material("Other"))
    layer = obj.data.uv_layers[0]
    return obj, skin, surface_points.object_points(obj, skin, layer, COUNT)


def _by_hand(values, points, corner_index=None):
    """``values`` at the points: the weights times the values at the triangle's corners."""
    corners = points.corners if corner_index is None else corner_index[points.corners]
    return np.einsum("tn,tnc->nc", points.weights.astype(float), values[corners])


def test_vertex_corner_and_face_values_at_the_points(faces):
    from makeup_skin_addon import mesh_attributes, surface_points

    obj, _, points = faces
    mesh = obj.data
    rng = np.random.default_rng(3)
    per_vertex = rng.random((len(mesh.vertices), 4)).astype(np.float32)
    mesh.color_attributes.new("Paint", "FLOAT_COLOR", "POINT").data.foreach_set(
        "color", per_vertex.ravel())
    found = mesh_attributes.at_points(obj, "Paint", points)
    assert found.colour and found.problem == ""
    np.testing.assert_allclose(found.values, _by_hand(per_vertex, points,
                                                      surface_points.corner_verts(mesh)),
                               rtol=1e-6, atol=1e-7)
    # A byte colour per corner, read linear (as the node gives it).
    codes = rng.integers(0, 256, (len(mesh.loops), 4))
    corner = mesh.color_attributes.new("Corner", "BYTE_COLOR", "CORNER")
    corner.data.foreach_set("color_srgb", (codes / 255.0).astype(np.float32).ravel())
    linear = np.concatenate([exact_mean.srgb_to_linear(codes[:, :3] / 255.0),
                             codes[:, 3:] / 255.0], axis=1)
    found = mesh_attributes.at_points(obj, "Corner", points)
    np.testing.assert_allclose(found.values, _by_hand(linear, points), atol=2e-3)
    # A number per face: the point's face's, grey, alpha 1.
    mesh.attributes.new("Weight", "FLOAT", "FACE").data.foreach_set(
        "value", np.array([0.25, 0.75, 9.0], np.float32))
    found = mesh_attributes.at_points(obj, "Weight", points)
    assert not found.colour
    face = surface_points.corner_faces(mesh)[points.corners[0]]
    np.testing.assert_allclose(found.values[:, 0], np.where(face == 0, 0.25, 0.75))
    np.testing.assert_allclose(found.values[:, 1:], np.column_stack(
        [found.values[:, 0], found.values[:, 0], np.ones(len(face))]))
    assert set(face) == {0, 1}  # the other slot's face has no point


def test_the_render_colour_attribute_and_what_is_not_read(faces):
    from makeup_skin_addon import mesh_attributes

    obj, _, points = faces
    mesh = obj.data
    assert mesh_attributes.at_points(obj, "", points).problem == (
        "'Two Faces' has no attribute to render")
    assert mesh_attributes.at_points(obj, "Missing", points).problem == (
        "'Two Faces' has no attribute 'Missing'")
    for name, colour in (("First", (0.1, 0.2, 0.3, 1.0)), ("Second", (0.6, 0.5, 0.4, 1.0))):
        attribute = mesh.color_attributes.new(name, "FLOAT_COLOR", "POINT")
        attribute.data.foreach_set("color", np.tile(colour, len(mesh.vertices)))
    mesh.color_attributes.render_color_index = mesh.color_attributes.find("Second")
    np.testing.assert_allclose(mesh_attributes.at_points(obj, "", points).values,
                               np.tile((0.6, 0.5, 0.4, 1.0), (COUNT, 1)), rtol=1e-6)
    mesh.attributes.new("Crease", "FLOAT", "EDGE")
    assert mesh_attributes.at_points(obj, "Crease", points).problem == (
        "'Two Faces''s attribute 'Crease' is FLOAT on EDGE: not read")


def test_a_vertex_coloured_skin_is_read_as_it_renders(faces):
    """A Principled skin whose Base Color is a Color Attribute node (vertex colours): the
    skin's mean colour is the colours' area-weighted mean (exact: a triangle's mean of a
    linear interpolation is its corners' mean) within the points' sampling error; an
    Attribute node's Fac is the mean of the channels (as Cycles gives it), its Alpha the
    attribute's."""
    from makeup_skin_addon import skin_sampling, surface_values
    from makeup_skin_addon.artist_shader import source

    obj, skin, _ = faces
    mesh = obj.data
    rng = np.random.default_rng(5)
    per_vertex = np.concatenate([rng.random((len(mesh.vertices), 3)), np.full(
        (len(mesh.vertices), 1), 0.5)], axis=1).astype(np.float32)
    mesh.color_attributes.new("Skin", "FLOAT_COLOR", "POINT").data.foreach_set(
        "color", per_vertex.ravel())
    tree = skin.node_tree
    principled = next(n for n in tree.nodes if n.type == "BSDF_PRINCIPLED")
    colours = tree.nodes.new("ShaderNodeVertexColor")
    colours.layer_name = "Skin"
    tree.links.new(colours.outputs["Color"], principled.inputs["Base Color"])
    samples = skin_sampling.surface_samples(skin)
    notes = []
    mean = surface_values.mean(source(principled.inputs["Base Color"], ()), samples, notes)
    assert notes == []
    # The exact mean: each quad's two fan triangles by area, each its corners' mean.
    positions = np.array([v.co for v in mesh.vertices])
    exact, total = np.zeros(3), 0.0
    for polygon in mesh.polygons[:2]:
        corners = list(polygon.vertices)
        for second in range(1, len(corners) - 1):
            triangle = [corners[0], corners[second], corners[second + 1]]
            a, b, c = positions[triangle]
            area = 0.5 * np.linalg.norm(np.cross(b - a, c - a))
            exact += area * per_vertex[triangle, :3].mean(axis=0)
            total += area
    np.testing.assert_allclose(mean, exact / total, atol=5e-3)
    attribute = tree.nodes.new("ShaderNodeAttribute")
    attribute.attribute_name = "Skin"
    values, colour = samples.attribute("Skin")
    assert colour
    fac = np.average(values[:, :3].mean(axis=1), weights=samples.weights)
    for output, expected in (("Fac", fac), ("Alpha", 0.5)):
        socket = next(s for s in attribute.outputs if s.identifier == output)  # 5.0: "Factor"
        tree.links.new(socket, principled.inputs["Roughness"])
        assert surface_values.mean(source(principled.inputs["Roughness"], ()), samples, notes,
                                   "VALUE") == pytest.approx(expected, rel=1e-6)


def test_a_colour_attribute_that_is_not_finite_is_the_others_mean(faces):
    """A NaN vertex colour (a script's slip): the points it reaches take the mean of the
    others, and the note says how many (a value assumed: the first Apply warns)."""
    from makeup_skin_addon import skin_sampling, surface_values

    obj, skin, _ = faces
    mesh = obj.data
    colours = np.tile(np.float32([0.6, 0.4, 0.3, 1.0]), (len(mesh.vertices), 1))
    colours[0] = np.nan
    mesh.color_attributes.new("Skin", "FLOAT_COLOR", "POINT").data.foreach_set(
        "color", colours.ravel())
    samples = skin_sampling.surface_samples(skin)
    values, _ = samples.attribute("Skin", "Color Attribute")
    assert np.all(np.isfinite(values))
    np.testing.assert_allclose(values, np.tile([0.6, 0.4, 0.3, 1.0], (len(values), 1)),
                               rtol=1e-6)
    note = next(n for n in samples.notes if n.startswith("attribute 'Skin'"))
    assert note.endswith("points: taken as the mean of the others")
    assert surface_values.assumed(note)
