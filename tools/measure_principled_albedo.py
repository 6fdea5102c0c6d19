"""Measure what a dielectric Principled BSDF renders under uniform white light, the table of
lut_baker.closures.principled_albedo, and how far that module's function is from renders.

Usage::

    python tools/measure_principled_albedo.py [--write] [--part cycles eevee check doc]
        [--engine CYCLES|EEVEE] [--size 96]

The default (``cycles eevee check``) took 6 min 50 s on 2 shared cores (13 minutes when they
were busy) and rewrites the table byte for byte: the seeds are fixed.

The scene is tests/support/furnace_albedo.py's: a 1 m sphere under a uniform white sky, the
mean colour over its disc (the bihemispherical albedo) and its standard error.  Parts:

- ``cycles``: the specular layer's residuals against the replicas and the subsurface methods'
  ratio ``rho`` (the subsurface body over a Diffuse body of the same Base Color under the same
  specular layer).  At each node (Roughness, IOR) of a grid it renders Base Color 0 (the gloss
  ``T0``) and 1 with Subsurface Weight 0 (``T1``: the gloss and the layer's ``W``), with either
  distribution: their ratios to the replicas' gloss and ``W``.  Then Base Colors three at a
  time (one per channel: the channels are independent) with Subsurface Weight 1: ``rho = (T -
  T0) / ((T1 - T0) base)``, Random Walk at every node, Random Walk (Skin) and
  Christensen-Burley, which follow Base Color whatever the Roughness and IOR, at one.  4-7
  minutes.
- ``eevee``: EEVEE's gloss over Cycles' Multiscatter GGX replica, per distribution on a
  Roughness x IOR grid, from a Diffuse Principled BSDF of Base Color (0, 1, 0.5) per node (red:
  the gloss, green: gloss + W, which stays 1, blue: checks linearity), each channel divided by
  a white Diffuse BSDF's render (EEVEE lights a white Lambertian sphere under this sky at 0.993,
  0.993, 0.985: its own world lighting, not the shader's), and subsurface renders against the
  diffuse one.  2-3 minutes (software OpenGL).
- ``check``: off-grid points in ``--engine`` against
  :func:`lut_baker.closures.principled_albedo.principled_albedo`: the error per channel
  relative to the rendered albedo, beside the render's noise; the noise estimate itself
  checked against two seeds; for EEVEE also the distance from Cycles.  Run it on Blender 4.5
  too (its venv's python).
- ``doc`` (not run by default): the Markdown table of docs/principled_albedo.md, rendered
  albedos against Base Color at the textured head's Roughness and IOR for each method, beside
  the "Lambert + gloss" reading (Base Color + the specular layer's gloss).  Half a minute.

``--write`` merges the measured parts into lut_baker/closures/principled_albedo.json (then
``check`` compares with the new table).  Prints every measurement and the time taken.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO_ROOT = Path(__file__).resolve().parent.parent
for _path in (REPO_ROOT, REPO_ROOT / "tests"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

from lut_baker.closures import principled_albedo as pa  # noqa: E402
from lut_baker.offline.atomic_files import write_text  # noqa: E402

__all__ = ["main", "RANDOM_WALK_ROUGHNESS", "RANDOM_WALK_IOR", "BASE_GROUPS", "EEVEE_ROUGHNESS",
           "EEVEE_IOR", "CHECK_POINTS", "DOC_LAYER", "DOC_BASES"]

RANDOM_WALK_ROUGHNESS = (0.0, 0.25, 0.4, 0.5, 0.6, 0.7, 0.85, 1.0)
RANDOM_WALK_IOR = (1.3, 1.45, 1.6)
FIXED_NODE = (0.5, 1.45)
"""The one (Roughness, IOR) node of the methods that do not depend on them."""
BASE_GROUPS = (((0.01, 0.03, 0.046), 128), ((0.06, 0.1, 0.15), 64), ((0.22, 0.3, 0.4), 64),
               ((0.5, 0.6, 0.7), 32), ((0.8, 0.86, 0.918), 32), ((0.95, 0.975, 1.0), 32))
"""Base Colors rendered together (one per channel) and their samples per pixel (walks of dark
colours are short and noisier relative to their level: more samples; bright ones are long).
Two nodes sit where Cycles' inversion of Base Color into a single-scattering albedo meets its
clamps
(``subsurface_random_walk_coefficients``, isotropic): 0.046, below which the albedo stays at
0.2 and the throughput is scaled down, and 0.918, above which it stays at 0.999999 and every
random walk is the same (its body flat, 0.91-0.92 of the layer's W)."""
LAYER_SAMPLES = 32
"""Samples of the Base Color 0 and 1 renders (no subsurface: little noise)."""
EEVEE_ROUGHNESS = (0.0, 0.15, 0.3, 0.45, 0.6, 0.75, 0.9, 1.0)
EEVEE_IOR = (1.3, 1.45, 1.6)
EEVEE_SAMPLES = 4
"""EEVEE's samples (anti-aliasing only here: its albedo moves by under 0.05% from 4 to 16)."""
CHECK_POINTS = (
    # (method, Subsurface Weight, Roughness, IOR, distribution, Base Color)
    ("RANDOM_WALK", 0.0, 0.3, 1.55, "MULTI_GGX", (0.08, 0.35, 0.7)),
    ("RANDOM_WALK", 0.0, 0.65, 1.35, "GGX", (0.08, 0.35, 0.7)),
    ("RANDOM_WALK", 1.0, 0.45, 1.38, "MULTI_GGX", (0.08, 0.27, 0.61)),
    ("RANDOM_WALK", 1.0, 0.78, 1.55, "MULTI_GGX", (0.045, 0.2, 0.45)),
    ("RANDOM_WALK", 1.0, 0.15, 1.45, "GGX", (0.04, 0.5, 0.92)),
    ("RANDOM_WALK", 0.5, 0.55, 1.45, "MULTI_GGX", (0.12, 0.33, 0.74)),
    ("RANDOM_WALK", 1.0, 0.4, 1.4, "MULTI_GGX", (0.55, 0.33, 0.25)),
    ("RANDOM_WALK_SKIN", 1.0, 0.3, 1.35, "MULTI_GGX", (0.08, 0.27, 0.61)),
    ("RANDOM_WALK_SKIN", 1.0, 0.8, 1.6, "MULTI_GGX", (0.04, 0.5, 0.92)),
    ("RANDOM_WALK_SKIN", 1.0, 0.4, 1.4, "MULTI_GGX", (0.55, 0.33, 0.25)),
    ("BURLEY", 1.0, 0.45, 1.55, "MULTI_GGX", (0.08, 0.27, 0.61)),
    ("BURLEY", 1.0, 0.2, 1.3, "GGX", (0.04, 0.5, 0.92)),
)
"""Off-grid points of ``check`` (Cycles); EEVEE renders :data:`EEVEE_CHECKS` of them."""
EEVEE_CHECKS = (0, 1, 2, 7)
CHECK_SAMPLES = 64
DOC_LAYER = (0.45, 1.4)
"""Roughness and IOR of the ``doc`` table: the textured head's (tests/support/character.py)."""
DOC_BASES = ((0.05, 0.1, 0.2), (0.35, 0.5, 0.7))


def _scene(engine: str, size: int, samples: int):
    from support import furnace_albedo as fa

    return fa.build_scene(size=size, samples=samples, engine=engine)


def _samples(samples: int) -> None:
    import bpy

    scene = bpy.context.scene
    if scene.render.engine == "CYCLES":
        scene.cycles.samples = samples
    else:
        scene.eevee.taa_render_samples = samples


def _render(node, base, roughness, ior, *, weight=0.0, method="RANDOM_WALK",
            distribution="MULTI_GGX", samples=None):
    from support import furnace_albedo as fa

    if samples is not None:
        _samples(samples)
    fa.set_principled(node, base, roughness, ior, subsurface_weight=weight, method=method,
                      distribution=distribution)
    return fa.render_albedo()


def measure_layer(node, roughness: float, ior: float, distribution: str):
    """``(gloss, W, standard error of the gloss)`` rendered at one (Roughness, IOR) node: Base
    Color 0 (the gloss ``T0``) and 1 without subsurface (``T1``, so ``W = T1 - T0``)."""
    zero, zero_error, _ = _render(node, (0.0,) * 3, roughness, ior, distribution=distribution,
                                  samples=LAYER_SAMPLES)
    one, _, _ = _render(node, (1.0,) * 3, roughness, ior, distribution=distribution,
                        samples=LAYER_SAMPLES)
    return float(np.mean(zero)), float(np.mean(one - zero)), float(np.max(zero_error))


def measure_ratio(node, method: str, roughness: float, ior: float, layer):
    """``(base nodes, rho, standard error of rho)`` at one (Roughness, IOR) node whose
    Multiscatter GGX layer rendered as ``layer`` (:func:`measure_layer`)."""
    zero, passed, zero_error = layer
    bases, ratios, errors = [], [], []
    for base, samples in BASE_GROUPS:
        total, error, _ = _render(node, base, roughness, ior, weight=1.0, method=method,
                                  samples=samples)
        base = np.asarray(base)
        bases.append(base)
        ratios.append((total - zero) / (passed * base))
        errors.append(np.hypot(error, zero_error) / (passed * base))
    return np.concatenate(bases), np.concatenate(ratios), np.concatenate(errors)


def cycles_part(size: int) -> dict:
    """The ``cycles`` part (module docstring) as the table's ``cycles`` entry: the layer's
    residuals against the replicas and the subsurface ratios."""
    node = _scene("CYCLES", size, LAYER_SAMPLES)
    layers, residuals = {}, {d: ([], []) for d in pa.DISTRIBUTIONS}
    for roughness in RANDOM_WALK_ROUGHNESS:
        for rows in residuals.values():
            rows[0].append([])
            rows[1].append([])
        for ior in RANDOM_WALK_IOR:
            for distribution in pa.DISTRIBUTIONS:
                layer = measure_layer(node, roughness, ior, distribution)
                gloss, passed = pa.specular_layer(roughness, ior, distribution)
                residuals[distribution][0][-1].append(layer[0] / gloss)
                residuals[distribution][1][-1].append(layer[1] / passed)
                if distribution == "MULTI_GGX":
                    layers[roughness, ior] = layer
                print(f"layer {distribution:9s} roughness {roughness:4.2f} IOR {ior:4.2f}: gloss "
                      f"{layer[0]:.5f} (replica {gloss:.5f}), W {layer[1]:.5f} (replica "
                      f"{passed:.5f})", flush=True)
    layer_entry = {"roughness": list(RANDOM_WALK_ROUGHNESS), "ior": list(RANDOM_WALK_IOR),
                   "gloss_residual": {d: np.round(r[0], 5).tolist()
                                      for d, r in residuals.items()},
                   "passed_residual": {d: np.round(r[1], 5).tolist()
                                       for d, r in residuals.items()}}
    grids = {"RANDOM_WALK": (RANDOM_WALK_ROUGHNESS, RANDOM_WALK_IOR),
             "RANDOM_WALK_SKIN": ((FIXED_NODE[0],), (FIXED_NODE[1],)),
             "BURLEY": ((FIXED_NODE[0],), (FIXED_NODE[1],))}
    entry = {}
    for method, (roughness_nodes, ior_nodes) in grids.items():
        table, noise, bases = [], 0.0, None
        for roughness in roughness_nodes:
            row = []
            for ior in ior_nodes:
                start = time.perf_counter()
                bases, ratio, error = measure_ratio(node, method, roughness, ior,
                                                    layers[roughness, ior])
                row.append(ratio)
                noise = max(noise, float(np.max(error[bases >= 0.06])))
                print(f"{method:16s} roughness {roughness:4.2f} IOR {ior:4.2f}: rho "
                      + " ".join(f"{r:.4f}" for r in ratio)
                      + f"  (largest standard error {np.max(error):.4f}, "
                      f"{time.perf_counter() - start:.0f} s)", flush=True)
            table.append(row)
        entry[method] = {"roughness": list(roughness_nodes), "ior": list(ior_nodes),
                         "base": [round(float(b), 4) for b in bases],
                         "ratio": np.round(np.asarray(table), 4).tolist(),
                         "standard_error": round(noise, 4)}
    print(f"base nodes: {' '.join(f'{b:.3f}' for b in bases)}")
    return {"layer": layer_entry, "subsurface_ratio": entry}


def _white_lambert(node):
    """The engine's rendered albedo of a white Diffuse BSDF sphere (its lighting of this sky);
    leaves the material's output on ``node``."""
    from support import furnace_albedo as fa

    tree = node.id_data
    output = next(n for n in tree.nodes if n.type == "OUTPUT_MATERIAL")
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    tree.links.new(diffuse.outputs["BSDF"], output.inputs["Surface"])
    try:
        white, error, _ = fa.render_albedo()
    finally:
        tree.links.new(node.outputs["BSDF"], output.inputs["Surface"])
        tree.nodes.remove(diffuse)
    return white, error


def eevee_part(size: int) -> dict:
    """The ``eevee`` part (module docstring) as the table's ``eevee`` entry."""
    node = _scene("EEVEE", size, EEVEE_SAMPLES)
    white, _ = _white_lambert(node)
    print(f"EEVEE white Diffuse BSDF: {white.round(5)}", flush=True)
    gloss_ratio, energy, linearity = {}, 0.0, 0.0
    for distribution in pa.DISTRIBUTIONS:
        rows = []
        for roughness in EEVEE_ROUGHNESS:
            row = []
            for ior in EEVEE_IOR:
                total, _, seconds = _render(node, (0.0, 1.0, 0.5), roughness, ior,
                                            distribution=distribution)
                gloss, whole, half = total / white
                replica_gloss, replica_passed = pa.specular_layer(roughness, ior, distribution)
                row.append(gloss / pa.specular_layer(roughness, ior, "MULTI_GGX")[0])
                energy = max(energy, abs(whole - 1.0))
                linearity = max(linearity, abs((half - gloss) / (whole - gloss) - 0.5))
                print(f"EEVEE {distribution:9s} roughness {roughness:4.2f} IOR {ior:4.2f}: "
                      f"gloss {gloss:.5f} (Cycles {replica_gloss:.5f}), W {whole - gloss:.5f} "
                      f"(Cycles {replica_passed:.5f}), {seconds:.0f} s", flush=True)
            rows.append(row)
        gloss_ratio[distribution] = np.round(rows, 4).tolist()
    base = (0.05, 0.3, 0.7)
    diffuse, _, _ = _render(node, base, 0.5, 1.45)
    subsurface = {}
    for method in ("RANDOM_WALK", "BURLEY"):
        total, _, _ = _render(node, base, 0.5, 1.45, weight=1.0, method=method)
        subsurface[method] = float(np.max(np.abs(total / diffuse - 1.0)))
    print(f"EEVEE: gloss + W - 1 within {energy:.4f}; blue's body at Base Color 0.5 off linear "
          f"by {linearity:.4f} of W; subsurface "
          f"against diffuse at Base Color {base}: "
          + ", ".join(f"{m} {d:.4f}" for m, d in subsurface.items()), flush=True)
    return {"roughness": list(EEVEE_ROUGHNESS), "ior": list(EEVEE_IOR),
            "gloss_ratio": gloss_ratio, "energy_residual": round(energy, 5),
            "white_lambert": np.round(white, 5).tolist(),
            "subsurface_against_diffuse": {m: round(d, 4) for m, d in subsurface.items()}}


def check_part(engine: str, size: int) -> None:
    """The ``check`` part (module docstring): prints each point and the worst per method."""
    import bpy

    node = _scene(engine, size, CHECK_SAMPLES if engine == "CYCLES" else EEVEE_SAMPLES)
    white = np.ones(3)
    if engine == "EEVEE":
        white, _ = _white_lambert(node)
        print(f"EEVEE white Diffuse BSDF {white.round(5)}: EEVEE's renders are divided by it")
    points = [CHECK_POINTS[i] for i in EEVEE_CHECKS] if engine == "EEVEE" else CHECK_POINTS
    worst: dict[str, tuple[float, float]] = {}
    print(f"check, {engine} in Blender {bpy.app.version_string}: rendered albedo, the function's,"
          " relative error per channel (render's standard error)")
    for method, weight, roughness, ior, distribution, base in points:
        total, error, seconds = _render(node, base, roughness, ior, weight=weight,
                                        method=method, distribution=distribution)
        total, error = total / white, error / white
        predicted = pa.principled_albedo(base, roughness, ior, weight, method, engine,
                                         distribution).total
        relative = predicted / total - 1.0
        label = "DIFFUSE" if weight == 0.0 else method
        key = f"{label} ({distribution})" if weight == 0.0 else label
        previous = worst.get(key, (0.0, 0.0))
        worst[key] = (max(previous[0], float(np.max(np.abs(relative)))),
                      max(previous[1], float(np.max(error / total))))
        extra = ""
        if engine == "EEVEE":
            cycles = pa.principled_albedo(base, roughness, ior, weight, method, "CYCLES",
                                          distribution).total
            extra = "; EEVEE/Cycles - 1: " + " ".join(f"{v:+.4f}" for v in total / cycles - 1)
        print(f"  {label:16s} w {weight:3.1f} r {roughness:4.2f} IOR {ior:4.2f} {distribution:9s}"
              f" base {base}: render {total.round(4)} function {predicted.round(4)} error "
              + " ".join(f"{v:+.4f}" for v in relative)
              + " (" + " ".join(f"{v:.4f}" for v in error / total) + f"){extra}, {seconds:.1f} s",
              flush=True)
    for key, (error, noise) in worst.items():
        print(f"worst {key}: {error:.4f} (noise {noise:.4f})")
    if engine == "CYCLES":
        _seed_check(node)


def doc_part(size: int) -> None:
    """The ``doc`` part (module docstring): a Markdown table of rendered albedos against Base
    Color at the textured head's Roughness and IOR, beside the 'Lambert + gloss' reading."""
    roughness, ior = DOC_LAYER
    node = _scene("CYCLES", size, CHECK_SAMPLES)
    columns = [("Diffuse (Subsurface Weight 0)", 0.0, "RANDOM_WALK"),
               ("Random Walk", 1.0, "RANDOM_WALK"),
               ("Random Walk (Skin)", 1.0, "RANDOM_WALK_SKIN"),
               ("Christensen-Burley", 1.0, "BURLEY")]
    rendered = {}
    for _, weight, method in columns:
        values = []
        for group in DOC_BASES:
            total, _, _ = _render(node, group, roughness, ior, weight=weight, method=method)
            values.extend(total)
        rendered[weight, method] = np.asarray(values)
    base = np.concatenate(DOC_BASES)
    gloss, passed = pa.rendered_layer(roughness, ior)
    print(f"\nRendered albedo (Cycles, Blender {_version()}), Roughness {roughness}, IOR {ior}: "
          f"gloss {gloss:.4f}, W {passed:.4f}; in brackets against 'Lambert + gloss' (Base Color "
          "+ gloss)\n")
    print("| Base Color | Lambert + gloss | " + " | ".join(c[0] for c in columns) + " |")
    print("| ---: | ---: |" + " ---: |" * len(columns))
    for k, b in enumerate(base):
        reading = b + gloss
        cells = [f"{rendered[w, m][k]:.4f} ({rendered[w, m][k] / reading - 1:+.1%})"
                 for _, w, m in columns]
        print(f"| {b:.2f} | {reading:.4f} | " + " | ".join(cells) + " |")


def _version() -> str:
    import bpy

    return bpy.app.version_string


def _seed_check(node) -> None:
    """Two seeds of one subsurface render: their difference against the standard errors."""
    import bpy

    method, weight, roughness, ior, distribution, base = CHECK_POINTS[2]
    totals, errors = [], []
    for seed in (1, 2):
        bpy.context.scene.cycles.seed = seed
        total, error, _ = _render(node, base, roughness, ior, weight=weight, method=method,
                                  distribution=distribution)
        totals.append(total)
        errors.append(error)
    z = (totals[0] - totals[1]) / np.hypot(*errors)
    print("noise check (two seeds): difference over the estimated standard error "
          + " ".join(f"{v:+.2f}" for v in z) + " (about 1 if the estimate is right)")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--write", action="store_true",
                        help="merge the measured parts into the table file")
    parser.add_argument("--part", nargs="+", choices=("cycles", "eevee", "check", "doc"),
                        default=["cycles", "eevee", "check"])
    parser.add_argument("--engine", choices=pa.ENGINES, default="CYCLES",
                        help="the engine of the check part")
    parser.add_argument("--size", type=int, default=96, help="image size (pixels)")
    args = parser.parse_args(argv)
    os.environ.setdefault("BLENDER_USER_RESOURCES",
                          tempfile.mkdtemp(prefix="measure_principled_albedo_"))
    import bpy

    start = time.perf_counter()
    table = json.loads(pa.TABLE_FILE.read_text()) if pa.TABLE_FILE.exists() else {}
    measured = {}
    if "cycles" in args.part:
        measured["cycles"] = cycles_part(args.size)
    if "eevee" in args.part:
        measured["eevee"] = eevee_part(args.size)
    if measured and args.write:
        table.update(measured)
        table["about"] = ("A dielectric Principled BSDF's albedo under uniform white light: "
                          "what lut_baker.closures.principled_albedo reads, measured by "
                          "tools/measure_principled_albedo.py (rerun it with --write)")
        table["blender"] = bpy.app.version_string
        table["render"] = {"size": args.size, "base_groups": [list(g) for g in BASE_GROUPS],
                           "subsurface_radius_m": 0.003}
        write_text(pa.TABLE_FILE, json.dumps(table, separators=(",", ":")) + "\n")
        pa.albedo_table.cache_clear()
        print(f"wrote {pa.TABLE_FILE}")
    if "check" in args.part:
        check_part(args.engine, args.size)
    if "doc" in args.part:
        doc_part(args.size)
    print(f"measure_principled_albedo: {time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
