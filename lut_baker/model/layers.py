"""Single-layer functions of the made-up skin model (paper section 2).

Every function is vectorised: directions are arrays of shape ``(..., 3)`` in the local frame
(normal +z, ``wi`` toward the light, ``wo`` toward the viewer), and every layer parameter may be
a scalar or an RGB triple.  Results have shape ``batch + channels`` where ``channels`` is ``()``
for scalar layers and ``(3,)`` for RGB ones.

Functions
---------
- :func:`fresnel_reflectance` -- unpolarised dielectric Fresnel ``F_r`` (paper eq. 2).
- :func:`microfacet_distribution` -- ``D = exp(-(alpha n)^2)``, alpha in degrees (eq. 2).
- :func:`geometric_attenuation` -- Torrance-Sparrow ``G`` (eq. 2).
- :func:`ts_reflection` -- Torrance-Sparrow BRDF ``P_d + P_s D G F_r`` (eq. 2).
- :func:`ts_transmission` -- thin-film BTDF ``P_d + P_t D(beta) F_t`` (eq. 4).
- :func:`fresnel_diffuse_reflectance` -- ``F_dr`` of the dipole (eq. 6).
- :func:`dipole_profile` -- radial diffuse reflectance ``R(d)``, d in mm (eq. 6).
- :func:`dipole_total_reflectance` -- closed-form ``Rd = 2 pi Int R(d) d dd`` (Jensen 2001).

References
----------
Baba, Mukaigawa, Yagi, "Reflection Model for Made-up Skin Consisting of Double-layered Structure
of Cosmetic and Skin" (Osaka University).  Jensen, Marschner, Levoy, Hanrahan, "A Practical Model
for Subsurface Light Transport", SIGGRAPH 2001.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

__all__ = [
    "ReflectionLayer",
    "TransmissionLayer",
    "Dipole",
    "fresnel_reflectance",
    "microfacet_distribution",
    "geometric_attenuation",
    "ts_reflection",
    "ts_transmission",
    "fresnel_diffuse_reflectance",
    "dipole_profile",
    "dipole_total_reflectance",
    "check_directions",
]

UNIT_TOLERANCE = 1e-6
"""How far ``|w|`` may stray from 1 before a direction is rejected."""


# --------------------------------------------------------------------------------------------
# Parameter types
# --------------------------------------------------------------------------------------------
def _parameter(name: str, value, low: float, high: float, *, low_open: bool, high_open: bool):
    """Validate one layer field: a finite scalar or RGB triple within ``[low, high]``."""
    array = np.asarray(value, dtype=float)
    if array.shape not in ((), (3,)):
        raise ValueError(f"{name} must be a float or an RGB triple, got shape {array.shape}")
    below = array <= low if low_open else array < low
    above = array >= high if high_open else array > high
    if not np.all(np.isfinite(array)) or np.any(below) or np.any(above):
        lo = "(" if low_open else "["
        hi = ")" if high_open else "]"
        raise ValueError(f"{name} must lie in {lo}{low:g}, {high:g}{hi}, got {value!r}")
    array = array.copy()
    array.setflags(write=False)
    return array


class _Layer:
    """Shared behaviour of the parameter types: validation and channel shape."""

    _ranges: dict[str, tuple[float, float, bool, bool]] = {}

    def __post_init__(self):
        for field in fields(self):
            low, high, low_open, high_open = self._ranges[field.name]
            checked = _parameter(
                field.name, getattr(self, field.name), low, high,
                low_open=low_open, high_open=high_open,
            )
            object.__setattr__(self, field.name, checked)

    @property
    def channels(self) -> tuple[int, ...]:
        """``()`` when every field is scalar, ``(3,)`` when any is RGB."""
        return (3,) if any(getattr(self, f.name).shape == (3,) for f in fields(self)) else ()

    def channel(self, index: int):
        """The same layer restricted to one RGB channel (scalars stay as they are)."""
        values = {
            f.name: (v[index] if (v := getattr(self, f.name)).shape == (3,) else v)
            for f in fields(self)
        }
        return type(self)(**values)

    def scaled(self, **factors):
        """A copy with the named fields multiplied by ``factors`` (scalar or RGB)."""
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        for name, factor in factors.items():
            values[name] = values[name] * np.asarray(factor, dtype=float)
        return type(self)(**values)

    def as_dict(self) -> dict:
        """Fields as plain floats or lists, for metadata and parameter files."""
        return {f.name: getattr(self, f.name).tolist() for f in fields(self)}


_POSITIVE = (0.0, np.inf, True, True)
_NON_NEGATIVE = (0.0, np.inf, False, True)


@dataclass(frozen=True, eq=False)
class ReflectionLayer(_Layer):
    """Torrance-Sparrow reflecting layer (paper eq. 2).

    ``P_d``, ``P_s``: diffuse and specular scale (any consistent unit; counts in the paper,
    1/sr once normalised); ``n``: roughness in 1/degree (the lobe's 1/e half-width is 1/n
    degrees); ``eta``: relative refractive index.
    """

    P_d: object
    P_s: object
    n: object
    eta: object

    _ranges = {"P_d": _NON_NEGATIVE, "P_s": _NON_NEGATIVE, "n": _POSITIVE, "eta": _POSITIVE}


@dataclass(frozen=True, eq=False)
class TransmissionLayer(_Layer):
    """Thin transmitting film (paper eq. 4): diffuse ``P_d`` plus a lobe ``P_t`` of roughness
    ``n`` (1/degree) around the straight-through direction, with Fresnel transmission at
    ``eta``."""

    P_d: object
    P_t: object
    n: object
    eta: object

    _ranges = {"P_d": _NON_NEGATIVE, "P_t": _NON_NEGATIVE, "n": _POSITIVE, "eta": _POSITIVE}


@dataclass(frozen=True, eq=False)
class Dipole(_Layer):
    """Dipole subsurface scattering (paper eq. 6): ``sigma_s``, ``sigma_a`` in 1/mm, phase
    asymmetry ``g`` in (-1, 1), relative refractive index ``eta`` >= 1 (the ``F_dr`` fit of
    eq. 6 holds for eta >= 1)."""

    sigma_s: object
    sigma_a: object
    g: object = 0.0
    eta: object = 1.3

    _ranges = {
        "sigma_s": _NON_NEGATIVE,
        "sigma_a": _NON_NEGATIVE,
        "g": (-1.0, 1.0, True, True),
        "eta": (1.0, np.inf, False, True),
    }

    def __post_init__(self):
        super().__post_init__()
        if np.any(self.sigma_s * (1.0 - self.g) + self.sigma_a <= 0.0):
            raise ValueError(
                "sigma_s * (1 - g) + sigma_a must be > 0 (1/mm): the medium must interact"
            )


# --------------------------------------------------------------------------------------------
# Helpers
# --------------------------------------------------------------------------------------------
def check_directions(name: str, w) -> np.ndarray:
    """Return ``w`` as a float array of unit vectors ``(..., 3)`` or raise ``ValueError``."""
    w = np.asarray(w, dtype=float)
    if w.ndim == 0 or w.shape[-1] != 3:
        raise ValueError(f"{name} must have shape (..., 3), got {w.shape}")
    if not np.all(np.isfinite(w)):
        raise ValueError(f"{name} must be finite unit vectors; it holds NaN or Inf")
    norm = np.linalg.norm(w, axis=-1)
    if np.any(np.abs(norm - 1.0) > UNIT_TOLERANCE):
        worst = float(np.max(np.abs(norm - 1.0)))
        raise ValueError(f"{name} must be unit vectors (|w| = 1 within 1e-6), off by {worst:.3g}")
    return w


def _channel_axis(x: np.ndarray, layer: _Layer) -> np.ndarray:
    """Append a channel axis to a per-direction array when the layer is RGB."""
    return x[..., None] if layer.channels else x


def _half_vector(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Normalised ``a + b``; the normal where ``a + b`` vanishes (opposite horizontal pair)."""
    h = a + b
    length = np.linalg.norm(h, axis=-1, keepdims=True)
    safe = length > 1e-12
    return np.where(safe, h / np.where(safe, length, 1.0), np.array([0.0, 0.0, 1.0]))


