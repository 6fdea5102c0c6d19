"""The session's bakes and fits by key, and what a fit measured (makeup_skin_addon.bakes),
without Blender state: a bake record is baked and fitted once, a measurement is found again
only at its own coverage and absorption, and its traits read back as they were."""

import numpy as np
import pytest

from lut_baker.model import presets


@pytest.fixture
def record(bpy_factory):
    """A bake record: importing the add-on imports bpy, which only the fixture may import
    first (and the fixture marks the tests ``bpy``, so that ``-m "not bpy"`` leaves them
    out)."""
    from makeup_skin_addon import bakes

    return bakes.bake_record(presets.made_up_skin("light_ivory", "jensen_skin1"), "preview")


def test_a_record_is_baked_and_fitted_once(record, monkeypatch):
    from lut_baker.closures import fitting
    from makeup_skin_addon import bakes

    bakes.clear()
    calls = []
    original = fitting.fit_closures
    monkeypatch.setattr(fitting, "fit_closures",
                        lambda *a, **k: (calls.append(1), original(*a, **k))[1])
    assert bakes.cached(record) is None
    tables, fit = bakes.baked(record)
    again = bakes.baked(record)
    assert again[0] is tables and again[1] is fit and len(calls) == 1
    assert bakes.cached(record)[1] is fit
    assert bakes.cached(record, "RANDOM_WALK") is None  # a forced method is another fit


def test_only_a_preview_record_is_fitted_as_a_preview(record, monkeypatch):
    """The preview's shortcuts (lut_baker.closures.fitting.fit_closures's ``preview``) are
    taken for a record at preview resolution only, never at the settings' resolution."""
    from lut_baker.closures import fitting
    from makeup_skin_addon import bakes

    bakes.clear()
    tables = bakes.rebake(record)
    asked = {}
    original = fitting.fit_closures

    def spy(*args, **kwargs):
        asked[kwargs["preview"]] = asked.get(kwargs["preview"], 0) + 1
        return original(*args, **kwargs)

    monkeypatch.setattr(fitting, "fit_closures", spy)
    monkeypatch.setattr(bakes, "rebake", lambda *args, **kwargs: tables)  # no bake at default
    skin = presets.made_up_skin("light_ivory", "jensen_skin1")
    for resolution in ("preview", "default", "high"):
        bakes.baked(bakes.bake_record(skin, resolution), tiers=("LAYERED",))
    assert asked == {True: 1, False: 2}
    bakes.clear()


def test_a_measurement_is_found_at_its_own_coverage_and_absorption(record):
    from makeup_skin_addon import bakes

    tables, fit = bakes.baked(record)
    measured = bakes.measure(tables, fit, 0.6, (0.1, 0.2, 0.3))
    meta = {"measured": measured}
    assert bakes.measured_at(meta, 0.6, (0.1, 0.2, 0.3)) is measured
    assert bakes.measured_at(meta, 0.6 + 1e-9, (0.1, 0.2, 0.3)) is measured
    assert bakes.measured_at(meta, 0.7, (0.1, 0.2, 0.3)) is None
    assert bakes.measured_at(meta, 0.6, (0.1, 0.2, 0.4)) is None
    assert bakes.measured_at({}, 0.6, (0.1, 0.2, 0.3)) is None
    assert set(measured["errors"]) == {"PRINCIPLED", "LAYERED", "EEVEE"}
    # An older add-on's measurement, without the EEVEE tier, is taken again.
    older = {**measured, "errors": {tier: e for tier, e in measured["errors"].items()
                                    if tier != "EEVEE"}}
    assert bakes.measured_at({"measured": older}, 0.6, (0.1, 0.2, 0.3)) is None
    # Without traits a measurement does not serve the Auto tier.
    bare = bakes.measure(tables, fit, 0.6, (0.1, 0.2, 0.3), with_traits=False)
    assert bare["traits"] is None
    assert bakes.measured_at({"measured": bare}, 0.6, (0.1, 0.2, 0.3), with_traits=True) is None
    assert bare["errors"] == measured["errors"]


