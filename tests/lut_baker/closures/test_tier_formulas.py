"""The tiers' formulas (lut_baker.closures.tier_formulas) with the numpy algebra: what they give
at the ends of coverage and Gloss, that they are vectorised over any inputs, and that the two
ways of carrying the skin seen through the film give the same product.  The node algebra's
side is tests/makeup_skin_addon/test_node_mix.py (Cycles against these formulas)."""

import numpy as np
import pytest

from lut_baker.closures import tier_formulas as tf
from lut_baker.closures import view_image


def _algebra(fit, cos_view):
    return tf.NumpyAlgebra(dict(zip(view_image.IMAGE_ROWS, fit.view_rows, strict=True)), cos_view)


def test_bare_skin_is_the_skins_own_principled_lobe(paper_fit):
    skin = np.array([0.6, 0.4, 0.3])
    x = tf.TierInputs.numpy(0.0, (0.5, 0.2, 0.1), skin, 1.0)
    sockets = tf.principled_sockets(paper_fit, x, tf.NumpyAlgebra())
    assert sockets["Coat Weight"].item() == 0.0
    assert sockets["Roughness"].item() == paper_fit.specular_bare.roughness
    assert sockets["Specular IOR Level"].item() == paper_fit.specular_bare.level
    # The base colour carries what the bare specular errs under uniform light (a white lobe).
    assert np.ptp(paper_fit.bare_to_diffuse) < 1e-12
    np.testing.assert_allclose(sockets["Base Color"],
                               (skin + paper_fit.bare_to_diffuse)
                               / (1.0 - paper_fit.specular_albedo_mean[0]), rtol=1e-12)
    assert sockets["Subsurface Weight"].item() == pytest.approx(1.0)  # all of it is the skin's


def test_gloss_zero_leaves_the_diffuse_albedo_unattenuated(paper_fit):
    x = tf.TierInputs.numpy(0.7, (0.3, 0.1, 0.6), (0.5, 0.5, 0.4), 0.0)
    sockets = tf.principled_sockets(paper_fit, x, tf.NumpyAlgebra())
    assert sockets["Coat Weight"].item() == 0.0 and sockets["Specular IOR Level"].item() == 0.0
    once = 1.0 - np.array([0.3, 0.1, 0.6])
    skin = np.array([0.5, 0.5, 0.4])
    total = 0.3 * skin + 0.7 * (once * paper_fit.film_albedo
                                + once**2 * skin * paper_fit.transmittance_mean**2)
    np.testing.assert_allclose(sockets["Base Color"], total, rtol=1e-12)


def test_the_formulas_are_vectorised_over_every_input(paper_fit):
    rng = np.random.default_rng(11)
    n = 6
    coverage, gloss = rng.uniform(size=n), rng.uniform(size=n)
    absorption, skin = rng.uniform(size=(n, 3)), rng.uniform(0.1, 0.9, (n, 3))
    cos_view = rng.uniform(0.05, 1.0, n)
    batch = tf.TierInputs.numpy(coverage, absorption, skin, gloss)
    principled = tf.principled_sockets(paper_fit, batch, tf.NumpyAlgebra())
    layered = tf.view_weighted_closures(paper_fit, batch, _algebra(paper_fit, cos_view))
    for i in range(n):
        one = tf.TierInputs.numpy(coverage[i], absorption[i], skin[i], gloss[i])
        single = tf.principled_sockets(paper_fit, one, tf.NumpyAlgebra())
        for name, value in single.items():
            np.testing.assert_allclose(np.ravel(np.broadcast_to(
                principled[name], (n, np.size(value)))[i]), np.ravel(value), rtol=1e-12)
        closures = tf.view_weighted_closures(paper_fit, one, _algebra(paper_fit, cos_view[i]))
        for many, alone in zip(layered.covered + layered.bare, closures.covered + closures.bare,
                               strict=True):
            np.testing.assert_allclose(np.broadcast_to(many.colour, (n, 3))[i],
                                       np.ravel(alone.colour), rtol=1e-12)


def test_tinted_and_plain_subsurface_carry_the_same_light(paper_fit):
    """The skin seen through the film as a bright tinted colour with its strongest channel as
    the closure's weight (Cycles' random walk), or as the product itself: the same product."""
    x = tf.TierInputs.numpy(0.6, (0.2, 0.5, 0.7), (0.7, 0.45, 0.35), 1.0)
    cos_view = np.linspace(0.02, 1.0, 12)
    tinted = tf.view_weighted_closures(paper_fit, x, _algebra(paper_fit, cos_view))
    plain = tf.view_weighted_closures(paper_fit, x, _algebra(paper_fit, cos_view),
                                      tinted_subsurface=False)
    through_tinted, through_plain = tinted.covered[-1], plain.covered[-1]
    assert through_plain.weight is None
    np.testing.assert_allclose(through_tinted.colour * through_tinted.weight,
                               through_plain.colour, rtol=1e-12)
    assert np.all(np.max(through_tinted.colour / np.array([0.7, 0.45, 0.35]), axis=-1)
                  == pytest.approx(1.0))  # the strongest channel keeps the skin's colour


def test_one_shared_subsurface_carries_what_two_did(paper_fit):
    """The EEVEE tier's one Subsurface closure outside the coverage mix: its colour is the
    areal mix of the two it replaces, and nothing else moves."""
    x = tf.TierInputs.numpy(0.6, (0.2, 0.5, 0.7), (0.7, 0.45, 0.35), 1.0)
    algebra = _algebra(paper_fit, np.linspace(0.02, 1.0, 12))
    two = tf.view_weighted_closures(paper_fit, x, algebra, tinted_subsurface=False)
    one = tf.view_weighted_closures(paper_fit, x, algebra, tinted_subsurface=False,
                                    one_subsurface=True)
    kinds = [c.kind for c in one.covered + one.bare + one.shared]
    assert kinds.count("subsurface") == 1 and [c.kind for c in one.shared] == ["subsurface"]
    for mine, theirs in zip(one.covered + one.bare, two.covered[:-1] + two.bare[:-1],
                            strict=True):
        assert mine.name == theirs.name
        np.testing.assert_array_equal(mine.colour, theirs.colour)
    np.testing.assert_allclose(one.shared[0].colour,
                               0.6 * two.covered[-1].colour + 0.4 * two.bare[-1].colour,
                               rtol=1e-12)


def test_plain_numbers_are_inputs_too(paper_fit):
    """Python floats need no algebra of their own: the formulas are plain arithmetic."""
    x = tf.TierInputs(coverage=0.5, absorption=np.array([0.1, 0.2, 0.3]),
                      skin_color=np.array([0.6, 0.5, 0.4]), gloss=0.8)
    sockets = tf.principled_sockets(paper_fit, x, tf.NumpyAlgebra())
    batch = tf.principled_sockets(paper_fit, tf.TierInputs.numpy(0.5, (0.1, 0.2, 0.3),
                                                                 (0.6, 0.5, 0.4), 0.8),
                                  tf.NumpyAlgebra())
    for name in sockets:
        np.testing.assert_allclose(np.ravel(sockets[name]), np.ravel(batch[name]), rtol=1e-12)
