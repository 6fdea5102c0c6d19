"""The tables' codec (lut_baker.tables.codec): the atlas's blocks."""

import pytest

from lut_baker import bake
from lut_baker.model import presets
from lut_baker.tables import codec


@pytest.fixture(scope="module")
def baked():
    skin = presets.made_up_skin("medium_beige", "jensen_skin1", coverage=0.7)
    return bake.bake(skin, "preview", inter_reflection=True)


def test_atlas_of_plain_tables_has_no_inter_reflection_block(baked):
    from dataclasses import replace

    _, layout = codec.atlas(replace(baked, inter_reflection=None))
    assert "inter_reflection" not in layout["blocks"]
