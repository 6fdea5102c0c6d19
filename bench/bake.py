"""Benchmark and convergence study of the bake (a benchmark, not a test).

    python bench/bake.py                      # timing table (median of --runs runs)
    python bench/bake.py --study              # convergence study (markdown tables)
    python bench/bake.py --study --write-docs # ... and put them into docs/baking.md

Errors are those of :func:`lut_baker.offline.validation.table_accuracy.table_error`: the largest of
``|table - exact| / max(|exact|, 0.1 peak)`` over 500 random points (20% with theta_i and 20% with
both angles in the grazing rows 80..89 degrees), so <= 1e-3 meets "1e-3 relative or 1e-4 of the
peak, whichever is larger".  The machine is shared: timings are medians, and ratios measured in
one run are more telling than absolute times.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from doc_block import replace_block  # noqa: E402  (bench/doc_block.py)

from lut_baker import bake  # noqa: E402
from lut_baker.evaluate.made_up import made_up_reflection  # noqa: E402
from lut_baker.model import presets  # noqa: E402
from lut_baker.offline.validation import table_accuracy  # noqa: E402
from lut_baker.tables.table_set import ANGULAR, DIRECTIONAL  # noqa: E402

DOC = ROOT / "docs" / "baking.md"
BEGIN, END = "<!-- study:begin -->", "<!-- study:end -->"
GOAL = 1e-3
PRESETS = {
    "paper": lambda: presets.paper(),
    "light_ivory": lambda: presets.made_up_skin("light_ivory"),
    "medium_beige": lambda: presets.made_up_skin("medium_beige"),
    "deep_mocha": lambda: presets.made_up_skin("deep_mocha"),
    "paper film on jensen_skin1": lambda: presets.made_up_skin("paper_natural", "jensen_skin1"),
    "medium_beige on jensen_skin2": lambda: presets.made_up_skin("medium_beige", "jensen_skin2"),
    "paper, coverage 0.5": lambda: presets.paper().replace(coverage=0.5),
    "paper, coverage 0": lambda: presets.paper().replace(coverage=0.0),
}


CPU_TIMES: list[float] = []
"""Process CPU seconds of the last :func:`timed` call's runs (all threads)."""


def timed(function, runs: int) -> tuple[float, float, object]:
    """(median, min) wall time in seconds over ``runs`` calls, and the last result; the CPU
    times of the runs go to ``CPU_TIMES`` (less sensitive to other processes' load)."""
    times, result = [], None
    CPU_TIMES.clear()
    for _ in range(runs):
        start, cpu = time.perf_counter(), time.process_time()
        result = function()
        times.append(time.perf_counter() - start)
        CPU_TIMES.append(time.process_time() - cpu)
    return float(np.median(times)), float(np.min(times)), result


def entries(res: bake.Resolution) -> int:
    return res.n_theta**2 * res.n_phi


def megabytes(tables) -> float:
    """float32 size of every table (what the EXR atlas holds), MB."""
    return sum(np.asarray(v).size for v in tables.arrays.values()) * 4 / 1e6


