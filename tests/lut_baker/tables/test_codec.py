"""The tables' codec (lut_baker.tables.codec): the atlas's blocks, the slab's among them."""

from dataclasses import replace

import numpy as np
import pytest

from lut_baker import bake
from lut_baker.model import presets
from lut_baker.tables import codec


@pytest.fixture(scope="module")
def baked():
    skin = presets.made_up_skin("medium_beige", "jensen_skin1", coverage=0.7)
    return bake.bake(skin, "preview", inter_reflection=True)


def test_atlas_of_plain_tables_has_no_inter_reflection_block(baked):
    _, layout = codec.atlas(replace(baked, inter_reflection=None))
    assert "inter_reflection" not in layout["blocks"]


@pytest.fixture(scope="module")
def slab_baked():
    from lut_baker.model import film_slab

    skin = presets.made_up_skin("paper_natural", "jensen_skin1", absorption=[0.1, 0.3, 0.5])
    return bake.bake(skin, "preview", film=film_slab.DEFAULT_THICKNESS_UM)


def test_the_slab_goes_through_the_atlas(slab_baked):
    """The slab's blocks sit above the paper's, which keep their rows (a paper file's atlas and
    hash do not change); every slab table comes back as its float32 value, its thickness axis
    (ending in inf) from its closed form."""
    pixels, layout = codec.atlas(slab_baked)
    plain, plain_layout = codec.atlas(replace(slab_baked, slab=None))
    assert {k: v for k, v in layout["blocks"].items() if not k.startswith("slab_")} \
        == plain_layout["blocks"]
    np.testing.assert_array_equal(pixels[:plain.shape[0], :plain.shape[1]], plain)
    meta = codec.sidecar_data(slab_baked, layout, codec.pixel_hash(pixels), "s.exr")
    codec.check_layout(meta, "s.json")
    loaded = codec.tables_from_atlas(pixels, meta).slab
    slab = slab_baked.slab
    np.testing.assert_array_equal(loaded.thickness_um, slab.thickness_um)
    for name in codec.SLAB_ANGULAR + codec.SLAB_DIRECTIONAL + codec.SLAB_PER_THICKNESS:
        np.testing.assert_array_equal(getattr(loaded, name),
                                      np.asarray(getattr(slab, name), np.float32), err_msg=name)
    for name in ("theta_deg", "phi_deg", "absorption", "surface_share", "theta_spacing",
                 "theta_offset", "phi_spacing"):
        np.testing.assert_array_equal(getattr(loaded, name), getattr(slab, name))
    assert codec.content_hash(codec.tables_from_atlas(pixels, meta)) \
        == codec.content_hash(slab_baked)


def test_a_sidecar_whose_slab_grid_disagrees_is_refused(slab_baked):
    pixels, layout = codec.atlas(slab_baked)
    meta = codec.sidecar_data(slab_baked, layout, codec.pixel_hash(pixels), "s.exr")
    meta["slab"] = {**meta["slab"], "thickness_nodes": meta["slab"]["thickness_nodes"] + 1}
    with pytest.raises(codec.TableFileError, match="layout does not match"):
        codec.check_layout(meta, "s.json")


def test_the_slab_at_one_thickness_is_not_written(slab_baked):
    """A preview's slab at one thickness has no axis the sidecar could describe: refused."""
    from lut_baker.model import film_slab

    one = replace(slab_baked, slab=bake.bake_slab(
        presets.made_up_skin("paper_natural", "jensen_skin1", absorption=[0.1, 0.3, 0.5]),
        "preview", only_um=film_slab.DEFAULT_THICKNESS_UM))
    pixels, layout = codec.atlas(one)
    with pytest.raises(ValueError, match="one thickness"):
        codec.sidecar_data(one, layout, codec.pixel_hash(pixels), "s.exr")
