"""The EEVEE tier measured as the Cycles tiers are: against the exact sphere images, against
Cycles, and its render time against the Principled tier's in EEVEE.

A benchmark, not a test::

    python bench/eevee_tier.py          # docs/eevee_tier.csv, the table in speed_accuracy.md
    python bench/eevee_tier.py --quick  # the paper preset only, nothing written to docs/
    python bench/eevee_tier.py --costs [--write]  # the EEVEE candidates' costs

Scene (tests/support/bench_scene.py): a 256 x 128 mesh UV sphere of 10 mm, 64 x 64 px,
orthographic camera, one sun (angle 0) at 0, 45 and 75 degrees from the view, black world,
0.01 px pixel filter, lights' shadows off (a convex sphere shadows nothing; software OpenGL
renders shadows slowly).  Per foundation of :data:`FOUNDATIONS` on the paper's bio-plate
(the foundation's own shade) and coverage 0, 0.5 and 1 (0 is bare skin, the same for every
foundation: rendered once):

- **exact**: :func:`lut_baker.offline.validation.compare.reference_image` from "high" tables
  (within 6e-4 of the exact evaluator), the skin's spread at 1.5 entry samples per mean free
  path (within 2.5e-5 of the default at these sizes);
- **EEVEE tier in EEVEE** (:data:`EEVEE_SAMPLES` samples, EEVEE's default): relative RMS
  against the exact image;
- **EEVEE tier in Cycles** (:data:`CYCLES_SAMPLES` samples, seeds 0 and 1): EEVEE against
  Cycles with Cycles' noise removed, ``sqrt(e^2 - s^2)`` with ``e`` the mean relative RMS of
  EEVEE against the two Cycles images and ``s`` their noise floor
  (:func:`lut_baker.offline.validation.compare.noise_floor`);
- **Principled tier in EEVEE**, the same samples: its error, and (paper preset only, light
  :data:`TIME_LIGHT_DEG`, at :data:`TIME_SAMPLES` samples: EEVEE frames take 20-40 s here, and
  the time hardly depends on the foundation) the time per frame of the two tiers in EEVEE
  (shaders compiled first; renders interleaved; median of :data:`TIME_REPEATS`).

Each case (foundation, coverage) runs in a process of its own and appends its rows to
``bench/results/eevee_tier.jsonl``; a run that stopped resumes from there.

``--costs``: the EEVEE tier's four candidates (with or without subsurface and gloss, as Fit to
Scene sets them) at coverage 1 and 0, light 45 degrees, time per frame relative to the fullest
(median of ``--repeats`` interleaved runs), printed; with ``--write`` they replace the
``eevee_costs`` section of lut_baker/auto_tier/measured.json, which the Auto tier reads.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
for _path in (ROOT, ROOT / "bench", ROOT / "tests"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

from doc_block import replace_block  # noqa: E402  (bench/doc_block.py)

from lut_baker import auto_tier, bake  # noqa: E402
from lut_baker.auto_tier import measured  # noqa: E402
from lut_baker.model import presets  # noqa: E402
from lut_baker.offline.validation import compare  # noqa: E402

DOCS = ROOT / "docs"
BEGIN, END = "<!-- eevee:begin -->", "<!-- eevee:end -->"
FOUNDATIONS = ("paper_natural", "medium_beige", "clarins_103", "clarins_105", "clarins_108",
               "clarins_112")
"""The paper preset, one hand shade and the four measured products."""
SKIN = "paper_bioplate"
COVERAGES = (0.0, 0.5, 1.0)
LIGHTS_DEG = (0.0, 45.0, 75.0)
SIZE = 64
RADIUS_MM = 10.0
EEVEE_SAMPLES = 64
"""EEVEE samples of the images compared: EEVEE's default for a render.  EEVEE picks one
Diffuse or Subsurface closure per pixel and sample, so a pixel whose closures differ in hue is
noise that samples average away: a matte film at coverage 0.5 (no spread, no gloss) errs 2.3%
against its replica at 16 samples, 0.6% at 64 and 0.5% at 256 (docs/addon.md, "The EEVEE
tier")."""
TIME_SAMPLES = 64
"""EEVEE samples of the timed frames (an artist's final frame)."""
TIME_LIGHT_DEG = 45.0
"""The light of the timed frames (time hardly depends on it)."""
CYCLES_SAMPLES = 1024
SEEDS = (0, 1)
TIME_REPEATS = 3
SPREAD_PER_MEAN_FREE_PATH = 1.5
TARGETS = {"exact": 0.02, "cycles": 0.03, "time": 1.5}
"""The goals: EEVEE tier against the exact image at most 2%, against Cycles at most 3%, time
per frame at most 1.5x the Principled tier's in EEVEE."""
FIELDS = ("foundation", "coverage", "light_deg", "eevee_error", "eevee_mean_ratio",
          "principled_eevee_error", "cycles_error", "cycles_floor", "eevee_vs_cycles",
          "eevee_seconds", "principled_seconds", "time_ratio")


def _skin(foundation: str, coverage: float):
    return presets.made_up_skin(foundation, SKIN, coverage=coverage)


def _cases(foundations):
    """``(foundation, coverage)`` pairs; bare skin once (it is every foundation's)."""
    out = [(foundations[0], 0.0)]
    out += [(f, c) for f in foundations for c in COVERAGES if c > 0.0]
    return out


def _median(values) -> float:
    return statistics.median(values) if values else float("nan")


def measure_case(foundation: str, coverage: float, *, timed: bool,
                 eevee_samples=EEVEE_SAMPLES, cycles_samples=CYCLES_SAMPLES,
                 repeats=TIME_REPEATS) -> list[dict]:
    """The rows of one foundation and coverage, one per light (module docstring); with
    ``timed``, the time per frame of both tiers at :data:`TIME_SAMPLES` samples and light
    :data:`TIME_LIGHT_DEG` (the shaders compiled first, renders interleaved)."""
    import bpy
    from support import bench_scene as scene_module
    from support import sphere_scene

    sphere = scene_module.sphere_scene(size=SIZE, samples=eevee_samples, radius_mm=RADIUS_MM)
    scene = bpy.context.scene
    sun = scene.objects["Sun"]
    rows = []
    with sphere_scene.addon_registered():
        skin = _skin(foundation, coverage)
        tables = bake.bake(skin, "default")
        high = bake.bake(skin, "high")
        materials = {}
        for tier in ("EEVEE", "PRINCIPLED"):
            sphere.data.materials.clear()
            materials[tier] = sphere_scene.made_up_material(sphere, tables, tier,
                                                            coverage=coverage)
        for light in LIGHTS_DEG:
            sun.rotation_euler = (math.pi / 2, 0.0, math.radians(light))
            ref = scene_module.exact_image(
                skin, high, size=SIZE, light_deg=light, radius_mm=RADIUS_MM,
                spread_per_mean_free_path=SPREAD_PER_MEAN_FREE_PATH)
            scene_module.use_eevee(scene, eevee_samples)
            images = {}
            for tier, material in materials.items():
                scene_module.set_material(sphere, material)
                images[tier] = scene_module.render_image()[1]
            seconds = {tier: [] for tier in materials}
            if timed and light == TIME_LIGHT_DEG:
                scene_module.set_samples(scene, TIME_SAMPLES)
                for _ in range(repeats):
                    for tier, material in materials.items():
                        scene_module.set_material(sphere, material)
                        seconds[tier].append(scene_module.render_image()[0])
            scene_module.set_material(sphere, materials["EEVEE"])
            scene_module.use_cycles(scene, cycles_samples)
            cycles = []
            for seed in SEEDS:
                scene_module.set_samples(scene, cycles_samples, seed)
                cycles.append(scene_module.render_image()[1])
            eevee = images["EEVEE"]
            mask = compare.sphere_mask(SIZE)
            floor = compare.noise_floor(*cycles, cycles[0])
            against = sum(compare.relative_rms(eevee, c) for c in cycles) / len(cycles)
            row = {
                "foundation": foundation, "coverage": coverage, "light_deg": light,
                "eevee_error": compare.relative_rms(eevee, ref),
                "eevee_mean_ratio": float(eevee[mask].mean() / ref[mask].mean()),
                "principled_eevee_error": compare.relative_rms(images["PRINCIPLED"], ref),
                "cycles_error": sum(compare.relative_rms(c, ref) for c in cycles) / 2,
                "cycles_floor": floor,
                "eevee_vs_cycles": compare.bias(against, floor),
                "eevee_seconds": _median(seconds["EEVEE"]),
                "principled_seconds": _median(seconds["PRINCIPLED"]),
            }
            row["time_ratio"] = row["eevee_seconds"] / row["principled_seconds"]
            rows.append(row)
            print(" ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}"
                           for k, v in row.items()), flush=True)
    return rows


