"""Stability where the methods fail, and the costs the Auto tier uses (a benchmark).

    python bench/stability_sweep.py [--out docs/stability.md] [--no-render] [--regimes K ...]
    python bench/stability_sweep.py --costs [--repeats 3] [--write]
    python bench/stability_sweep.py --traits [--write]

The first form runs :func:`lut_baker.offline.validation.stability.sweep` (the exact model, the bake,
the closure fits and the reference images in every regime of stability.REGIMES) and, unless
``--no-render``, renders each tier in the same regimes with Cycles (:func:`render_regimes`): no NaN,
Inf or negative pixel, the white furnace (world colour 1, no light) and the error against the
reference image. It prints the table of docs/stability.md (``--out`` rewrites the part of that file
between its ``<!-- sweep -->`` markers).

``--costs`` measures what :mod:`lut_baker.auto_tier` stores: per-sample render time of every
candidate relative to the fullest (the slope between two sample counts, so that scene set-up
does not count) and its Monte Carlo noise coefficient (relative RMS between two seeds);
``--traits`` prints the paper preset's traits it assumes without tables.  With ``--write`` each
rewrites its section of lut_baker/auto_tier/measured.json (:mod:`lut_baker.auto_tier.measured`),
where the Auto tier reads them.

The scene is tests/support/bench_scene.py's (the reference's scene, shared with the tests):
its :class:`~support.bench_scene.Stage` (one scene built once, changed between renders),
:func:`~support.bench_scene.candidate_material` and :func:`~support.bench_scene.furnace_rings`.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
for _path in (ROOT, ROOT / "tests", ROOT / "bench"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

from doc_block import replace_block  # noqa: E402  (bench/doc_block.py)
from support.bench_scene import IRRADIANCE, Stage, furnace_rings  # noqa: E402
from support.sphere_scene import addon_registered  # noqa: E402

from lut_baker.offline.validation import compare  # noqa: E402

__all__ = ["measure_costs", "render_regime", "render_regimes", "main"]


# --------------------------------------------------------------------------------------------
# Costs and noise of the candidates (lut_baker.auto_tier's constants)
# --------------------------------------------------------------------------------------------
def measure_costs(*, size=96, samples=(16, 272), repeats=3, radius_mm=30.0, coverage=1.0):
    """Per-sample render time (relative to the fullest candidate) and noise coefficient
    ``k`` (one render's relative RMS deviation = k / sqrt(samples)) of every candidate of
    :data:`lut_baker.auto_tier.CANDIDATES`, Cycles CPU, paper preset at ``coverage``, sun at
    45 degrees.

    Times: the slope ``(t(high) - t(low)) / (high - low)`` (scene set-up does not count), the
    fastest of ``repeats`` interleaved runs, in wall-clock seconds (``relative_cost``) and in
    the process's CPU seconds (``relative_cpu``: all of Cycles' threads; on a shared machine
    other processes slow the wall clock but not this).  Noise:
    :func:`lut_baker.offline.validation.compare.noise_floor` of two seeds at the higher count, times
    ``sqrt(samples)``."""
    from lut_baker import auto_tier, bake
    from lut_baker.model import presets

    tables = bake.bake(presets.made_up_skin("paper_natural", "paper_bioplate",
                                            coverage=coverage), "preview")
    low, high = samples
    times = {c: {low: [], high: []} for c in auto_tier.CANDIDATES}
    cpu = {c: {low: [], high: []} for c in auto_tier.CANDIDATES}
    noise = {}

    with addon_registered():
        stage = Stage(size=size, samples=high, radius_mm=radius_mm)
        for _ in range(repeats):
            for candidate in auto_tier.CANDIDATES:
                for count in (low, high):
                    start = time.process_time()
                    times[candidate][count].append(
                        stage.render(tables, candidate, samples=count)[0])
                    cpu[candidate][count].append(time.process_time() - start)
        for candidate in auto_tier.CANDIDATES:
            a = stage.render(tables, candidate, seed=0)[1]
            b = stage.render(tables, candidate, seed=1)[1]
            noise[candidate] = compare.noise_floor(a, b, 0.5 * (a + b)) * math.sqrt(high)
    def slope(table):
        return {c: (min(t[high]) - min(t[low])) / (high - low) for c, t in table.items()}

    wall, busy = slope(times), slope(cpu)
    return {c: {"relative_cost": wall[c] / wall[auto_tier.FULLEST],
                "seconds_per_sample": wall[c],
                "relative_cpu": busy[c] / busy[auto_tier.FULLEST],
                "cpu_seconds_per_sample": busy[c],
                "noise_k": noise[c]} for c in auto_tier.CANDIDATES}


# --------------------------------------------------------------------------------------------
# Each tier in each regime
# --------------------------------------------------------------------------------------------


def _furnace_reference(tables, size):
    """The exact model's white-furnace image: at each pixel the directional albedo at its
    view angle (reciprocity; uniform light spreads nothing)."""
    centres = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    x, y = np.meshgrid(centres, -centres)
    r2 = x * x + y * y
    theta = np.degrees(np.arccos(np.sqrt(np.clip(1.0 - r2, 0.0, 1.0))))
    image = np.asarray(tables.directional_albedo(theta), float)
    return np.where((r2 < 1.0)[..., None], image, 0.0)


def render_regime(stage, item, candidates, *, seeds=(0, 1), furnace=True, tables=None):
    """Render every candidate in one :class:`lut_baker.offline.validation.stability.Regime` on
    ``stage`` (a :class:`Stage`; the add-on registered): per candidate name ``{"lit", "furnace",
    "spread"}``. Lit (each of the regime's lights, the worst kept): finite, min, max, ``error``
    against :func:`lut_baker.offline.validation.compare.reference_image` (from the tables; spread
    where the reference affords it), ``noise`` (two seeds) and ``bias``. Furnace: finite, min, max
    pixel, the largest ring mean of :func:`furnace_rings` and its standard error, the exact albedo's
    largest value and the error against the exact furnace image."""
    from lut_baker import bake
    from lut_baker.offline.validation import reference, stability

    skin = stability.regime_skin(item)
    tables = tables or bake.bake(skin, "preview")
    size = stage.scene.render.resolution_x
    # The spread needs the film's exact transmittance: for sharp lobes it does not fit in
    # memory (4.5 GB at 5 degrees); there the reference is local.
    affordable = (item.exact_affordable and reference.default_samples(skin, item.radius_mm)
                  <= stability.MAX_SPREAD_SAMPLES)
    references = {light: compare.reference_image(
        skin, tables=tables, resolution=size, radius_mm=item.radius_mm, light_angle_deg=light,
        irradiance=IRRADIANCE, spread=affordable) for light in item.lights_deg}
    furnace_ref = _furnace_reference(tables, size)
    mask = compare.sphere_mask(size)
    stage.frame(item.radius_mm)
    out = {}
    for candidate in candidates:
        lit = []
        stage.furnace(False)
        for light in item.lights_deg:
            stage.light(light)
            images = [stage.render(tables, candidate, seed=seed)[1] for seed in seeds]
            ref = references[light]
            error = compare.relative_rms(images[0], ref)
            floor = compare.noise_floor(images[0], images[-1], ref) if len(images) > 1 else 0.0
            lit.append({"light_deg": light, **stability.summary(np.stack(images)),
                        "error": error, "noise": floor, "bias": compare.bias(error, floor)})
        result = {"lit": dict(max(lit, key=lambda r: r["error"])), "spread": affordable}
        result["lit"]["finite"] = all(r["finite"] for r in lit)
        result["lit"]["min"] = min(r["min"] for r in lit)
        if furnace:
            stage.furnace(True)
            image = stage.render(tables, candidate)[1]
            stage.furnace(False)
            _, means, errors = furnace_rings(image)
            k = np.unravel_index(np.argmax(means), means.shape)
            result["furnace"] = {**stability.summary(image[mask]),
                                 "ring_max": float(means[k]), "ring_se": float(errors[k]),
                                 "albedo_max": float(furnace_ref[mask].max()),
                                 "error": compare.relative_rms(image, furnace_ref)}
        out[candidate.name] = result
    return out


def render_regimes(regimes=None, **options) -> dict:
    """:func:`render_regime` of both add-on tiers (and the Auto tier's choice where it is
    another candidate) over ``regimes`` (default all), by regime key."""
    from lut_baker import auto_tier
    from lut_baker.offline.validation import stability

    regimes = stability.REGIMES if regimes is None else regimes
    out = {}
    with addon_registered():
        stage = Stage(**{k: options.pop(k) for k in ("size", "samples") if k in options})
        for item in regimes:
            candidates = [auto_tier.Candidate("PRINCIPLED"), auto_tier.Candidate("LAYERED")]
            auto = stability.auto_choice(item).candidate
            if auto not in candidates:
                candidates.append(auto)
            start = time.perf_counter()
            out[item.key] = render_regime(stage, item, candidates, **options)
            print(f"# rendered {item.key}: {time.perf_counter() - start:.0f} s", flush=True)
    return out


def _print_costs(costs, args, coverage) -> None:
    print(f"# python bench/stability_sweep.py --costs --repeats {args.repeats} --size "
          f"{args.size} --samples {args.samples[0]} {args.samples[1]}: coverage {coverage:g}")
    for candidate, value in costs.items():
        print(f"{candidate.name:35s} relative cost {value['relative_cost']:.3f}  "
              f"({1e3 * value['seconds_per_sample']:.2f} ms/sample)  cpu "
              f"{value['relative_cpu']:.3f} ({1e3 * value['cpu_seconds_per_sample']:.2f} "
              f"ms/sample)  noise k {value['noise_k']:.4f}")
    for key in ("relative_cost", "relative_cpu"):
        print(f"# coverage {coverage:g}, {key} in CANDIDATES order:",
              tuple(round(v[key], 3) for v in costs.values()))
    print(f"# coverage {coverage:g}, noise k in CANDIDATES order:",
          tuple(round(v["noise_k"], 4) for v in costs.values()))


def _costs_section(by_coverage: dict, args) -> dict:
    """The ``cycles_costs`` section of lut_baker/auto_tier/measured.json from
    :func:`measure_costs` at coverages 1 and 0."""
    from lut_baker import auto_tier
    from lut_baker.auto_tier import measured

    old = measured.load()["cycles_costs"]

    def table(key, digits):
        return {f"{coverage:g}": {c.name: round(value[key], digits) for c, value in costs.items()}
                for coverage, costs in by_coverage.items()}

    shares = {f"{coverage:g}": round(auto_tier.gloss_and_skin_shares(
        _paper_tables(coverage), 45.0)[1], 4) for coverage in by_coverage}
    return {"command": (f"python bench/stability_sweep.py --costs --repeats {args.repeats} "
                        f"--size {args.size} --samples {args.samples[0]} {args.samples[1]} "
                        "--write"),
            "about": old["about"], "relative_cost": table("relative_cost", 3),
            "noise_k": table("noise_k", 4), "skin_share": shares}


def _paper_tables(coverage=1.0):
    from lut_baker import bake
    from lut_baker.model import presets

    return bake.bake(presets.made_up_skin("paper_natural", "paper_bioplate",
                                          coverage=coverage), "default")


def _traits_section() -> dict:
    """The ``paper_traits`` section of lut_baker/auto_tier/measured.json."""
    from lut_baker import auto_tier
    from lut_baker.auto_tier import measured
    from lut_baker.closures import fitting

    tables = _paper_tables()
    traits = auto_tier.traits_from_tables(tables, fitting.fit_closures(tables))

    def by_angle(table):
        return {f"{angle:g}": round(value, 4) for angle, value in table.items()}

    return {"command": "python bench/stability_sweep.py --traits --write",
            "about": measured.load()["paper_traits"]["about"],
            "tier_errors": {k: round(v, 4) for k, v in traits.tier_errors.items()},
            "profile_mismatch": round(traits.profile_mismatch, 4),
            "skin_share": by_angle(traits.skin_share),
            "gloss_share": by_angle(traits.gloss_share),
            "gloss_omission": {tier: by_angle(by_light)
                               for tier, by_light in traits.gloss_omission.items()}}


def _print_traits() -> None:
    """The paper preset's traits as lut_baker.auto_tier stores them."""
    from lut_baker import auto_tier, bake
    from lut_baker.closures import fitting
    from lut_baker.model import presets

    tables = bake.bake(presets.made_up_skin("paper_natural", "paper_bioplate"), "default")
    traits = auto_tier.traits_from_tables(tables, fitting.fit_closures(tables))
    print(f"# {auto_tier.TRAITS_COMMAND}")
    print("PAPER_TIER_ERRORS =", {k: round(v, 4) for k, v in traits.tier_errors.items()})
    print("PAPER_MISMATCH =", round(traits.profile_mismatch, 4))
    print("PAPER_SKIN_SHARE =", {k: round(v, 4) for k, v in traits.skin_share.items()})
    print("PAPER_GLOSS_SHARE =", {k: round(v, 4) for k, v in traits.gloss_share.items()})
    print("PAPER_GLOSS_OMISSION =", {tier: {k: round(v, 4) for k, v in by_light.items()}
                                     for tier, by_light in traits.gloss_omission.items()})
    print(f"# mean radius {traits.mean_radius_mm:.3f} mm")


# --------------------------------------------------------------------------------------------
# The docs' tables
# --------------------------------------------------------------------------------------------
TEST_SAMPLES = 64
"""Samples of tests/makeup_skin_addon/test_render_stability.py's renders: the bounds allow
for their noise."""
MARKERS = ("<!-- sweep: begin (python bench/stability_sweep.py --out docs/stability.md) -->",
           "<!-- sweep: end -->")


def bound(bias: float, noise: float, samples: int, test_samples: int = TEST_SAMPLES) -> float:
    """The error bound a render at ``test_samples`` keeps: the measured ``bias`` and the
    ``noise`` scaled to those samples in quadrature, plus a quarter and 0.5%, rounded up to
    0.5%."""
    expected = math.hypot(bias, noise * math.sqrt(samples / test_samples))
    return math.ceil((1.25 * expected + 0.005) / 0.005) * 0.005


def _pct(value, digits=1) -> str:
    return f"{100 * value:.{digits}f}%"


def pure_table(results) -> str:
    """Markdown: the methods without Blender in every regime."""
    lines = ["| regime | model: finite, min, albedo max | bake: min, albedo max, error | "
             "reference: finite, min, spread (light kept) | fits: Principled / Layered "
             "(RMS, albedo) | Auto |",
             "| --- | --- | --- | --- | --- | --- |"]
    for r in results:
        model = r["model"]["reflection"]
        albedo = r["model"].get("albedo")
        model_text = (f"{'yes' if model['finite'] else 'NO'}, {model['min']:.2g}, "
                      + (f"{albedo['max']:.3f}" if albedo else
                         f"{r['model']['pairs']} pairs only (~8 s, 2.4 GB each)"))
        baked = r["bake"]
        error = baked.get("error", {})
        bake_text = (f"{baked['min']:.2g}, {baked['albedo']['max']:.3f}, "
                     + (_pct(error["reflection"], 2) if error else "-"))
        ref = r["reference"]
        if ref is None:
            ref_text = "not drawn (exact evaluator unaffordable)"
        else:
            kept = (f"yes ({_pct(ref['spread_over_local'])})" if ref["spread"] else
                    f"no ({ref['entry_samples']:.1e} entry samples)")
            image = ref["image"]
            ref_text = f"{'yes' if image['finite'] else 'NO'}, {image['min']:.2g}, {kept}"
        tiers = r.get("tiers", {})
        fits = " / ".join(f"{_pct(tiers[t]['rms'])}, {_pct(tiers[t]['albedo'])}"
                          for t in ("PRINCIPLED", "LAYERED") if t in tiers) or "-"
        lines.append(f"| `{r['key']}` {r['name']} | {model_text} | {bake_text} | {ref_text} | "
                     f"{fits} | {r['auto']['choice']} |")
    return "\n".join(lines)


def render_table(renders, samples) -> str:
    """Markdown: each tier rendered in every regime (the test's bounds in the last but one
    column)."""
    lines = ["| regime | tier | finite, min | error | noise | bias | bound at "
             f"{TEST_SAMPLES} samples | furnace: brightest ring (se) / exact albedo max |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for key, by_tier in renders.items():
        for name, r in by_tier.items():
            lit, furnace = r["lit"], r.get("furnace")
            furnace_text = (f"{furnace['ring_max']:.3f} ({furnace['ring_se']:.3f}) / "
                            f"{furnace['albedo_max']:.3f}" if furnace else "-")
            lines.append(
                f"| `{key}` | {name} | {'yes' if lit['finite'] else 'NO'}, {lit['min']:.2g} | "
                f"{_pct(lit['error'])} | {_pct(lit['noise'])} | {_pct(lit['bias'])} | "
                f"{_pct(bound(lit['bias'], lit['noise'], samples))} | {furnace_text} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--costs", action="store_true",
                        help="measure the candidates' relative costs and noise")
    parser.add_argument("--traits", action="store_true",
                        help="print the paper preset's traits (lut_baker.auto_tier)")
    parser.add_argument("--write", action="store_true",
                        help="--costs, --traits: rewrite their section of "
                             "lut_baker/auto_tier/measured.json")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--size", type=int, default=None,
                        help="render size, px (default 96 for --costs, 32 for the sweep)")
    parser.add_argument("--samples", type=int, nargs="+", default=None,
                        help="--costs: two sample counts (16 272); sweep: one (128)")
    parser.add_argument("--regimes", nargs="+", help="regime keys (default all)")
    parser.add_argument("--out", type=Path, help="rewrite the tables in this markdown file")
    parser.add_argument("--no-render", action="store_true", help="pure sweep only")
    args = parser.parse_args(argv)
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="stability_"))
    if args.traits:
        _print_traits()
        if args.write:
            from lut_baker.auto_tier import measured

            measured.write_section("paper_traits", _traits_section())
            print(f"# wrote paper_traits to {measured.PATH}")
        return 0
    if args.costs:
        args.size = args.size or 96
        args.samples = args.samples or [16, 272]
        by_coverage = {}
        for coverage in (1.0, 0.0):
            by_coverage[coverage] = measure_costs(size=args.size, samples=tuple(args.samples[:2]),
                                                  repeats=args.repeats, coverage=coverage)
            _print_costs(by_coverage[coverage], args, coverage)
        if args.write:
            from lut_baker.auto_tier import measured

            measured.write_section("cycles_costs", _costs_section(by_coverage, args))
            print(f"# wrote cycles_costs to {measured.PATH}")
        return 0
    from lut_baker.offline.validation import stability

    regimes = ([stability.regime(k) for k in args.regimes] if args.regimes
               else list(stability.REGIMES))
    size, samples = args.size or 32, (args.samples or [128])[0]
    start = time.perf_counter()
    results = []
    for item in regimes:
        results.append(stability.check_regime(item, error_points=60, model_points=24,
                                              fit=True))
        print(f"# checked {item.key}: {time.perf_counter() - start:.0f} s", flush=True)
    text = ("Methods without Blender (`lut_baker.offline.validation.stability.check_regime`: exact "
            "model at 24 direction pairs, preview bake, its error at 60 random points, reference "
            "images 16 px):\n\n" + pure_table(results))
    if not args.no_render:
        renders = render_regimes(regimes, size=size, samples=samples)
        text += (f"\n\nEach tier in Cycles (`render_regimes`: {size} px, {samples} samples, "
                 "seeds 0 and 1, against `lut_baker.offline.validation.compare.reference_image` "
                 "from the preview tables, spread where affordable; white furnace: world colour 1, "
                 "no light, rings of equal width in cos(theta_o)):\n\n"
                 + render_table(renders, samples))
    print(text)
    print(f"# stability sweep: {time.perf_counter() - start:.0f} s")
    if args.out:
        replace_block(args.out, text, *MARKERS)
    return 0


if __name__ == "__main__":
    sys.exit(main())
