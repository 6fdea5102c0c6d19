"""Render time against error for the Made-up Skin tiers and the baseline.

A benchmark, not a test::

    python bench/speed_accuracy.py            # docs/speed_accuracy.csv, .png, the table in .md
    python bench/speed_accuracy.py --quick    # 16 and 64 samples, no bake axis (smoke run)
    python bench/speed_accuracy.py --replot   # redraw the PNG from the CSV
    python bench/speed_accuracy.py --eevee-only   # the EEVEE points alone, added to the CSV
    python bench/speed_accuracy.py --film         # the film as a slab at 9.6 and 50 um:
                                                  # docs/speed_accuracy_slab.csv, .png, its section
    python bench/speed_accuracy.py --film 20      # ... at 20 um (other thicknesses' rows kept)

Scene (``tests/support/bench_scene.py``, shared with the tests): the paper preset on a sphere of
10 mm radius, 48 x 48 px, Cycles CPU, light 0, 45 and 75 degrees from the view. Each of PRINCIPLED,
LAYERED (the add-on's node group, "default" tables) and BASELINE (a stock Principled BSDF whose
sockets :func:`lut_baker.offline.validation.baseline.fit_baseline` fitted to the same tables)
renders at 16, 64, 256 and 1024 samples with seeds 0 and 1, configurations interleaved so that the
load of a shared machine falls on all alike.
Against the reference (:func:`lut_baker.offline.validation.compare.reference_image`, paths 1 + 3
from "high" tables, the skin's diffuse part spread by the dipole profile): relative RMS error over
the sphere's pixels (mean of the two seeds), the noise floor ``rms(a - b) / sqrt(2)`` and the time
per render (mean of the two). EEVEE points: the EEVEE tier and the Principled tier in EEVEE
(software OpenGL here) at :data:`EEVEE_SAMPLES` samples, shadows off, one render each (EEVEE's
images do not depend on a seed), time per frame after a first render compiled the shaders.
The bake axis: per bake resolution, the tables' size, bake time
(median of 3), table error
(:func:`lut_baker.offline.validation.table_accuracy.table_error`, 500 points) and the LAYERED
tier's render error at 256 samples, light 45 degrees, seed 0. 48 px keeps the whole run near 8
minutes on 2 cores (the 1024-sample renders take most of it; 64 px would take ~14).

``--film UM ...``: the same chart for the film as a slab (docs/model.md, "Made-up skin at a
thickness") at each thickness (``--film`` alone: :data:`SLAB_FILMS_UM`): tables baked with
``film=UM`` (the tiers the add-on builds from them are the slab's, fitted to it), the reference
:func:`lut_baker.offline.validation.compare.slab_reference_image` from "high" tables, the
baseline fitted to the slab's images (:func:`lut_baker.offline.validation.baseline.fit_baseline`
takes its reference from the fit, which is the slab's).  No bake axis.  The rows (column
``film_um``) go to ``speed_accuracy_slab.csv`` and ``.png``, replacing that thickness's rows and
keeping the others', and each thickness's tables to its block of the section "The film at a
thickness" of docs/speed_accuracy.md.
"""

from __future__ import annotations