def measure(foundations, rows_path: Path, *, repeats=TIME_REPEATS) -> list[dict]:
    """Every row of the table, each case (foundation, coverage) in a process of its own (a
    long EEVEE session on software OpenGL has crashed in Blender's allocator here), its rows
    appended to ``rows_path`` (JSON lines); cases already there are not measured again, so a
    run that stopped resumes.  A case whose process fails twice is an error."""
    done = _read_rows(rows_path)
    for foundation, coverage in _cases(foundations):
        if any(r["foundation"] == foundation and r["coverage"] == coverage for r in done):
            print(f"{foundation}, coverage {coverage:g}: measured before, in {rows_path}")
            continue
        command = [sys.executable, __file__, "--case", foundation, str(coverage),
                   "--rows", str(rows_path), "--repeats", str(repeats)]
        if foundation == foundations[0]:
            command.append("--timed")
        for attempt in (1, 2):
            rc = subprocess.run(command, check=False).returncode
            if rc == 0:
                break
            print(f"{foundation}, coverage {coverage:g}: the process ended with {rc} "
                  f"(attempt {attempt})", flush=True)
        else:
            raise RuntimeError(f"{foundation}, coverage {coverage:g} failed twice: see above")
        done = _read_rows(rows_path)
    order = {case: k for k, case in enumerate(_cases(foundations))}
    rows = [r for r in done if (r["foundation"], r["coverage"]) in order]
    return sorted(rows, key=lambda r: (order[r["foundation"], r["coverage"]], r["light_deg"]))


