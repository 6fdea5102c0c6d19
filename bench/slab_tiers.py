"""The tiers at a thickness (docs/model.md, "The tiers at a thickness"): each tier fitted to the
film as a slab at sheer, default and full thicknesses, against the slab's tables and against the
exact closed form (a benchmark that prints figures).

    python bench/slab_tiers.py [--resolution default] [--thickness 2 9.6 50 150]

Printed, per skin and thickness: each tier's relative RMS of ``f cos(theta_i)`` and largest
view-albedo error against the slab's tables (:func:`lut_baker.closures.tiers.tier_errors`, the
fitted skin at coverage 1), its colour under uniform light against the exact closed form
(:func:`lut_baker.model.slab_skin.slab_colour`, per channel, worst channel's relative error),
the fit's CPU time; and the paper's film (paths 1 + 3) on the same skin for comparison.
Then, per thickness, the fit at 9.6 um moved there without fitting
(:func:`lut_baker.closures.fitting.at_thickness`, what a Thickness slider costs): its CPU time
(best of 5) and the tiers' errors beside those of a fit made there.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from lut_baker import bake as B  # noqa: E402
from lut_baker.closures import fitting, tiers  # noqa: E402
from lut_baker.closures.view_grid import lobe_widths_deg, view_grid  # noqa: E402
from lut_baker.model import presets  # noqa: E402
from lut_baker.model import slab_skin as SS  # noqa: E402
from lut_baker.numerics.quadrature import hemisphere_panels  # noqa: E402

SKINS = (("paper_natural", "paper_bioplate", 0.0), ("medium_beige", "jensen_skin1", 0.0),
         ("paper_natural", "jensen_skin1", [0.1, 0.3, 0.5]))


def colour_error(fit, tables, name: str, exact: np.ndarray) -> float:
    """The tier's colour under uniform light (its view albedos, cosine-weighted over evenly
    spaced view cosines) against ``exact``: the worst channel's relative error."""
    grid = view_grid(min(lobe_widths_deg(tables).values()), 32)
    f = tiers.tier_replica(fit, tables, name, 1.0, 0.0, directions=grid.directions)
    colour = 2.0 * np.mean(grid.cos_view[:, None] * grid.view_albedo(f), axis=0)
    return float(np.max(np.abs(colour / exact - 1.0)))


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resolution", default="default")
    parser.add_argument("--thickness", type=float, nargs="+", default=[2.0, 9.6, 50.0, 150.0])
    args = parser.parse_args(argv)
    for foundation, skin_name, absorption in SKINS:
        skin = presets.made_up_skin(foundation, skin_name, absorption=absorption)
        print(f"\n{foundation} on {skin_name}, absorption {absorption}")
        paper = B.bake(skin, args.resolution)
        start = time.process_time()
        fit = fitting.fit_closures(paper)
        print(f"  paper film   fit {1e3 * (time.process_time() - start):6.0f} ms  "
              + "  ".join(f"{n} {e.rms:6.1%} {e.albedo:6.1%}" for n, e in fit.errors.items()))
        slab = B.bake(skin, args.resolution, film=args.thickness[0])
        res = B.resolution(args.resolution)  # the slab's quadrature (bake.bake_slab)
        grid = hemisphere_panels(res.quad_panels, res.quad_points, res.quad_phi)
        for h in args.thickness:
            tables = dataclasses.replace(slab, parameters={**slab.parameters,
                                                           "film_thickness_um": h})
            start = time.process_time()
            fit = fitting.fit_closures(tables)
            ms = 1e3 * (time.process_time() - start)
            exact = SS.slab_colour(skin.film, skin.film_transmission, skin.skin_reflection,
                                   fit.skin_albedo, h, grid, skin.absorption)
            print(f"  {h:6.1f} um    fit {ms:6.0f} ms  "
                  + "  ".join(f"{n} {e.rms:6.1%} {e.albedo:6.1%} (colour "
                              f"{colour_error(fit, tables, n, exact):5.1%})"
                              for n, e in fit.errors.items()))
        base = fitting.fit_closures(dataclasses.replace(
            slab, parameters={**slab.parameters, "film_thickness_um": 9.6}))
        for h in args.thickness:
            tables = dataclasses.replace(slab, parameters={**slab.parameters,
                                                           "film_thickness_um": h})
            times = []
            for _ in range(5):
                start = time.process_time()
                moved = fitting.at_thickness(base, tables, h)
                times.append(time.process_time() - start)
            errors = tiers.tier_errors(moved, tables, 1.0, 0.0)
            print(f"  9.6 -> {h:6.1f} um  {1e3 * min(times):5.1f} ms  "
                  + "  ".join(f"{n} {e.rms:6.1%} {e.albedo:6.1%}" for n, e in errors.items()))


if __name__ == "__main__":
    main()
