"""The film as a slab (lut_baker.model.film_slab; docs/model.md, "The film as a slab"): how
closely it gives the measured film back, its energy at every thickness, its thick limit and the
presets that limit implies, and what a thickness costs (a benchmark that prints figures).

    python bench/film_slab.py [--grid PANELS POINTS N_PHI] [--repeat N]

Printed:

- the free film of the paper's thickness against the measured one (eq. 2's P_d, eq. 4):
  directional albedos per incidence, and the transmission's shape in the plane at the paper's
  incidences (0, 30, 60 degrees), for the exact slab and the passive one;
- the largest R + T of the free film and the largest made-up albedo over a white skin
  (white furnace) at thicknesses from 0.5 to 15000 micrometres;
- the thick limit under uniform light, against the stacked film of lut_baker.model.thick_layer;
- the measured presets' absorptions re-derived as the slab's thick limit, and how far they move;
- timings: the body at a new absorption (all orders), at a new thickness, made-up skin at a new
  thickness, the thick-limit solve; on the bake's default quadrature and on the exact
  evaluator's grid for the paper's film.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from lut_baker.model import film_slab as FS  # noqa: E402
from lut_baker.model import presets  # noqa: E402
from lut_baker.model import thick_layer as TL  # noqa: E402
from lut_baker.model.albedo import grid_for  # noqa: E402
from lut_baker.model.layers import ReflectionLayer  # noqa: E402
from lut_baker.model.microfacet import ts_transmission  # noqa: E402
from lut_baker.numerics import adding_doubling as AD  # noqa: E402
from lut_baker.numerics.geometry import direction  # noqa: E402
from lut_baker.numerics.quadrature import hemisphere_panels  # noqa: E402

THICKNESSES_UM = (0.5, 2.0, 5.0, FS.DEFAULT_THICKNESS_UM, 20.0, 45.0, 75.0, 150.0, 450.0,
                  1500.0, 15000.0)
WHITE_SKIN = ReflectionLayer(P_d=1.0 / np.pi, P_s=0.0, n=0.05, eta=1.3)


def _best_of(function, repeat: int) -> float:
    """The shortest of ``repeat`` runs, milliseconds."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return 1e3 * min(times)


def albedo_errors(grid, passive: bool):
    """Relative error of the free film's directional albedos at the paper's thickness, per
    node: ``(theta_deg, reflection, transmission)``."""
    base = presets.paper()
    film = FS.film_slab(base.film, base.film_transmission, grid, passive=passive)
    scale0 = AD.star_scale(grid)[0]
    r_meas, t_meas = FS.measured_body_matrices(base.film, base.film_transmission, grid)
    r, t = FS.free_film_matrices(film, 1.0)
    er = AD.star_albedo(r[:, 0], scale0) / AD.star_albedo(r_meas[:, 0], scale0) - 1.0
    et = AD.star_albedo(t[:, 0], scale0) / AD.star_albedo(t_meas[:, 0], scale0) - 1.0
    return np.degrees(grid.theta), er[0], et[0]


def in_plane_shape(grid, passive: bool) -> dict:
    """The transmission kernel in the plane of incidence at the grid's nodes nearest 0, 30 and
    60 degrees against eq. 4 there: rms and worst of ``slab / eq. 4 - 1`` over exit angles up
    to 80 degrees, both divided by their own albedo (the shape alone).  The exit node at the
    incident polar angle is left out (on both sides): there the slab holds the light no
    scattering deflected (a delta, about exp(-7.8) of it), which eq. 4 has no term for."""
    base = presets.paper()
    film = FS.film_slab(base.film, base.film_transmission, grid, passive=passive)
    scale = AD.star_scale(grid)
    _, t = FS.free_film_matrices(film, 1.0)
    kernel = AD.from_star(t[0], scale)  # (orders, N, N) in 1/sr
    m = np.arange(kernel.shape[0])
    theta = grid.theta
    out = {}
    for incidence in (0.0, 30.0, 60.0):
        i = int(np.argmin(np.abs(np.degrees(theta) - incidence)))
        values, measured = [], []
        for phi in (0.0, np.pi):  # both sides of the straight-through direction
            exits = (np.degrees(theta) <= 80.0) & (np.arange(theta.size) != i)
            values.append(np.einsum("mo,m->o", kernel[:, i, exits], np.cos(m * phi)))
            wi = direction(theta[i], 0.0)
            u = direction(theta[exits], phi)
            measured.append(ts_transmission(np.broadcast_to(wi, u.shape), -u,
                                            base.film_transmission))
        values = np.concatenate(values)
        measured = np.concatenate(measured)
        t_slab = AD.star_albedo(t[0, 0], scale[0])[i]
        _, t_meas = FS.measured_body_matrices(base.film, base.film_transmission, grid)
        t_ref = AD.star_albedo(t_meas[0, 0], scale[0])[i]
        ratio = (values / t_slab) / (measured / t_ref) - 1.0
        out[round(float(np.degrees(theta[i])), 1)] = (float(np.sqrt(np.mean(ratio**2))),
                                                      float(np.max(np.abs(ratio))))
    return out