def _read_rows(path: Path) -> list[dict]:
    if not path.exists():
        return []
    with open(path, encoding="utf-8") as handle:
        return [json.loads(line) for line in handle if line.strip()]


def _append_rows(rows, path: Path) -> None:
    with open(path, "a", encoding="utf-8") as handle:
        for row in rows:
            handle.write(json.dumps(row) + "\n")


def measure_costs(repeats: int) -> dict:
    """``{coverage: {candidate: relative time per frame}}`` of the EEVEE tier's candidates."""
    import bpy
    from support import bench_scene as scene_module
    from support import sphere_scene

    sphere = scene_module.sphere_scene(size=SIZE, samples=EEVEE_SAMPLES, radius_mm=RADIUS_MM)
    scene = bpy.context.scene
    out = {}
    with sphere_scene.addon_registered():
        for coverage in (1.0, 0.0):
            tables = bake.bake(_skin("paper_natural", coverage), "default")
            materials = {}
            for candidate in auto_tier.EEVEE_CANDIDATES:
                sphere.data.materials.clear()
                materials[candidate] = scene_module.candidate_material(sphere, tables,
                                                                       candidate)
            scene_module.use_eevee(scene, EEVEE_SAMPLES)
            times = {c: [] for c in materials}
            for material in materials.values():  # compile every shader first
                scene_module.set_material(sphere, material)
                scene_module.render_image()
            for _ in range(repeats):
                for candidate, material in materials.items():
                    scene_module.set_material(sphere, material)
                    times[candidate].append(scene_module.render_image()[0])
            full = statistics.median(times[auto_tier.EEVEE_CANDIDATES[0]])
            out[coverage] = {c: statistics.median(t) / full for c, t in times.items()}
            print(f"coverage {coverage:g}: " + ", ".join(
                f"{c.name} {statistics.median(t):.2f} s ({min(t):.2f}-{max(t):.2f})"
                for c, t in times.items()), flush=True)
    return out


def _costs_section(costs: dict, repeats: int) -> dict:
    """The ``eevee_costs`` section of lut_baker/auto_tier/measured.json from
    :func:`measure_costs`."""
    old = measured.load()["eevee_costs"]
    return {"command": f"python bench/eevee_tier.py --costs --repeats {repeats} --write",
            "about": old["about"],
            "relative_cost": {f"{coverage:g}": {c.name: round(value, 3)
                                                for c, value in by_candidate.items()}
                              for coverage, by_candidate in costs.items()}}


def _percent(x: float) -> str:
    return f"{100 * x:.2f}%"


