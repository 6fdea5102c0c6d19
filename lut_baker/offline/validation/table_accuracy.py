"""How close baked tables come to the exact evaluator, at random points.

The goal (docs/baking.md): every table within 1e-3 relative or 1e-4 of its peak, whichever is
larger, against the exact model (paths 1 + 3, path 4's factor, the directional albedo, the
profile).

Functions and types
-------------------
- :func:`error_samples`, :class:`ErrorSamples` -- random points (grazing included) and the
  exact evaluator's values there; :func:`sample_directions` -- the random direction pairs.
- :func:`table_error` -- the interpolated tables against those values.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...bake import profile_radius, rgb_view
from ...evaluate.made_up import directional_albedo, made_up_reflection
from ...evaluate.two_layer import transmission_factor
from ...model.dipole import dipole_profile, dipole_total_reflectance
from ...model.made_up_skin import MadeUpSkin
from ...numerics.geometry import direction, folded_azimuth_deg, polar_angle_deg
from ...tables.table_set import Tables

__all__ = ["sample_directions", "ErrorSamples", "error_samples", "table_error"]


def sample_directions(n_points: int, rng: np.random.Generator, theta_max_deg: float):
    """Random (wi, wo): 60% with both polar angles uniform on [0, theta_max], 20% with wi and
    20% with both on the grazing rows [80, theta_max] degrees; azimuths uniform."""
    grazing = min(80.0, theta_max_deg)
    n_one = n_points // 5
    low_i = np.zeros(n_points)
    low_o = np.zeros(n_points)
    low_i[n_points - 2 * n_one:] = grazing
    low_o[n_points - n_one:] = grazing
    theta_i = rng.uniform(low_i, theta_max_deg)
    theta_o = rng.uniform(low_o, theta_max_deg)
    phi_i, phi_o = rng.uniform(0.0, 2.0 * np.pi, (2, n_points))
    return direction(np.radians(theta_i), phi_i), direction(np.radians(theta_o), phi_o)


@dataclass(frozen=True, eq=False)
class ErrorSamples:
    """Random points and the exact evaluator's values there (see :func:`error_samples`)."""

    skin: MadeUpSkin
    wi: np.ndarray
    wo: np.ndarray
    reflection: np.ndarray
    theta_deg: np.ndarray
    albedo_theta_deg: np.ndarray
    albedo: np.ndarray
    transmission: np.ndarray
    d_mm: np.ndarray
    profile: np.ndarray


def error_samples(skin: MadeUpSkin, n_points: int = 500, seed: int = 0, *, level: int = 0,
                  albedo_level: int | None = None, albedo_points: int | None = None,
                  theta_max_deg: float = 89.0) -> ErrorSamples:
    """``n_points`` random points (grazing rows included, polar angles up to
    ``theta_max_deg``) and the exact evaluator there: paths 1 + 3
    (:func:`lut_baker.evaluate.made_up.made_up_reflection`) and path 4's factor at ``level``, the
    directional albedo at ``albedo_level`` (default ``level``) on the first ``albedo_points``
    of them (default all), and R(d)/Rd on [0, :func:`profile_radius`] (denser near 0)."""
    albedo_level = level if albedo_level is None else albedo_level
    rng = np.random.default_rng(seed)
    wi, wo = sample_directions(n_points, rng, theta_max_deg)
    theta = rng.uniform(0.0, theta_max_deg, n_points)
    albedo_theta = theta[:n_points if albedo_points is None else albedo_points]
    transmission = transmission_factor(direction(np.radians(theta), 0.0), skin.film_transmission,
                                       skin.dipole, level=level)
    d = profile_radius(skin.dipole) * rng.uniform(0.0, 1.0, n_points) ** 2
    profile = np.reshape(dipole_profile(d, skin.dipole), (n_points, -1)) / np.atleast_1d(
        dipole_total_reflectance(skin.dipole))
    return ErrorSamples(
        skin=skin, wi=wi, wo=wo, reflection=made_up_reflection(wi, wo, skin, level=level),
        theta_deg=theta, albedo_theta_deg=albedo_theta,
        albedo=directional_albedo(albedo_theta, skin, level=albedo_level),
        transmission=rgb_view(np.reshape(transmission, (n_points, -1))), d_mm=d,
        profile=rgb_view(profile))


def _normalised_error(approx, exact, peak) -> np.ndarray:
    """``|approx - exact| / max(|exact|, 0.1 peak)``: <= 1e-3 is the goal's "1e-3 relative or
    1e-4 of the peak, whichever is larger"."""
    return np.abs(approx - exact) / np.maximum(np.abs(exact), 0.1 * np.asarray(peak))


def table_error(tables: Tables, skin: MadeUpSkin | None = None, n_points: int = 500,
                seed: int = 0, *, level: int = 0, samples: ErrorSamples | None = None) -> dict:
    """Interpolated tables against the exact evaluator at random points.

    Errors are normalised as ``|table - exact| / max(|exact|, 0.1 peak)`` per channel (peak: the
    largest value of the quantity on the table's nodes), so a value <= 1e-3 meets "1e-3 relative
    or 1e-4 of the peak, whichever is larger".  The points come from :func:`error_samples`
    (``skin``, ``n_points``, ``seed``, ``level``) unless ``samples`` are given.  Returns a dict
    of maxima: ``reflection`` (paths 1 + 3 by :meth:`Tables.made_up_reflection`, without
    inter-reflection), ``albedo`` (directional), ``transmission`` (path 4's factor),
    ``profile`` (R(d)/Rd), ``max`` (of those four); ``worst`` (theta_i, theta_o, relative
    azimuth in degrees of the worst reflection point) and ``peak`` (1/sr per channel).
    """
    if samples is None:
        if skin is None:
            raise ValueError("table_error needs the skin or precomputed samples")
        samples = error_samples(skin, n_points, seed, level=level)
    skin = samples.skin
    plain = replace(tables, inter_reflection=None)
    w, a = skin.coverage, skin.absorption
    peak = plain.node_values(w, a).reshape(-1, 3).max(axis=0)
    reflection = _normalised_error(plain.made_up_reflection(samples.wi, samples.wo, w, a),
                                   samples.reflection, peak)
    albedo = _normalised_error(plain.directional_albedo(samples.albedo_theta_deg, w, a),
                               samples.albedo,
                               plain.directional_albedo(tables.theta_deg, w, a).max(axis=0))
    transmission = _normalised_error(tables.directional("transmission_factor", samples.theta_deg),
                                     samples.transmission, tables.transmission_factor.max(axis=0))
    profile = _normalised_error(tables.radial(samples.d_mm), samples.profile,
                                tables.profile.max(axis=0))
    worst = int(np.argmax(reflection.max(axis=-1)))
    wi, wo = samples.wi[worst], samples.wo[worst]
    result = {
        "reflection": float(reflection.max()),
        "albedo": float(albedo.max()),
        "transmission": float(transmission.max()),
        "profile": float(profile.max()),
        "peak": peak.tolist(),
        "worst": [float(polar_angle_deg(wi)), float(polar_angle_deg(wo)),
                  float(folded_azimuth_deg(wi, wo))],
    }
    result["max"] = max(result[k] for k in ("reflection", "albedo", "transmission", "profile"))
    return result
