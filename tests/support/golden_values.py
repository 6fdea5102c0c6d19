"""Golden values: what the model produces, stored with a tolerance per quantity.

The set
-------
For three made-up skins (:data:`SKINS`: the paper preset; medium beige on Jensen's Skin 1 at
coverage 0.6; deep mocha on Skin 2): the baked tables at the preview and the default
resolution, and the closure fit of the default tables; for the paper's layers, the three
measurement protocols (four data sets) synthesised with 2% noise (seed 7) and fitted.
:func:`compute` returns them as named quantities (:func:`support.quantities.flatten`):
``tables/<skin>/<resolution>/<field>``, ``closure_fit/<skin>/default/<field>/...``,
``measurement_fit/<protocol>/<field>/...``.

What is stored
--------------
Every value of the preview tables.  Of the default tables every grid, directional, radial
and constant array, and of the three angular tables (600 000 nodes each, 94% of the values)
the strided sub-grid ``[::8, ::8, ::8]`` (1 296 nodes) with the sum and the largest value of
the whole table: the default tables are the preview's functions on finer grids, which the
preview tables check value by value; what only the default bake does (more nodes, its
chunks, the narrow-lobe scaling) shows in the sub-grid and the sums.  Storing them in full
would take 13 MB a skin.  In the file an array whose RGB channels are equal is kept once
(the comparison still checks all three), an array equal to another is kept once, and the
arrays are stored byte plane by byte plane (the sign-and-exponent bytes of smooth tables
compress well, the low mantissa bytes do not): 1.9 MB instead of 5 MB as plain ``.npz``.

Tolerances
----------
A numeric quantity passes when its change (:func:`support.quantities.change`: largest
absolute difference over the reference's largest magnitude) is at most its ``rtol``;
anything discrete (a distribution's or a method's name, a count, a flag, a warning's text)
must be equal.  ``rtol`` = :data:`MULTIPLE` x the largest change measured between the
configurations of :data:`CONFIGS` (this CPU; an AVX2 CPU emulated: numpy's AVX-512 loops and
OpenBLAS's SkylakeX kernels off; 1 and 2 BLAS/OpenMP threads), at least :data:`FLOOR` (what a
processor none of them emulates may move), at most :data:`CAP` (far below a change a render
could show).  ``python bench/golden_values.py --write`` measures and writes them;
docs/stability.md, "Golden values and how far results move between machines", has the
figures.
"""

from __future__ import annotations

import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .quantities import change, flatten, is_numeric

__all__ = ["REFERENCE", "METADATA", "SKINS", "RESOLUTIONS", "CONFIGS", "BASELINE", "MULTIPLE",
           "FLOOR", "CAP", "MIN_MULTIPLE", "REGENERATE", "compute", "reduce", "kind", "tolerance",
           "write_reference", "read_reference", "Row", "compare", "failure_message"]

DATA = Path(__file__).resolve().parent.parent / "data"
REFERENCE = DATA / "golden_values.npz"
"""The reference arrays (byte planes, :func:`write_reference`)."""
METADATA = DATA / "golden_values.json"
"""Per quantity: how it is stored, its tolerance and why, its measured movement; the
discrete quantities' values."""
REGENERATE = "python bench/golden_values.py --write"

SKINS = {
    "paper": ("paper_natural", "paper_bioplate", 1.0),
    "medium_beige+jensen_skin1@0.6": ("medium_beige", "jensen_skin1", 0.6),
    "deep_mocha+jensen_skin2": ("deep_mocha", "jensen_skin2", 1.0),
}
"""``name -> (foundation, skin, coverage)``."""
RESOLUTIONS = ("preview", "default")
ANGULAR_STRIDE = 8
"""Stride of the default angular tables' stored sub-grid (each axis)."""
MEASUREMENT_NOISE, MEASUREMENT_SEED = 0.02, 7

_AVX512 = ("AVX512F AVX512CD AVX512_SKX AVX512_CLX AVX512_CNL AVX512_ICL AVX512VL AVX512BW "
           "AVX512DQ")
