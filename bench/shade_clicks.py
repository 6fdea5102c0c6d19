"""Match Skin and the shade steps across the Thickness the panel allows: each click's CPU on
the main thread (a benchmark, not a test).

    python bench/shade_clicks.py --repo CHECKOUT [--thicknesses 1 9.56 300 3000 10000]
                                 [--repeats 3] [--json FILE]

In one process: the textured head of ``tests/support/artist_skins.py`` (its Principled skin,
uniform white light), Apply at every default (preview first, the refinement swapped in as
the add-on's timers would), then for each thickness (``thickness_um`` set, its rebuild
swapped in): Match Skin, Lighter, Darker, Match Skin again, each click's CPU seconds
(``time.process_time``, the main thread's: the group's rebuild runs on a worker and is
waited for between clicks).  ``--repeats``: fresh processes; the table gives the median and
the worst.  The target is a click's 0.2 s (docs/addon.md, "Match Skin"), three times slower
0.6 s of this machine's.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

from checkout import machine_load, swapped_in, write_figures  # bench/checkout.py
from interactive import _scene, _setup  # bench/interactive.py

CLICKS = ("match", "lighter", "darker", "match again")
TARGET_S = 0.2
"""A click's target, CPU seconds on this machine (docs/addon.md, "Match Skin")."""


def one_process(repo: Path, thicknesses: list[float]) -> dict:
    """Every click at every thickness in this process: ``{thickness: {click: CPU s}}``."""
    bpy, artist_skins, sphere_scene = _setup(repo)
    obj = _scene(bpy, artist_skins, sphere_scene, "defaults/principled")
    import makeup_skin_addon
    from makeup_skin_addon import live

    makeup_skin_addon.register()
    live.can_refine = lambda: True  # as with a window: rebuilds go to a worker thread
    material = obj.active_material
    settings = material.makeup_skin
    settings.live_update = False

    def settle() -> None:
        if material.name in live.in_flight():
            swapped_in(bpy, live, material.name, lambda: None)

    def run(click: str) -> float:
        start = time.process_time()
        if click.startswith("match"):
            result = bpy.ops.makeup_skin.match_skin()
        else:
            result = bpy.ops.makeup_skin.shade_step(direction=click.upper())
        spent = time.process_time() - start
        if result != {"FINISHED"}:
            raise SystemExit(f"shade_clicks: {click} returned {result}")
        settle()
        return spent

    try:
        bpy.ops.makeup_skin.apply()
        settle()
        out = {}
        for thickness in thicknesses:
            settings.thickness_um = thickness
            settle()
            out[str(thickness)] = {click: run(click) for click in CLICKS}
        return out
    finally:
        makeup_skin_addon.unregister()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repo", type=Path, default=Path(__file__).resolve().parents[1])
    parser.add_argument("--thicknesses", type=float, nargs="+",
                        default=[1.0, 9.56, 300.0, 3000.0, 10000.0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--json", type=Path)
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        print("RESULT " + json.dumps(one_process(args.repo, args.thicknesses)))
        return 0
    load = machine_load()
    runs = []
    for _ in range(args.repeats):
        command = [sys.executable, __file__, "--worker", "--repo", str(args.repo),
                   "--thicknesses", *map(str, args.thicknesses)]
        done = subprocess.run(command, capture_output=True, text=True, check=False)
        line = next((x for x in done.stdout.splitlines() if x.startswith("RESULT ")), None)
        if done.returncode != 0 or line is None:
            print(done.stdout[-2000:], done.stderr[-4000:], sep="\n")
            raise SystemExit("shade_clicks: a worker failed")
        runs.append(json.loads(line.removeprefix("RESULT ")))
    print(f"{args.repo}; {args.repeats} fresh processes; load {load}; CPU s of the main "
          f"thread, median (worst); target {TARGET_S} s, x3 {3 * TARGET_S:.1f} s")
    print(f"  {'thickness um':>12}  " + "  ".join(f"{c:>16}" for c in CLICKS))
    table = {}
    for thickness in runs[0]:
        cells, row = [], {}
        for click in CLICKS:
            values = [run[thickness][click] for run in runs]
            median, worst = statistics.median(values), max(values)
            row[click] = {"median_s": median, "worst_s": worst}
            mark = "" if worst <= TARGET_S else " !"
            cells.append(f"{median:7.3f} ({worst:.3f}){mark}")
        table[thickness] = row
        print(f"  {float(thickness):>12g}  " + "  ".join(f"{c:>16}" for c in cells))
    print(f"load after {machine_load()} ('!': the worst over the target)")
    write_figures(args.json, {"load": load, "repeats": args.repeats, "clicks": table})
    return 0


if __name__ == "__main__":
    sys.exit(main())
