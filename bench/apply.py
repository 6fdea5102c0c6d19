"""Apply's time and memory per foundation preset, the panel's draw time and the command-line
bake's, for any checkout (a benchmark, not a test).

    python bench/apply.py --repo CHECKOUT [--json FILE] [--presets A B ...] [--repeats 3]
                          [--tier LAYERED|AUTO|PRINCIPLED] [--single-above SECONDS] [--no-cli]
    python bench/apply.py --before FILE --after FILE [--chart PNG]

Measures the add-on of ``CHECKOUT`` (its ``makeup_skin_addon`` and ``lut_baker``, first on
``sys.path``: bench/checkout.py) on the scene of *this* repository: the textured head of
tests/support/character.py (seed 0) with its portrait camera and lights, resolution
``default``, skin ``paper_bioplate`` (the default), tier ``--tier`` (default Layered).  Cases:
every foundation of the checkout's ``lut_baker.model.presets.FOUNDATIONS`` (chosen in the panel:
its own shade), ``film_min``: Film Roughness at its minimum (the default foundation; in older
checkouts ``override_film`` on and ``film_lobe_width`` at the property's minimum), and where the
checkout has them ``skin_min``: Skin Roughness at its minimum, and ``defaults``: every setting
at its default (the first Apply matches the shade to the skin).

Per case, one fresh process per repeat (so the first Apply is truly cold: first imports,
bake, closure fit, group, material):

- ``cold_s`` -- wall seconds of the first ``bpy.ops.makeup_skin.apply()``;
- ``cold_mb`` -- memory it added: the resident set's high-water mark during Apply minus the
  resident set before it (VmHWM is reset just before Apply through /proc/self/clear_refs; where
  that is refused, ``ru_maxrss`` after minus VmRSS before, which is exact whenever Apply's peak
  is the process's highest so far); ``kept_mb``: the resident set after Apply minus before;
- ``repeat_s`` / ``repeat_mb`` -- Apply again on the same object with the same settings
  (median of up to 3 in the process, one when the first took over a second);
- ``draw_ms`` -- one draw of the Made-up Skin panel (``ui.draw_settings`` and ``ui.draw_fit``
  into tests/support/panel_layout.py's stand-in layout; the Properties editor's context, whose
  ``material`` is the object's): the first after Apply, and the median of 20; ``draw_auto_ms``:
  the same after switching the tier to Auto (the panel then shows the Auto choice, which it
  works out while drawing).

Per foundation, the command line ``python -m lut_baker bake --foundation NAME --out DIR`` run
from the checkout (one process per repeat): ``wall_s`` (whole process), ``peak_mb`` (the child's
``ru_maxrss`` from ``os.wait4``) and ``bytes`` (what it wrote to DIR).

Reports medians over the processes; the raw runs go to ``--json``.  ``--single-above S``: a
case whose first process took longer than S seconds gets that one process only (the old code
takes up to 90 s and 5 GB per Apply for narrow gloss lobes); the JSON says how many ran.  The
machine's load (``os.getloadavg``) is recorded at the start and the end.

``--before``/``--after`` (two such JSON files): a Markdown table of both with the targets, and
with ``--chart PNG`` bars per case for cold Apply time and memory, before and after, log scale,
target lines drawn.

Run with the venv's python of the Blender line to measure (``$(tools/venv.sh)/bin/python``).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from checkout import (  # bench/checkout.py
    MB,
    Memory,
    addon_attribute,
    commit,
    machine_load,
    packages_commit,
    use_checkout,
    write_figures,
)

HERE = Path(__file__).resolve()
FILM_MIN = "film_min"
"""The case of Film Roughness at its minimum (the default foundation; older checkouts: Override
Film on and the film's lobe width at its minimum)."""
SKIN_MIN = "skin_min"
"""The case of Skin Roughness at its minimum (the default foundation and skin), in checkouts
that have it: the narrowest skin gloss path 3 goes through, the largest grids."""
DEFAULTS = "defaults"
"""The case of every setting at its default, in checkouts whose first Apply matches the shade to
the skin (the mean of the head's albedo texture) before baking."""
NEW_CASES = (SKIN_MIN, DEFAULTS)
DRAWS = 20
REPEATS_IN_PROCESS = 3
TARGETS = {
    "cold_s": 1.0,
    "cold_s paper_natural": 0.5,
    "repeat_s": 0.05,
    "cold_mb": 300.0,
    "draw_ms": 5.0,
    "cli wall_s": 2.0,
    "cli mb written": 16.0,
}
"""The goals these figures are judged by (wall time on a quiet machine)."""


# -- the worker: one case in a fresh process ------------------------------------------------

def _setup(repo: Path):
    """Import bpy, the checkout's add-on and this repository's tests/support; returns ``(bpy,
    addon, support)`` with ``support`` a namespace of the modules used."""
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="bench_apply_"))
    import bpy

    _, addon = use_checkout(repo, ("lut_baker", "makeup_skin_addon"), who="apply")
    from support import character, panel_layout, sphere_scene

    return bpy, addon, (character, panel_layout, sphere_scene)