import argparse
import csv
import importlib
import math
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
for _path in (ROOT, ROOT / "bench", ROOT / "tests"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

from doc_block import replace_block  # noqa: E402  (bench/doc_block.py)

from lut_baker import bake  # noqa: E402
from lut_baker.model import presets  # noqa: E402
from lut_baker.model.film_slab import DEFAULT_THICKNESS_UM  # noqa: E402
from lut_baker.offline.validation import (  # noqa: E402
    compare,
    table_accuracy,  # noqa: E402
)
from lut_baker.offline.validation.baseline import fit_baseline  # noqa: E402

DOCS = ROOT / "docs"
BEGIN, END = "<!-- results:begin -->", "<!-- results:end -->"
EEVEE_MARKERS = ("<!-- eevee-points:begin -->", "<!-- eevee-points:end -->")
SLAB_MARKERS = ("<!-- slab-results:begin -->", "<!-- slab-results:end -->")
"""The section "The film at a thickness": one block per thickness inside (:func:`film_markers`)."""
SLAB_FILMS_UM = (DEFAULT_THICKNESS_UM, 50.0)
"""``--film`` alone: the default thickness (docs/model.md, "The film as a slab") and 50 um."""
CONFIGS = ("PRINCIPLED", "LAYERED", "BASELINE")
EEVEE_CONFIGS = ("EEVEE", "PRINCIPLED_EEVEE")
"""The tiers rendered in EEVEE: the EEVEE tier, the Principled tier."""
EEVEE_TIERS = {"EEVEE": "EEVEE", "PRINCIPLED_EEVEE": "PRINCIPLED"}
EEVEE_SAMPLES = (16, 64)
LABELS = {"PRINCIPLED": "Principled tier", "LAYERED": "Layered tier",
          "BASELINE": "baseline (stock Principled)", "EEVEE": "EEVEE tier in EEVEE",
          "PRINCIPLED_EEVEE": "Principled tier in EEVEE"}
COLOURS = {"PRINCIPLED": "tab:blue", "LAYERED": "tab:orange", "BASELINE": "tab:grey",
           "EEVEE": "tab:green", "PRINCIPLED_EEVEE": "tab:purple"}
RADIUS_MM = 10.0
SEEDS = (0, 1)
SPREAD_PER_MEAN_FREE_PATH = 1.5
"""The reference's spread with half its default sample spacing: within 2.5e-5 of the default
at 48 px, 10 mm (measured), four times faster."""
GOAL_SAMPLES = 256
GOAL_EXCESS = 0.03
GOAL_BASELINE_RATIO = 1.0 / 3.0
GOAL_TIME_RATIO = 1.2
FIELDS = ("axis", "config", "light_deg", "samples", "size_px", "seconds", "error",
          "noise_floor", "bias", "excess", "pareto", "resolution", "table_entries", "table_mb",
          "bake_ms", "table_error", "film_um")


def _bake_bench():
    """bench/bake.py (its ``timed``, ``entries`` and ``megabytes``)."""
    return importlib.import_module("bake")


def references(skin, size: int, lights, film="paper") -> dict:
    """Reference image per light (degrees); ``film``: the paper's, or a thickness (um) of the
    film as a slab (:func:`lut_baker.offline.validation.compare.slab_reference_image`)."""
    from support import bench_scene

    tables = bake.bake(skin, "high", film=film)
    return {light: bench_scene.exact_image(
        skin, tables, size=size, light_deg=light, radius_mm=RADIUS_MM,
        spread_per_mean_free_path=SPREAD_PER_MEAN_FREE_PATH) for light in lights}


def _row(**values) -> dict:
    return {name: values.get(name, "") for name in FIELDS}


def render_rows(skin, tables, baseline, refs: dict, size: int, sample_counts,
                bake_tables=None):
    """Render every configuration at every light and sample count; the rows of the CSV.
    ``baseline``: the :class:`lut_baker.offline.validation.baseline.Baseline` of ``tables``.
    ``bake_tables``: ``{resolution: tables}`` whose LAYERED render error at
    :data:`GOAL_SAMPLES` samples, light 45, seed 0 is returned as ``{resolution: error}``."""
    import bpy
    from support import bench_scene as scene_module
    from support import sphere_scene

    rows, bake_errors = [], {}
    for light, ref in refs.items():
        sphere = scene_module.sphere_scene(size=size, samples=16, radius_mm=RADIUS_MM,
                                           light_deg=light)
        scene = bpy.context.scene
        with sphere_scene.addon_registered():
            materials = {name: scene_module.tier_material(sphere, tables, name)
                         for name in CONFIGS[:2]}
            materials["BASELINE"] = scene_module.baseline_material(baseline, scene)
            scene_module.set_samples(scene, 1)
            scene_module.render_image()  # warm-up: kernels and images load once
            results = {}
            for samples in sample_counts:
                for seed in SEEDS:
                    for name in CONFIGS:
                        scene_module.set_material(sphere, materials[name])
                        scene_module.set_samples(scene, samples, seed)
                        seconds, image = scene_module.render_image()
                        results.setdefault((name, samples), []).append((seconds, image))
                        print(f"  light {light:g}, {name}, {samples} samples, seed {seed}: "
                              f"{seconds:.2f} s, error {compare.relative_rms(image, ref):.4f}",
                              flush=True)
            if bake_tables and light == 45.0:
                for resolution, other in bake_tables.items():
                    scene_module.tier_material(sphere, other, "LAYERED")
                    scene_module.set_samples(scene, GOAL_SAMPLES, 0)
                    _, image = scene_module.render_image()
                    bake_errors[resolution] = compare.relative_rms(image, ref)
            rows += eevee_rows(sphere, tables, ref, light, size)
        for (name, samples), runs in results.items():
            (t0, a), (t1, b) = runs
            error = 0.5 * (compare.relative_rms(a, ref) + compare.relative_rms(b, ref))
            floor = compare.noise_floor(a, b, ref)
            rows.append(_row(axis="render", config=name, light_deg=light, samples=samples,
                             size_px=size, seconds=0.5 * (t0 + t1), error=error,
                             noise_floor=floor, bias=compare.bias(error, floor),
                             excess=error - floor))
    mark_pareto(rows)
    return rows, bake_errors


def eevee_rows(sphere, tables, ref, light: float, size: int) -> list[dict]:
    """The EEVEE points at one light (the add-on registered, the scene's sphere given): per
    configuration of :data:`EEVEE_CONFIGS` and sample count, the error against ``ref`` and the
    time per frame (a first render per material compiles its shaders)."""
    import bpy
    from support import bench_scene as scene_module

    scene = bpy.context.scene
    materials = {name: scene_module.tier_material(sphere, tables, tier)
                 for name, tier in EEVEE_TIERS.items()}
    scene_module.use_eevee(scene, EEVEE_SAMPLES[0])
    rows = []
    for name, material in materials.items():
        scene_module.set_material(sphere, material)
        scene_module.render_image()  # compile
        for samples in EEVEE_SAMPLES:
            scene_module.set_samples(scene, samples)
            seconds, image = scene_module.render_image()
            error = compare.relative_rms(image, ref)
            print(f"  light {light:g}, {name} in EEVEE, {samples} samples: {seconds:.2f} s, "
                  f"error {error:.4f}", flush=True)
            rows.append(_row(axis="eevee", config=name, light_deg=light, samples=samples,
                             size_px=size, seconds=seconds, error=error))
    return rows


def bake_rows(skin, runs: int = 3):
    """Per bake resolution: tables, and a row without the render error yet."""
    bench = _bake_bench()
    samples = table_accuracy.error_samples(skin, albedo_points=100)
    tables, rows = {}, {}
    for name, resolution in bake.RESOLUTIONS.items():
        median, _, baked = bench.timed(lambda r=resolution: bake.bake(skin, r), runs)
        tables[name] = baked
        rows[name] = _row(axis="bake", config="LAYERED", light_deg=45.0, samples=GOAL_SAMPLES,
                          resolution=name, table_entries=bench.entries(resolution),
                          table_mb=bench.megabytes(baked), bake_ms=1e3 * median,
                          table_error=table_accuracy.table_error(baked, samples=samples)["max"])
    return tables, rows


def goals(rows) -> list[dict]:
    """The goals at :data:`GOAL_SAMPLES` samples, per film and light: the best tier's excess
    over its noise floor, its error against the baseline's, its time against the baseline's."""
    out = []
    for film in films_of(rows):
        for light in sorted({r["light_deg"] for r in rows if r["axis"] == "render"}):
            at = {r["config"]: r for r in rows if r["axis"] == "render"
                  and r["light_deg"] == light and r["samples"] == GOAL_SAMPLES
                  and r.get("film_um", "") == film}
            if at:
                out.append(_goal(at, light, film))
    return out


def _goal(at: dict, light: float, film) -> dict:
    """:func:`goals`'s row of one film and light (``at``: its rows by configuration)."""
    best = min(CONFIGS[:2], key=lambda name: at[name]["error"])
    tier, base = at[best], at["BASELINE"]
    return {"film_um": film, "light_deg": light, "best": best, "error": tier["error"],
            "floor": tier["noise_floor"], "excess": tier["excess"],
            "baseline_error": base["error"], "error_ratio": tier["error"] / base["error"],
            "time_ratio": tier["seconds"] / base["seconds"],
            "met": (tier["excess"] < GOAL_EXCESS
                    and tier["error"] < GOAL_BASELINE_RATIO * base["error"]
                    and tier["seconds"] <= GOAL_TIME_RATIO * base["seconds"])}


def write_csv(rows, path: Path) -> None:
    def cell(value):
        return f"{value:.6g}" if isinstance(value, float) else value

    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=FIELDS)
        writer.writeheader()
        for row in rows:
            writer.writerow({k: cell(v) for k, v in row.items()})


