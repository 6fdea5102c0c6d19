"""What Blender's colour and math nodes compute (makeup_skin_addon.node_maths): a blend at
factor 0 is its first input and Mix at 1 its second, HSV goes there and back, Math's division
by zero gives 0 as Blender's does, an operation it does not know gives None."""

import numpy as np
import pytest


@pytest.fixture
def node_maths(bpy_factory):
    """The module (importing the add-on imports bpy: the fixture marks the tests ``bpy``)."""
    from makeup_skin_addon import node_maths

    return node_maths


def test_blend_modes_at_their_ends(node_maths):
    rng = np.random.default_rng(3)
    a, b = rng.random((5, 3)), rng.random((5, 3)) + 0.1
    for mode in ("MIX", "ADD", "SUBTRACT", "MULTIPLY", "SCREEN", "DIVIDE", "DIFFERENCE",
                 "DARKEN", "LIGHTEN", "OVERLAY", "SOFT_LIGHT", "LINEAR_LIGHT"):
        np.testing.assert_allclose(node_maths.blend(mode, 0.0, a, b), a, rtol=1e-12,
                                   err_msg=mode)
    np.testing.assert_allclose(node_maths.blend("MIX", 1.0, a, b), b, rtol=1e-12)
    np.testing.assert_allclose(node_maths.blend("MULTIPLY", 1.0, a, b), a * b, rtol=1e-12)
    assert node_maths.blend("HUE", 0.5, a, b) is None


def test_hsv_there_and_back(node_maths):
    rgb = np.random.default_rng(4).random((50, 3))
    h, s, v = node_maths.rgb_to_hsv(rgb)
    assert np.all((h >= 0.0) & (h < 1.0)) and np.all((s >= 0.0) & (s <= 1.0))
    np.testing.assert_allclose(v, rgb.max(axis=1), rtol=1e-12)
    np.testing.assert_allclose(node_maths.hsv_to_rgb(h, s, v), rgb, atol=1e-12)


def test_math_operations(node_maths):
    a, b = np.array([1.0, -2.0, 3.0]), np.array([0.0, 4.0, 2.0])
    np.testing.assert_allclose(node_maths.math_node("DIVIDE", a, b, 0.0), [0.0, -0.5, 1.5])
    np.testing.assert_allclose(node_maths.math_node("POWER", a, b, 0.0), [1.0, 0.0, 9.0])
    np.testing.assert_allclose(node_maths.math_node("MULTIPLY_ADD", a, b, 1.0), [1.0, -7.0, 7.0])
    assert node_maths.math_node("ARCTAN2", a, b, 0.0) is None
