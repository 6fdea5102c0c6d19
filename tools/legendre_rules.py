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

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository's lut_baker
from lut_baker.numerics import quadrature  # noqa: E402


def main(arguments: list[str]) -> int:
    if arguments not in ([], ["--check"]):
        print(__doc__)
        return 2
    fresh = quadrature.legendre_rules_data()
    target = quadrature.LEGENDRE_RULES_FILE
    if arguments:
        stored = json.loads(target.read_text())["rules"]
        differ = [count for count, rule in fresh["rules"].items() if stored.get(count) != rule]
        print(f"{len(fresh['rules'])} rules against numpy's: "
              + (f"{', '.join(differ)} points differ" if differ else "all identical"))
        return 1 if differ else 0
    target.write_text(json.dumps(fresh, indent=1) + "\n")
    print(f"wrote {target.name} ({len(fresh['rules'])} rules)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
