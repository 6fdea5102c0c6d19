"""The layer fits (lut_baker.offline.measured.layer_fit).

The round trip: the paper's protocols synthesised from its parameters (docs/model.md §5,
raw counts) with 2% multiplicative noise, fitted from a poor start (x3 and /3 in turn, eta
1.5), over 20 noise seeds.  The targets are 5% for n, eta and the P ratio, 10% for the
dipole.  Where the protocol's information (the fit's covariance, the Cramer-Rao bound)
allows it, every seed must meet the target; elsewhere the median must, and every error must
lie within 4 reported standard errors (docs/fitting.md gives the numbers).  Then
ill-conditioned data, which the fit must flag, and the fit's options.
"""

import numpy as np
import pytest

from lut_baker.model.layers import Dipole, TransmissionLayer
from lut_baker.model.presets import paper_layers
from lut_baker.offline.measured import fit_results, fit_solver, fit_starts
from lut_baker.offline.measured import layer_fit as F
from lut_baker.offline.measured import measurements as M

SEEDS = range(20)
NOISE = 0.02
FILM, FILM_T, SKIN, DIPOLE = paper_layers()
TRUTH = {
    "film reflection": FILM,
    "film transmission": FILM_T,
    "film transmission, eta fixed": FILM_T,
    "skin reflection": SKIN,
    "skin dipole": DIPOLE,
}
TARGETS = {"n": 0.05, "eta": 0.05, "P_s/P_d": 0.05, "P_t/P_d": 0.05,
           "sigma_s": 0.10, "sigma_a": 0.10}
# (protocol, parameter) whose median relative standard error is below a third of the target:
# every seed must recover these within the target.
PINNED = {
    ("film reflection", "n"), ("film reflection", "eta"), ("film reflection", "P_s/P_d"),
    ("film transmission", "n"), ("film transmission, eta fixed", "n"),
    ("skin reflection", "eta"), ("skin dipole", "sigma_s"), ("skin dipole", "sigma_a"),
}
# The rest: skin n (median stderr 2.9%), skin P_s/P_d (4.3%), film P_t/P_d (2.3%) and film
# transmission eta (6% of eta; flagged) cannot be held to 5% on every one of 20 seeds at 2%
# noise: their covariance says so.  Their worst errors are printed by bench/fit_roundtrip.py
# and discussed in docs/fitting.md; here they are held to their median and to their reported
# standard errors (the tests below).


@pytest.fixture(scope="module")
def round_trips():
    """protocol -> list over seeds of (FitResult, relative errors, relative stderrs)."""
    out = {name: [] for name in TRUTH}

    def record(name, result):
        stderr = {k: v / float(getattr(result.params, k)) for k, v in result.stderr.items()}
        stderr.update({k: se / value for k, (value, se) in result.derived.items()})
        out[name].append((result, F.relative_errors(result.params, TRUTH[name]), stderr))
        return result

    for seed in SEEDS:
        data = M.paper_protocols(NOISE, seed)
        film = record("film reflection",
                      F.fit_reflection(data["film_reflection"], F.poor_start(FILM)))
        record("film transmission",
               F.fit_transmission(data["film_transmission"], F.poor_start(FILM_T)))
        record("film transmission, eta fixed",
               F.fit_transmission(data["film_transmission"], F.poor_start(FILM_T),
                                  eta=float(film.params.eta)))
        record("skin reflection",
               F.fit_reflection(data["skin_reflection"], F.poor_start(SKIN)))
        record("skin dipole",
               F.fit_dipole(data["skin_profile"], F.poor_start(DIPOLE), g=0.0, eta=1.26))
    return out


def _errors(round_trips, name, parameter):
    return np.array([errors[parameter] for _, errors, _ in round_trips[name]])


def _fitted_parameters(round_trips, name):
    result = round_trips[name][0][0]
    return [p for p in TARGETS if p in result.free or p in result.derived]