def markdown(rows, minutes: float) -> str:
    met = {name: sum(1 for r in rows if r[key] <= TARGETS[name]) for name, key in
           (("exact", "eevee_error"), ("cycles", "eevee_vs_cycles"), ("time", "time_ratio"))}
    timed = sum(1 for r in rows if r["time_ratio"] == r["time_ratio"])
    lines = [f"Measured by `python bench/eevee_tier.py` (its last run {minutes:.0f} min, 2 "
             f"shared cores; the load is in docs/eevee_tier.csv's header). {SIZE} px, EEVEE "
             f"{EEVEE_SAMPLES} samples (timed frames {TIME_SAMPLES}, light "
             f"{TIME_LIGHT_DEG:g} degrees, the first foundation), Cycles {CYCLES_SAMPLES} x 2 "
             f"seeds, skin {SKIN}; coverage 0 is bare skin, the same for every foundation.", "",
             "| foundation | coverage | light | EEVEE tier vs exact | mean / exact | "
             "Principled in EEVEE vs exact | EEVEE vs Cycles (noise removed) | Cycles noise | "
             "time EEVEE tier / Principled (EEVEE) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['foundation']} | {r['coverage']:g} | {r['light_deg']:g} | "
                     f"{_percent(r['eevee_error'])} | {r['eevee_mean_ratio']:.3f} | "
                     f"{_percent(r['principled_eevee_error'])} | "
                     f"{_percent(r['eevee_vs_cycles'])} | {_percent(r['cycles_floor'])} | "
                     + (f"{r['time_ratio']:.2f} ({r['eevee_seconds']:.1f} / "
                        f"{r['principled_seconds']:.1f} s) |"
                        if r["time_ratio"] == r["time_ratio"] else "- |"))
    n = len(rows)
    lines += ["", f"Targets met: against the exact image <= 2% in {met['exact']} of {n} images; "
              f"against Cycles <= 3% in {met['cycles']} of {n}; time <= 1.5x in "
              f"{met['time']} of {timed} timed."]
    return "\n".join(lines)


def write_csv(rows, path: Path, load: str | None = None, fields=FIELDS) -> None:
    """``rows`` (dicts) as CSV with columns ``fields``, floats to 6 digits, after a ``# load``
    comment line if given."""
    with open(path, "w", newline="") as handle:
        if load is not None:
            handle.write(f"# {load}\n")
        writer = csv.DictWriter(handle, fieldnames=fields)
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v)
                             for k, v in row.items()})


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="the paper preset only; nothing written to docs/")
    parser.add_argument("--costs", action="store_true",
                        help="the EEVEE candidates' relative costs (lut_baker.auto_tier)")
    parser.add_argument("--repeats", type=int, default=TIME_REPEATS)
    parser.add_argument("--write", action="store_true",
                        help="with --costs: rewrite lut_baker/auto_tier/measured.json's "
                        "eevee_costs section")
    parser.add_argument("--out", type=Path, default=DOCS)
    parser.add_argument("--rows", type=Path, default=None,
                        help="the measured rows, JSON lines (default: "
                        "bench/results/eevee_tier[_quick].jsonl); cases already there are "
                        "kept: delete it to measure everything again")
    parser.add_argument("--case", nargs=2, metavar=("FOUNDATION", "COVERAGE"),
                        help=argparse.SUPPRESS)
    parser.add_argument("--timed", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="eevee_tier_"))
    suffix = "_quick" if args.quick else ""
    rows_path = args.rows or ROOT / "bench" / "results" / f"eevee_tier{suffix}.jsonl"
    if args.case:
        foundation, coverage = args.case[0], float(args.case[1])
        _append_rows(measure_case(foundation, coverage, timed=args.timed,
                                  repeats=args.repeats), rows_path)
        return 0
    start = time.perf_counter()
    load = f"load average before: {os.getloadavg()[0]:.2f}, {os.cpu_count()} cores"
    if args.costs:
        costs = measure_costs(args.repeats)
        print(f"# {load}, after: {os.getloadavg()[0]:.2f}")
        for coverage, by_candidate in costs.items():
            print(f"coverage {coverage:g}: " + ", ".join(
                f"{c.name} {value:.3f}" for c, value in by_candidate.items()))
        if args.write:
            measured.write_section("eevee_costs", _costs_section(costs, args.repeats))
            print(f"# wrote eevee_costs to {measured.PATH}")
        return 0
    foundations = FOUNDATIONS[:1] if args.quick else FOUNDATIONS
    rows_path.parent.mkdir(parents=True, exist_ok=True)
    rows = measure(foundations, rows_path, repeats=args.repeats)
    minutes = (time.perf_counter() - start) / 60
    load += f", after: {os.getloadavg()[0]:.2f}"
    text = markdown(rows, minutes)
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    write_csv(rows, args.out / f"eevee_tier{suffix}.csv", load)
    if not args.quick and args.out == DOCS:
        replace_block(DOCS / "speed_accuracy.md", text, BEGIN, END)
    return 0


if __name__ == "__main__":
    sys.exit(main())
