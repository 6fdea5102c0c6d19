"""The run-time fits audited: how far what they ship moves when their inputs move by 1e-9, and
how far each discrete choice is from flipping.

Usage::

    python bench/fit_stability.py                      # every case, 2 seeds (~10 minutes)
    python bench/fit_stability.py --cases paper --seeds 4 --rel 1e-7

For each made-up skin of ``support.fit_audit.CASES`` (the paper preset, medium beige on
Jensen's Skin 1, the four measured products on the bio-plate; preview tables) it prints:

- the largest movement of each group of outputs (``support.fit_audit.criterion``: relative,
  or absolute for error measures) when the skin's parameters are perturbed by ``--rel`` and
  baked again, and when the tables themselves are perturbed; a discrete output that changes
  shows as ``inf``;
- the margins of the discrete choices (``support.fit_audit.decision_margins``);
- the Auto tier's choice in the scenes of ``support.fit_audit.SCENES`` with its margins, and
  whether a perturbation of the material and the scene flips it.

docs/stability.md, "How far the fits move", is written from this output.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
for _path in (REPO, REPO / "tests"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

from support import fit_audit  # noqa: E402  (tests/support/fit_audit.py)
from support.perturbation import perturbed  # noqa: E402

from lut_baker import auto_tier  # noqa: E402
from lut_baker.closures import fitting  # noqa: E402

__all__ = ["main", "group"]


def group(name: str) -> str:
    """The output group of a quantity of :func:`support.fit_audit.fit_movement`: what it
    is, and which input was perturbed (the skin, through the bake, or the tables)."""
    source, *parts = name.split("/")
    if source == "tables":
        grids = parts[0] in ("theta_deg", "phi_deg", "radius_mm")
        return "bake: " + ("grids" if grids else "tables")
    via = "fit (skin perturbed): " if source == "fit" else "fit (tables perturbed): "
    field, last = parts[0], parts[-1]
    if field == "errors":
        return f"{via}tier errors, {last}"
    if field == "profiles":
        return via + ("subsurface radii" if last == "radius_mm" else "subsurface errors")
    if field == "glossy":
        return via + ("glossy roughness" if last == "roughness" else
                      "glossy distribution" if last == "distribution" else
                      "glossy weights, errors")
    return via + field


def print_by_case(title: str, by_case: dict, form: str, missing: float) -> None:
    """A Markdown table: a row per key of the cases' dicts, a column per case."""
    keys = sorted({key for values in by_case.values() for key in values})
    print(f"\n| {title} | {' | '.join(by_case)} |")
    print("| --- |" + " --- |" * len(by_case))
    for key in keys:
        cells = [format(by_case[case].get(key, missing), form) for case in by_case]
        print(f"| {key} | {' | '.join(cells)} |")


def movement_table(cases, seeds, rel) -> None:
    print(f"\nLargest movement under a {rel:g} relative perturbation ({len(seeds)} seeds; "
          "relative, absolute for error measures; inf: a discrete output changed)")
    results = {}
    for name in cases:
        start = time.perf_counter()
        groups: dict = {}
        for quantity, value in fit_audit.fit_movement(name, seeds, rel=rel).items():
            key = group(quantity)
            groups[key] = max(groups.get(key, 0.0), value)
        results[name] = groups
        print(f"  {name}: {time.perf_counter() - start:.0f} s", flush=True)
    print_by_case("output", results, ".1e", 0.0)


def margin_table(cases) -> None:
    print("\nMargins of the discrete choices (relative; no_lobe absolute; inf: no second "
          "valley / no choice)")
    rows = {}
    for name in cases:
        skin, tables = fit_audit.case_tables(name)
        rows[name] = fit_audit.decision_margins(tables, skin)
    print_by_case("choice", rows, ".2g", math.nan)


def auto_table(cases, seeds) -> None:
    print("\nThe Auto tier: choice, margins (error: absolute, in predicted relative RMS; cost, "
          "subsurface: relative), flips under perturbation of the material and the scene")
    print("\n| material | scene | choice | error | cost | subsurface | flips |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for name in cases:
        _, tables = fit_audit.case_tables(name)
        traits = auto_tier.traits_from_tables(tables, fitting.fit_closures(tables))
        for label, scene in fit_audit.SCENES.items():
            choice = auto_tier.choose(scene, traits)
            m = fit_audit.choice_margins(choice, scene, traits)
            flips = sum(auto_tier.choose(perturbed(scene, seed=s), perturbed(traits, seed=s))
                        .candidate != choice.candidate for s in seeds)
            print(f"| {name} | {label} | {choice.candidate.name} | {m['error']:.2g} | "
                  f"{m['cost']:.2g} | {m['subsurface']:.2g} | {flips} of {len(seeds)} |",
                  flush=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="+", default=list(fit_audit.CASES),
                        choices=list(fit_audit.CASES))
    parser.add_argument("--seeds", type=int, default=2)
    parser.add_argument("--rel", type=float, default=1e-9)
    parser.add_argument("--parts", nargs="+", default=["movement", "margins", "auto"],
                        choices=["movement", "margins", "auto"])
    args = parser.parse_args(argv)
    seeds = tuple(range(args.seeds))
    if "movement" in args.parts:
        movement_table(args.cases, seeds, args.rel)
    if "margins" in args.parts:
        margin_table(args.cases)
    if "auto" in args.parts:
        auto_table(args.cases, seeds)
    return 0


if __name__ == "__main__":
    sys.exit(main())