# --------------------------------------------------------------------------------------------
# Round trip
# --------------------------------------------------------------------------------------------
@pytest.mark.slow  # the 20-seed round trip, ~5 s
@pytest.mark.parametrize(("name", "parameter"), sorted(PINNED))
def test_round_trip_meets_target_on_every_seed(round_trips, name, parameter):
    worst = np.max(np.abs(_errors(round_trips, name, parameter)))
    assert worst <= TARGETS[parameter], f"{name} {parameter}: worst error {worst:.3%}"


@pytest.mark.slow  # the 20-seed round trip, ~5 s
@pytest.mark.parametrize("name", sorted(TRUTH))
def test_round_trip_median_error_within_target(round_trips, name):
    for parameter in _fitted_parameters(round_trips, name):
        if (name, parameter) == ("film transmission", "eta"):
            continue  # not determined by transmission at all: see the flag test below
        median = np.median(np.abs(_errors(round_trips, name, parameter)))
        assert median <= TARGETS[parameter], f"{name} {parameter}: median {median:.3%}"


@pytest.mark.slow  # the 20-seed round trip, ~5 s
@pytest.mark.parametrize("name", sorted(set(TRUTH) - {"film transmission"}))
def test_round_trip_errors_match_reported_standard_errors(round_trips, name):
    """The covariance is honest: no error beyond 4 standard errors, and the errors' spread in
    standard-error units is about 1 (neither hidden nor inflated).  (Transmission with eta
    free has two minima the data do not choose between: test_transmission_flags_eta.)"""
    for parameter in _fitted_parameters(round_trips, name):
        z = np.array([errors[parameter] / stderr[parameter]
                      for _, errors, stderr in round_trips[name]])
        assert np.max(np.abs(z)) < 4.0, f"{name} {parameter}: {z}"
        assert 0.5 < np.sqrt(np.mean(z * z)) < 1.6, f"{name} {parameter}: {z}"


@pytest.mark.slow  # the 20-seed round trip, ~5 s
def test_round_trip_reaches_the_noise_floor(round_trips):
    """Every fit ends in the right basin: its residual rms is the 2% noise."""
    for name, runs in round_trips.items():
        rms = np.array([result.residual_rms for result, _, _ in runs])
        assert np.all(np.abs(rms - NOISE) < 0.004), f"{name}: {rms}"


@pytest.mark.slow  # the 20-seed round trip, ~5 s
def test_paper_protocols_raise_no_warning(round_trips):
    for name in ("film reflection", "film transmission, eta fixed", "skin reflection",
                 "skin dipole"):
        for result, _, _ in round_trips[name]:
            assert result.ok, f"{name}: {result.warnings}"


@pytest.mark.slow  # the 20-seed round trip, ~5 s
def test_transmission_flags_eta(round_trips):
    """Eta enters transmission only through F_t = 1 - F_r (about 1% here): the fit says so.
    Its starts end in two minima, near the true eta and near eta = 3, whose chi-squares differ
    by less than the noise: every fit names the rival (its covariance describes one basin)."""
    for result, _, _ in round_trips["film transmission"]:
        assert result.warnings and all(w.startswith(("eta ", "another minimum"))
                                       for w in result.warnings)
        assert any(w.startswith("another minimum") for w in result.warnings)
        assert result.starts.reached < result.starts.count
        assert result.relative_stderr["eta"] > 0.10
    counts = {"film reflection": len(fit_starts.ETA_STARTS) + 1,
              "skin reflection": len(fit_starts.ETA_STARTS) + 1,
              "film transmission, eta fixed": fit_starts.N_GRID_PARTS + 1, "skin dipole": None}
    for name, count in counts.items():  # the others: every start ends in the same minimum
        for result, _, _ in round_trips[name]:
            assert result.starts.reached == result.starts.count >= 3, name
            assert count is None or result.starts.count == count, name
            assert result.starts.spread < 1e-4 and result.starts.next_excess is None


