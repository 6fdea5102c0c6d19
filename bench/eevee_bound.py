"""How close any tier of EEVEE's closures can come to the model, beside the tiers themselves.

A benchmark, not a test::

    python bench/eevee_bound.py            # docs/eevee_bound.csv, the table in speed_accuracy.md
    python bench/eevee_bound.py --quick    # the paper preset only, nothing written

Per foundation of :data:`bench.eevee_tier.FOUNDATIONS` on the paper's bio-plate at coverage 0
(bare skin, once), 0.5 and 1, and per light (0, 45, 75 degrees from the view): the relative RMS
against the exact local image (paths 1 + 3 from "high" tables, no spread: the closures alone,
64 px, :func:`lut_baker.offline.validation.compare.local_image`) of

- the bound of EEVEE's closures and the bound of Cycles' closures
  (:func:`lut_baker.offline.validation.closure_bound.closure_bound`: the best non-negative,
  view-weighted sum of many Glossy lobes and a Lambertian term, fitted over all lights);
- the EEVEE tier's and the LAYERED tier's replicas (fitted to "default" tables, as Apply
  fits them).

Where EEVEE's bound exceeds a goal, no tier of EEVEE's closures meets it.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
for _path in (ROOT, ROOT / "bench"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

from doc_block import replace_block  # noqa: E402  (bench/doc_block.py)
from eevee_tier import FOUNDATIONS, LIGHTS_DEG, SKIN, write_csv  # noqa: E402

from lut_baker import bake  # noqa: E402
from lut_baker.closures import fitting, tiers  # noqa: E402
from lut_baker.model import presets  # noqa: E402
from lut_baker.offline.validation import compare  # noqa: E402
from lut_baker.offline.validation.closure_bound import bound_reflection, closure_bound  # noqa: E402

DOCS = ROOT / "docs"
BEGIN, END = "<!-- eevee-bound:begin -->", "<!-- eevee-bound:end -->"
SIZE = 64
GOAL = 0.02
"""The EEVEE tier's goal against the exact image."""
COLUMNS = ("eevee_bound", "cycles_bound", "eevee_tier", "layered_tier")
FIELDS = ("foundation", "coverage", "light_deg", *COLUMNS, "eevee_bound_grid")


def measure_case(foundation: str, coverage: float) -> list[dict]:
    """The rows of one foundation and coverage, one per light (module docstring)."""
    skin = presets.made_up_skin(foundation, SKIN, coverage=coverage)
    high = bake.bake(skin, "high")
    fit = fitting.fit_closures(bake.bake(skin, "default"))
    w, a = high.coverage_and_absorption()
    bounds = {name: closure_bound(high, w, a, name) for name in ("EEVEE", "CYCLES")}
    reflections = {
        "eevee_bound": bound_reflection(bounds["EEVEE"]),
        "cycles_bound": bound_reflection(bounds["CYCLES"]),
        "eevee_tier": lambda wi, wo: tiers.tier_replica(fit, high, "EEVEE", w, a,
                                                        directions=(wi, wo)),
        "layered_tier": lambda wi, wo: tiers.tier_replica(fit, high, "LAYERED", w, a,
                                                          directions=(wi, wo)),
    }
    rows = []
    for light in LIGHTS_DEG:
        exact = compare.local_image(lambda wi, wo: high.made_up_reflection(wi, wo, w, a),
                                    SIZE, light)
        row = {"foundation": foundation, "coverage": coverage, "light_deg": light}
        for name, reflection in reflections.items():
            row[name] = compare.relative_rms(compare.local_image(reflection, SIZE, light), exact)
        row["eevee_bound_grid"] = bounds["EEVEE"].error
        rows.append(row)
        print(" ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}"
                       for k, v in row.items()), flush=True)
    return rows


def markdown(rows, minutes: float) -> str:
    lines = [f"Measured by `python bench/eevee_bound.py` in {minutes:.1f} min: relative RMS "
             f"against the exact local image ({SIZE} px, no spread), skin {SKIN}.", "",
             "| foundation | coverage | light | bound of EEVEE's closures | bound of Cycles' "
             "closures | EEVEE tier | LAYERED tier |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['foundation']} | {r['coverage']:g} | {r['light_deg']:g} | "
                     + " | ".join(f"{100 * r[c]:.2f}%" for c in COLUMNS) + " |")
    over = [r for r in rows if r["eevee_bound"] > GOAL]
    lines += ["", f"EEVEE's bound exceeds {100 * GOAL:g}% in {len(over)} of {len(rows)} images"
              + (": " + ", ".join(sorted({f"{r['foundation']} at coverage {r['coverage']:g}"
                                          for r in over})) if over else "") + "."]
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="the paper preset only; nothing written to docs/")
    args = parser.parse_args(argv)
    start = time.perf_counter()
    foundations = FOUNDATIONS[:1] if args.quick else FOUNDATIONS
    rows = measure_case(foundations[0], 0.0)
    for foundation in foundations:
        for coverage in (0.5, 1.0):
            rows += measure_case(foundation, coverage)
    text = markdown(rows, (time.perf_counter() - start) / 60)
    print(text)
    if not args.quick:
        write_csv(rows, DOCS / "eevee_bound.csv", fields=FIELDS)
        replace_block(DOCS / "speed_accuracy.md", text, BEGIN, END)
    return 0


if __name__ == "__main__":
    sys.exit(main())
