"""The measure of baked tables against the exact evaluator
(lut_baker.offline.validation.table_accuracy): what it samples, and that it reports exactly the
difference it is shown."""

import dataclasses

import numpy as np
import pytest

from lut_baker import bake
from lut_baker.model import presets
from lut_baker.numerics.geometry import polar_angle_deg
from lut_baker.offline.validation import table_accuracy


def test_sample_directions_put_two_fifths_on_the_grazing_rows():
    wi, wo = table_accuracy.sample_directions(500, np.random.default_rng(0), 89.0)
    theta_i, theta_o = polar_angle_deg(wi), polar_angle_deg(wo)
    assert theta_i.max() <= 89.0 + 1e-9 and theta_o.max() <= 89.0 + 1e-9
    assert np.all(theta_i[300:] >= 80.0) and np.all(theta_o[400:] >= 80.0)
    assert np.mean(theta_i[:300] >= 80.0) < 0.3  # the rest spread over the whole range


@pytest.fixture(scope="module")
def tables_and_samples():
    skin = presets.made_up_skin("medium_beige", "jensen_skin1", coverage=0.7)
    tables = bake.bake(skin, "preview")
    samples = table_accuracy.error_samples(skin, n_points=40, seed=3, albedo_points=5)
    return tables, samples


def _as_the_tables_say(tables, samples):
    """``samples`` with every exact value replaced by the tables' own interpolation."""
    plain = dataclasses.replace(tables, inter_reflection=None)
    w, a = samples.skin.coverage, samples.skin.absorption
    return dataclasses.replace(
        samples,
        reflection=plain.made_up_reflection(samples.wi, samples.wo, w, a),
        albedo=plain.directional_albedo(samples.albedo_theta_deg, w, a),
        transmission=tables.directional("transmission_factor", samples.theta_deg),
        profile=tables.radial(samples.d_mm))


def test_no_error_where_the_tables_are_the_truth(tables_and_samples):
    tables, samples = tables_and_samples
    error = table_accuracy.table_error(tables, samples=_as_the_tables_say(tables, samples))
    assert error["max"] == 0.0


def test_a_one_percent_difference_is_relative_to_the_value_or_a_tenth_of_the_peak(
        tables_and_samples):
    """Errors are ``|table - exact| / max(|exact|, 0.1 peak)`` per channel."""
    tables, samples = tables_and_samples
    truth = _as_the_tables_say(tables, samples)
    reflection = np.array(truth.reflection)
    brightest = int(np.argmax(reflection.max(axis=-1)))
    reflection[brightest] *= 1.01
    error = table_accuracy.table_error(tables, samples=dataclasses.replace(truth,
                                                                          reflection=reflection))
    value, peak = truth.reflection[brightest], np.asarray(error["peak"])
    expected = np.max(0.01 * value / np.maximum(1.01 * value, 0.1 * peak))
    assert 0.0 < error["reflection"] <= 0.01 / 1.01 + 1e-12
    assert error["reflection"] == pytest.approx(expected, rel=1e-9)
    assert error["max"] == error["reflection"]
    assert error["albedo"] == error["transmission"] == error["profile"] == 0.0


def test_the_measure_needs_a_skin_or_samples(tables_and_samples):
    with pytest.raises(ValueError, match="skin or precomputed samples"):
        table_accuracy.table_error(tables_and_samples[0])