# --------------------------------------------------------------------------------------------
# Ill-conditioning
# --------------------------------------------------------------------------------------------
def test_single_relative_angle_makes_ps_and_eta_degenerate():
    """At one psi, V.H = cos(psi/2) for every sample, so F_r is one number: only P_s F_r is
    determined."""
    data = M.synthesize_reflection(FILM, (60.0,), noise=NOISE, rng=1)
    result = F.fit_reflection(data, F.poor_start(FILM))
    assert not result.ok
    assert any(w.startswith("P_s and eta are degenerate") for w in result.warnings)
    assert any(w.startswith("eta is ill-conditioned") for w in result.warnings)
    assert not any(w.startswith("n ") for w in result.warnings)  # the lobe shape is measured
    assert abs(result.correlation[1, 3]) > 0.999


@pytest.mark.parametrize("seed", range(4))
def test_short_profile_flags_sigma_a(seed):
    """0.1 to 0.5 mm of profile cannot pin absorption (1/s_tr ~ 2 mm): sigma_a is flagged as
    ill-conditioned, or as stuck at its bound, but never returned as if it were known."""
    data = M.synthesize_profile(DIPOLE, np.arange(0.0, 0.5001, 0.05), noise=NOISE, rng=seed)
    result = F.fit_dipole(data, F.poor_start(DIPOLE), g=0.0, eta=1.26)
    flags = [w for w in result.warnings if w.startswith("sigma_a ")]
    assert flags and ("ill-conditioned" in flags[0] or "at its bound" in flags[0])
    assert result.relative_stderr["sigma_a"] > 0.10
    assert not any(w.startswith("sigma_s is") for w in result.warnings)  # the shape is measured


def test_data_the_model_cannot_describe_are_flagged():
    data = M.synthesize_reflection(FILM, noise=0.0)
    rng = np.random.default_rng(5)
    factor = np.exp(rng.normal(0.0, 0.5, data.psi_deg.size))
    scrambled = M.ReflectionData(data.psi_deg, data.alpha_deg, data.intensity_counts * factor)
    result = F.fit_reflection(scrambled)
    assert any("does not describe these data" in w for w in result.warnings)


def test_stricter_limits_flag_the_film_reflection_correlation():
    """P_s and eta correlate at -0.98 on the paper's protocol: quiet at the default 0.99."""
    data = M.paper_protocols(NOISE, 0)["film_reflection"]
    assert F.fit_reflection(data).ok
    strict = F.fit_reflection(data, limits=fit_results.Limits(correlation=0.95))
    assert any(w.startswith("P_s and eta are degenerate") for w in strict.warnings)


# --------------------------------------------------------------------------------------------
# Fit options
# --------------------------------------------------------------------------------------------
def test_dipole_leaves_out_the_lit_pixel_neighbourhood():
    """Samples at d < d_min may be anything (direct light): the fit does not see them."""
    clean = M.synthesize_profile(DIPOLE, noise=NOISE, rng=7)
    near = clean.distance_mm < F.D_MIN_MM
    spoiled = M.ProfileData(clean.distance_mm, np.where(near, 3.0 * clean.ratio, clean.ratio))
    a, b = F.fit_dipole(clean), F.fit_dipole(spoiled)
    assert float(a.params.sigma_a) == pytest.approx(float(b.params.sigma_a), rel=1e-6)
    assert a.samples == b.samples == np.count_nonzero(~near)
    c = F.fit_dipole(spoiled, d_min_mm=0.0)  # now they count, and the fit says it is poor
    assert c.samples == clean.distance_mm.size and c.residual_rms > 5 * a.residual_rms


def test_dipole_free_scale_absorbs_a_wrong_lit_pixel():
    profile = M.synthesize_profile(DIPOLE, noise=NOISE, rng=11)
    dimmed = M.ProfileData(profile.distance_mm, 0.7 * profile.ratio)
    assert not F.fit_dipole(dimmed).ok
    result = F.fit_dipole(dimmed, free_scale=True)
    errors = F.relative_errors(result.params, DIPOLE)
    assert abs(errors["sigma_s"]) < 0.10 and abs(errors["sigma_a"]) < 0.10
    scale, se = result.derived["scale"]
    assert abs(scale - 0.7) < 3 * se + 0.01


def test_fixed_eta_is_kept_and_not_reported():
    data = M.paper_protocols(NOISE, 2)["film_transmission"]
    result = F.fit_transmission(data, eta=1.3)
    assert float(result.params.eta) == 1.3
    assert result.free == ("P_d", "P_t", "n") and "eta" not in result.stderr
    assert result.correlation.shape == (3, 3)


