"""How far the Auto tier's subsurface omission error (:func:`lut_baker.auto_tier.
subsurface_omission_error`) moves with its grid, and what each grid costs (a benchmark, not a
test).

    python bench/omission_grid.py [--grids 4/384 4/192 8/768] [--scales 0.5 1 2]

Each grid ``SUPERSAMPLE/MAX_CELLS`` (:data:`lut_baker.auto_tier.blur.SUPERSAMPLE`,
:data:`~lut_baker.auto_tier.blur.MAX_CELLS`) computes the error over the scenes of
:data:`FOOTPRINTS_MM` x :data:`SIZES_MM` x :data:`LIGHTS_DEG` (objects 2 to 4000 pixels
across) with the paper preset's profile (:func:`lut_baker.auto_tier.paper_traits`) at each
Subsurface Scale of ``--scales``.  Against the first grid it prints, per grid: the CPU seconds
of the whole sweep, the relative change (median, largest, largest where the first grid's error
is over 1%), and, over the scenes whose spread is under half a pixel (where the Auto tier
leaves the closure out if the error is small enough: :func:`lut_baker.auto_tier.
needs_subsurface`), the largest change in points of error.
"""

from __future__ import annotations

import argparse
import itertools
import statistics
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from lut_baker.auto_tier import blur, paper_traits, profile_mean_radius_mm  # noqa: E402

FOOTPRINTS_MM = (0.05, 0.2, 0.5, 1.0, 1.9, 4.0, 10.0)
SIZES_MM = (6.0, 60.0, 220.0, 400.0)
LIGHTS_DEG = (0.0, 45.0, 75.0)


def _errors(grid: tuple[int, int], scenes: list[tuple]) -> tuple[list[float], float]:
    """The error of every scene on ``grid`` ``(supersample, max_cells)`` and the CPU
    seconds it took."""
    kept = blur.SUPERSAMPLE, blur.MAX_CELLS
    blur.SUPERSAMPLE, blur.MAX_CELLS = grid
    try:
        start = time.process_time()
        values = [blur.subsurface_omission_error(footprint, size, light, radius, profile)
                  for footprint, size, light, radius, profile, _ in scenes]
        return values, time.process_time() - start
    finally:
        blur.SUPERSAMPLE, blur.MAX_CELLS = kept


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--grids", nargs="+", default=["4/384", "4/192", "8/768"],
                        help="SUPERSAMPLE/MAX_CELLS, the first the one compared against")
    parser.add_argument("--scales", nargs="+", type=float, default=[0.5, 1.0, 2.0],
                        help="Subsurface Scales of the paper preset's profile")
    args = parser.parse_args(argv)
    grids = [tuple(int(n) for n in text.split("/")) for text in args.grids]
    traits = paper_traits()
    scenes = []
    for footprint, size, light, scale in itertools.product(FOOTPRINTS_MM, SIZES_MM, LIGHTS_DEG,
                                                           args.scales):
        if not 2.0 <= size / footprint <= 4000.0:
            continue
        radius, profile = scale * traits.radius_mm, traits.profile / scale**2
        needed = profile_mean_radius_mm(radius, profile) >= 0.5 * footprint
        scenes.append((footprint, size, light, radius, profile, needed))
    print(f"{len(scenes)} scenes ({sum(s[-1] for s in scenes)} resolving the spread), "
          f"scales {args.scales}; against grid {args.grids[0]}")
    first: list[float] | None = None
    for text, grid in zip(args.grids, grids, strict=True):
        values, seconds = _errors(grid, scenes)
        if first is None:
            first = values
            print(f"  {text:>8}: {seconds:6.2f} s CPU, errors {min(values):.2e}-"
                  f"{max(values):.3f}")
            continue
        change = [abs(v / f - 1.0) for v, f in zip(values, first, strict=True)]
        over = [c for c, f in zip(change, first, strict=True) if f > 0.01]
        points = [abs(v - f) for v, f, s in zip(values, first, scenes, strict=True)
                  if not s[-1]]
        print(f"  {text:>8}: {seconds:6.2f} s CPU, relative change median "
              f"{statistics.median(change):.2%}, largest {max(change):.1%}, largest where "
              f"over 1% {max(over, default=0.0):.1%}; spread under half a pixel: largest "
              f"change {100 * max(points, default=0.0):.3f} points")
    return 0


if __name__ == "__main__":
    sys.exit(main())
