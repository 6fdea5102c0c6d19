"""Write lut_baker/model/slab_shades.json: every foundation preset's thick-limit curve with
the film as a slab (lut_baker.model.slab_shade), which the add-on reads to turn a bottle
colour into an absorption and back without computing it in the panel.

Usage::

    python tools/slab_shades.py          # write it (about 2 s)
    python tools/slab_shades.py --check  # compare with a fresh computation, exit 1 if it moved

Run it after any change to the film's model (docs/model.md, "The film as a slab");
tests/lut_baker/model/test_slab_shade.py fails until then.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

import numpy as np  # noqa: E402

from lut_baker.model import slab_shade  # noqa: E402


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="compare only")
    args = parser.parse_args(argv)
    fresh = slab_shade.preset_curves()
    if args.check:
        stored = slab_shade.read_curves()
        moved = {name: float(np.max(np.abs(stored[name].colours - curve.colours)))
                 if name in stored else float("inf") for name, curve in fresh.items()}
        for name, change in moved.items():
            print(f"{name:16s} largest change {change:.2e}")
        return 0 if max(moved.values()) <= 1e-9 else 1
    slab_shade.SHADES_FILE.write_text(
        json.dumps(slab_shade.curves_data(fresh), indent=1) + "\n")
    print(f"wrote {slab_shade.SHADES_FILE.relative_to(REPO)} ({len(fresh)} presets)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