def test_fit_measurements_dispatches_on_type():
    data = M.paper_protocols(NOISE, 4)
    assert isinstance(F.fit_measurements(data["skin_profile"]).params, Dipole)
    assert isinstance(F.fit_measurements(data["film_transmission"], eta=1.19).params,
                      TransmissionLayer)
    with pytest.raises(ValueError, match="no fit"):
        F.fit_measurements(object())


def test_too_few_samples_is_an_error():
    data = M.synthesize_reflection(FILM, noise=0.0)
    few = M.ReflectionData(data.psi_deg[:4], data.alpha_deg[:4], data.intensity_counts[:4])
    with pytest.raises(ValueError, match="at least 5 samples"):
        F.fit_reflection(few)


@pytest.mark.parametrize(("data_name", "truth"), [("film_reflection", FILM),
                                                  ("skin_profile", DIPOLE)])
def test_far_starts_reach_the_same_minimum(data_name, truth):
    data = M.paper_protocols(NOISE, 6)[data_name]
    reference = F.fit_measurements(data, F.poor_start(truth)).params.as_dict()
    for factor, eta in ((30.0, 1.02), (1 / 30, 2.5)):
        start = F.poor_start(truth, factor, eta)
        fitted = F.fit_measurements(data, start).params.as_dict()
        for key, value in reference.items():
            assert fitted[key] == pytest.approx(value, rel=1e-4), (factor, key)


def test_poor_start_is_poor():
    start = F.poor_start(FILM)
    assert float(start.P_d) == pytest.approx(3 * float(FILM.P_d))
    assert float(start.P_s) == pytest.approx(float(FILM.P_s) / 3)
    assert float(start.n) == pytest.approx(3 * float(FILM.n))
    assert float(start.eta) == 1.5
    assert float(F.poor_start(DIPOLE).sigma_a) == pytest.approx(float(DIPOLE.sigma_a) / 3)


# --------------------------------------------------------------------------------------------
# Several data sets at once, the tilt, no lobe
# --------------------------------------------------------------------------------------------
CHANNEL_LAYERS = (FILM.scaled(P_d=1.3, P_s=0.8), FILM, FILM.scaled(P_d=0.6, P_s=1.2))


def _channels(tilt_deg, noise, seed, layers=CHANNEL_LAYERS):
    geometry = M.synthesize_reflection(FILM, (60.0, 120.0), noise=0.0)
    rng = np.random.default_rng(seed)
    return [M.ReflectionData(geometry.psi_deg, geometry.alpha_deg,
                             M.reflection_counts(geometry, layer, tilt_deg)
                             * (1.0 + noise * rng.standard_normal(geometry.psi_deg.size)))
            for layer in layers]


@pytest.fixture(scope="module")
def tilted():
    """``(data, joint fit)``: three channels of a sample tilted by 1.2 degrees, fitted with
    a shared tilt (two tests read the one fit)."""
    data = _channels(1.2, NOISE, 3)
    return data, F.fit_reflection_sets(data, tilt=True)


def test_a_shared_tilt_is_fitted_with_its_standard_error(tilted):
    joint = tilted[1]
    tilt, stderr = joint.nuisance[fit_solver.TILT]
    assert 0.0 < stderr < 0.1 and abs(tilt - 1.2) < 4 * stderr
    assert joint.labels == ("R", "G", "B") and joint.names[-1] == fit_solver.TILT
    assert joint.names[:4] == ("R.P_d", "R.P_s", "R.n", "R.eta")
    assert joint.starts.count == len(fit_starts.ETA_STARTS) * len(fit_starts.TILT_STARTS_DEG)
    assert joint.starts.reached == joint.starts.count and not joint.warnings
    for fit, truth in zip(joint.fits, CHANNEL_LAYERS, strict=True):
        assert fit.derived[fit_solver.TILT] == (tilt, stderr) and fit.ok
        errors = F.relative_errors(fit.params, truth)
        assert abs(errors["n"]) < 0.05 and abs(errors["P_s/P_d"]) < 0.10
    # Untilted data, tilt fitted: zero within its error; exact data give the truth.
    exact = F.fit_reflection_sets(_channels(0.0, 0.0, 0), tilt=True)
    assert abs(exact.nuisance[fit_solver.TILT][0]) < 1e-8
    for fit, truth in zip(exact.fits, CHANNEL_LAYERS, strict=True):
        assert all(abs(e) < 1e-7 for e in F.relative_errors(fit.params, truth).values())


