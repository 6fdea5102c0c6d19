"""SHA-256 digests of what the model produces, to show a refactoring changed no bit.

For three made-up skins (the paper preset; medium beige on Jensen's Skin 1 at coverage 0.6;
deep mocha on Skin 2) :func:`compute` bakes the tables (preview and default resolutions) and
fits the closures; for the paper's layers it fits the three measurement protocols synthesised
with noise.  Every array is digested as float64 bytes with its shape; every float by its exact
hex form, so a difference in the last bit shows.  :data:`GOLDEN` holds the recorded digests
(tests/test_golden_digests.py compares; ``python bench/golden_digests.py`` prints and
``--write`` records them).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from pathlib import Path

import numpy as np

from lut_baker import bake
from lut_baker.closures import fitting
from lut_baker.model import presets
from lut_baker.offline.measured import layer_fit, measurements

__all__ = ["GOLDEN", "SKINS", "RESOLUTIONS", "plain", "digest", "compute", "golden"]

GOLDEN = Path(__file__).resolve().parent.parent / "data" / "golden_digests.json"
"""The recorded digests, by item name."""

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
    """SHA-256 (hex) of :func:`plain` of ``value`` as sorted JSON."""
    return hashlib.sha256(json.dumps(plain(value), sort_keys=True).encode()).hexdigest()


def compute() -> dict[str, str]:
    """The current digests, by item name (``tables/<skin>/<resolution>``,
    ``closure_fit/<skin>/default``, ``measurement_fit/<protocol>``); ~5 s."""
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


def golden() -> dict[str, str]:
    """The recorded digests (:data:`GOLDEN`)."""
    return json.loads(GOLDEN.read_text())
