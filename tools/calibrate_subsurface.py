"""Measure how Cycles' subsurface methods blur a shadow edge, against the replicas in
lut_baker.closures.cycles (Burley's profile at d = radius / (4 pi); random walks as a Burley
profile of radius k(albedo) x radius, k measured here).

Usage::

    python tools/calibrate_subsurface.py [--samples 256] [--albedo 0.2 0.5 0.8 0.95]

The scene and the replica are tests/support/subsurface_edge.py's (shared with the tests): a
thick slab with a Subsurface Scattering material of radius 10 mm lit up to a straight shadow
edge, the rendered edge response against
:func:`lut_baker.closures.profiles.edge_response` of the replica's profile.  Prints, per method
and albedo, the RMS difference from the replica and the Burley radius factor k that fits best
(on a grid of ratio 1.08).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO_ROOT = Path(__file__).resolve().parent.parent
for _path in (REPO_ROOT, REPO_ROOT / "tests"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

from support.subsurface_edge import RADIUS_M, render_edge, replica_edge  # noqa: E402

__all__ = ["main"]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", type=int, default=256)
    parser.add_argument("--albedo", type=float, nargs="+", default=[0.2, 0.5, 0.8, 0.95])
    parser.add_argument("--methods", nargs="+",
                        default=["BURLEY", "RANDOM_WALK", "RANDOM_WALK_SKIN"])
    args = parser.parse_args(argv)
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="calibrate_"))
    import bpy

    print(f"Cycles {bpy.app.version_string}, {args.samples} samples")
    print("method            albedo  rms vs replica  best k (Burley radius factor)  rms at k")
    for method in args.methods:
        for albedo in args.albedo:
            x, measured = render_edge(method, albedo, args.samples)
            near = np.abs(x) < 3 * RADIUS_M * 1e3
            rms = np.sqrt(np.mean((measured - replica_edge(x, method, albedo))[near] ** 2))
            # The factor is relative to the replica's own radius (1 = the replica is right).
            trials = [(np.sqrt(np.mean((measured - replica_edge(x, method, albedo, k))[near]
                                       ** 2)), k) for k in np.geomspace(0.2, 5.0, 43)]
            best_rms, best_k = min(trials)
            print(f"{method:17s} {albedo:6.2f}  {rms:14.4f}  {best_k:29.3f}  {best_rms:8.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