def read_csv(path: Path) -> list[dict]:
    """Rows of a CSV written by :func:`write_csv`, numbers and flags converted back."""
    def value(text):
        if text in ("True", "False"):
            return text == "True"
        try:
            number = float(text)
        except ValueError:
            return text
        return int(number) if number.is_integer() and "." not in text else number

    with open(path, newline="") as handle:
        return [{k: value(v) for k, v in row.items()} for row in csv.DictReader(handle)]


def films_of(rows) -> list:
    """The films of ``rows``' renders: ``[""]`` for the paper's film, else the thicknesses
    (um), thinnest first."""
    return sorted({r.get("film_um", "") for r in rows if r["axis"] in ("render", "eevee")},
                  key=lambda film: -1.0 if film == "" else float(film))


def _film_name(film) -> str:
    return "the paper's film" if film == "" else f"film {float(film):.3g} um"


def chart(rows, path: Path) -> None:
    """Time against error per light (log-log; Pareto front ringed and joined), one row of
    panels per film, and the bake axis (table size against table and render error, bake time
    labelled) when the rows hold it."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    lights = sorted({r["light_deg"] for r in rows if r["axis"] == "render"})
    films = films_of(rows)
    baked = [r for r in rows if r["axis"] == "bake"]
    panels = len(lights) + (1 if baked else 0)
    fig, axes = plt.subplots(len(films), panels, figsize=(4.2 * panels, 0.4 + 4.5 * len(films)),
                             squeeze=False)
    for axes_row, film in zip(axes, films, strict=True):
        for ax, light in zip(axes_row, lights, strict=False):
            _render_panel(ax, [r for r in rows if r.get("film_um", "") == film
                               and r["light_deg"] == light])
            ax.set_title(f"light {light:g} deg from the view" if film == ""
                         else f"{_film_name(film)}, light {light:g} deg", fontsize=10)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=8,
               title="dotted: noise floor; numbers: samples; squares: EEVEE (software OpenGL), "
               "time per frame", title_fontsize=8, frameon=False)
    if baked:
        _bake_panel(axes[0][-1], baked)
    what = ("paper preset" if films == [""] else
            "paper preset, the film as a slab (tiers and reference at its thickness)")
    fig.suptitle(f"Made-up Skin, {what}, 10 mm sphere, 48 px, Cycles CPU and EEVEE",
                 fontsize=10)
    fig.tight_layout(rect=(0, 0.7 / (0.4 + 4.5 * len(films)), 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _render_panel(ax, mine) -> None:
    """One panel of :func:`chart`: the render and EEVEE rows of one film and light."""
    import matplotlib.ticker

    renders = [r for r in mine if r["axis"] == "render"]
    for name in CONFIGS:
        points = sorted((r for r in renders if r["config"] == name), key=lambda r: r["samples"])
        x = [r["seconds"] for r in points]
        ax.plot(x, [r["error"] for r in points], "o-", color=COLOURS[name], label=LABELS[name])
        ax.plot(x, [r["noise_floor"] for r in points], ":", color=COLOURS[name], lw=1)
        for r in points:
            ax.annotate(str(r["samples"]), (r["seconds"], r["error"]), fontsize=7,
                        xytext=(3, 3), textcoords="offset points")
    for name in EEVEE_CONFIGS:
        points = sorted((r for r in mine if r["axis"] == "eevee" and r["config"] == name),
                        key=lambda r: r["samples"])
        ax.plot([r["seconds"] for r in points], [r["error"] for r in points], "s--",
                color=COLOURS[name], label=LABELS[name])
        for r in points:
            ax.annotate(str(r["samples"]), (r["seconds"], r["error"]), fontsize=7,
                        xytext=(3, 3), textcoords="offset points")
    front = sorted((r for r in mine if r["pareto"]), key=lambda r: r["seconds"])
    ax.plot([r["seconds"] for r in front], [r["error"] for r in front], "k--", lw=0.8)
    ax.scatter([r["seconds"] for r in front], [r["error"] for r in front], s=90,
               facecolors="none", edgecolors="k", label="Pareto front", zorder=3)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlabel("render time per image (s)")
    ax.set_ylabel("relative RMS error vs reference")
    ax.grid(True, which="both", alpha=0.3)


def _bake_panel(ax, baked) -> None:
    """The bake axis's panel of :func:`chart`."""
    import matplotlib.ticker

    size = [r["table_mb"] for r in baked]
    ax.plot(size, [r["table_error"] for r in baked], "s-", color="tab:green",
            label="table error (max, 500 points)")
    ax.plot(size, [r["error"] for r in baked], "o-", color=COLOURS["LAYERED"],
            label=f"Layered render error ({GOAL_SAMPLES} samples, 45 deg)")
    for r in baked:
        ax.annotate(f"{r['resolution']}\n{r['bake_ms']:.0f} ms bake",
                    (r["table_mb"], r["table_error"]), fontsize=7, xytext=(3, 3),
                    textcoords="offset points")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlabel("tables, MB (float32)")
    ax.set_ylabel("relative error")
    ax.set_title("bake resolution")
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.3)


