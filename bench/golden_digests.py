"""SHA-256 digests of what the model produces, to show a refactoring changed no bit.

Usage::

    python bench/golden_digests.py            # compare with tests/data/golden_digests.json
    python bench/golden_digests.py --write    # record the current digests there

For three made-up skins (the paper preset; medium beige on Jensen's Skin 1 at coverage 0.6;
deep mocha on Skin 2) it bakes the tables (preview and default resolutions) and fits the
closures; for the paper's layers it fits the three measurement protocols synthesised with
noise (tests/support/digests.py, which tests/test_golden_digests.py uses too). Every array is
digested as float64 bytes with its shape; every float by its exact hex form, so a difference in
the last bit shows. Prints one line per item, ``same``/``DIFFERENT``, and exits 1 if any differ.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
for _path in (REPO, REPO / "tests"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

from support.digests import GOLDEN, compute  # noqa: E402  (tests/support/digests.py)

__all__ = ["main"]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="record the digests as golden")
    args = parser.parse_args(argv)
    current = compute()
    if args.write:
        GOLDEN.write_text(json.dumps(current, indent=1, sort_keys=True) + "\n")
        print(f"wrote {len(current)} digests to {GOLDEN.relative_to(REPO)}")
        return 0
    golden = json.loads(GOLDEN.read_text())
    different = 0
    for key in sorted(golden.keys() | current.keys()):
        same = golden.get(key) == current.get(key)
        different += not same
        print(f"{'same     ' if same else 'DIFFERENT'} {key}  {current.get(key, 'missing')[:16]}")
    print(f"{len(golden) - different} of {len(golden)} digests identical to {GOLDEN.name}")
    return 1 if different else 0


if __name__ == "__main__":
    sys.exit(main())
