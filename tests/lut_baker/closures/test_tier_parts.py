"""The built-in tiers' parts of a fit (lut_baker.closures.tier_parts): each part the shape its
tier's image and shader read, over the artist's shader the bare skin's gloss left out, and
what they are fitted to computed once."""

import numpy as np
import pytest

from lut_baker.bake import bake
from lut_baker.closures import tier_parts
from lut_baker.closures.view_image import EEVEE_IMAGE_ROWS, IMAGE_ROWS
from lut_baker.model import presets

SIZE = 16


@pytest.fixture(scope="module")
def targets():
    return tier_parts.FitTargets(bake(presets.paper(), "preview"), SIZE)


def test_targets_are_computed_once(targets):
    assert targets.target("film_gloss") is targets.target("film_gloss")
    assert targets.grid("skin_gloss") is targets.target("path3_gloss")[0]
    assert targets.transmittance_rows().shape == (SIZE, 3)


def test_view_weighted_parts_hold_their_images(targets):
    """Each image has one row per name of its tier, of ``SIZE`` texels; over the artist's
    shader the bare skin's Glossy lobe is left out (rows 0, error 1)."""
    layered = tier_parts.layered_parts(targets, False)
    assert layered["view_rows"].shape == (len(IMAGE_ROWS), SIZE, 3)
    assert set(layered["glossy"]) == {"film_gloss", "path3_gloss", "skin_gloss"}
    eevee = tier_parts.eevee_parts(targets, True)
    assert eevee["eevee_view_rows"].shape == (len(EEVEE_IMAGE_ROWS), SIZE, 3)
    left_out = eevee["eevee_glossy"]["skin_gloss"]
    assert left_out.error == 1.0 and not np.any(left_out.weights)
    assert not np.any(eevee["eevee_view_rows"][EEVEE_IMAGE_ROWS.index("skin_gloss")])


def test_principled_parts_over_the_artists_shader(targets):
    """Over the artist's shader the bare specular has level 0 and the film's roughness (the
    group mixes the two roughnesses by coverage); the layering means are albedos."""
    over = tier_parts.principled_parts(targets, True)
    own = tier_parts.principled_parts(targets, False)
    assert over["specular_bare"].level == 0.0
    assert over["specular_bare"].roughness == over["specular_film"].roughness
    assert own["specular_bare"].level > 0.0
    for parts in (over, own):
        assert 0.0 < parts["coat_albedo_mean"] < 1.0
        assert all(0.0 <= mean < 1.0 for mean in parts["specular_albedo_mean"])