def energy(grid, passive: bool):
    """Per thickness (micrometres): the free film's largest R + T (gloss included) and the
    largest made-up albedo over a white Lambertian skin, no absorption."""
    base = presets.paper()
    film = FS.film_slab(base.film, base.film_transmission, grid, passive=passive)
    scale0 = AD.star_scale(grid)[0]
    rows = []
    for um in THICKNESSES_UM:
        x = FS.relative_thickness(um)
        r, t = FS.free_film_matrices(film, x)
        total = film.measured_face + AD.star_albedo(r[:, 0], scale0) + AD.star_albedo(t[:, 0],
                                                                                      scale0)
        rows.append((um, float(total.max()), float(FS.made_up_albedo(film, x, WHITE_SKIN).max())))
    return rows


def thick_limits(grid):
    base = presets.paper()
    exact = FS.film_slab(base.film, base.film_transmission, grid, passive=False)
    passive = FS.film_slab(base.film, base.film_transmission, grid)
    return {
        "stacked film (thick_layer)": float(TL.stack_reflectance(0.0, TL.paper_film_exchange())),
        "slab, exact": float(FS.bihemispherical_on_grid(FS.thick_limit_albedo(exact), grid)[0]),
        "slab, passive": float(FS.bihemispherical_on_grid(FS.thick_limit_albedo(passive),
                                                          grid)[0]),
    }


def preset_movement(grid):
    """Per measured product: stored absorption, the slab's thick limit under the paper film's
    surface and under the product's own surface, and which channels are out of reach."""
    base = presets.paper()
    stored = json.loads(presets.MEASURED_FOUNDATIONS_FILE.read_text())["foundations"]
    rows = []
    for name, entry in stored.items():
        target = np.array(entry["target"])
        paper_face, clamped = FS.solve_thick_absorption(target, base.film, base.film_transmission,
                                                        grid)
        own = FS.face_albedo(presets.foundation_film(name), grid)
        own_face, own_clamped = FS.solve_thick_absorption(target, base.film,
                                                          base.film_transmission, grid, face=own)
        rows.append((name, np.array(entry["absorption"]), paper_face, clamped, own_face,
                     own_clamped))
    return rows


