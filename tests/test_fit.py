"""Tests of lut_baker.offline.measured.layer_fit, lut_baker.offline.measured.measurements and ``python -m lut_baker fit``.

The round trip (issue 2, item 4): the paper's protocols synthesised from its parameters (SPEC 5,
raw counts) with 2% multiplicative noise, fitted from a poor start (x3 and /3 in turn, eta 1.5),
over 20 noise seeds.  The targets are 5% for n, eta and the P ratio, 10% for the dipole.  Where
the protocol's information (the fit's covariance, the Cramer-Rao bound) allows it, every seed
must meet the target; elsewhere the median must, and every error must lie within 4 reported
standard errors (docs/fitting.md gives the numbers).  About 20 s for the 100 fits.
"""

import json
import tomllib

import numpy as np
import pytest

from lut_baker.model.layers import Dipole, ReflectionLayer, TransmissionLayer
from lut_baker.model.microfacet import fresnel_reflectance
from lut_baker.model.presets import paper_layers
from lut_baker.offline.cli.fit_command import STRICT_EXIT
from lut_baker.offline.cli.main import main
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
@pytest.mark.parametrize(("name", "parameter"), sorted(PINNED))
def test_round_trip_meets_target_on_every_seed(round_trips, name, parameter):
    worst = np.max(np.abs(_errors(round_trips, name, parameter)))
    assert worst <= TARGETS[parameter], f"{name} {parameter}: worst error {worst:.3%}"


@pytest.mark.parametrize("name", sorted(TRUTH))
def test_round_trip_median_error_within_target(round_trips, name):
    for parameter in _fitted_parameters(round_trips, name):
        if (name, parameter) == ("film transmission", "eta"):
            continue  # not determined by transmission at all: see the flag test below
        median = np.median(np.abs(_errors(round_trips, name, parameter)))
        assert median <= TARGETS[parameter], f"{name} {parameter}: median {median:.3%}"


@pytest.mark.parametrize("name", sorted(TRUTH))
def test_round_trip_errors_match_reported_standard_errors(round_trips, name):
    """The covariance is honest: no error beyond 4 standard errors, and the errors' spread in
    standard-error units is about 1 (neither hidden nor inflated)."""
    for parameter in _fitted_parameters(round_trips, name):
        z = np.array([errors[parameter] / stderr[parameter]
                      for _, errors, stderr in round_trips[name]])
        assert np.max(np.abs(z)) < 4.0, f"{name} {parameter}: {z}"
        assert 0.5 < np.sqrt(np.mean(z * z)) < 1.6, f"{name} {parameter}: {z}"


def test_round_trip_reaches_the_noise_floor(round_trips):
    """Every fit ends in the right basin: its residual rms is the 2% noise."""
    for name, runs in round_trips.items():
        rms = np.array([result.residual_rms for result, _, _ in runs])
        assert np.all(np.abs(rms - NOISE) < 0.004), f"{name}: {rms}"


def test_paper_protocols_raise_no_warning(round_trips):
    for name in ("film reflection", "film transmission, eta fixed", "skin reflection",
                 "skin dipole"):
        for result, _, _ in round_trips[name]:
            assert result.ok, f"{name}: {result.warnings}"


def test_transmission_flags_eta(round_trips):
    """Eta enters transmission only through F_t = 1 - F_r (about 1% here): the fit says so."""
    for result, _, _ in round_trips["film transmission"]:
        assert result.warnings and all(w.startswith("eta ") for w in result.warnings)
        assert result.relative_stderr["eta"] > 0.10


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
    strict = F.fit_reflection(data, limits=F.Limits(correlation=0.95))
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
# Measurements
# --------------------------------------------------------------------------------------------
def test_reflection_counts_at_the_mirror_configuration():
    """alpha = 0 at psi = 60: D = 1, G = 1, V.H = cos 30 deg, N.L = cos 30 deg (eq. 2)."""
    data = M.ReflectionData([60.0], [0.0], [1.0])
    c = np.cos(np.radians(30.0))
    expected = (float(FILM.P_d) + float(FILM.P_s) * fresnel_reflectance(c, 1.19)) * c
    assert M.reflection_counts(data, FILM)[0] == pytest.approx(expected, rel=1e-9)


def test_transmission_counts_straight_through():
    """theta_t = incidence: beta = 0, c = cos(incidence), I = (P_d + P_t F_t) N.L (eq. 4)."""
    data = M.TransmissionData([30.0], [30.0], [1.0])
    c = np.cos(np.radians(30.0))
    expected = (float(FILM_T.P_d) + float(FILM_T.P_t) * (1 - fresnel_reflectance(c, 1.19))) * c
    assert M.transmission_counts(data, FILM_T)[0] == pytest.approx(expected, rel=1e-9)


def test_profile_ratio_is_one_at_the_lit_pixel_and_falls():
    ratio = M.profile_ratio(np.linspace(0.0, 3.0, 31), DIPOLE)
    assert ratio[0] == 1.0 and np.all(np.diff(ratio) < 0.0)


def test_synthesis_follows_the_paper_protocols():
    data = M.paper_protocols(NOISE, 0)
    assert sorted(set(data["film_reflection"].psi_deg)) == [30.0, 60.0, 90.0, 120.0]
    assert sorted(set(data["film_transmission"].incidence_deg)) == [0.0, 30.0, 60.0]
    exact = M.synthesize_reflection(FILM)
    noise = data["film_reflection"].intensity_counts / exact.intensity_counts - 1.0
    assert abs(np.std(noise) - NOISE) < 0.003 and abs(np.mean(noise)) < 0.003
    again = M.paper_protocols(NOISE, 0)["skin_profile"].ratio
    assert np.array_equal(again, data["skin_profile"].ratio)