def table(header: list[str], rows: list[list]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def fmt(x: float) -> str:
    return f"{x:.1e}"


# --------------------------------------------------------------------------------------------
# Timings
# --------------------------------------------------------------------------------------------
def timings(runs: int) -> str:
    load_before = os.getloadavg()[0]
    skin = presets.paper()
    samples = table_accuracy.error_samples(skin, albedo_points=100)
    out = []
    rows = []
    goals = {"preview": 0.030, "default": 0.200}
    for name in ("preview", "default", "high"):
        med, best, tables = timed(lambda n=name: bake.bake(skin, n), runs)
        err = table_accuracy.table_error(tables, samples=samples)
        goal = goals.get(name)
        rows.append([name, tables.path3_gloss.shape[:3], f"{megabytes(tables):.1f}",
                     f"{med * 1e3:.1f}", f"{best * 1e3:.1f}",
                     f"{np.median(CPU_TIMES) * 1e3:.1f}",
                     f"< {goal * 1e3:.0f} ms" if goal else "-",
                     fmt(err["reflection"]), fmt(err["max"])])
    med, best, tables = timed(lambda: bake.bake(skin, "default", inter_reflection=True), runs)
    rows.append(["default + inter-reflection", tables.path3_gloss.shape[:3],
                 f"{megabytes(tables):.1f}", f"{med * 1e3:.1f}", f"{best * 1e3:.1f}",
                 f"{np.median(CPU_TIMES) * 1e3:.1f}", "-", "-", "-"])
    out.append(f"Full bakes of the paper preset (wall time: median and min of {runs} runs; CPU: "
               f"median process time, all threads; load average {load_before:.1f} at the "
               f"start on {os.cpu_count()} cores):\n")
    out.append(table(["resolution", "angular grid", "MB (float32)", "median ms", "min ms",
                      "CPU ms", "goal", "reflection error", "max error (all tables)"], rows))

    base = bake.RESOLUTIONS["default"]
    t0, _, _ = timed(lambda: bake.bake(skin, base), runs)
    sweeps = [
        ("n_theta", [replace(base, n_theta=n) for n in (24, 48, 96, 192)]),
        ("n_phi", [replace(base, n_phi=n) for n in (17, 33, 65, 129)]),
        ("quadrature panels x points", [replace(base, quad_panels=p, quad_points=q)
                                        for p, q in ((2, 6), (3, 8), (6, 8), (12, 8))]),
        ("quadrature azimuths", [replace(base, quad_phi=n) for n in (9, 17, 33, 65)]),
        ("n_radius", [replace(base, n_radius=n) for n in (64, 256, 1024)]),
    ]
    rows = []
    for label, variants in sweeps:
        for res in variants:
            med, _, _ = timed(lambda r=res: bake.bake(skin, r), runs)
            value = {"n_theta": res.n_theta, "n_phi": res.n_phi,
                     "quadrature panels x points": f"{res.quad_panels} x {res.quad_points}",
                     "quadrature azimuths": res.quad_phi, "n_radius": res.n_radius}[label]
            rows.append([label, value, f"{med * 1e3:.1f}", f"{med / t0:.2f}"])
    out.append(f"\nHow the time grows with each grid dimension (the others at `default`; "
               f"default = {t0 * 1e3:.1f} ms in this run):\n")
    out.append(table(["dimension", "value", "median ms", "x default"], rows))

    rng = np.random.default_rng(1)
    wi, wo = table_accuracy.sample_directions(200, rng, 89.0)
    exact_med, _, _ = timed(lambda: made_up_reflection(wi, wo, skin, level=0), max(1, runs // 3))
    per_point = exact_med / 200
    rows = []
    for name in ("preview", "default", "high"):
        res = bake.RESOLUTIONS[name]
        med, _, _ = timed(lambda n=name: bake.bake(skin, n), runs)
        per_entry = med / entries(res)
        rows.append([name, entries(res), f"{per_entry * 1e9:.0f} ns",
                     f"{per_point * 1e6:.0f} us", f"{per_point / per_entry:.0f}x"])
    out.append("\nSpeed-up over the exact evaluator (`normalise.made_up_reflection`, level 0, "
               "paths 1 + 3 per point) per angular table entry (a full bake fills path 3's "
               "angular table plus the 1-D ones):\n")
    out.append(table(["resolution", "angular entries", "bake time per entry",
                      "exact evaluator per point", "speed-up"], rows))
    out.append(f"\nLoad average at the end: {os.getloadavg()[0]:.1f}.")
    return "\n".join(out)


# --------------------------------------------------------------------------------------------
# Convergence study
# --------------------------------------------------------------------------------------------
def path3_node_error(tables, skin, n_nodes=300, seed=0) -> float:
    """Quadrature error of path 3 alone: the baked ``path3_gloss`` at random nodes against
    :func:`lut_baker.evaluate.two_layer.layered_reflection` (level 0) there, normalised by path 3's
    peak."""
    from lut_baker.evaluate.two_layer import layered_reflection
    from lut_baker.numerics.geometry import direction

    rng = np.random.default_rng(seed)
    n, p = tables.theta_deg.size, tables.phi_deg.size
    i, j, k = rng.integers(0, n, n_nodes), rng.integers(0, n, n_nodes), rng.integers(0, p, n_nodes)
    azimuth = np.radians(tables.node_azimuths()[i, j, k])
    wi = direction(np.radians(tables.theta_deg[i]), azimuth)
    wo = direction(np.radians(tables.theta_deg[j]), 0.0)
    exact = np.reshape(layered_reflection(wi, wo, skin.film_transmission,
                                          bake.gloss_layer(skin.skin_reflection)), (n_nodes, -1))
    peak = np.max(tables.path3_gloss)
    return float(np.max(np.abs(tables.path3_gloss[i, j, k] - exact)) / peak)


def study(runs: int) -> str:
    out = []
    skin = presets.paper()
    print("exact samples (seeds 0-2) ...", file=sys.stderr)
    samples = [table_accuracy.error_samples(skin, seed=s, albedo_points=500 if s == 0 else 1)
               for s in range(3)]
    base = bake.RESOLUTIONS["default"]

    def reflection_errors(res):
        tables = bake.bake(skin, res)
        return tables, [table_accuracy.table_error(tables, samples=s)["reflection"]
                        for s in samples]

    # 1. spacings
    rows = []
    size = replace(base, n_theta=64, n_phi=49)
    for theta_spacing, offset in (("grazing", 0.03), ("grazing", 0.1), ("grazing", 0.3),
                                  ("uniform_cos", 0.03), ("uniform_theta", 0.03)):
        for phi_spacing in ("half_vector", "uniform"):
            res = replace(size, theta_spacing=theta_spacing, theta_offset=offset,
                          phi_spacing=phi_spacing)
            tables, errs = reflection_errors(res)
            name = f"{theta_spacing} ({offset})" if theta_spacing == "grazing" else theta_spacing
            rows.append([name, phi_spacing, fmt(errs[0]), fmt(max(errs))])
            print("spacing", rows[-1], file=sys.stderr)
    out.append("### 1. Grid spacing (64 x 64 x 49 angular nodes, paper preset)\n")
    out.append(table(["theta spacing (mu0)", "azimuth spacing", "error, 500 points (seed 0)",
                      "max over seeds 0-2"], rows))

    # 2. angular sizes
    rows = []
    for n_theta in (16, 24, 32, 48, 64, 96, 112, 128):
        for n_phi in (9, 17, 33, 49, 65, 97):
            if n_theta >= 96 and n_phi < 33 or n_theta <= 24 and n_phi > 49:
                continue
            res = replace(base, n_theta=n_theta, n_phi=n_phi)
            med, _, _ = timed(lambda r=res: bake.bake(skin, r), runs)
            tables, errs = reflection_errors(res)
            rows.append([f"{n_theta} x {n_theta} x {n_phi}", f"{entries(res) / 1e3:.0f}k",
                         f"{megabytes(tables):.1f}", f"{med * 1e3:.0f}", fmt(errs[0]),
                         fmt(max(errs))])
            print("size", rows[-1], file=sys.stderr)
    out.append("\n### 2. Angular table size against error (grazing 0.03 / half-vector, "
               "quadrature 3 x 8 / 33)\n")
    out.append(table(["theta_i x theta_o x azimuth", "entries per table", "MB (float32, all)",
                      "bake ms (median)", "error, 500 points (seed 0)", "max over seeds 0-2"],
                     rows))

    # 3. quadrature
    rows = []
    for panels, points, quad_phi in ((1, 6, 9), (2, 6, 17), (2, 8, 17), (3, 8, 17), (3, 8, 33),
                                     (3, 10, 33), (4, 8, 65)):
        res = replace(base, quad_panels=panels, quad_points=points, quad_phi=quad_phi)
        med, _, tables = timed(lambda r=res: bake.bake(skin, r), runs)
        err = table_accuracy.table_error(tables, samples=samples[0])
        rows.append([f"{panels} x {points}", quad_phi, f"{med * 1e3:.0f}",
                     fmt(path3_node_error(tables, skin)), fmt(err["transmission"]),
                     fmt(err["albedo"]), fmt(err["reflection"])])
        print("quadrature", rows[-1], file=sys.stderr)
    out.append("\n### 3. Quadrature of the integrals (tables at the default size)\n")
    out.append(table(["polar panels x Gauss points", "azimuths (path 3)", "bake ms",
                      "path 3 at nodes (of its peak)", "transmission factor",
                      "directional albedo", "reflection (500 points)"], rows))

    # 4. radial
    rows = []
    for spacing in ("quadratic", "uniform"):
        for n_radius in (16, 32, 64, 96, 128, 256, 512):
            tables = bake.bake(skin, replace(base, radius_spacing=spacing, n_radius=n_radius))
            error = table_accuracy.table_error(tables, samples=samples[0])
            rows.append([spacing, n_radius, fmt(error["profile"])])
    out.append("\n### 4. Radial profile R(d)/Rd (paper dipole, d up to "
               f"{bake.profile_radius(skin.dipole):.2f} mm)\n")
    out.append(table(["spacing", "n_radius", "error (500 points)"], rows))

    # 5. resolutions and presets, float32 storage
    rows = []
    for label, make in PRESETS.items():
        made_up = make()
        preset_samples = table_accuracy.error_samples(made_up, albedo_points=100)
        for name in bake.RESOLUTIONS:
            tables = bake.bake(made_up, name)
            err = table_accuracy.table_error(tables, samples=preset_samples)
            as_float32 = replace(tables, **{k: np.asarray(getattr(tables, k), np.float32)
                                            for k in ANGULAR + DIRECTIONAL + ("profile",)})
            err32 = table_accuracy.table_error(as_float32, samples=preset_samples)
            rows.append([label, name, fmt(err["reflection"]), fmt(err["albedo"]),
                         fmt(err["transmission"]), fmt(err["profile"]), fmt(err32["max"]),
                         "yes" if err["max"] <= (GOAL if name != "preview" else 10 * GOAL)
                         else "no"])
            print("preset", rows[-1], file=sys.stderr)
    out.append("\n### 5. The resolutions on every preset (500 points, seed 0, the albedo at 100 "
               "of them; the float32 column is the largest error after rounding the tables to "
               "float32 as stored)\n")
    out.append(table(["preset", "resolution", "reflection", "albedo", "transmission",
                      "profile", "max, float32", "goal met (preview: 1e-2)"], rows))
    return "\n".join(out)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--study", action="store_true", help="run the convergence study")
    parser.add_argument("--write-docs", action="store_true",
                        help="put the study's tables into docs/baking.md")
    parser.add_argument("--runs", type=int, default=7, help="runs per timing (median)")
    args = parser.parse_args()
    text = study(args.runs) if args.study else timings(args.runs)
    print(text)
    if args.write_docs and args.study:
        replace_block(DOC, text, BEGIN, END)


if __name__ == "__main__":
    main()
