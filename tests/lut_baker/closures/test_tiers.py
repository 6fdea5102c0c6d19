"""The tiers' replicas and errors (lut_baker.closures.tiers) on the paper's tables: what they
keep, how they follow coverage and Gloss, and that they take any directions."""


import numpy as np
import pytest

from lut_baker.closures import tier_formulas, tiers, view_image
from lut_baker.numerics.geometry import direction


def test_layered_tier_keeps_the_albedo(paper_tables, paper_fit):
    # Glossy weights are albedo ratios, so the tier's view albedo follows the tables'.
    for coverage in (0.0, 0.5, 1.0):
        errors = tiers.tier_errors(paper_fit, paper_tables, coverage, (0.1, 0.2, 0.4))
        assert errors["LAYERED"].albedo < 0.03
        assert errors["LAYERED"].rms < 0.12
        assert np.isfinite(errors["PRINCIPLED"].rms)

def test_layered_beats_principled_on_bare_skin(paper_tables, paper_fit):
    errors = tiers.tier_errors(paper_fit, paper_tables, 0.0, 0.0)
    assert errors["LAYERED"].rms < errors["PRINCIPLED"].rms

def test_principled_inputs_follow_coverage(paper_fit):
    bare, weight_bare = tiers.principled_inputs(paper_fit, 0.0, 0.0)
    full, weight_full = tiers.principled_inputs(paper_fit, 1.0, (0.3, 0.3, 0.3))
    assert bare.coat_weight == 0.0 and full.coat_weight == 1.0
    assert weight_bare == pytest.approx(1.0)  # bare skin: all diffuse light is the skin's
    assert 0.0 < weight_full < 1.0
    # Absorption darkens the film's diffuse light: the base colour drops.
    darker, _ = tiers.principled_inputs(paper_fit, 1.0, (0.6, 0.6, 0.6))
    assert np.all(np.array(darker.base_color) < np.array(full.base_color))

def test_principled_error_does_not_peak_between_coverages(paper_tables, paper_fit):
    # The node group mixes roughness and level by coverage: a half-covered surface must not
    # err much more than the worse of bare and fully covered skin.
    ends = [tiers.tier_errors(paper_fit, paper_tables, w, 0.0)["PRINCIPLED"].rms
            for w in (0.0, 1.0)]
    for coverage in (0.25, 0.5, 0.75):
        middle = tiers.tier_errors(paper_fit, paper_tables, coverage, 0.0)["PRINCIPLED"]
        assert middle.rms < 1.2 * max(ends)

def test_gloss_zero_leaves_only_the_diffuse_closures(paper_tables, paper_fit):
    """The group's Gloss input at 0: the Principled tier has coat weight 0 and specular level
    0 (eta 1: Cycles allocates neither closure) and its base colour is the diffuse albedo
    itself; the Layered tier's Glossy weights are 0 and it is linear in Gloss.  Without its
    gloss, each tier misses the tables' gloss."""
    w, a = 0.5, (0.1, 0.2, 0.4)
    inputs, weight = tiers.principled_inputs(paper_fit, w, a, gloss=0.0)
    once = 1.0 - np.array(a)  # the diffuse albedo, docs/model.md §4: film once, skin twice
    skin = (1 - w) * paper_fit.skin_albedo + w * once**2 * paper_fit.skin_albedo \
        * paper_fit.transmittance_mean**2
    total = skin + w * once * paper_fit.film_albedo
    assert inputs.coat_weight == 0.0 and inputs.specular_ior_level == 0.0
    assert inputs.specular_eta_f0()[0] == 1.0
    np.testing.assert_allclose(inputs.base_color, np.clip(total, 0.0, 1.0), rtol=1e-12)
    assert weight == pytest.approx(float(np.mean(skin / total)))
    matte = tiers.tier_replica(paper_fit, paper_tables, "PRINCIPLED", w, a, gloss=0.0)
    np.testing.assert_allclose(matte, np.broadcast_to(np.clip(total, 0, 1) / np.pi,
                                                      matte.shape), rtol=1e-12)
    algebra = tier_formulas.NumpyAlgebra(dict(zip(view_image.IMAGE_ROWS, paper_fit.view_rows,
                                                  strict=True)),
                                         np.linspace(0.0, 1.0, 9))
    closures = tier_formulas.view_weighted_closures(
        paper_fit, tier_formulas.TierInputs.numpy(w, a, paper_fit.skin_albedo, 0.0), algebra)
    glossy = [c for c in closures.covered + closures.bare if c.kind == "glossy"]
    assert len(glossy) == 3 and not any(np.any(c.colour) for c in glossy)
    layered = {g: tiers.tier_replica(paper_fit, paper_tables, "LAYERED", w, a, gloss=g)
               for g in (0.0, 0.5, 1.0)}
    np.testing.assert_allclose(layered[0.5], 0.5 * (layered[0.0] + layered[1.0]), rtol=1e-9)
    kept = tiers.tier_errors(paper_fit, paper_tables, w, a)
    dropped = tiers.tier_errors(paper_fit, paper_tables, w, a, gloss=0.0)
    for tier in tiers.TIERS:
        assert dropped[tier].rms > 2.0 * kept[tier].rms