class _PanelContext:
    """``bpy.context`` as the Properties editor's material tab gives it to a panel: its
    ``material`` is the active object's (headless ``bpy.context`` has none)."""

    def __init__(self, context, material):
        self._context, self.material = context, material

    def __getattr__(self, name):
        return getattr(self._context, name)


def _draw_ms(bpy, ui, layout_type, material, draws: int) -> tuple[float, float]:
    """``(first, median of draws)`` milliseconds of one panel draw (settings, then fit)."""
    context = _PanelContext(bpy.context, material)
    times = []
    for _ in range(draws + 1):
        layout = layout_type()
        start = time.perf_counter()
        ui.draw_settings(layout, context)
        ui.draw_fit(layout, context)
        times.append(1e3 * (time.perf_counter() - start))
    return times[0], statistics.median(times[1:])


CPU_SECONDS: list[float] = []
"""Process CPU seconds (all threads) of each :func:`_apply_once` call in this process."""


def _apply_once(bpy) -> float:
    """Run Apply on the active object; returns wall seconds (CPU seconds to CPU_SECONDS)."""
    start, cpu = time.perf_counter(), time.process_time()
    result = bpy.ops.makeup_skin.apply()
    seconds = time.perf_counter() - start
    CPU_SECONDS.append(time.process_time() - cpu)
    if result != {"FINISHED"}:
        raise SystemExit(f"apply: Apply returned {result}")
    return seconds


def worker(bpy, support, case: str, tier: str) -> dict:
    """Cold Apply, repeated Apply, panel draws of one case in this (fresh) process."""
    character, panel_layout, _ = support
    from makeup_skin_addon import ui

    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    head = character.build_character("Head", seed=0)
    character.portrait_camera_and_lights(bpy.context.scene, head)
    for other in bpy.context.view_layer.objects:
        other.select_set(other == head)
    bpy.context.view_layer.objects.active = head
    material = head.active_material
    settings = material.makeup_skin
    settings.tier = tier
    settings.resolution = "default"
    has_roughness = "film_roughness" in settings.bl_rna.properties
    if case == FILM_MIN and has_roughness:
        settings.film_roughness = settings.bl_rna.properties["film_roughness"].hard_min
    elif case == FILM_MIN:
        settings.override_film = True
        settings.film_lobe_width = settings.bl_rna.properties["film_lobe_width"].hard_min
    elif case == SKIN_MIN:
        settings.skin_roughness = settings.bl_rna.properties["skin_roughness"].hard_min
    elif case != DEFAULTS:
        settings.foundation = case
    out = {"case": case, "tier": tier, "foundation": settings.foundation,
           "film_lobe_width_deg": (float(settings.film_lobe_width) * 180.0 / 3.141592653589793
                                   if settings.override_film and not has_roughness else None),
           "film_roughness": float(settings.film_roughness) if has_roughness else None,
           "skin_roughness": float(settings.skin_roughness) if has_roughness else None}
    with Memory() as memory:
        out["cold_s"] = _apply_once(bpy)
    out["cold_cpu_s"] = CPU_SECONDS[-1]
    out.update(cold_mb=memory.added_mb, kept_mb=memory.kept_mb, peak_reset=memory.reset,
               rss_before_mb=memory.before / MB)
    material = head.active_material
    out["draw_first_ms"], out["draw_ms"] = _draw_ms(bpy, ui, panel_layout.RecordingLayout,
                                                    material, DRAWS)
    repeats, peaks = [], []
    while len(repeats) < REPEATS_IN_PROCESS and (not repeats or repeats[0] <= 1.0):
        with Memory() as memory:
            repeats.append(_apply_once(bpy))
        peaks.append(memory.added_mb)
    out.update(repeat_s=statistics.median(repeats), repeat_runs=repeats,
               repeat_cpu_s=statistics.median(CPU_SECONDS[-len(repeats):]),
               repeat_mb=max(peaks))
    out["resolved_tier"] = (addon_attribute("resolve_tier")(settings, bpy.context.scene)
                            if tier == "AUTO" else tier)
    settings.tier = "AUTO"  # headless: marks the material for a preview re-bake, nothing more
    out["draw_auto_first_ms"], out["draw_auto_ms"] = _draw_ms(
        bpy, ui, panel_layout.RecordingLayout, material, DRAWS)
    return out