def timings(grid, repeat: int) -> dict:
    base = presets.paper()
    skin = presets.paper().skin_reflection
    FS.film_slab(base.film, base.film_transmission, grid)  # the measured matrices, cached
    film = FS.film_slab(base.film, base.film_transmission, grid, absorption=(0.1, 0.2, 0.3))
    FS.made_up_matrices(film, 0.1, skin)  # the skin's kernel, cached
    x = FS.relative_thickness(FS.DEFAULT_THICKNESS_UM)
    return {
        "film_slab (new absorption, RGB, all orders)": _best_of(
            lambda: FS.film_slab(base.film, base.film_transmission, grid,
                                 absorption=(0.1, 0.2, 0.3)), repeat),
        "body at a new thickness (RGB)": _best_of(lambda: FS.body(film, x), repeat),
        "made-up skin at a new thickness (RGB)": _best_of(
            lambda: FS.made_up_matrices(film, x, skin), repeat),
        "thick-limit absorption solve (RGB)": _best_of(
            lambda: FS.solve_thick_absorption((0.7, 0.5, 0.4), base.film,
                                              base.film_transmission, grid), max(1, repeat // 3)),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grid", type=int, nargs=3, default=(3, 10, 33),
                        metavar=("PANELS", "POINTS", "N_PHI"),
                        help="quadrature of the slab (default: the bake's default resolution)")
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)
    grid = hemisphere_panels(*args.grid)
    print(f"# slab grid: {grid.theta.size} polar nodes, {grid.orders} Fourier orders")
    print(f"# default thickness {FS.DEFAULT_THICKNESS_UM:.2f} um "
          f"({FS.APPLIED_MASS_MG_PER_CM2:.3f} mg/cm^2 at {FS.FOUNDATION_DENSITY_G_PER_CM3} "
          f"g/cm^3); paper's film {FS.PAPER_FILM_THICKNESS_UM} um, optical thickness "
          f"{FS.PAPER_FILM_OPTICAL_THICKNESS:.2f}")

    print("\n## The free film at the paper's thickness against the measured film")
    for passive in (False, True):
        theta, er, et = albedo_errors(grid, passive)
        inside = theta <= 85.0
        print(f"{'passive' if passive else 'exact'}: directional albedo, relative error: "
              f"reflection worst {np.max(np.abs(er[inside])):.4f} up to 85 deg "
              f"({np.max(np.abs(er)):.4f} at any), transmission worst "
              f"{np.max(np.abs(et[inside])):.4f} up to 85 deg ({np.max(np.abs(et)):.4f})")
        keep = np.linspace(0, theta.size - 1, 8).astype(int)
        print("  theta  " + " ".join(f"{v:7.1f}" for v in theta[keep]))
        print("  R err  " + " ".join(f"{v:+7.4f}" for v in er[keep]))
        print("  T err  " + " ".join(f"{v:+7.4f}" for v in et[keep]))
        shape = in_plane_shape(grid, passive)
        print("  transmission shape in the plane (rms, worst of slab/eq.4 - 1, exits <= 80 deg): "
              + "; ".join(f"{k} deg: {v[0]:.4f}, {v[1]:.4f}" for k, v in shape.items()))

    print("\n## Energy, no absorption (largest over incidence)")
    for passive in (False, True):
        print(f"{'passive' if passive else 'exact'}:")
        print("  um       free film R+T   made-up over white skin")
        for um, film_total, furnace in energy(grid, passive):
            print(f"  {um:8.2f} {film_total:14.5f} {furnace:14.5f}")

    print("\n## Thick limit under uniform light, no absorption")
    for name, value in thick_limits(grid).items():
        print(f"  {name}: {value:.4f}")

    print("\n## Measured presets re-derived as the slab's thick limit")
    print("| product | stored A | slab, paper film's surface | moved | slab, own surface | moved |")
    print("| --- | --- | --- | --- | --- | --- |")
    for name, stored, paper_face, clamped, own, own_clamped in preset_movement(grid):
        def fmt(a, c):
            return " / ".join(f"{v:.4f}{'*' if k else ''}" for v, k in zip(a, c, strict=True))
        print(f"| {name} | {' / '.join(f'{v:.4f}' for v in stored)} | {fmt(paper_face, clamped)} "
              f"| {np.max(np.abs(paper_face - stored)):.4f} | {fmt(own, own_clamped)} | "
              f"{np.max(np.abs(own - stored)):.4f} |")
    print("(* out of reach: the thick film cannot be that light)")

    print("\n## Timings (best of runs, ms)")
    for label, g in (("bake's default quadrature", grid),
                     ("exact evaluator's grid (paper's film and skin)",
                      grid_for(presets.paper().film_transmission,
                               presets.paper().skin_reflection))):
        print(f"{label}: {g.theta.size} nodes, {g.orders} orders")
        for name, ms in timings(g, args.repeat).items():
            print(f"  {name}: {ms:.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