def _percent(x: float) -> str:
    return f"{100 * x:.2f}%"


def eevee_markdown(rows, how: str = "`python bench/speed_accuracy.py`, or `--eevee-only` for "
                   "these points alone") -> str:
    """The EEVEE points of ``rows`` as a table (``how``: the command that measures them)."""
    lines = ["In EEVEE (5.0.1, software OpenGL; one render each, time per frame after the "
             f"shaders compiled; {how}):", "",
             "| light | config | samples | s per frame | error |", "|---|---|---|---|---|"]
    lines += [f"| {r['light_deg']:g} | {LABELS[r['config']]} | {r['samples']} | "
              f"{r['seconds']:.2f} | {_percent(r['error'])} |"
              for r in rows if r["axis"] == "eevee"]
    return "\n".join(lines)


def mark_pareto(rows) -> None:
    """Set each render and EEVEE row's ``pareto`` flag: on the front of time against error
    at its film and light."""
    points = [r for r in rows if r["axis"] in ("render", "eevee")]
    for film, light in {(r.get("film_um", ""), r["light_deg"]) for r in points}:
        mine = [r for r in points if r.get("film_um", "") == film and r["light_deg"] == light]
        front = compare.pareto_front([r["seconds"] for r in mine], [r["error"] for r in mine])
        for row, on in zip(mine, front, strict=True):
            row["pareto"] = bool(on)