# -- the command-line bake ------------------------------------------------------------------

def cli_bake(repo: Path, foundation: str) -> dict:
    """One ``python -m lut_baker bake --foundation NAME`` process run from ``repo``: wall
    seconds, the child's peak resident set, bytes written."""
    env = dict(os.environ, PYTHONPATH=str(repo))
    with tempfile.TemporaryDirectory(prefix="bench_apply_cli_") as folder, \
            tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        written = Path(folder) / "out"
        start = time.perf_counter()
        process = subprocess.Popen(
            [sys.executable, "-m", "lut_baker", "bake", "--foundation", foundation,
             "--out", str(written)], cwd=repo, env=env, stdout=out, stderr=err)
        _, status, usage = os.wait4(process.pid, 0)  # the child's own rusage
        seconds = time.perf_counter() - start
        process.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        if process.returncode != 0:
            raise SystemExit(f"apply: the bake of {foundation} failed:\n{out.read()}\n"
                             f"{err.read()}")
        files = {p.name: p.stat().st_size for p in written.iterdir()}
        line = out.read().strip()
    return {"wall_s": seconds, "peak_mb": usage.ru_maxrss * 1024 / MB,
            "bytes": sum(files.values()), "files": files, "line": line}


# -- the runner ------------------------------------------------------------------------------

def _run_worker(repo: Path, case: str, tier: str) -> dict:
    result = subprocess.run([sys.executable, str(HERE), "--repo", str(repo), "--worker", case,
                             "--tier", tier], capture_output=True, text=True, check=False)
    line = next((line for line in reversed(result.stdout.splitlines())
                 if line.startswith("RESULT ")), None)
    if result.returncode != 0 or line is None:
        raise SystemExit(f"apply: worker {case} failed ({result.returncode}):\n"
                         f"{result.stdout[-2000:]}\n{result.stderr[-4000:]}")
    return json.loads(line[len("RESULT "):])


def _repeated(measure, repeats: int, single_above: float | None, key: str) -> list:
    """``repeats`` results of ``measure()``, or one when the first's ``key`` exceeds
    ``single_above`` seconds."""
    runs = [measure()]
    while len(runs) < repeats and (single_above is None or runs[0][key] <= single_above):
        runs.append(measure())
    return runs


def _medians(runs: list[dict]) -> dict:
    keys = [k for k, v in runs[0].items() if isinstance(v, int | float) and not isinstance(v, bool)]
    return {k: statistics.median(run[k] for run in runs) for k in keys}


def _new_cases(repo: Path) -> list[str]:
    """:data:`NEW_CASES` when the checkout's settings have Skin Roughness (and a first Apply
    that matches the skin), else none."""
    text = (repo / "makeup_skin_addon" / "properties.py").read_text(encoding="utf-8")
    return list(NEW_CASES) if "skin_roughness" in text else []


def _foundations(repo: Path) -> list[str]:
    """The checkout's foundation presets (in a child process: this one keeps its sys.path)."""
    code = ("import json, sys; sys.path.insert(0, sys.argv[1]); "
            "from lut_baker.model.presets import FOUNDATIONS; print(json.dumps(list(FOUNDATIONS)))")
    result = subprocess.run([sys.executable, "-c", code, str(repo)], capture_output=True,
                            text=True, check=True)
    return json.loads(result.stdout)