def _replica(tier):
    """Tier ``tier``'s replica, ``(fit, tables, coverage, absorption, gloss, directions)``."""
    return lambda fit, tables, *rest: tiers.tier_replica(fit, tables, tier, *rest)


def test_replicas_take_any_directions(paper_tables, paper_fit):
    """At the tables' own nodes passed explicitly, each replica gives its default values; on
    an (n, m) batch of directions it keeps the batch's shape; a NaN light direction touches
    no other value (its own is NaN for the Principled tier; the Layered tier's Glossy lobes
    count it as below the horizon and its diffuse part does not depend on it)."""
    nodes = paper_tables.node_directions()
    wi = direction(np.radians([[10.0, 40.0, 70.0], [0.0, 85.0, 30.0]]), 1.0)
    wo = direction(np.radians([[60.0, 5.0, 20.0], [45.0, 10.0, 89.0]]), 0.0)
    wi_nan = wi.copy()
    wi_nan[0, 0] = np.nan
    for tier in tiers.TIERS:
        replica = _replica(tier)
        np.testing.assert_array_equal(replica(paper_fit, paper_tables, 1.0, 0.0, 1.0, nodes),
                                      replica(paper_fit, paper_tables, 1.0, 0.0), err_msg=tier)
        batch = replica(paper_fit, paper_tables, 1.0, 0.0, 1.0, (wi, wo))
        assert batch.shape == (2, 3, 3) and np.all(np.isfinite(batch)) and batch.min() >= 0
        with np.errstate(invalid="ignore"):
            poisoned = replica(paper_fit, paper_tables, 1.0, 0.0, 1.0, (wi_nan, wo))
        assert not np.isinf(poisoned[0, 0]).any(), tier
        np.testing.assert_allclose(poisoned[1], batch[1], rtol=1e-12, err_msg=tier)
        np.testing.assert_allclose(poisoned[0, 1:], batch[0, 1:], rtol=1e-12, err_msg=tier)


def test_replicas_share_the_rows_they_read(paper_tables, paper_fit):
    """A tier's replicas at the same directions and other inputs may share the rows read
    there (``read``): filled by the first, read-only, and every replica the same as alone
    (the same arrays: bit for bit)."""
    wi = direction(np.radians(np.linspace(0.0, 80.0, 12)), 0.5)
    wo = direction(np.radians(np.linspace(70.0, 5.0, 12)), 0.0)
    for tier in tiers.TIERS:
        read: dict = {}
        for gloss, coverage in ((1.0, 1.0), (0.0, 1.0), (0.5, 0.3)):
            alone = tiers.tier_replica(paper_fit, paper_tables, tier, coverage, 0.2, gloss,
                                       (wi, wo))
            shared = tiers.tier_replica(paper_fit, paper_tables, tier, coverage, 0.2, gloss,
                                        (wi, wo), read=read)
            np.testing.assert_array_equal(shared, alone, err_msg=tier)
        assert all(not row.flags.writeable for row in read.values()), tier
        assert read or tier != "LAYERED"  # the Layered tier reads its view-angle image


def test_over_the_artists_shader_the_bare_skin_is_the_tables(paper_tables, paper_fit):
    """Over the artist's shader a tier's BRDF is its covered skin mixed by coverage with the
    tables' bare skin (the artist's shader stands there): at coverage 0 it is that bare skin,
    at 1 the tier's own, and its errors are measured so (some tiers at a time)."""
    wi, wo = paper_tables.node_directions()
    bare = paper_tables.made_up_reflection(wi, wo, 0.0, 0.3)
    for tier in tiers.TIERS:
        at_zero = tiers.tier_reflection(paper_fit, paper_tables, tier, 0.0, 0.3,
                                        over_shader=True)
        np.testing.assert_allclose(at_zero, bare, rtol=1e-12, atol=1e-15)
        at_one = tiers.tier_reflection(paper_fit, paper_tables, tier, 1.0, 0.3,
                                       over_shader=True)
        np.testing.assert_allclose(at_one, _replica(tier)(paper_fit, paper_tables,
                                                                     1.0, 0.3), rtol=1e-12)
    over = tiers.tier_errors(paper_fit, paper_tables, 0.5, 0.3, tiers=("LAYERED",),
                             over_shader=True)
    whole = tiers.tier_errors(paper_fit, paper_tables, 0.5, 0.3, tiers=("LAYERED",))
    assert set(over) == {"LAYERED"} and over["LAYERED"].rms < whole["LAYERED"].rms