def _angle_from_normal_deg(cos_angle: np.ndarray) -> np.ndarray:
    """Angle (degrees) of a unit vector with z-component ``cos_angle`` from the normal."""
    return np.degrees(np.arccos(np.clip(cos_angle, -1.0, 1.0)))


# --------------------------------------------------------------------------------------------
# Formulas
# --------------------------------------------------------------------------------------------
def fresnel_reflectance(cos_theta, eta):
    """Unpolarised dielectric Fresnel reflectance ``F_r(c, eta)`` (paper eq. 2).

    ``cos_theta`` in [0, 1] is the cosine between the direction and the (micro)normal on the
    incident side; ``eta`` > 0 the relative index.  The two broadcast by numpy's rules.  Total
    internal reflection (``eta < 1`` beyond the critical angle) gives 1; ``eta = 1`` (no
    interface) gives 0 at every angle, grazing included.

    >>> float(fresnel_reflectance(1.0, 1.5))  # ((1.5 - 1) / (1.5 + 1))^2
    0.04
    """
    c = np.asarray(cos_theta, dtype=float)
    eta = np.asarray(eta, dtype=float)
    if np.any(np.isnan(c)) or np.any((c < -UNIT_TOLERANCE) | (c > 1.0 + UNIT_TOLERANCE)):
        raise ValueError("cos_theta must lie in [0, 1]")
    if not np.all(np.isfinite(eta)) or np.any(eta <= 0.0):
        raise ValueError(f"eta must lie in (0, inf), got {eta!r}")
    return _fresnel(np.clip(c, 0.0, 1.0), eta)


