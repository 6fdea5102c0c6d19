"""The matte products against a thick slab of a scattering medium instead of eq. 2 (a benchmark
that prints fit errors; docs/model.md, "The film as a slab"; docs/foundations/README.md).

    python bench/slab_matte_fit.py [--grid PANELS POINTS N_PHI]

For Clarins 103 and 108 (data/lanza2024, matte; eq. 2 fits them with P_d alone at 19.4% and
19.5% rms, 23.1% and 19.0% held out) this fits an infinitely thick slab of a medium with a
single-scattering albedo per channel and a two-lobe Henyey-Greenstein phase function (g1, g2,
weight; shared by the channels, as Lanza et al. 2024 fit theirs), no surface, by adding and
doubling (lut_baker.numerics.adding_doubling: the medium's transport matrices per Fourier
order, the slab's infinite-thickness limit), read in the plane of incidence by a bicubic spline
over the grid's polar nodes.  It prints the relative error (model/measured - 1) on every
incidence, and fitted on alternate incidences predicting the others, as
lut_baker/offline/foundations.py does for eq. 2.  Several starts; the best is printed.  About
9 minutes on two cores at the default grid.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from scipy.interpolate import RectBivariateSpline
from scipy.optimize import least_squares

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from lut_baker.numerics import adding_doubling as AD  # noqa: E402
from lut_baker.numerics.quadrature import hemisphere_panels, uniform_azimuths  # noqa: E402
from lut_baker.offline.foundations import PRODUCTS  # noqa: E402
from lut_baker.offline.measured.inplane import read_inplane  # noqa: E402
from lut_baker.offline.measured.inplane_fit import (  # noqa: E402
    alternate_incidences,
    relative_error,
)

DATA = ROOT / "data" / "lanza2024"
STARTS = ((-0.3, -0.2, 0.0), (0.5, -0.5, 0.0), (-0.1, 0.6, 0.5), (0.0, 0.0, 0.0))
"""Starts of (atanh g1, atanh g2, logit weight); the albedos start at logit 3, 2, 1."""


class ThickMedium:
    """An infinitely thick slab of a two-lobe Henyey-Greenstein medium on one grid."""

    def __init__(self, grid):
        self.grid = grid
        self.scale = AD.star_scale(grid)
        self.mu = np.cos(grid.theta)
        sin = np.sin(grid.theta)
        cos_phi = np.cos(uniform_azimuths(grid.n_phi))
        # cos of the angle between two downgoing directions (transmission-like: straight at
        # azimuth 0); between a downgoing and an upgoing one it is the negative.
        self.cos_between = (self.mu[:, None, None] * self.mu[None, :, None]
                            + sin[:, None, None] * sin[None, :, None] * cos_phi)
        self.theta_deg = np.degrees(grid.theta)

    def _fourier(self, values):
        spectrum = np.fft.rfft(values, axis=-1).real / self.grid.n_phi
        spectrum[..., 1:] *= 2.0
        return np.moveaxis(spectrum, -1, 0)

    @staticmethod
    def henyey_greenstein(g, cos_angle):
        """The Henyey-Greenstein phase function (1/sr, integrating to 1 over the sphere)."""
        return (1.0 - g * g) / (4.0 * np.pi * (1.0 + g * g - 2.0 * g * cos_angle) ** 1.5)

    def reflection(self, albedo, g1, g2, weight):
        """The thick slab's reflection kernel (1/sr) per channel and order."""
        def phase(c):
            return (weight * self.henyey_greenstein(g1, c)
                    + (1.0 - weight) * self.henyey_greenstein(g2, c))

        forward = self._fourier(phase(self.cos_between))
        back = self._fourier(phase(-self.cos_between))
        s = self.scale
        k = s[:, :, None] * s[:, None, :] / np.outer(self.mu, self.mu)
        single = np.asarray(albedo, float)[:, None, None, None]
        loss = np.eye(self.mu.size) / self.mu[:, None] - single * forward * k
        scatter = single * back * k
        # Per unit of full thickness, half the half slab's transport matrices.
        generator = AD.generator_from_matrices(0.5 * (loss + scatter), 0.5 * (loss - scatter))
        return AD.from_star(AD.thick_slab(generator), s)

    def in_plane(self, kernel, theta_i, theta_o):
        """Reflectance factors ``pi f_r`` at ``theta_i`` and signed ``theta_o`` (> 0: the
        mirror side, azimuth pi), ``(rows, channels)``."""
        m = np.arange(kernel.shape[1])
        out = np.empty((theta_i.size, kernel.shape[0]))
        mirror_side = theta_o >= 0.0
        for c in range(kernel.shape[0]):
            values = []
            for phi in (np.pi, 0.0):
                plane = np.einsum("mab,m->ab", kernel[c], np.cos(m * phi))
                spline = RectBivariateSpline(self.theta_deg, self.theta_deg, plane)
                values.append(spline.ev(theta_i, np.abs(theta_o)))
            out[:, c] = np.pi * np.where(mirror_side, values[0], values[1])
        return out


def unpack(p):
    return 1.0 / (1.0 + np.exp(-p[:3])), np.tanh(p[3]), np.tanh(p[4]), 1.0 / (1.0 + np.exp(-p[5]))


def fit(medium, theta_i, theta_o, rgb, rows, start):
    def residual(p):
        try:
            model = medium.in_plane(medium.reflection(*unpack(p)), theta_i[rows], theta_o[rows])
        except (ValueError, np.linalg.LinAlgError):
            return np.full(rgb[rows].size, 1e3)
        return (model / rgb[rows] - 1.0).ravel()

    return least_squares(residual, start, diff_step=1e-4, max_nfev=300).x


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grid", type=int, nargs=3, default=(6, 8, 65),
                        metavar=("PANELS", "POINTS", "N_PHI"))
    args = parser.parse_args(argv)
    medium = ThickMedium(hemisphere_panels(*args.grid))
    for name in ("clarins_103", "clarins_108"):
        data = read_inplane(DATA / PRODUCTS[name][0])
        ti, to, rgb = data.theta_i_deg, data.theta_o_deg, data.rgb
        every = np.ones(ti.size, bool)
        best = None
        for start in STARTS:
            p = fit(medium, ti, to, rgb, every, np.array([3.0, 2.0, 1.0, *start]))
            err = relative_error(medium.in_plane(medium.reflection(*unpack(p)), ti, to), rgb)
            if best is None or err[0] < best[0][0]:
                best = (err, p)
        (rms, worst), p = best
        albedo, g1, g2, weight = unpack(p)
        fitted, held = alternate_incidences(data.incidences_deg)
        q = fit(medium, ti, to, rgb, np.isin(ti, fitted), p)
        rows = np.isin(ti, held)
        held_rms, held_worst = relative_error(
            medium.in_plane(medium.reflection(*unpack(q)), ti[rows], to[rows]), rgb[rows])
        print(f"{name}: thick two-lobe HG slab, fit on every incidence {100 * rms:.1f}% rms, "
              f"{100 * worst:.1f}% worst; fitted on {fitted} predicting {held}: "
              f"{100 * held_rms:.1f}% rms, {100 * held_worst:.1f}% worst")
        print(f"  single-scattering albedo {np.round(albedo, 4)}, g1 {g1:.3f}, g2 {g2:.3f}, "
              f"weight of g1 {weight:.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
