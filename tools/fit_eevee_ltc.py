"""Refit EEVEE's GGX LTC table into lut_baker/closures/eevee_ltc.json (the runtime's replica of
EEVEE's Glossy BSDF under a lamp reads it).

Usage::

    python tools/fit_eevee_ltc.py [--size 64] [--out lut_baker/closures/eevee_ltc.json]

About 15 minutes on one core (64 x 64 Nelder-Mead fits, :mod:`lut_baker.offline.eevee_ltc`);
prints one line per roughness.  The fit is deterministic (stratified samples, fixed starts), so
the file only changes when the method does.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
if str(REPO_ROOT) not in sys.path:
    sys.path.insert(0, str(REPO_ROOT))

from lut_baker.closures.eevee import LTC_TABLE_FILE, LTC_TABLE_SIZE  # noqa: E402
from lut_baker.offline import eevee_ltc  # noqa: E402


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=LTC_TABLE_SIZE)
    parser.add_argument("--out", type=Path, default=LTC_TABLE_FILE)
    args = parser.parse_args(argv)
    start = time.perf_counter()

    def progress(done, total):
        print(f"fit_eevee_ltc: {done}/{total} roughness values, "
              f"{time.perf_counter() - start:.0f} s", flush=True)

    path = eevee_ltc.write_table(args.out, args.size, progress)
    print(f"fit_eevee_ltc: wrote {path} in {time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
