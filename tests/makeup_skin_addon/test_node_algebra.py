"""Shader-node arithmetic (makeup_skin_addon.node_algebra): which node each operation adds, the
operations whose result is known without a node, and numpy arrays on the left.  What the
emitted formulas compute is tests/makeup_skin_addon/test_node_mix.py (rendered by Cycles)."""

import numpy as np
import pytest


@pytest.fixture
def tree(bpy_factory):
    group = bpy_factory.data.node_groups.new("algebra test", "ShaderNodeTree")
    yield group
    bpy_factory.data.node_groups.remove(group)


def _values(tree):
    from makeup_skin_addon.node_algebra import Builder, NodeValue

    build = Builder(tree)
    value = build.node("ShaderNodeValue")
    rgb = build.node("ShaderNodeRGB")
    return build, NodeValue(build, value.outputs[0], False), NodeValue(build, rgb.outputs[0], True)


def test_scalars_make_math_nodes_and_colours_vector_math(tree):
    build, scalar, colour = _values(tree)
    product = scalar * 2.0
    assert product.socket.node.bl_idname == "ShaderNodeMath" and not product.colour
    assert product.socket.node.operation == "MULTIPLY"
    mixed = scalar + colour  # a scalar meeting a colour is linked into the vector input
    assert mixed.socket.node.bl_idname == "ShaderNodeVectorMath" and mixed.colour
    assert (1.0 - colour).socket.node.operation == "SUBTRACT"
    assert (scalar / colour).socket.node.operation == "DIVIDE"


def test_numpy_arrays_on_the_left_hand_the_operation_to_the_node_value(tree):
    build, scalar, colour = _values(tree)
    product = np.array([0.2, 0.3, 0.4]) * scalar
    assert type(product).__name__ == "NodeValue" and product.colour
    node = product.socket.node
    assert tuple(node.inputs[1].default_value) == pytest.approx((0.2, 0.3, 0.4))


def test_known_results_add_no_node(tree):
    build, scalar, colour = _values(tree)
    before = len(tree.nodes)
    assert scalar * 1.0 is scalar and scalar + 0.0 is scalar and colour / 1.0 is colour
    assert scalar * 0.0 == 0.0
    assert np.array_equal(colour * 0.0, np.zeros(3))
    assert len(tree.nodes) == before
    grey = scalar + np.zeros(3)  # a scalar plus a colour 0 is a colour: a node, not the scalar
    assert grey.colour and len(tree.nodes) == before + 1


def test_squares_only(tree):
    build, scalar, colour = _values(tree)
    assert (colour**2).socket.node.operation == "MULTIPLY"
    with pytest.raises(ValueError):
        scalar**3


def test_channel_functions(tree):
    from makeup_skin_addon.node_algebra import NodeAlgebra

    build, scalar, colour = _values(tree)
    algebra = NodeAlgebra(build)
    mean = algebra.channel_mean(colour)
    assert not mean.colour and mean.socket.node.operation == "DOT_PRODUCT"
    assert algebra.channel_mean(scalar) is scalar
    assert algebra.channel_max(np.array([0.1, 0.5, 0.2])) == 0.5
    assert algebra.maximum(0.2, np.array([0.1, 0.3, 0.0])).tolist() == [0.2, 0.3, 0.2]
    assert algebra.minimum(colour, 1.0).socket.node.operation == "MINIMUM"


def test_a_finished_build_lays_its_nodes_out_in_columns_of_ten(tree):
    """The nodes a build added, in the order it added them, ten to a column (the tree's
    nodes before it stay where they were)."""
    from makeup_skin_addon.node_algebra import Builder

    before = tree.nodes.new("ShaderNodeValue")
    before.location = (5.0, 7.0)
    build = Builder(tree)
    added = [build.node("ShaderNodeMath", operation="MULTIPLY") for _ in range(23)]
    build.finish()
    assert tuple(before.location) == (5.0, 7.0)
    for i, node in enumerate(added):
        assert tuple(node.location) == (200 * (i // 10) - 400, -160 * (i % 10))
        assert node.operation == "MULTIPLY"
