"""The measured foundation presets re-derived from data/lanza2024, the measured values optionally
perturbed, for the tests that hold the shipped presets to their data
(tests/lut_baker/offline/test_foundation_presets.py).

Run as a script (``python -m support.measured_presets [PERTURBATION]`` with ``tests`` on the
path) it prints the derived entries as JSON, with the CPU features numpy dispatches to: the
tests run it in subprocesses with other BLAS thread counts and CPU features.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from lut_baker.offline.foundation_presets import derive_presets
from lut_baker.offline.foundations import PRODUCTS
from lut_baker.offline.measured.inplane import read_inplane
from lut_baker.offline.measured.inplane_fit import well_posed
from lut_baker.offline.measured.spectra import spectra_to_rgb

__all__ = ["DATA", "SHIPPED_KEYS", "derive", "shipped_values", "largest_move"]

DATA = Path(__file__).resolve().parents[2] / "data" / "lanza2024"
SHIPPED_KEYS = ("absorption", "film", "target", "stack")
"""The numbers of a preset entry compared (``finish``, ``label`` and ``clamped`` must be equal)."""


def derive(perturbation: float = 0.0, seed: int = 0) -> dict:
    """The preset entries derived as ``python -m lut_baker foundations`` derives them (the
    well-posed fit of each product, :func:`~lut_baker.offline.foundation_presets.
    derive_presets`), every measured value times ``1 + perturbation s`` with ``s`` a fixed
    pseudo-random +-1 pattern (``seed``)."""
    fits = {}
    for name, (filename, finish) in PRODUCTS.items():
        data = read_inplane(DATA / filename)
        sign = np.random.default_rng(seed).choice([-1.0, 1.0], data.values.shape)
        rgb = spectra_to_rgb(data.values * (1.0 + perturbation * sign))
        fits[name] = (finish, well_posed(data.theta_i_deg, data.theta_o_deg, rgb).fit.layers)
    return derive_presets(fits)


def shipped_values(entry: dict) -> dict[str, float]:
    """``"<key>[i]"`` or ``"film.<field>"`` -> value, over :data:`SHIPPED_KEYS`."""
    out = {f"film.{k}": float(v) for k, v in entry["film"].items()}
    for key in SHIPPED_KEYS[:1] + SHIPPED_KEYS[2:]:
        out.update({f"{key}[{i}]": float(v) for i, v in enumerate(entry[key])})
    return out


def largest_move(derived: dict, stored: dict) -> tuple[float, str]:
    """The largest move of a shipped value between two sets of entries, relative to the stored
    value (absolute where it is 0), and where; labels, finishes and clamps must agree."""
    assert derived.keys() == stored.keys()
    worst = (0.0, "")
    for name, entry in derived.items():
        for key in ("label", "finish", "clamped"):
            assert entry[key] == stored[name][key], (name, key)
        old, new = shipped_values(stored[name]), shipped_values(entry)
        for key, value in old.items():
            move = abs(new[key] - value) / (abs(value) if value != 0.0 else 1.0)
            worst = max(worst, (move, f"{name} {key}"))
    return worst


if __name__ == "__main__":
    features = np.core._multiarray_umath.__cpu_features__
    print(json.dumps({"avx512f": bool(features.get("AVX512F")),
                      "presets": derive(float(sys.argv[1]) if len(sys.argv) > 1 else 0.0)}))