def markdown(rows, goal_rows, seconds: float, command: str = "python bench/speed_accuracy.py"
             ) -> str:
    """The render rows, the bake axis and the goals as Markdown tables (one film's rows)."""
    lines = [f"Measured by `{command}` in {seconds / 60:.1f} min (2 cores, shared).", "",
             "| light | config | samples | s per render | error | noise floor | bias | "
             "Pareto |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["axis"] != "render":
            continue
        lines.append(f"| {r['light_deg']:g} | {r['config']} | {r['samples']} | "
                     f"{r['seconds']:.2f} | {_percent(r['error'])} | "
                     f"{_percent(r['noise_floor'])} | {_percent(r['bias'])} | "
                     f"{'yes' if r['pareto'] else ''} |")
    baked = [r for r in rows if r["axis"] == "bake"]
    if baked:
        lines += ["", "| bake resolution | angular entries | MB | bake ms | table error | "
                  f"Layered render error ({GOAL_SAMPLES} samples, 45 deg, seed 0) |",
                  "|---|---|---|---|---|---|"]
        lines += [f"| {r['resolution']} | {r['table_entries']} | {r['table_mb']:.1f} | "
                  f"{r['bake_ms']:.0f} | {r['table_error']:.1e} | {_percent(r['error'])} |"
                  for r in baked]
    lines += ["", f"Goals at {GOAL_SAMPLES} samples (best tier: lower error):", "",
              "| light | best tier | error | floor | error - floor (< 3%) | baseline error | "
              "tier / baseline error (< 1/3) | tier / baseline time (<= 1.2) | met |",
              "|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {g['light_deg']:g} | {g['best']} | {_percent(g['error'])} | "
              f"{_percent(g['floor'])} | {_percent(g['excess'])} | "
              f"{_percent(g['baseline_error'])} | {g['error_ratio']:.2f} | "
              f"{g['time_ratio']:.2f} | {'yes' if g['met'] else 'NO'} |" for g in goal_rows]
    return "\n".join(lines)


def baseline_text(baseline, seconds: float) -> str:
    """The baseline's fitted sockets and its fit's image errors, as Markdown."""
    def number(value):
        if isinstance(value, tuple):
            return "(" + ", ".join(f"{v:.3f}" for v in value) + ")"
        return f"{value:.3f}"

    lights = sorted(baseline.error)
    lines = [f"The baseline, fitted by `lut_baker.offline.validation.baseline.fit_baseline` in "
             f"{seconds:.1f} s "
             f"({baseline.evaluations} evaluations; subsurface method "
             f"{baseline.subsurface_method}):", "",
             "| " + " | ".join(baseline.socket_values()) + " |",
             "|" + "---|" * len(baseline.socket_values()),
             "| " + " | ".join(number(v) for v in baseline.socket_values().values()) + " |", "",
             "Its local image error (replicas, no spread), at the start (the Principled tier's "
             "values) and fitted: " + "; ".join(
                 f"light {light:g}: {_percent(baseline.start_error[light])} -> "
                 f"{_percent(baseline.error[light])}" for light in lights) + "."]
    return "\n".join(lines)


def film_markers(film: float) -> tuple[str, str]:
    """The markers of one thickness's block inside :data:`SLAB_MARKERS`."""
    return f"<!-- slab-film {film:.6g}:begin -->", f"<!-- slab-film {film:.6g}:end -->"


def write_film_block(path: Path, film: float, text: str) -> None:
    """Put ``text`` in ``film``'s block of the section between :data:`SLAB_MARKERS` (a new
    block goes last in it)."""
    begin, end = film_markers(film)
    if begin not in path.read_text():
        doc = path.read_text()
        if SLAB_MARKERS[1] not in doc:
            raise SystemExit(f"{path} has no {SLAB_MARKERS[0]} ... {SLAB_MARKERS[1]} block")
        path.write_text(doc.replace(SLAB_MARKERS[1], f"{begin}\n{end}\n{SLAB_MARKERS[1]}", 1))
    replace_block(path, text, begin, end)


def _same_film(a, b) -> bool:
    return a != "" and b != "" and math.isclose(float(a), float(b), rel_tol=1e-5)


def run_films(args, films) -> int:
    """``--film``: the chart of the film as a slab at each thickness of ``films`` (um), the
    rows of other thicknesses in the CSV kept."""
    suffix = "_quick" if args.quick else ""
    csv_path = args.out / f"speed_accuracy_slab{suffix}.csv"
    args.out.mkdir(parents=True, exist_ok=True)
    skin = presets.paper()
    for film in films:
        start = time.perf_counter()
        print(f"film {film:.3g} um: reference images ...", flush=True)
        tables = bake.bake(skin, "default", film=film)
        refs = references(skin, args.size, args.lights, film)
        started = time.perf_counter()
        baseline = fit_baseline(skin, tables)
        fitted = baseline_text(baseline, time.perf_counter() - started)
        print(fitted, flush=True)
        rows, _ = render_rows(skin, tables, baseline, refs, args.size, args.samples)
        for row in rows:
            row["film_um"] = film
        seconds = time.perf_counter() - start
        command = "python bench/speed_accuracy.py --film" + (
            "" if any(_same_film(film, f) for f in SLAB_FILMS_UM) else f" {film:g}")
        text = "\n\n".join([
            f"### The film at {film:.3g} um", markdown(rows, goals(rows), seconds, command),
            fitted, eevee_markdown(rows, f"`{command}`")])
        print(text)
        kept = [r for r in read_csv(csv_path) if not _same_film(r["film_um"], film)] \
            if csv_path.exists() else []
        rows = sorted(kept + rows, key=lambda r: float(r["film_um"]))  # stable: thinnest first
        mark_pareto(rows)
        write_csv(rows, csv_path)
        chart(rows, csv_path.with_suffix(".png"))
        if not args.quick and args.out == DOCS:
            write_film_block(DOCS / "speed_accuracy.md", film, text)
        print(f"speed_accuracy: film {film:.3g} um, {seconds / 60:.1f} min -> {csv_path}, .png",
              flush=True)
    return 0


def add_eevee_points(args) -> int:
    """``--eevee-only``: the EEVEE rows rendered again, the CSV's other rows kept."""
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="speed_accuracy_"))
    from support import bench_scene as scene_module
    from support import sphere_scene

    path = args.out / "speed_accuracy.csv"
    rows = [r for r in read_csv(path) if r["axis"] != "eevee"]
    sizes = {r["size_px"] for r in rows if r["axis"] == "render"}
    if sizes != {args.size}:
        raise SystemExit(f"{path} was rendered at {sorted(sizes)} px, not --size {args.size}")
    skin = presets.paper()
    tables = bake.bake(skin, "default")
    for light, ref in references(skin, args.size, args.lights).items():
        sphere = scene_module.sphere_scene(size=args.size, samples=16, radius_mm=RADIUS_MM,
                                           light_deg=light)
        with sphere_scene.addon_registered():
            rows += eevee_rows(sphere, tables, ref, light, args.size)
    mark_pareto(rows)
    write_csv(rows, path)
    chart(rows, args.out / "speed_accuracy.png")
    if args.out == DOCS:
        replace_block(DOCS / "speed_accuracy.md", eevee_markdown(rows), *EEVEE_MARKERS)
    print(eevee_markdown(rows))
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=48, help="pixels (square), default 48")
    parser.add_argument("--samples", type=int, nargs="+", default=[16, 64, 256, 1024])
    parser.add_argument("--lights", type=float, nargs="+", default=[0.0, 45.0, 75.0],
                        help="light angles from the view, degrees")
    parser.add_argument("--quick", action="store_true",
                        help="16 and 64 samples, no bake axis, nothing written to docs/")
    parser.add_argument("--out", type=Path, default=DOCS, help="folder for the CSV and PNG")
    parser.add_argument("--replot", action="store_true",
                        help="only redraw the PNG from the CSV in --out (no rendering)")
    parser.add_argument("--eevee-only", action="store_true",
                        help="render the EEVEE points alone and add them to the CSV in --out "
                        "(its other rows kept), the chart and the table")
    parser.add_argument("--film", type=float, nargs="*", metavar="UM",
                        help="the film as a slab at these thicknesses (um; none given: "
                        f"{', '.join(f'{f:.3g}' for f in SLAB_FILMS_UM)}): "
                        "speed_accuracy_slab.csv, .png and the section 'The film at a "
                        "thickness' (default: the paper's film)")
    args = parser.parse_args(argv)
    stem = "speed_accuracy" if args.film is None else "speed_accuracy_slab"
    if args.replot:
        chart(read_csv(args.out / f"{stem}.csv"), args.out / f"{stem}.png")
        return 0
    if args.eevee_only:
        if args.film is not None:
            parser.error("--eevee-only redraws the paper film's EEVEE points only")
        return add_eevee_points(args)
    if args.quick:
        args.samples = [16, 64]
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="speed_accuracy_"))
    if args.film is not None:
        return run_films(args, args.film or list(SLAB_FILMS_UM))
    start = time.perf_counter()
    skin = presets.paper()
    tables = bake.bake(skin, "default")
    print("reference images ...", flush=True)
    refs = references(skin, args.size, args.lights)
    bake_tables, baked = ({}, {}) if args.quick else bake_rows(skin)
    started = time.perf_counter()
    baseline = fit_baseline(skin, tables)
    fitted = baseline_text(baseline, time.perf_counter() - started)
    print(fitted, flush=True)
    rows, bake_errors = render_rows(skin, tables, baseline, refs, args.size, args.samples,
                                    bake_tables)
    for name, row in baked.items():
        row["error"] = bake_errors.get(name, float("nan"))
        rows.append(row)
    goal_rows = goals(rows)
    seconds = time.perf_counter() - start
    text = markdown(rows, goal_rows, seconds) + "\n\n" + fitted
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    suffix = "_quick" if args.quick else ""
    write_csv(rows, args.out / f"speed_accuracy{suffix}.csv")
    chart(rows, args.out / f"speed_accuracy{suffix}.png")
    if not args.quick and args.out == DOCS:
        replace_block(DOCS / "speed_accuracy.md", text, BEGIN, END)
        replace_block(DOCS / "speed_accuracy.md", eevee_markdown(rows), *EEVEE_MARKERS)
    print(f"speed_accuracy: {seconds / 60:.1f} min -> {args.out}/speed_accuracy{suffix}.csv, .png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
