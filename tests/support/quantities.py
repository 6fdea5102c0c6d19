"""Results as named quantities, and how far one moved from another.

:func:`flatten` turns what the model produces (baked :class:`lut_baker.tables.table_set.Tables`,
a :class:`lut_baker.closures.closure_fit.ClosureFit`, a measurement fit's result; any nesting of
dataclasses, dicts, lists and arrays) into ``{name: value}``: numbers become float64 arrays,
and what is discrete (a chosen distribution or subsurface method, a count, a flag, None) stays
as it is, to be compared exactly.  :func:`change` measures one numeric quantity against its
reference the one way the golden values (:mod:`support.golden_values`) and the perturbation
tests (:mod:`support.perturbation`) both use.

Change of a numeric quantity
----------------------------
``abs`` = the largest absolute difference over its elements; ``rel`` = ``abs`` over the
reference's largest magnitude (norm-wise, so the near-zero values of a table, 1e-142 at a
sharp lobe's grazing end, do not turn last-bit noise into a huge element-wise ratio); for an
all-zero reference ``rel = abs``.  A change of shape, or a NaN where the reference has none, is
infinite.
"""

from __future__ import annotations

import dataclasses
import math
from numbers import Number

import numpy as np

__all__ = ["flatten", "is_numeric", "change", "Change", "largest_changes"]


def _is_number(value) -> bool:
    return isinstance(value, (Number, np.number)) and not isinstance(value, (bool, np.bool_))


def flatten(value, prefix: str = "") -> dict:
    """``{name: value}`` of every leaf of ``value``: names join field names, dict keys and
    list indices with ``/``; numbers (and lists of numbers) become float64 arrays; strings,
    booleans, None and integers of a count-like field stay exact.  Dict keys are sorted."""
    out: dict = {}
    _flatten(value, prefix, out)
    return out


def _join(prefix: str, name) -> str:
    return f"{prefix}/{name}" if prefix else str(name)


def _flatten(value, prefix: str, out: dict) -> None:
    if isinstance(value, np.ndarray) or _is_number(value):
        array = np.asarray(value)
        if array.dtype.kind in "iu" and array.ndim == 0:  # a count: exact
            out[prefix] = int(array)
        elif array.dtype.kind in "fciu":
            out[prefix] = np.array(array, dtype=np.float64)
        else:
            out[prefix] = array.tolist()
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        for f in dataclasses.fields(value):
            _flatten(getattr(value, f.name), _join(prefix, f.name), out)
    elif isinstance(value, dict):
        for key in sorted(value, key=str):
            _flatten(value[key], _join(prefix, key), out)
    elif isinstance(value, (list, tuple)):
        if value and all(_is_number(v) for v in value):
            out[prefix] = np.array(value, dtype=np.float64)
        elif not value:
            out[prefix] = []
        else:
            for i, item in enumerate(value):
                _flatten(item, _join(prefix, i), out)
    else:  # str, bool, None: discrete
        out[prefix] = value


def is_numeric(value) -> bool:
    """Whether a flattened quantity is compared with a tolerance (a float array or scalar)."""
    return isinstance(value, (np.ndarray, np.floating))


@dataclasses.dataclass(frozen=True)
class Change:
    """How far a quantity moved: ``abs`` and ``rel`` (module docstring); for a discrete
    quantity ``rel = abs = 0`` if equal, else infinite."""

    abs: float
    rel: float
    scale: float

    @property
    def moved(self) -> bool:
        return self.abs != 0.0


def change(current, reference) -> Change:
    """:class:`Change` of ``current`` against ``reference`` (flattened quantities)."""
    if not (is_numeric(current) and is_numeric(reference)):
        same = (not is_numeric(current) and not is_numeric(reference)
                and type(current) is type(reference) and current == reference)
        return Change(0.0 if same else math.inf, 0.0 if same else math.inf, 0.0)
    a, b = np.asarray(current, float), np.asarray(reference, float)
    if a.shape != b.shape:
        return Change(math.inf, math.inf, 0.0)
    if a.size == 0:
        return Change(0.0, 0.0, 0.0)
    nan_a, nan_b = np.isnan(a), np.isnan(b)
    if np.any(nan_a != nan_b):
        return Change(math.inf, math.inf, 0.0)
    diff = np.where(nan_a, 0.0, np.abs(a - b))
    # equal infinities give NaN differences: count them as unmoved
    diff = np.where(np.isnan(diff), np.where(a == b, 0.0, math.inf), diff)
    largest = float(np.max(diff))
    scale = float(np.max(np.where(np.isfinite(b), np.abs(b), 0.0), initial=0.0))
    return Change(largest, largest / scale if scale > 0 else largest, scale)


def largest_changes(current: dict, reference: dict) -> dict:
    """:func:`change` of every quantity of ``reference`` (flattened); a quantity missing from
    ``current`` has an infinite change, one ``current`` adds is reported too."""
    out = {}
    for name in sorted(reference.keys() | current.keys()):
        if name not in current or name not in reference:
            out[name] = Change(math.inf, math.inf, 0.0)
        else:
            out[name] = change(current[name], reference[name])
    return out