def _fresnel(c: np.ndarray, eta: np.ndarray) -> np.ndarray:
    """:func:`fresnel_reflectance` without argument checks, for inner loops."""
    # g^2 = (eta^2 - 1) + c^2, with eta^2 - 1 = (eta - 1)(eta + 1): no cancellation near
    # eta = 1 (where g -> c and F -> 0), and no underflow of c^2 for eta >= 1 (hypot).
    excess = (eta - 1.0) * (eta + 1.0)
    g2 = excess + c * c
    g = np.where(excess >= 0.0, np.hypot(np.sqrt(np.maximum(excess, 0.0)), c),
                 np.sqrt(np.maximum(g2, 0.0)))
    gpc = g + c
    gmc = g - c
    with np.errstate(divide="ignore", invalid="ignore"):
        first = 0.5 * (gmc / gpc) ** 2
        second = 1.0 + ((c * gpc - 1.0) / (c * gmc + 1.0)) ** 2
        f = first * second
    # g2 < 0 is total internal reflection.  Otherwise g + c = 0 only at eta = 1 and grazing,
    # where the formula is 0/0: with no interface nothing is reflected.
    f = np.where(g2 < 0.0, 1.0, np.where(gpc > 0.0, f, 0.0))
    return np.clip(f, 0.0, 1.0)


def microfacet_distribution(angle_deg, n):
    """Torrance-Sparrow facet distribution ``D = exp(-(angle n)^2)`` (paper eq. 2, eq. 4).

    ``angle_deg`` is alpha (or beta for transmission) in degrees, ``n`` in 1/degree.
    """
    angle = np.asarray(angle_deg, dtype=float)
    n = np.asarray(n, dtype=float)
    if not np.all(np.isfinite(angle)):
        raise ValueError("angle_deg must be finite angles (degrees)")
    if not np.all(np.isfinite(n)) or np.any(n <= 0.0):
        raise ValueError(f"n must lie in (0, inf) (1/degree), got {n!r}")
    return _distribution(angle, n)


def _distribution(angle_deg: np.ndarray, n) -> np.ndarray:
    """:func:`microfacet_distribution` without argument checks, for inner loops."""
    return np.exp(-np.square(angle_deg * n))


