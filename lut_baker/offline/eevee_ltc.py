"""EEVEE's GGX under a light, tabulated: linearly transformed cosines fitted to GGX.

EEVEE (4.2 - 5.0) does not evaluate the GGX lobe of a Glossy BSDF under a lamp: it evaluates a
linearly transformed cosine (LTC, Heitz, Dupuy, Hill and Neubelt 2016, "Real-Time
Polygonal-Light Shading with Linearly Transformed Cosines") read from a table fitted to GGX,
bilinearly in ``(roughness, sqrt(1 - cos(theta_o)))`` on 64 x 64 nodes.  The LTC drops GGX's
tails and cuts the lobe where the transformed direction leaves the hemisphere, so for broad
lobes EEVEE's sphere differs from Cycles' by 10-20% (docs/addon.md, "Why the Layered tier
breaks in EEVEE").  This module fits the same kind of table by the published method, so that
:mod:`lut_baker.closures.eevee` can replicate EEVEE's Glossy closure in numpy: rendered white
Glossy spheres in EEVEE 5.0.1 and 4.5 agree with the replica within about 1% RMS where GGX
itself differs by 6-19% (``tests/lut_baker/closures/test_eevee_renders.py``).

The method, per roughness (alpha = roughness^2) and view:

- the lobe ``f cos(theta_i)`` of GGX (height-correlated Smith, no Fresnel) has albedo
  ``magnitude`` and mean direction ``Z`` (both by the GGX importance sampler on a stratified
  32 x 32 grid);
- the LTC is ``D(w) = D_o(M^-1 w / |M^-1 w|) |det M^-1| / |M^-1 w|^3`` with the clamped cosine
  ``D_o = max(z, 0) / pi`` and ``M = [X Y Z] [[m11, 0, m13], [0, m22, 0], [0, 0, 1]]``,
  ``X = (Z_z, 0, -Z_x)``, ``Y = (0, 1, 0)`` (isotropic, ``m13 = 0``, at normal view);
- ``(m11, m22, m13)`` minimise the cubed difference of ``magnitude D`` and the lobe, sampled
  from both (multiple importance sampling, the same 32 x 32 grid), by Nelder-Mead, each fit
  starting from the previous view's (the normal view from the previous roughness's).

The table keeps ``M^-1`` divided by its middle entry (the LTC does not change when the matrix
is scaled): four entries per node, and the magnitude.

Functions
---------
- :func:`ggx_lobe` -- GGX's ``f cos(theta_i)`` and its sampling density.
- :func:`fit_node` -- the LTC of one roughness and view.
- :func:`fit_table` -- the whole table (minutes).
- :func:`write_table`, :data:`TABLE_FILE` -- the runtime's JSON file.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from scipy.optimize import minimize

from ..closures.eevee import LTC_TABLE_FILE, LTC_TABLE_SIZE

__all__ = ["SAMPLES", "MIN_ALPHA", "ggx_lobe", "ggx_sample", "fit_node", "fit_table",
           "write_table", "TABLE_FILE"]

TABLE_FILE = LTC_TABLE_FILE
SAMPLES = 32
"""Stratified samples per axis of the albedo, mean direction and error estimates."""
MIN_ALPHA = 1e-4
"""Smallest GGX alpha fitted (roughness 0 is a mirror)."""
_U = (np.arange(SAMPLES) + 0.5) / SAMPLES
U1, U2 = (u.ravel() for u in np.meshgrid(_U, _U, indexing="ij"))


def _smith_lambda(cos_theta, alpha: float):
    c = np.clip(np.asarray(cos_theta, float), 1e-9, 1.0)
    return 0.5 * (np.sqrt(1.0 + alpha * alpha * (1.0 - c * c) / (c * c)) - 1.0)


def ggx_lobe(view: np.ndarray, light: np.ndarray, alpha: float):
    """``(f cos(theta_i), pdf)`` of GGX with height-correlated Smith shadowing (no Fresnel) at
    unit ``light`` directions ``(K, 3)`` for one ``view`` ``(3,)`` (normal +z); ``pdf``: the
    density of :func:`ggx_sample` (visible normals not used: ``D cos(theta_h) / (4 h.v)``)."""
    lz = light[:, 2]
    g2 = np.where(lz > 0.0, 1.0 / (1.0 + _smith_lambda(view[2], alpha)
                                   + _smith_lambda(np.maximum(lz, 1e-9), alpha)), 0.0)
    h = light + view
    h = h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-300)
    c2 = h[:, 2] ** 2
    a2 = alpha * alpha
    d = np.where(h[:, 2] > 0.0, a2 / (np.pi * ((a2 - 1.0) * c2 + 1.0) ** 2), 0.0)
    pdf = np.abs(d * h[:, 2] / 4.0 / np.maximum(np.abs(h @ view), 1e-12))
    return d * g2 / 4.0 / view[2], pdf


def ggx_sample(view: np.ndarray, alpha: float) -> np.ndarray:
    """Light directions ``(SAMPLES^2, 3)``: normals drawn from GGX's ``D cos`` on the
    stratified grid, the view reflected about them."""
    phi = 2.0 * np.pi * U1
    r = alpha * np.sqrt(U2 / (1.0 - U2))
    n = np.stack([r * np.cos(phi), r * np.sin(phi), np.ones_like(r)], -1)
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    return 2.0 * n * (n @ view)[:, None] - view


class _Ltc:
    """One LTC: ``M`` from the parameters and frame, its inverse, evaluation and sampler."""

    def __init__(self, params, frame: np.ndarray, magnitude: float):
        m11, m22, m13 = params
        self.m = frame @ np.array([[m11, 0.0, m13], [0.0, m22, 0.0], [0.0, 0.0, 1.0]])
        self.inverse = np.linalg.inv(self.m)
        self.det_inverse = abs(np.linalg.det(self.inverse))
        self.magnitude = magnitude

    def value(self, light: np.ndarray) -> np.ndarray:
        """``magnitude D(light)``."""
        original = light @ self.inverse.T
        length = np.linalg.norm(original, axis=-1)
        return (self.magnitude * np.maximum(original[:, 2], 0.0) * self.det_inverse
                / (np.pi * length**4))

    def sample(self) -> np.ndarray:
        theta = np.arccos(np.sqrt(U1))
        phi = 2.0 * np.pi * U2
        cosine = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi),
                           np.cos(theta)], -1)
        light = cosine @ self.m.T
        return light / np.linalg.norm(light, axis=-1, keepdims=True)


def _error(ltc: _Ltc, view: np.ndarray, alpha: float) -> float:
    """Multiple-importance-sampled integral of ``|magnitude D - f cos|^3``."""
    total = 0.0
    for light in (ltc.sample(), ggx_sample(view, alpha)):
        lobe, pdf_lobe = ggx_lobe(view, light, alpha)
        fitted = ltc.value(light)
        total += float(np.sum(np.abs(lobe - fitted) ** 3
                              / np.maximum(fitted / ltc.magnitude + pdf_lobe, 1e-300)))
    return total / SAMPLES**2


def _magnitude_and_direction(view: np.ndarray, alpha: float):
    light = ggx_sample(view, alpha)
    lobe, pdf = ggx_lobe(view, light, alpha)
    weight = np.where(pdf > 0.0, lobe / np.maximum(pdf, 1e-300), 0.0)
    mean = weight @ light
    mean[1] = 0.0
    return float(np.mean(weight)), mean / np.linalg.norm(mean)


def fit_node(roughness: float, s: float, start=None, *, isotropic: bool = False):
    """``(params (m11, m22, m13), frame (3, 3), magnitude)`` of the LTC at Blender roughness
    ``roughness`` and view ``cos(theta_o) = 1 - s^2``, Nelder-Mead from ``start`` (default
    ``(alpha, alpha, 0)``); ``isotropic``: ``m11 = m22``, ``m13 = 0`` in the normal's frame
    (the normal view's lobe is symmetric)."""
    alpha = max(roughness * roughness, MIN_ALPHA)
    cos_o = max(1.0 - s * s, 1e-4)
    theta = min(np.arccos(cos_o), 1.57)
    view = np.array([np.sin(theta), 0.0, np.cos(theta)])
    magnitude, mean = _magnitude_and_direction(view, alpha)
    start = (alpha, alpha, 0.0) if start is None else tuple(start)
    options = {"xatol": 1e-6, "fatol": 1e-12, "maxiter": 800}
    if isotropic:
        frame = np.eye(3)

        def unpack(x):
            m = max(float(x[0]), MIN_ALPHA)
            return m, m, 0.0

        x0 = [start[0]]
    else:
        frame = np.stack([np.array([mean[2], 0.0, -mean[0]]), np.array([0.0, 1.0, 0.0]),
                          mean], 1)

        def unpack(x):
            return max(float(x[0]), MIN_ALPHA), max(float(x[1]), MIN_ALPHA), float(x[2])

        x0 = list(start)
    found = minimize(lambda x: _error(_Ltc(unpack(x), frame, magnitude), view, alpha), x0,
                     method="Nelder-Mead", options=options)
    return unpack(found.x), frame, magnitude


def _packed(params, frame) -> list[float]:
    """``M^-1`` divided by its middle entry: ``[m00, m02, m20, m22]``."""
    m11, m22, m13 = params
    inverse = np.linalg.inv(frame @ np.array([[m11, 0.0, m13], [0.0, m22, 0.0],
                                              [0.0, 0.0, 1.0]]))
    inverse = inverse / inverse[1, 1]
    return [float(inverse[0, 0]), float(inverse[0, 2]), float(inverse[2, 0]),
            float(inverse[2, 2])]


def fit_table(size: int = LTC_TABLE_SIZE, progress=None):
    """``(inverse (size, size, 4), magnitude (size, size))`` on roughness ``i / (size - 1)``
    (first axis) and ``s = j / (size - 1)``, ``cos(theta_o) = 1 - s^2`` (second axis); fitted
    from roughness 1 down and, per roughness, from the normal view out, each fit starting
    from its neighbour's.  ``progress(done, size)`` after each roughness."""
    nodes = np.arange(size) / (size - 1)
    inverse = np.zeros((size, size, 4))
    magnitude = np.zeros((size, size))
    normal = (1.0, 1.0, 0.0)
    for i in range(size - 1, -1, -1):
        start = None
        for j in range(size):
            if j == 0:
                params, frame, mag = fit_node(nodes[i], nodes[j], normal, isotropic=True)
                normal = params
            else:
                params, frame, mag = fit_node(nodes[i], nodes[j], start)
            inverse[i, j] = _packed(params, frame)
            magnitude[i, j] = mag
            start = params
        if progress is not None:
            progress(size - i, size)
    return inverse, magnitude


def write_table(path: Path = TABLE_FILE, size: int = LTC_TABLE_SIZE, progress=None) -> Path:
    """Fit the table and write it as JSON (7 significant digits): ``size``, ``inverse``
    (nested lists ``[roughness][s][4]``), ``magnitude`` (``[roughness][s]``) and how it was
    made."""
    inverse, magnitude = fit_table(size, progress)
    data = {
        "about": "EEVEE's GGX LTC table refitted by lut_baker.offline.eevee_ltc "
                 "(Heitz et al. 2016): M^-1 / M^-1[1][1] as [m00, m02, m20, m22] and the GGX "
                 "albedo, on roughness i/(size-1) and s = sqrt(1 - cos(theta_o)) = j/(size-1)",
        "size": size,
        "inverse": np.round(inverse, 7).tolist(),
        "magnitude": np.round(magnitude, 7).tolist(),
    }
    text = json.dumps(data, separators=(",", ":"))
    from .atomic_files import write_text

    write_text(path, text + "\n")
    return path