def test_traits_read_back_as_they_were(record):
    import json

    from lut_baker import auto_tier
    from makeup_skin_addon import bakes

    tables, fit = bakes.baked(record)
    measured = json.loads(json.dumps(bakes.measure(tables, fit, 1.0, (0.0, 0.0, 0.0))))
    traits = bakes.traits(measured)
    direct = auto_tier.traits_from_tables(tables, fit, 1.0, (0.0, 0.0, 0.0))
    assert traits.tier_errors == pytest.approx(direct.tier_errors, rel=1e-12)
    np.testing.assert_array_equal(traits.profile, direct.profile)
    assert traits.skin_share == direct.skin_share and traits.gloss_share == direct.gloss_share
    assert traits.gloss_omission == direct.gloss_omission
    assert bakes.traits({"traits": {"tier_errors": {}}}) is None


def test_the_tiers_asked_for_are_fitted_and_others_when_asked(record, monkeypatch):
    """A fit asked for the Cycles tiers holds those alone; asking for the EEVEE tier later
    fits it onto the cached fit (nothing fitted again); a fit over the artist's shader is
    another fit.  A measurement serves only if it holds the tiers asked for."""
    from lut_baker.closures import fitting
    from makeup_skin_addon import bakes

    bakes.clear()
    calls = []
    original = fitting.fit_closures
    monkeypatch.setattr(fitting, "fit_closures", lambda *a, **k: (
        calls.append((k["tiers"], k["onto"] is not None, k["over_shader"])),
        original(*a, **k))[1])
    cycles = ("PRINCIPLED", "LAYERED")
    tables, fit = bakes.baked(record, tiers=cycles)
    assert fit.tiers == cycles and calls == [(cycles, False, False)]
    assert bakes.cached(record, tiers=cycles)[1] is fit
    assert bakes.cached(record, tiers=("EEVEE",)) is None  # cached() never fits
    _, every = bakes.baked(record, tiers=("EEVEE",))
    assert every.tiers == ("PRINCIPLED", "LAYERED", "EEVEE") and every.glossy is fit.glossy
    assert calls[-1] == (("EEVEE",), True, False)
    assert bakes.baked(record, tiers=cycles)[1] is every and len(calls) == 2
    _, over = bakes.baked(record, tiers=cycles, over_shader=True)
    assert calls[-1] == (cycles, False, True) and over is not every
    measured = bakes.measure(tables, fit, 0.6, (0.1, 0.2, 0.3))
    assert set(measured["errors"]) == set(cycles)
    meta = {"measured": measured}
    assert bakes.measured_at(meta, 0.6, (0.1, 0.2, 0.3), tiers=cycles) is measured
    assert bakes.measured_at(meta, 0.6, (0.1, 0.2, 0.3), tiers=("EEVEE",)) is None
    assert bakes.measured_at(meta, 0.6, (0.1, 0.2, 0.3), with_traits=True,
                            tiers=("LAYERED",)) is measured


def test_a_slab_fit_is_made_on_the_records_skin(bpy_factory, monkeypatch):
    """The film at a thickness: the skin the film covers (``skin_albedo``) is in the record's
    key (another colour is another fit, the same colour reuses it; the paper's film ignores
    it), every skin shares the slab's tables, and each fit's Skin Color is its record's; a
    fit at another thickness on the same skin moves from it (no fit)."""
    from lut_baker.closures import fitting
    from makeup_skin_addon import bakes

    bakes.clear()
    skin = presets.made_up_skin("light_ivory", "jensen_skin1", absorption=[0.2, 0.4, 0.6])
    tan, pale = [0.55, 0.27, 0.16], [0.7, 0.55, 0.45]
    records = [bakes.bake_record(skin, "preview", 9.6, None, albedo) for albedo in (tan, pale)]
    assert records[0]["key"] != records[1]["key"] and records[0]["skin_albedo"] == tan
    assert bakes.bake_record(skin, "preview", 9.6, None, list(tan))["key"] == records[0]["key"]
    assert bakes.record_key(records[0]) == records[0]["key"]
    paper = bakes.bake_record(skin, "preview", "paper", None, tan)
    assert "skin_albedo" not in paper and paper == bakes.bake_record(skin, "preview")
    fits = [bakes.baked(record, tiers=("PRINCIPLED",)) for record in records]
    assert fits[0][0].slab is fits[1][0].slab  # one bake of the slab
    for (_, fit), albedo in zip(fits, (tan, pale), strict=True):
        np.testing.assert_array_equal(fit.skin_albedo, albedo)
    calls = []
    original = fitting.fit_closures
    monkeypatch.setattr(fitting, "fit_closures",
                        lambda *a, **k: (calls.append(1), original(*a, **k))[1])
    moved = bakes.baked(bakes.bake_record(skin, "preview", 30.0, None, tan),
                        tiers=("PRINCIPLED",))[1]
    assert calls == [] and moved.slab.thickness_um == 30.0
    np.testing.assert_array_equal(moved.skin_albedo, tan)
    bakes.clear()


