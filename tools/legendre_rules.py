"""Write lut_baker/numerics/legendre_rules.json: numpy's Gauss-Legendre rules on [-1, 1]
(``leggauss``) at the point counts the runtime uses, as exact hexadecimal floats, which
lut_baker.numerics.quadrature reads instead of computing them in every new process (0.2 ms
at 5 nodes to 3 ms at 96).

Usage::

    python tools/legendre_rules.py          # write it
    python tools/legendre_rules.py --check  # compare with numpy's, exit 1 if any differs

Run it after changing ``STORED_LEGENDRE_POINTS`` or numpy.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from lut_baker.numerics import quadrature  # noqa: E402


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="compare only")
    args = parser.parse_args(argv)
    fresh = quadrature.legendre_rules_data()
    if args.check:
        stored = json.loads(quadrature.LEGENDRE_RULES_FILE.read_text())
        differ = [count for count, rule in fresh["rules"].items()
                  if stored["rules"].get(count) != rule]
        print(f"{len(fresh['rules'])} rules, "
              + (f"differ at {', '.join(differ)} points" if differ else "all identical"))
        return 1 if differ else 0
    quadrature.LEGENDRE_RULES_FILE.write_text(json.dumps(fresh, indent=1) + "\n")
    print(f"wrote {quadrature.LEGENDRE_RULES_FILE.relative_to(REPO)} "
          f"({len(fresh['rules'])} rules)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
