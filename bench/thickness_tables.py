"""The film as a slab in the tables (lut_baker.tables.slab_tables; docs/baking.md, "The film as
a slab in the tables"): what the thickness axis costs and how well it interpolates (a benchmark
that prints figures).

    python bench/thickness_tables.py [--resolution default] [--repeat 5]

Printed:

- the bake's CPU time with the paper's film and with the slab at every thickness (process
  time, best of ``--repeat``), and the slab block's size;
- a thickness change: the 1-D parts and the angular table at a new thickness from the tables
  (what a material needs to follow a Thickness slider or a painted map), CPU ms;
- Match Skin at a thickness (the exact order-0 solve), CPU ms;
- the colour under uniform light from the tables against the exact closed form, at the axis's
  nodes and halfway between them (geometric means), per channel.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from lut_baker import bake as B  # noqa: E402
from lut_baker.model import film_slab as FS  # noqa: E402
from lut_baker.model import presets  # noqa: E402
from lut_baker.model import slab_skin as SS  # noqa: E402
from lut_baker.numerics.quadrature import hemisphere_panels  # noqa: E402
from lut_baker.tables import slab_tables as ST  # noqa: E402

ABSORPTION = [0.1, 0.3, 0.5]


def _best_cpu_ms(function, repeat: int) -> float:
    """The least process time of ``repeat`` runs, milliseconds."""
    times = []
    for _ in range(repeat):
        start = time.process_time()
        function()
        times.append(time.process_time() - start)
    return 1e3 * min(times)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resolution", default="default")
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)
    skin = presets.made_up_skin("paper_natural", "jensen_skin1", absorption=ABSORPTION)
    res = B.resolution(args.resolution)
    grid = hemisphere_panels(res.quad_panels, res.quad_points, res.quad_phi)
    tables = B.bake(skin, res, film=FS.DEFAULT_THICKNESS_UM)
    slab = tables.slab
    paper_ms = _best_cpu_ms(lambda: B.bake(skin, res), args.repeat)
    slab_ms = _best_cpu_ms(lambda: B.bake_slab(skin.replace(absorption=[0.11, 0.3, 0.5]), res),
                           args.repeat)
    size = sum(np.asarray(getattr(slab, name)).nbytes for name in
               ("top", "top_albedo", "through", "through_mean", "below"))
    print(f"bake ({res.name}): paper film {paper_ms:.0f} ms CPU; the slab at "
          f"{slab.thickness_um.size} thicknesses adds {slab_ms:.0f} ms; "
          f"slab block {size / 1e6:.1f} MB float64 ({size / 2e6:.1f} MB float32), angular "
          f"grid {slab.theta_deg.size} x {slab.theta_deg.size} x {slab.phi_deg.size}")

    def change():
        h = float(np.random.uniform(1.0, 100.0))
        slab.at(h, slab.theta_deg)
        slab._along(slab.top, h)

    print(f"a thickness change (1-D parts + the angular table at it): "
          f"{_best_cpu_ms(change, 20):.2f} ms CPU")
    target = (0.661, 0.346, 0.243)
    albedo = np.array(target) - 0.0413
    match_ms = _best_cpu_ms(lambda: SS.matching_shade(
        target, skin.film, skin.film_transmission, skin.skin_reflection, albedo,
        FS.DEFAULT_THICKNESS_UM, grid), max(1, args.repeat // 2))
    print(f"Match Skin at 9.6 um (exact, order 0): {match_ms:.0f} ms CPU")

    print("\n| thickness um | exact colour | tables / exact - 1 (R, G, B) |")
    print("|---|---|---|")
    nodes = slab.thickness_um
    between = np.sqrt(nodes[:-2] * nodes[1:-1])
    a = np.pi * np.asarray(skin.skin_reflection.P_d)
    for h in sorted(list(nodes) + list(between) + [1000.0]):
        exact = SS.slab_colour(skin.film, skin.film_transmission, skin.skin_reflection, a, h,
                               grid, ABSORPTION)
        error = ST.slab_colour(tables, h) / exact - 1.0
        print(f"| {h:.3g} | {', '.join(f'{v:.4f}' for v in exact)} | "
              f"{', '.join(f'{v:+.2%}' for v in error)} |")


if __name__ == "__main__":
    main()