def test_csv_round_trip(tmp_path):
    data = M.paper_protocols(NOISE, 1)
    for name, dataset in data.items():
        path = M.write_measurements(tmp_path / f"{name}.csv", dataset, ("a comment",))
        back = M.read_measurements(path)
        assert type(back) is type(dataset)
        for column in dataset.COLUMNS:
            np.testing.assert_allclose(getattr(back, column), getattr(dataset, column),
                                       rtol=1e-6)


def test_csv_accepts_theta_r_instead_of_alpha(tmp_path):
    path = tmp_path / "r.csv"
    path.write_text("intensity_counts,theta_r_deg,psi_deg,note\n100,-25,60,x\n90,-40,90,y\n")
    data = M.read_measurements(path)
    np.testing.assert_allclose(data.alpha_deg, [5.0, 5.0])
    np.testing.assert_allclose(data.wo[:, 0], np.sin(np.radians([-25.0, -40.0])))


@pytest.mark.parametrize(("text", "message"), [
    ("", "empty file"),
    ("psi_deg,intensity_counts\n30,1\n", "missing column alpha_deg"),
    ("psi_deg,alpha_deg,intensity_counts\n30,0,abc\n", "row 2, column intensity_counts"),
    ("psi_deg,alpha_deg,intensity_counts\n", "no data rows"),
    ("foo,bar\n1,2\n", "unknown columns"),
    ("distance_mm,ratio\n0,1\n0.1,-0.5\n", "ratio must be > 0"),
    ("psi_deg,alpha_deg,intensity_counts\n30,80,5\n", "below the sample"),
    ("incidence_deg,theta_t_deg,intensity_counts\n95,0,5\n", "incidence_deg must lie in"),
])
def test_csv_problems_raise_one_line(tmp_path, text, message):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(ValueError, match=message) as info:
        M.read_measurements(path)
    assert "\n" not in str(info.value) and str(path) in str(info.value)


# --------------------------------------------------------------------------------------------
# Command line
# --------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def synthesized(tmp_path_factory):
    out = tmp_path_factory.mktemp("synth")
    assert main(["fit", "synthesize", "--preset", "paper", "--out", str(out),
                 "--noise", "0.02", "--seed", "3"]) == 0
    return out


def test_cli_synthesize_writes_the_protocols(synthesized):
    names = sorted(p.name for p in synthesized.iterdir())
    assert names == ["film_reflection.csv", "film_transmission.csv", "skin_profile.csv",
                     "skin_reflection.csv", "truth.toml"]
    truth = tomllib.loads((synthesized / "truth.toml").read_text())
    assert ReflectionLayer(**truth["film_reflection"]).as_dict() == FILM.as_dict()
    header = (synthesized / "film_reflection.csv").read_text().splitlines()
    assert "psi_deg,alpha_deg,intensity_counts" in header


@pytest.mark.parametrize(("kind", "file", "layer_type", "truth"), [
    ("reflection", "film_reflection.csv", ReflectionLayer, FILM),
    ("reflection", "skin_reflection.csv", ReflectionLayer, SKIN),
    ("dipole", "skin_profile.csv", Dipole, DIPOLE),
])
def test_cli_fit_round_trip_toml(synthesized, tmp_path, capsys, kind, file, layer_type, truth):
    assert main(["fit", kind, str(synthesized / file)]) == 0
    captured = capsys.readouterr()
    document = tomllib.loads(captured.out)
    fitted = layer_type(**document[kind])
    errors = F.relative_errors(fitted, truth)
    for parameter in ("n", "eta", "sigma_s", "sigma_a"):
        if parameter in document["stderr"]:
            assert abs(errors[parameter]) < 0.05
            assert document["stderr"][parameter] > 0
    assert document["fit"]["warnings"] == [] and captured.err == ""
    n = len(document["fit"]["free"])
    assert np.array(document["fit"]["correlation"]).shape == (n, n)


def test_cli_transmission_warns_and_strict_fails(synthesized, tmp_path, capsys):
    path = str(synthesized / "film_transmission.csv")
    assert main(["fit", "transmission", path]) == 0
    assert capsys.readouterr().err.startswith("warning: eta is ill-conditioned")
    assert main(["fit", "transmission", path, "--strict"]) == STRICT_EXIT
    out = tmp_path / "t.json"
    assert main(["fit", "transmission", path, "--eta", "1.19", "--strict", "--out",
                 str(out)]) == 0
    document = json.loads(out.read_text())
    assert document["transmission"]["eta"] == 1.19 and document["fit"]["warnings"] == []
    assert abs(document["transmission"]["n"] / float(FILM_T.n) - 1) < 0.05


@pytest.mark.parametrize(("args", "message"), [
    (["reflection", "{dir}/missing.csv"], "no such file"),
    (["reflection", "{dir}/empty.csv"], "empty file"),
    (["reflection", "{dir}/nocolumn.csv"], "missing column intensity_counts"),
    (["reflection", "{dir}/text.csv"], "not a number"),
    (["reflection", "{dir}/profile.csv"], "holds profile columns"),
    (["dipole", "{dir}/profile.csv", "--eta", "0.5"], "--eta"),
])
def test_cli_bad_input_exits_2_with_one_line(tmp_path, capsys, args, message):
    (tmp_path / "empty.csv").write_text("")
    (tmp_path / "nocolumn.csv").write_text("psi_deg,alpha_deg\n30,0\n")
    (tmp_path / "text.csv").write_text("psi_deg,alpha_deg,intensity_counts\n30,zero,1\n")
    (tmp_path / "profile.csv").write_text("distance_mm,ratio\n0,1\n0.5,0.5\n1,0.2\n")
    with pytest.raises(SystemExit) as info:
        main(["fit"] + [a.format(dir=tmp_path) for a in args])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err