def test_without_lobe_only_P_d_is_fitted():
    data = _channels(0.0, NOISE, 5, [FILM.scaled(P_s=0.0)] * 3)
    joint = F.fit_reflection_sets(data, lobe=False)
    assert joint.starts.count == 1  # linear in log P_d: the start is the solution
    for fit, one in zip(joint.fits, data, strict=True):
        assert fit.free == ("P_d",) and float(fit.params.P_s) == 0.0
        # Least squares in log: the geometric mean of measured over the unit diffuse signal.
        unit = M.reflection_counts(one, FILM.scaled(P_d=1.0 / float(FILM.P_d), P_s=0.0))
        expected = np.exp(np.mean(np.log(one.intensity_counts / unit)))
        assert float(fit.params.P_d) == pytest.approx(expected, rel=1e-12)
        assert fit.relative_stderr["P_d"] == pytest.approx(NOISE / np.sqrt(unit.size), rel=0.2)


def test_joint_data_sets_must_share_their_geometry():
    one = M.synthesize_reflection(FILM, noise=0.0)
    other = M.synthesize_reflection(FILM, (60.0,), noise=0.0)
    with pytest.raises(ValueError, match="share their geometry"):
        F.fit_reflection_sets([one, other])
    with pytest.raises(ValueError, match="2 labels for 3 data sets"):
        F.fit_reflection_sets([one] * 3, labels=("a", "b"))


# --------------------------------------------------------------------------------------------
# Determined by the data: a 1e-9 change of the data moves the fit by about as much
# --------------------------------------------------------------------------------------------
def _perturbed(data, size=1e-9, seed=0):
    """``data`` with its measured column times ``1 + size s``, ``s`` a fixed +-1 pattern."""
    columns = [getattr(data, name) for name in data.COLUMNS]
    sign = np.random.default_rng(seed).choice([-1.0, 1.0], columns[-1].size)
    return type(data)(*columns[:-1], columns[-1] * (1.0 + size * sign))


def _values(fit):
    values = {name: float(getattr(fit.params, name)) for name in fit.free}
    values.update({name: value for name, (value, _) in fit.derived.items()})
    return values


@pytest.mark.parametrize(("name", "fit"), [
    ("film_reflection", F.fit_reflection),
    ("film_transmission", F.fit_transmission),
    ("film_transmission", lambda data: F.fit_transmission(data, eta=1.19)),
    ("skin_reflection", F.fit_reflection),
    ("skin_profile", F.fit_dipole),
    ("skin_profile", lambda data: F.fit_dipole(data, free_scale=True)),
])
def test_the_fits_are_determined_by_their_data(name, fit):
    """Every fitted value moves by less than 1e-6 (relative) when the data move by 1e-9 (it
    moves by about 1e-9: the optimum is polished to that)."""
    data = M.paper_protocols(NOISE, 8)[name]
    reference, moved = _values(fit(data)), _values(fit(_perturbed(data)))
    for key, value in reference.items():
        assert abs(moved[key] / value - 1.0) < 1e-6, (key, value, moved[key])


def test_a_joint_tilted_fit_is_determined_by_its_data(tilted):
    data, reference = tilted
    moved = F.fit_reflection_sets([_perturbed(d, seed=s) for s, d in enumerate(data)], tilt=True)
    assert abs(moved.nuisance[fit_solver.TILT][0] - reference.nuisance[fit_solver.TILT][0]) < 1e-6
    for a, b in zip(reference.fits, moved.fits, strict=True):
        for key, value in _values(a).items():
            assert abs(_values(b)[key] / value - 1.0) < 1e-6, key