def measure(repo: Path, cases: list[str], tier: str, repeats: int, single_above, cli: bool,
            progress=print) -> dict:
    results = {"repo": str(repo), "commit": commit(repo),
               "packages_commit": packages_commit(repo), "tier": tier, "repeats": repeats,
               "single_above_s": single_above, "python": sys.executable,
               "machine": platform.node(), "cpus": os.cpu_count(), "load_start": machine_load(),
               "started": time.strftime("%Y-%m-%d %H:%M:%S"), "apply": {}, "cli": {}}
    start = time.perf_counter()
    for case in cases:
        runs = _repeated(lambda case=case: _run_worker(repo, case, tier), repeats,
                         single_above, "cold_s")
        results["apply"][case] = {"median": _medians(runs), "runs": runs,
                                  "load": machine_load()}
        m = results["apply"][case]["median"]
        progress(f"  {case}: cold {m['cold_s']:.2f} s, {m['cold_mb']:.0f} MB, repeat "
                 f"{m['repeat_s']:.3f} s, draw {m['draw_ms']:.2f} ms ({len(runs)} runs, load "
                 f"{results['apply'][case]['load'][0]})")
    if cli:
        for case in (c for c in cases if c != FILM_MIN):
            runs = _repeated(lambda case=case: cli_bake(repo, case), repeats, single_above,
                             "wall_s")
            results["cli"][case] = {"median": _medians(runs), "runs": runs, "load": machine_load()}
            m = results["cli"][case]["median"]
            progress(f"  cli {case}: {m['wall_s']:.2f} s, {m['peak_mb']:.0f} MB peak, "
                     f"{m['bytes'] / MB:.1f} MB written ({len(runs)} runs)")
    results["load_end"] = machine_load()
    results["seconds"] = time.perf_counter() - start
    return results


# -- reports ---------------------------------------------------------------------------------

def print_report(results: dict) -> None:
    print(f"\nApply on the head of tests/support/character.py, tier {results['tier']}, "
          f"resolution default, skin paper_bioplate -- checkout {results['repo']} at "
          f"{results['commit']} (packages last changed in {results['packages_commit'][:12]}); "
          f"load {results['load_start']} -> {results['load_end']} on "
          f"{results['cpus']} CPUs; {results['seconds'] / 60:.1f} min")
    print(f"\n{'case':<14} {'runs':>4} {'cold s':>8} {'cold CPU':>8} {'cold MB':>8} "
          f"{'kept MB':>8} {'repeat s':>9} {'repeat MB':>9} {'draw ms':>8} {'1st draw':>8} "
          f"{'Auto draw':>9} {'1st Auto':>8}")
    for case, entry in results["apply"].items():
        m = entry["median"]
        print(f"{case:<14} {len(entry['runs']):>4} {m['cold_s']:>8.2f} {m['cold_cpu_s']:>8.2f} "
              f"{m['cold_mb']:>8.0f} {m['kept_mb']:>8.0f} {m['repeat_s']:>9.3f} "
              f"{m['repeat_mb']:>9.0f} {m['draw_ms']:>8.2f} {m['draw_first_ms']:>8.2f} "
              f"{m['draw_auto_ms']:>9.2f} {m['draw_auto_first_ms']:>8.1f}")
    if results["cli"]:
        print(f"\n{'bake (CLI)':<14} {'runs':>4} {'wall s':>8} {'peak MB':>8} {'written MB':>10}")
        for case, entry in results["cli"].items():
            m = entry["median"]
            print(f"{case:<14} {len(entry['runs']):>4} {m['wall_s']:>8.2f} {m['peak_mb']:>8.0f} "
                  f"{m['bytes'] / MB:>10.2f}")
    print(f"\nTargets (quiet machine): cold Apply <= {TARGETS['cold_s']} s (paper_natural "
          f"<= {TARGETS['cold_s paper_natural']} s), repeat <= {1e3 * TARGETS['repeat_s']:.0f} "
          f"ms, memory <= {TARGETS['cold_mb']:.0f} MB, draw <= {TARGETS['draw_ms']} ms, CLI "
          f"<= {TARGETS['cli wall_s']} s and <= {TARGETS['cli mb written']:.0f} MB written.")


def _label(results: dict) -> str:
    """The commit that last changed the measured packages (short), else the checkout's."""
    return results.get("packages_commit", results["commit"])[:12]


def _cell(before, after, fmt: str) -> str:
    pick = [format(v, fmt) if v is not None else "-" for v in (before, after)]
    return " / ".join(pick)


def _median_of(results, kind, case, key):
    entry = results.get(kind, {}).get(case)
    return None if entry is None else entry["median"].get(key)


