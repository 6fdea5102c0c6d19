"""SHA-256 digests of what the model produces, to show a refactoring changed no bit.

Usage::

    python bench/golden_digests.py            # compare with tests/data/golden_digests.json
    python bench/golden_digests.py --write    # record the current digests there

For three made-up skins (the paper preset; medium beige on Jensen's Skin 1 at coverage 0.6;
deep mocha on Skin 2) it bakes the tables (preview and default resolutions) and fits the
closures; for the paper's layers it fits the three measurement protocols synthesised with
noise. Every array is digested as float64 bytes with its shape; every float by its exact hex
form, so a difference in the last bit shows. Prints one line per item, ``same``/``DIFFERENT``,
and exits 1 if any differ.
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from lut_baker import bake  # noqa: E402
from lut_baker.closures import fitting  # noqa: E402
from lut_baker.model import presets  # noqa: E402
from lut_baker.offline.measured import layer_fit, measurements  # noqa: E402

GOLDEN = REPO / "tests" / "data" / "golden_digests.json"

SKINS = {
    "paper": lambda: presets.made_up_skin("paper_natural", "paper_bioplate"),
    "medium_beige+jensen_skin1@0.6": lambda: presets.made_up_skin(
        "medium_beige", "jensen_skin1", coverage=0.6),
    "deep_mocha+jensen_skin2": lambda: presets.made_up_skin("deep_mocha", "jensen_skin2"),
}
RESOLUTIONS = ("preview", "default")


def plain(value):
    """``value`` as JSON-able data that keeps every bit (arrays -> digest, floats -> hex)."""
    if isinstance(value, np.ndarray) or isinstance(value, np.generic):
        array = np.ascontiguousarray(np.asarray(value))
        if array.dtype.kind in "fc":
            array = array.astype(np.float64)
        return {"shape": list(array.shape), "dtype": str(array.dtype),
                "sha256": hashlib.sha256(array.tobytes()).hexdigest()}
    if isinstance(value, float):
        return float(value).hex()
    if dataclasses.is_dataclass(value):
        return {f.name: plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in sorted(value.items(), key=lambda kv: str(kv[0]))}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    return value


def digest(value) -> str:
    return hashlib.sha256(json.dumps(plain(value), sort_keys=True).encode()).hexdigest()


def compute() -> dict[str, str]:
    out = {}
    for name, make in SKINS.items():
        skin = make()
        for resolution in RESOLUTIONS:
            tables = bake.bake(skin, resolution)
            out[f"tables/{name}/{resolution}"] = digest(tables)
            if resolution == "default":
                out[f"closure_fit/{name}/{resolution}"] = digest(fitting.fit_closures(tables))
    data = measurements.paper_protocols(noise=0.02, seed=7)
    for kind, item in sorted(data.items()):
        out[f"measurement_fit/{kind}"] = digest(layer_fit.fit_measurements(item))
    return out


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