def geometric_attenuation(n_dot_h, n_dot_v, n_dot_l, v_dot_h):
    """Torrance-Sparrow shadowing/masking ``G = min(1, 2 NH NV / VH, 2 NH NL / VH)`` (eq. 2).

    Arguments are cosines in [0, 1].  Where ``VH`` is 0 (an opposite horizontal pair) G is 0.
    """
    cosines = np.broadcast_arrays(*(np.asarray(x, dtype=float)
                                    for x in (n_dot_h, n_dot_v, n_dot_l, v_dot_h)))
    if any(np.any(~((x >= 0.0) & (x <= 1.0 + UNIT_TOLERANCE))) for x in cosines):
        raise ValueError("n_dot_h, n_dot_v, n_dot_l and v_dot_h must lie in [0, 1]")
    return _attenuation(*cosines)


def _attenuation(n_dot_h, n_dot_v, n_dot_l, v_dot_h) -> np.ndarray:
    """:func:`geometric_attenuation` without argument checks, for inner loops."""
    n_dot_h, n_dot_v, n_dot_l, v_dot_h = np.broadcast_arrays(n_dot_h, n_dot_v, n_dot_l, v_dot_h)
    safe = v_dot_h > 1e-12
    ratio = 2.0 * n_dot_h * np.minimum(n_dot_v, n_dot_l) / np.where(safe, v_dot_h, 1.0)
    return np.where(safe, np.clip(ratio, 0.0, 1.0), 0.0)


def ts_reflection(wi, wo, layer: ReflectionLayer):
    """Torrance-Sparrow BRDF ``f_r = P_d + P_s D G F_r`` (paper eq. 2), without the cosine.

    ``wi``, ``wo``: unit vectors ``(..., 3)``; where either lies below the surface (z < 0) the
    value is 0.  Units are those of ``P_d``/``P_s``.
    """
    wi = check_directions("wi", wi)
    wo = check_directions("wo", wo)
    return _ts_reflection(wi, wo, layer)


def _ts_reflection(wi: np.ndarray, wo: np.ndarray, layer: ReflectionLayer) -> np.ndarray:
    wi, wo = np.broadcast_arrays(wi, wo)
    h = _half_vector(wi, wo)
    n_dot_h = h[..., 2]
    n_dot_l = wi[..., 2]
    n_dot_v = wo[..., 2]
    v_dot_h = np.clip(np.sum(wo * h, axis=-1), 0.0, 1.0)
    alpha = _angle_from_normal_deg(n_dot_h)
    geometry = _attenuation(n_dot_h, n_dot_v, n_dot_l, v_dot_h)
    d = _distribution(_channel_axis(alpha, layer), layer.n)
    f = _fresnel(_channel_axis(v_dot_h, layer), layer.eta)
    value = layer.P_d + layer.P_s * d * _channel_axis(geometry, layer) * f
    upper = (n_dot_l >= 0.0) & (n_dot_v >= 0.0)
    return np.where(_channel_axis(upper, layer), value, 0.0)


def ts_transmission(wi, wt, layer: TransmissionLayer):
    """Thin-film BTDF ``f_t = P_d + P_t D(beta) F_t`` (paper eq. 4), without the cosine.

    ``wi`` above the film (z > 0) and ``wt`` below (z < 0); the film is symmetric, so the pair
    mirrored through the film plane gives the same value (light crossing upward).  Pairs on the
    same side evaluate to 0.  ``beta`` is the angle (degrees) between the normal and the half
    vector of ``wi`` and ``wt`` mirrored through the film plane; ``F_t = 1 - F_r``; no ``G``.
    """
    wi = check_directions("wi", wi)
    wt = check_directions("wt", wt)
    return _ts_transmission(wi, wt, layer)


