"""The group for a bake (makeup_skin_addon.groups): an Apply that repeats one finds its group
and bakes, fits and hashes nothing; Tier Auto makes the same choice."""

import pytest
from support.addon_steps import apply_pipeline


def _count_calls(monkeypatch):
    """Count the bakes, closure fits and content hashes from here on."""
    from lut_baker import bake
    from lut_baker.closures import fitting
    from lut_baker.tables import codec

    calls = []
    for module, name in ((bake, "bake"), (fitting, "fit_closures"), (codec, "content_hash")):
        original = getattr(module, name)
        monkeypatch.setattr(module, name, lambda *a, _n=name, _f=original, **k: (
            calls.append(_n), _f(*a, **k))[1])
    return calls


@pytest.mark.parametrize("tier", ["LAYERED", "AUTO"])
def test_apply_again_with_the_same_settings_bakes_and_fits_nothing(sphere, monkeypatch, tier):
    """The settings name their bake (a hash of the parameters, not of the tables): an Apply
    that repeats one finds its group and bakes, fits and hashes nothing, and Tier Auto makes
    the same choice."""
    import bpy

    from makeup_skin_addon import groups

    material, _ = apply_pipeline(sphere, tier, foundation="clarins_105")
    group = groups.group_of(material).node_tree
    calls = _count_calls(monkeypatch)
    again, _ = apply_pipeline(sphere, tier, foundation="clarins_105")
    assert calls == [] and groups.group_of(again).node_tree == group
    assert bpy.data.node_groups.get(group.name) == group
