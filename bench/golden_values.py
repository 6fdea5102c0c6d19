"""Golden values: the baked tables, closure fits and measurement fits against the stored
reference, quantity by quantity, with the tolerance each is held to.

Usage::

    python bench/golden_values.py              # compare with tests/data/golden_values.*
    python bench/golden_values.py --failed     # only what is beyond its tolerance
    python bench/golden_values.py --write      # regenerate the reference (~2-4 minutes)

The set, what is stored of it and how the tolerances are chosen: tests/support/
golden_values.py (tests/test_golden_values.py asserts it).  Without ``--write`` it prints one
line per quantity: its change relative to its size and as the largest absolute difference,
its tolerance (``exact`` for discrete ones), and ``ok``/``MOVED``; then how many are
bit-identical (on the machine that wrote the reference, a refactoring that should change
nothing leaves all of them so), and exits 1 if any is beyond its tolerance.

``--write`` runs the generator once per configuration of ``CONFIGS`` (this CPU; an AVX2 CPU
emulated; 1 and 2 BLAS threads), each in a process of its own (numpy and OpenBLAS read their
environment at import), stores this CPU's values, and sets each tolerance from the largest
movement between them.  It prints the largest movement per part and configuration: the
figures of docs/stability.md, "Golden values and how far results move between machines".
A discrete quantity (a name, a count) or a shape that differs between the configurations
has no golden value: then it names it and writes nothing.
"""

from __future__ import annotations

import argparse
import math
import os
import pickle
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
for _path in (REPO, REPO / "tests"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

from support import golden_values as gv  # noqa: E402  (tests/support/golden_values.py)
from support.quantities import largest_changes  # noqa: E402

__all__ = ["main"]


def _run_config(name: str, environment: dict, out: Path) -> dict:
    env = dict(os.environ)
    for key in ("NPY_DISABLE_CPU_FEATURES", "OPENBLAS_CORETYPE", "OPENBLAS_NUM_THREADS",
                "OMP_NUM_THREADS"):
        env.pop(key, None)
    env.update(environment)
    start = time.perf_counter()
    subprocess.run([sys.executable, __file__, "--dump", str(out)], env=env, check=True)
    print(f"  {name}: {time.perf_counter() - start:.0f} s", flush=True)
    with open(out, "rb") as file:
        return pickle.load(file)


def write() -> int:
    print("computing the golden set under each configuration:", flush=True)
    with tempfile.TemporaryDirectory() as folder:
        runs = {name: _run_config(name, env, Path(folder) / f"{i}.pickle")
                for i, (name, env) in enumerate(gv.CONFIGS.items())}
    base = runs.pop(gv.BASELINE)
    moved = {name: largest_changes(values, base) for name, values in runs.items()}
    differ = sorted({(config, name) for config, changes in moved.items()
                     for name, change in changes.items() if not math.isfinite(change.rel)})
    if differ:  # a count, a name or a shape that depends on the processor: no golden value
        for config, name in differ:
            print(f"ERROR: {name} differs under {config!r} (a discrete value or a shape)")
        print("nothing written: make these quantities independent of the processor first")
        return 1
    metadata = gv.write_reference(base, moved)
    quantities = metadata["quantities"]
    print(f"\nlargest movement against {gv.BASELINE!r} (relative), by part:")
    parts = sorted({gv.kind(n) for n in quantities})
    print(f"  {'configuration':16s}" + "".join(f"{p:>18s}" for p in parts))
    for config in moved:
        cells = []
        for part in parts:
            values = [moved[config][n].rel for n in quantities if gv.kind(n) == part]
            cells.append(f"{max(values, default=0.0):18.2g}")
        print(f"  {config:16s}" + "".join(cells))
    tight = [n for n, e in quantities.items()
             if "rtol" in e and e["rtol"] < gv.MIN_MULTIPLE * e["largest_movement"]]
    for name in tight:
        print(f"WARNING: {name}: tolerance {quantities[name]['rule']} (under "
              f"{gv.MIN_MULTIPLE:g} x): another processor may move it further")
    numeric = sum("rtol" in e for e in quantities.values())
    size = gv.REFERENCE.stat().st_size + gv.METADATA.stat().st_size
    print(f"\nwrote {len(quantities)} quantities ({numeric} with a tolerance, "
          f"{len(quantities) - numeric} exact) to {gv.REFERENCE.relative_to(REPO)} and "
          f"{gv.METADATA.name}: {size / 1e6:.2f} MB")
    return 0


def compare(failed_only: bool) -> int:
    reference = gv.read_reference()
    start = time.perf_counter()
    current = gv.compute()
    seconds = time.perf_counter() - start
    rows = gv.compare(current, reference)
    print(f"{'quantity':86s} {'change (rel)':>12s} {'largest diff':>12s} {'tolerance':>10s}")
    for row in rows:
        if failed_only and row.ok:
            continue
        tol = "exact" if row.rtol is None else f"{row.rtol:.2g}"
        print(f"{row.name:86s} {row.rel:12.3g} {row.abs:12.3g} {tol:>10s} "
              f"{'ok' if row.ok else 'MOVED'}")
    failed = [row for row in rows if not row.ok]
    identical = sum(row.abs == 0.0 for row in rows)
    print(f"{len(rows) - len(failed)} of {len(rows)} quantities within their tolerance, "
          f"{identical} bit-identical ({seconds:.0f} s)")
    if failed:
        print(gv.failure_message(failed, len(rows)))
    return 1 if failed else 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true",
                        help="measure the movement between configurations and write the "
                             "reference")
    parser.add_argument("--failed", action="store_true", help="print only what moved too far")
    parser.add_argument("--dump", type=Path, help=argparse.SUPPRESS)  # one configuration's run
    args = parser.parse_args(argv)
    if args.dump:
        with open(args.dump, "wb") as file:
            pickle.dump(gv.compute(), file)
        return 0
    return write() if args.write else compare(args.failed)


if __name__ == "__main__":
    sys.exit(main())