CONFIGS = {
    "this CPU": {},
    "AVX2 emulated": {"NPY_DISABLE_CPU_FEATURES": _AVX512, "OPENBLAS_CORETYPE": "Haswell"},
    "1 thread": {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"},
    "2 threads": {"OPENBLAS_NUM_THREADS": "2", "OMP_NUM_THREADS": "2"},
}
"""Environments the generator runs under to measure how far each quantity moves: numpy reads
``NPY_DISABLE_CPU_FEATURES`` and OpenBLAS its variables when they are imported, so each runs
in a process of its own."""
BASELINE = "this CPU"
"""The configuration whose values are stored."""
MULTIPLE = 1000.0
"""Tolerance = this many times the largest movement measured between :data:`CONFIGS`."""
FLOOR = {"tables": 1e-12, "closure_fit": 1e-10, "measurement_fit": 1e-10}
"""Smallest tolerance (relative), by part: for what moved less than a thousandth of it here.
Fits get more: their searches compare values (a comparison that flips on another processor
moves a refined minimum by up to ~1e-12 of its interval; a least-squares stop, more)."""
CAP = {"tables": 1e-6, "closure_fit": 1e-5, "measurement_fit": 1e-4}
"""Largest tolerance (relative), by part: far below anything a render shows (the tables'
interpolation errs by 1e-3, the closure fits by a few per cent, the measurement fits'
standard errors are 1-10%).  A quantity whose measured movement times :data:`MULTIPLE`
exceeds it is capped there."""
MIN_MULTIPLE = 100.0
"""``--write`` warns of a quantity whose tolerance is less than this many times its measured
movement (capped): another processor may move it beyond the tolerance."""


# --------------------------------------------------------------------------------------------
# The set
# --------------------------------------------------------------------------------------------
def _skin(name):
    from lut_baker.model import presets

    foundation, skin, coverage = SKINS[name]
    return presets.made_up_skin(foundation, skin, coverage=coverage)


SEARCH_DIAGNOSTICS = "/starts/"
"""A measurement fit's account of its starts (how many reached the best cost, how far their
ends spread, the next minimum's excess) describes the search, not the result: the spread is
the noise of nearly equal ends (about 1e-9, moving by its own size between processors).  Left
out of the set; the fitted values and their uncertainties are in it."""


def reduce(name: str, value):
    """What is stored of a quantity (module docstring): ``{stored name: value}``; nothing of
    the searches' diagnostics (:data:`SEARCH_DIAGNOSTICS`)."""
    if SEARCH_DIAGNOSTICS in name:
        return {}
    parts = name.split("/")
    angular = parts[0] == "tables" and parts[2] == "default" and parts[-1] in (
        "path3_gloss", "inter_reflection")
    if not (angular and is_numeric(value)):
        return {name: value}
    s = ANGULAR_STRIDE
    return {f"{name}[::{s},::{s},::{s}]": np.array(value[::s, ::s, ::s]),
            f"{name}:sum": np.array(np.sum(value)),
            f"{name}:max": np.array(np.max(value))}


def kind(name: str) -> str:
    """The part of the set a quantity belongs to (``tables``, ``closure_fit``,
    ``measurement_fit``)."""
    return name.split("/", 1)[0]


def compute(parts=("tables", "closure_fit", "measurement_fit"), skins=None) -> dict:
    """The golden set's current values, reduced as stored (:func:`reduce`): ``{name: value}``.
    ``parts``, ``skins``: a subset (default everything; ~15 s)."""
    from lut_baker import bake
    from lut_baker.closures import fitting

    values: dict = {}

    def add(prefix, result):
        for name, value in flatten(result, prefix).items():
            values.update(reduce(name, value))

    for skin_name in (SKINS if skins is None else skins):
        if not {"tables", "closure_fit"} & set(parts):
            break
        skin = _skin(skin_name)
        for resolution in RESOLUTIONS:
            tables = bake.bake(skin, resolution)
            if "tables" in parts:
                add(f"tables/{skin_name}/{resolution}", tables)
            if resolution == "default" and "closure_fit" in parts:
                add(f"closure_fit/{skin_name}/{resolution}", fitting.fit_closures(tables))
    if "measurement_fit" in parts:
        from lut_baker.offline.measured import layer_fit, measurements

        data = measurements.paper_protocols(noise=MEASUREMENT_NOISE, seed=MEASUREMENT_SEED)
        for protocol, item in sorted(data.items()):
            add(f"measurement_fit/{protocol}", layer_fit.fit_measurements(item))
    return values


# --------------------------------------------------------------------------------------------
# Tolerances and the reference files
# --------------------------------------------------------------------------------------------
def tolerance(name: str, movement: float) -> tuple[float, str]:
    """``(rtol, how it was chosen)`` for a quantity that moved ``movement`` (relative) at most
    between :data:`CONFIGS`."""
    part = kind(name)
    floor, cap = FLOOR[part], CAP[part]
    if MULTIPLE * movement > cap:
        return cap, (f"capped at {cap:g} ({part}): {cap / movement:.0f} x the measured "
                     f"movement {movement:.2g}")
    if MULTIPLE * movement < floor:
        return floor, (f"floor {floor:g} ({part}): moved {movement:.2g} "
                       f"(under {floor / MULTIPLE:g})")
    return MULTIPLE * movement, f"{MULTIPLE:g} x the measured movement {movement:.2g}"


def _planes(array: np.ndarray) -> np.ndarray:
    """float64 array -> its bytes as planes ``(8, n)`` (little-endian)."""
    raw = np.ascontiguousarray(array, dtype="<f8").reshape(-1).view(np.uint8)
    return raw.reshape(-1, 8).T.copy()


def _from_planes(planes: np.ndarray, shape) -> np.ndarray:
    return np.ascontiguousarray(planes.T).reshape(-1).view("<f8").reshape(shape).astype(float)


def _stored_form(value: np.ndarray) -> tuple[np.ndarray, bool]:
    """``(array to store, channels collapsed)``: a trailing RGB axis whose channels are equal
    is kept once."""
    if value.ndim >= 1 and value.shape[-1] == 3 and value.size > 3 and np.array_equal(
            value[..., :1] * np.ones(3), value):
        return np.ascontiguousarray(value[..., :1]), True
    return value, False


def write_reference(values: dict, moved: dict, configs=None) -> dict:
    """Write :data:`REFERENCE` and :data:`METADATA` from the baseline's ``values`` and
    ``moved`` = ``{config: {name: Change}}`` (against the baseline); returns the metadata."""
    arrays: dict = {}
    by_bytes: dict = {}
    quantities: dict = {}
    for index, name in enumerate(sorted(values)):
        value = values[name]
        movement = {config: changes[name].rel for config, changes in moved.items()}
        entry: dict = {"moved": {c: (m if math.isfinite(m) else "differs")
                                 for c, m in movement.items()}}
        if is_numeric(value):
            stored, collapsed = _stored_form(value)
            key = by_bytes.setdefault((stored.shape, stored.tobytes()), f"a{index}")
            if key == f"a{index}":
                arrays[key] = _planes(stored)
            largest = max([m for m in movement.values()], default=0.0)
            rtol, rule = tolerance(name, largest)
            entry.update({"array": key, "shape": list(value.shape),
                          "stored_shape": list(stored.shape), "channels_equal": collapsed,
                          "scale": float(np.max(np.abs(value), initial=0.0)),
                          "largest_movement": largest, "rtol": rtol, "rule": rule})
        else:
            entry.update({"exact": value})
        quantities[name] = entry
    metadata = {
        "about": ("Golden values (tests/support/golden_values.py): per quantity the stored "
                  "array or exact value, its tolerance and how it was chosen, and how far it "
                  f"moved between configurations. Regenerate with `{REGENERATE}`."),
        "configurations": configs or {c: CONFIGS.get(c, {}) for c in [BASELINE, *moved]},
        "baseline": BASELINE,
        "multiple": MULTIPLE, "floor": FLOOR, "cap": CAP,
        "python": sys.version.split()[0], "numpy": np.__version__,
        "quantities": quantities,
    }
    np.savez_compressed(REFERENCE, **arrays)
    METADATA.write_text(json.dumps(metadata, indent=1, sort_keys=True) + "\n")
    return metadata


def read_reference() -> tuple[dict, dict]:
    """``(values, metadata)`` of the stored reference: numeric quantities as float arrays of
    their full shape, discrete ones as stored."""
    metadata = json.loads(METADATA.read_text())
    values = {}
    with np.load(REFERENCE) as arrays:
        for name, entry in metadata["quantities"].items():
            if "array" in entry:
                stored = _from_planes(arrays[entry["array"]], entry["stored_shape"])
                values[name] = np.broadcast_to(stored, entry["shape"]) if entry[
                    "channels_equal"] else stored
            else:
                values[name] = entry["exact"]
    return values, metadata


# --------------------------------------------------------------------------------------------
# The comparison
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Row:
    """One quantity compared: its ``change`` (:class:`support.quantities.Change`), ``rtol``
    (None: compared exactly) and whether it passes."""

    name: str
    abs: float
    rel: float
    rtol: float | None
    ok: bool
    note: str = ""


def compare(current: dict, reference: tuple[dict, dict], names=None) -> list[Row]:
    """Every quantity of the reference (or of ``names``) against ``current``; a quantity
    the reference lacks, or ``current`` lacks, fails."""
    values, metadata = reference
    entries = metadata["quantities"]
    wanted = sorted(values.keys() | current.keys()) if names is None else sorted(names)
    rows = []
    for name in wanted:
        if name not in values:
            rows.append(Row(name, math.inf, math.inf, None, False, "not in the reference"))
            continue
        if name not in current:
            rows.append(Row(name, math.inf, math.inf, None, False, "no longer computed"))
            continue
        moved = change(current[name], values[name])
        rtol = entries[name].get("rtol")
        if rtol is None:
            note = "" if not moved.moved else (
                f"{current[name]!r} instead of {values[name]!r}")
            rows.append(Row(name, moved.abs, moved.rel, None, not moved.moved, note))
        else:
            rows.append(Row(name, moved.abs, moved.rel, rtol, moved.rel <= rtol,
                            entries[name]["rule"]))
    return rows


def failure_message(failed: list[Row], total: int) -> str:
    """Which quantities moved, by how much, against which tolerance, and how to regenerate."""
    lines = [f"{len(failed)} of {total} golden values moved beyond their tolerance "
             f"({METADATA.relative_to(DATA.parent.parent)}):"]
    for row in failed[:40]:
        if row.rtol is None:
            lines.append(f"  {row.name}: {row.note or 'differs'} (compared exactly)")
        else:
            lines.append(f"  {row.name}: moved {row.rel:.3g} relative (largest difference "
                         f"{row.abs:.3g}), tolerance {row.rtol:.3g} ({row.note})")
    if len(failed) > 40:
        lines.append(f"  ... and {len(failed) - 40} more (python bench/golden_values.py "
                     "lists them all)")
    lines.append(f"If the change is intended (the model, the bake or a fit changed), regenerate "
                 f"the reference with `{REGENERATE}` (a few minutes: it measures again how far "
                 "each quantity moves between machines) and commit tests/data/golden_values.*.")
    return "\n".join(lines)