def markdown(before: dict, after: dict) -> str:
    """The before/after table (Markdown), targets in the header."""
    cases = list(dict.fromkeys([*before["apply"], *after["apply"]]))
    lines = [f"Before: {_label(before)} (load {before['load_start'][0]}); after: "
             f"{_label(after)} (load {after['load_start'][0]}); tier "
             f"{before['tier']} / {after['tier']}; each cell before / after.", "",
             "| case | cold Apply s (<= 1; paper <= 0.5) | its CPU s | repeat Apply s (<= 0.05) "
             "| Apply MB (<= 300) | draw ms (<= 5) | first Auto draw ms (<= 5) "
             "| CLI s (<= 2) | CLI peak MB | CLI MB written (<= 16) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for case in cases:
        row = [case]
        for key, fmt in (("cold_s", ".2f"), ("cold_cpu_s", ".2f"), ("repeat_s", ".3f"),
                         ("cold_mb", ".0f"), ("draw_ms", ".2f"), ("draw_auto_first_ms", ".1f")):
            row.append(_cell(_median_of(before, "apply", case, key),
                             _median_of(after, "apply", case, key), fmt))
        for key, scale, fmt in (("wall_s", 1.0, ".2f"), ("peak_mb", 1.0, ".0f"),
                                ("bytes", 1 / MB, ".1f")):
            values = [_median_of(r, "cli", case, key) for r in (before, after)]
            row.append(_cell(*[v * scale if v is not None else None for v in values], fmt))
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def chart(before: dict, after: dict, path: Path) -> None:
    """Bars per case: cold Apply seconds and memory added, before and after, log scale, with
    the target lines."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    cases = list(dict.fromkeys([*before["apply"], *after["apply"]]))
    x = np.arange(len(cases))
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2), constrained_layout=True)
    for ax, key, unit, title in ((axes[0], "cold_s", "s", "First Apply (cold), wall time"),
                                 (axes[1], "cold_mb", "MB", "Memory added by Apply (peak)")):
        for offset, (label, results, colour) in zip((-0.2, 0.2), (
                (f"before {_label(before)[:7]}", before, "#c0504d"),
                (f"after {_label(after)[:7]}", after, "#4f81bd")), strict=True):
            values = [_median_of(results, "apply", c, key) for c in cases]
            heights = [v if v is not None else np.nan for v in values]
            ax.bar(x + offset, heights, 0.4, label=label, color=colour)
        if key == "cold_s":
            ax.axhline(TARGETS["cold_s"], color="k", ls="--", lw=1, label="target 1 s")
            ax.axhline(TARGETS["cold_s paper_natural"], color="k", ls=":", lw=1,
                       label="target paper 0.5 s")
        else:
            ax.axhline(TARGETS["cold_mb"], color="k", ls="--", lw=1, label="target 300 MB")
        ax.set_yscale("log")
        ax.set_ylabel(unit)
        ax.set_title(title)
        ax.set_xticks(x, cases, rotation=35, ha="right")
        ax.legend(fontsize=8)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repo", type=Path,
                        help="checkout whose makeup_skin_addon/ and lut_baker/ are measured")
    parser.add_argument("--presets", nargs="+", metavar="CASE",
                        help=f"foundations (and/or {FILM_MIN}) to measure (default: every "
                             f"foundation of the checkout and {FILM_MIN})")
    parser.add_argument("--tier", default="LAYERED", choices=("LAYERED", "PRINCIPLED", "AUTO"))
    parser.add_argument("--repeats", type=int, default=3,
                        help="fresh processes per case (default 3)")
    parser.add_argument("--single-above", type=float, metavar="SECONDS",
                        help="one process only for a case whose first took longer")
    parser.add_argument("--no-cli", action="store_true", help="leave out the command-line bake")
    parser.add_argument("--json", type=Path, help="write the figures here")
    parser.add_argument("--before", type=Path, help="a --json file of the old code")
    parser.add_argument("--after", type=Path, help="a --json file of the new code")
    parser.add_argument("--chart", type=Path, help="with --before/--after: the chart (PNG)")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.before or args.after:
        if not (args.before and args.after):
            parser.error("--before and --after go together")
        before, after = (json.loads(p.read_text()) for p in (args.before, args.after))
        print(markdown(before, after))
        if args.chart:
            chart(before, after, args.chart)
            print(f"\n-> {args.chart}")
        return 0
    if args.repo is None:
        parser.error("--repo is required")
    repo = args.repo.resolve()
    if not (repo / "makeup_skin_addon").is_dir():
        parser.error(f"{repo} has no makeup_skin_addon/")
    if args.worker is not None:
        bpy, addon, support = _setup(repo)
        with support[2].addon_registered():  # unregistered at the end: bpy 4.5 hangs otherwise
            result = worker(bpy, support, args.worker, args.tier)
        print("RESULT " + json.dumps(result))
        return 0
    cases = args.presets or [*_foundations(repo), FILM_MIN, *_new_cases(repo)]
    results = measure(repo, cases, args.tier, args.repeats, args.single_above, not args.no_cli)
    print_report(results)
    write_figures(args.json, results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
