"""Print the closure fits of the presets as Markdown tables (docs/addon.md lists them).

Usage::

    python tools/closure_report.py [--resolution default]

For every foundation on every skin: each tier's angular error against the tables (relative
RMS of ``f cos(theta_i)`` and largest view-albedo error, lut_baker.closures.fitting) at coverage 1,
0.5 and 0 with the shade's absorption; then per skin the Subsurface Radius each Blender method
needs and how far its edge response stays from the skin's dipole.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
if str(REPO_ROOT) not in sys.path:
    sys.path.insert(0, str(REPO_ROOT))

COVERAGES = (1.0, 0.5, 0.0)


def main(argv=None) -> int:
    from lut_baker import bake
    from lut_baker.closures import fitting, tiers
    from lut_baker.model import presets

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--resolution", default="default")
    args = parser.parse_args(argv)
    print("| foundation | skin | coverage | Principled RMS | Principled albedo | "
          "Layered RMS | Layered albedo |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    fits, seconds = {}, []
    for skin in presets.SKINS:
        for foundation in presets.FOUNDATIONS:
            made_up = presets.made_up_skin(foundation, skin)
            tables = bake.bake(made_up, args.resolution)
            start = time.perf_counter()
            fit = fitting.fit_closures(tables)
            seconds.append(time.perf_counter() - start)
            fits[skin] = fit
            for coverage in COVERAGES:
                errors = tiers.tier_errors(fit, tables, coverage, made_up.absorption)
                p, lay = errors["PRINCIPLED"], errors["LAYERED"]
                print(f"| {foundation} | {skin} | {coverage:g} | {100 * p.rms:.1f}% | "
                      f"{100 * p.albedo:.1f}% | {100 * lay.rms:.1f}% | {100 * lay.albedo:.1f}% |")
    print(f"\nfit time per preset ({args.resolution} tables): median "
          f"{sorted(seconds)[len(seconds) // 2]:.1f} s\n")
    print("| skin | method | Subsurface Radius R, G, B (mm) | edge RMS | edge max | chosen |")
    print("| --- | --- | --- | --- | --- | --- |")
    for skin, fit in fits.items():
        for method, profile in fit.profiles.items():
            radius = ", ".join(f"{r:.2f}" for r in profile.radius_mm)
            chosen = "yes" if method == fit.subsurface_method else ""
            print(f"| {skin} | {method} | {radius} | {100 * profile.worst_error:.2f}% | "
                  f"{100 * profile.max_error.max():.2f}% | {chosen} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
