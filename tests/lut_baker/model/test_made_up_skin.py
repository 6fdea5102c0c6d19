"""lut_baker.model.made_up_skin (docs/model.md §4): the normalisation constant K, the paper's
counts in albedo units, and the bundle's validation."""

import numpy as np
import pytest
from support import reference_impl as ref

from lut_baker.model import albedo, made_up_skin, presets
from lut_baker.numerics.geometry import direction

THETA_DEG = np.arange(0.0, 90.0)  # 0, 1, ..., 89 degrees


def _fields(layer):
    return tuple(float(v) for v in layer.as_dict().values())


def _film_per_second():
    film = made_up_skin.per_second(presets.PAPER_FILM_REFLECTION, made_up_skin.REFLECTION_SHUTTER_S)
    film_t = made_up_skin.per_second(presets.PAPER_FILM_TRANSMISSION,
                                  made_up_skin.TRANSMISSION_SHUTTER_S)
    return film, film_t


# --- K -------------------------------------------------------------------------------------
@pytest.mark.slow  # brute-force hemisphere sums
def test_k_is_the_films_brightest_total_albedo():
    """A dense independent scan (0..89.5 degrees every 0.5, brute-force hemisphere sums of the
    reference formulas, Richardson-extrapolated) finds the same maximum and where it is."""
    film, film_t = _film_per_second()
    k, theta_max = made_up_skin.normalisation_constant(film, film_t)
    assert presets.paper().K == k
    theta = np.arange(0.0, 90.0, 0.5)
    w = direction(np.radians(theta), 0.0)

    def total(n):
        reflection = ref.brute_force_albedo(
            lambda a, u: ref.vector_reflection(a, u, *_fields(film)), w, n, 2 * n)
        transmission = ref.brute_force_albedo(
            lambda a, u: ref.vector_transmission_down(a, u, *_fields(film_t)), w, n, 2 * n)
        return reflection + transmission

    coarse, fine = total(32), total(64)
    scan = fine + (fine - coarse) / 3
    accuracy = float(np.max(np.abs(fine - coarse) / 3 / scan))
    best = int(np.argmax(scan))
    print(f"K = {k:.6g} counts/s at {theta_max:.3g} deg; independent scan {scan[best]:.6g} at "
          f"{theta[best]:g} deg (brute-force accuracy {accuracy:.1e})")
    assert k == pytest.approx(scan[best], rel=max(1e-4, accuracy))
    assert abs(theta_max - theta[best]) <= 0.5
    # K is a maximum: no incidence of the scan is brighter beyond the quadratures' accuracy.
    assert np.all(scan <= k * (1 + max(1e-4, accuracy)))


def test_film_albedo_is_at_most_one_and_one_at_k():
    paper = presets.paper()
    film = (albedo.reflection_albedo(THETA_DEG, paper.film)
            + albedo.transmission_albedo(THETA_DEG, paper.film_transmission))
    print(f"film albedo: max {film.max():.9f}, min {film.min():.4f}")
    assert np.all(film <= 1.0 + 1e-12)
    assert film.max() == pytest.approx(1.0, abs=1e-9)


def test_paper_counts_become_albedo_units():
    paper = presets.paper()
    film, _ = _film_per_second()
    np.testing.assert_allclose(paper.film.P_s, film.P_s / paper.K, rtol=1e-14)
    np.testing.assert_allclose(paper.skin_reflection.P_d, 2.00e4 / 3.0 / paper.K, rtol=1e-14)
    np.testing.assert_allclose(paper.film_transmission.P_t, 1.08e4 / 10.0 / paper.K, rtol=1e-14)


@pytest.mark.parametrize("field, value, message", [
    ("coverage", 1.5, r"coverage must lie in \[0, 1\]"),
    ("coverage", float("nan"), r"coverage must lie in \[0, 1\]"),
    ("absorption", (0.1, -0.1, 0.2), r"absorption must lie in \[0, 1\]"),
    ("absorption", 2.0, r"absorption must lie in \[0, 1\]"),
])
def test_bundle_validation(field, value, message):
    with pytest.raises(ValueError, match=message):
        presets.paper().replace(**{field: value})


def test_combine_is_the_coverage_and_absorption_mix():
    """covered [top + (1 - A) once + (1 - A)^2 twice] + (1 - w) bare, per channel and
    broadcasting."""
    from lut_baker.model.made_up_skin import combine, coverage_weights

    weights = coverage_weights(0.25, (0.0, 0.5, 1.0))
    value = combine(weights, top=1.0, once=2.0, twice=4.0, bare=8.0)
    np.testing.assert_allclose(value, 0.25 * (1.0 + np.array([2.0, 1.0, 0.0])
                                              + np.array([4.0, 1.0, 0.0])) + 0.75 * 8.0)
    parts = np.ones((5, 2, 3))
    assert combine(weights, twice=parts).shape == (5, 2, 3)
    assert np.all(combine(coverage_weights(0.0, 0.3), top=parts, bare=2 * parts) == 2.0)
