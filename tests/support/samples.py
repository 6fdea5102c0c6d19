"""Sample layers, direction sets and table nodes shared by the lut_baker tests.

- :data:`RAW_REFLECTION`, :data:`RAW_TRANSMISSION` -- the paper's film and skin layers in raw
  counts (docs/model.md §5) and RGB layers of varied lobes and indices.
- :data:`DIPOLES` -- the paper's skin, Jensen's two skins, a nearly lossless one and one with
  forward scattering (``g = 0.8``).
- :func:`unit`, :func:`random_upper`, :func:`grazing_pairs` -- unit vectors, directions over
  the upper hemisphere, and pairs at or next to the horizon.
- :func:`layer_args` -- a layer's fields as floats (one channel), as
  :mod:`support.reference_impl` takes them.
- :func:`node_directions` -- ``(wi, wo)`` of every angular node of baked tables.
"""

from __future__ import annotations

import math

import numpy as np

from lut_baker.model import presets
from lut_baker.model.layers import Dipole, ReflectionLayer, TransmissionLayer
from lut_baker.numerics.geometry import direction

__all__ = ["RAW_REFLECTION", "RAW_TRANSMISSION", "DIPOLES", "unit", "random_upper",
           "grazing_pairs", "layer_args", "node_directions"]

RAW_REFLECTION = {
    "film": presets.PAPER_FILM_REFLECTION,
    "skin": presets.PAPER_SKIN_REFLECTION,
    "rgb": ReflectionLayer(P_d=(1.0e4, 2.0e4, 0.0), P_s=(9e5, 2e5, 5e4), n=(0.02, 0.04, 0.3),
                           eta=(1.19, 1.26, 1.6)),
}
RAW_TRANSMISSION = {
    "film": presets.PAPER_FILM_TRANSMISSION,
    "rgb": TransmissionLayer(P_d=(2.64e4, 1e4, 0.0), P_t=(1.08e4, 3e4, 1e5), n=(0.0346, 0.1, 1.0),
                             eta=(1.19, 1.5, 1.05)),
}
DIPOLES = {
    "paper": presets.PAPER_SKIN_DIPOLE,
    "jensen_skin1": Dipole(sigma_s=(0.74, 0.88, 1.01), sigma_a=(0.032, 0.17, 0.48), eta=1.3),
    "jensen_skin2": Dipole(sigma_s=(1.09, 1.59, 1.79), sigma_a=(0.013, 0.070, 0.145), eta=1.3),
    "tiny_sigma_a": Dipole(sigma_s=2.83, sigma_a=1e-9, eta=1.26),
    "forward_g": Dipole(sigma_s=5.0, sigma_a=0.1, g=0.8, eta=1.44),
}


def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def random_upper(rng, count):
    """Directions uniform over the upper hemisphere (z >= 0)."""
    v = unit(rng.normal(size=(count, 3)))
    v[:, 2] = np.abs(v[:, 2])
    return v


def grazing_pairs():
    """Pairs with one or both directions at 89.9 degrees or exactly on the horizon (z = 0)."""
    s, c = math.sin(math.radians(89.9)), math.cos(math.radians(89.9))
    near = [np.array([s * math.cos(p), s * math.sin(p), c]) for p in (0.0, 1.0, math.pi, 2.5)]
    horizon = [np.array([math.cos(p), math.sin(p), 0.0]) for p in (0.0, 0.7, math.pi, 4.0)]
    others = [np.array([0.0, 0.0, 1.0]), unit([0.3, -0.2, 0.9]), unit([-0.8, 0.1, 0.2])]
    pool = near + horizon + others
    return [(a, b) for a in pool for b in pool if (a[2] < 0.01 or b[2] < 0.01)]


def layer_args(layer, channel=None):
    """The layer's fields as floats (one channel) for the reference functions."""
    values = layer.as_dict()
    return [float(v[channel] if isinstance(v, list) else v) for v in values.values()]


def node_directions(t):
    """(wi, wo) of every angular node of the tables ``t``, shape (n, n, p, 3)."""
    theta = np.radians(t.theta_deg)
    wi = direction(theta[:, None, None], np.radians(t.node_azimuths()))
    wo = direction(theta[None, :, None], np.zeros((1, 1, 1)))
    return np.broadcast_arrays(wi, wo)