def test_a_previews_slab_at_one_thickness_is_kept_apart(bpy_factory, monkeypatch):
    """``one_thickness`` (an Apply at preview first): the slab is baked at the record's
    thickness only, kept apart from the axis's: the record's tables of the axis are baked when
    asked for (and shared with other thicknesses), the fit made on the one thickness is the
    record's either way (no fit again), and a fit at another thickness on the same skin moves
    on the axis's tables (baked then), as without the preview."""
    from lut_baker.closures import fitting
    from makeup_skin_addon import bakes

    bakes.clear()
    skin = presets.made_up_skin("light_ivory", "jensen_skin1", absorption=[0.2, 0.4, 0.6])
    tan = [0.55, 0.27, 0.16]
    record = bakes.bake_record(skin, "preview", 9.6, None, tan)
    one, fit = bakes.baked(record, tiers=("PRINCIPLED",), one_thickness=True)
    assert one.slab.one_thickness and one.slab.thickness_um.tolist() == [9.6]
    assert bakes.rebake(record, one_thickness=True) is one
    assert bakes.cached(record, tiers=("PRINCIPLED",)) == (one, fit)
    with pytest.raises(ValueError, match="only"):
        one.slab.sliced(30.0)
    calls = []
    original = fitting.fit_closures
    monkeypatch.setattr(fitting, "fit_closures",
                        lambda *a, **k: (calls.append(1), original(*a, **k))[1])
    series = bakes.rebake(record)
    assert series is not one and series.slab.thickness_um.size > 2
    assert bakes.baked(record, tiers=("PRINCIPLED",)) == (series, fit)
    assert bakes.rebake(record, one_thickness=True) is series  # the axis's will do
    other = bakes.bake_record(skin, "preview", 30.0, None, tan)
    tables, moved = bakes.baked(other, tiers=("PRINCIPLED",), one_thickness=True)
    assert tables.slab is series.slab and not tables.slab.one_thickness
    assert calls == [] and moved.slab.thickness_um == 30.0
    bakes.clear()
    monkeypatch.undo()
    bakes.baked(record, tiers=("PRINCIPLED",), one_thickness=True)  # a fit at 9.6 on `one`
    tables, moved = bakes.baked(other, tiers=("PRINCIPLED",), one_thickness=True)
    assert not tables.slab.one_thickness and moved.slab.thickness_um == 30.0
    bakes.clear()


def test_a_preview_measures_the_auto_tiers_spheres_smaller(record, monkeypatch):
    """At preview resolution the Auto tier's spheres are PREVIEW_SPHERE_PX across, at any
    other the traits' own size: the shares and gloss omissions within 2% of each other (the
    preview's are refined later at the settings' resolution), the tiers' errors the same."""
    from lut_baker import auto_tier
    from makeup_skin_addon import bakes

    sizes = []
    original = auto_tier.traits_from_tables
    monkeypatch.setattr(auto_tier, "traits_from_tables",
                        lambda *a, **k: (sizes.append(k["sphere_px"]), original(*a, **k))[1])
    tables, fit = bakes.baked(record)
    preview = bakes.measure(tables, fit, 0.6, (0.1, 0.2, 0.3), resolution="preview")
    full = bakes.measure(tables, fit, 0.6, (0.1, 0.2, 0.3), resolution="default")
    assert sizes == [bakes.PREVIEW_SPHERE_PX, auto_tier.SPHERE_PX]
    assert bakes.PREVIEW_SPHERE_PX < auto_tier.SPHERE_PX
    assert preview["errors"] == full["errors"]
    small, large = preview["traits"], full["traits"]
    for name in ("gloss_share", "skin_share"):
        for light, value in large[name].items():
            assert small[name][light] == pytest.approx(value, rel=0.02), (name, light)
    for tier, by_light in large["gloss_omission"].items():
        for light, value in by_light.items():
            assert small["gloss_omission"][tier][light] == pytest.approx(value, rel=0.02)