def _ts_transmission(wi: np.ndarray, wt: np.ndarray, layer: TransmissionLayer) -> np.ndarray:
    wi, wt = np.broadcast_arrays(wi, wt)
    crossing = wi[..., 2] * wt[..., 2] <= 0.0
    # Upward crossing (``wi`` below, or on the horizon with ``wt`` above): mirror the pair.
    flip = np.where(wi[..., 2:3] < wt[..., 2:3], -1.0, 1.0)
    top = wi * np.concatenate([np.ones_like(flip), np.ones_like(flip), flip], axis=-1)
    mirrored = wt * np.concatenate([np.ones_like(flip), np.ones_like(flip), -flip], axis=-1)
    h = _half_vector(top, mirrored)
    beta = _angle_from_normal_deg(h[..., 2])
    c = np.clip(np.sum(mirrored * h, axis=-1), 0.0, 1.0)
    d = _distribution(_channel_axis(beta, layer), layer.n)
    f_t = 1.0 - _fresnel(_channel_axis(c, layer), layer.eta)
    value = layer.P_d + layer.P_t * d * f_t
    return np.where(_channel_axis(crossing, layer), value, 0.0)


def fresnel_diffuse_reflectance(eta):
    """Diffuse Fresnel reflectance ``F_dr = -1.440/eta^2 + 0.710/eta + 0.668 + 0.0636 eta``
    (paper eq. 6; Jensen 2001 eq. 5), for eta >= 1."""
    eta = np.asarray(eta, dtype=float)
    return -1.440 / eta**2 + 0.710 / eta + 0.668 + 0.0636 * eta


def _dipole_terms(skin: Dipole):
    """Derived dipole quantities of eq. 6: reduced albedo a', reduced extinction s_t' (1/mm),
    ``k = s_tr / s_t' = sqrt(3 (1 - a'))`` and A.  (z_r = 1/s_t', z_v = z_r (1 + 4A/3).)"""
    sigma_s_reduced = skin.sigma_s * (1.0 - skin.g)
    sigma_t_reduced = sigma_s_reduced + skin.sigma_a
    albedo = sigma_s_reduced / sigma_t_reduced
    k = np.sqrt(3.0 * skin.sigma_a / sigma_t_reduced)
    f_dr = fresnel_diffuse_reflectance(skin.eta)
    a = (1.0 + f_dr) / (1.0 - f_dr)
    return albedo, sigma_t_reduced, k, a


def dipole_profile(d_mm, skin: Dipole):
    """Dipole diffuse reflectance ``R(d)`` in 1/mm^2 at distance ``d_mm`` >= 0 (paper eq. 6).

    ``d_mm`` of any shape; RGB dipoles add a trailing channel axis.  Finite at d = 0.
    """
    d = np.asarray(d_mm, dtype=float)
    if np.any(np.isnan(d)) or np.any(d < 0.0):
        raise ValueError("d_mm must be distances >= 0 (mm)")
    albedo, sigma_t_reduced, k, a = _dipole_terms(skin)
    # Lengths in reduced mean free paths 1/s' (s' = sigma_t' in 1/mm): z_r s' = 1, z_v s' =
    # 1 + 4A/3, s_tr / s' = k, so R = a' s'^2 / (4 pi) sum z (k + 1/r) e^(-k r) / r^2 with
    # dimensionless r = hypot(d s', z): no overflow as s' -> 0 (z_r -> inf).
    x = _channel_axis(d, skin) * sigma_t_reduced
    total = 0.0
    for z in (1.0, 1.0 + 4.0 * a / 3.0):
        r = np.hypot(x, z)
        with np.errstate(invalid="ignore"):  # k = 0 with r = inf: no decay
            decay = np.exp(-np.where(k > 0.0, k * r, 0.0))
        total = total + z / (r * r) * (k + 1.0 / r) * decay
    return albedo * sigma_t_reduced**2 / (4.0 * np.pi) * total


def dipole_total_reflectance(skin: Dipole):
    """Total diffuse reflectance ``Rd = 2 pi Int_0^inf R(d) d dd`` in closed form (Jensen 2001
    eq. 6 integrated): ``Rd = a'/2 (1 + exp(-4/3 A sqrt(3(1 - a')))) exp(-sqrt(3(1 - a')))``."""
    albedo, _, root, a = _dipole_terms(skin)
    return 0.5 * albedo * (1.0 + np.exp(-4.0 / 3.0 * a * root)) * np.exp(-root)
