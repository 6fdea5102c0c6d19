"""Inputs perturbed by a tiny relative amount: is a result determined by its data?

The house rule: perturb a fit's inputs by 1e-9 relative, and every output that ships (reaches
the node group or a render) moves by less than 1e-6.  A fit that picks among near-equal
candidates by a strict comparison (which coarse bracket, which distribution, which method)
fails it: its output jumps.

- :func:`perturbed` -- a copy of arrays, floats, parameter layers, a made-up skin or baked
  tables with every float multiplied by ``1 + rel u``, ``u`` uniform in [-1, 1] from a seeded
  generator (deterministic).  Zeros stay zero; a value at a bound of its range (coverage 1)
  moves inwards; the tables' grids stay as they are (their nodes are closed forms the tables
  check to 1e-9 degrees, not data).
- :func:`movement` -- the largest :func:`support.quantities.change` per quantity between
  results computed from the original and from perturbed inputs.
- :data:`LIMIT`, :data:`PERTURBATION` -- the rule's numbers.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from lut_baker.model.layers import Layer

from .quantities import flatten, largest_changes

__all__ = ["PERTURBATION", "LIMIT", "GRID_FIELDS", "perturbed", "movement"]

PERTURBATION = 1e-9
"""Relative size of the perturbation."""
LIMIT = 1e-6
"""How far (:func:`support.quantities.change` ``rel``) a shipped output may move under it."""
GRID_FIELDS = ("theta_deg", "phi_deg", "radius_mm", "theta_offset")
"""Fields of :class:`lut_baker.tables.table_set.Tables` that are grids, left unperturbed."""
BOUNDS = {"coverage": (0.0, 1.0), "absorption": (0.0, 1.0)}
"""Closed ranges of the fields of a made-up skin (and of the tables' parameter record) that
are not layer parameters; layers carry their own (:attr:`Layer._ranges`)."""


def _factor(rng, shape, rel):
    return 1.0 + rel * rng.uniform(-1.0, 1.0, shape)


def _bounded(value, rel, rng, bounds):
    """``value`` times ``1 + rel u``, or ``1 - rel u`` where that leaves ``bounds``."""
    array = np.asarray(value, float)
    u = rng.uniform(-1.0, 1.0, array.shape)
    moved = array * (1.0 + rel * u)
    if bounds is not None:
        low, high = bounds
        outside = (moved < low) | (moved > high)
        moved = np.where(outside, array * (1.0 - rel * u), moved)
    if np.ndim(value) == 0 and not isinstance(value, np.ndarray):
        return float(moved)
    return moved


def _perturb(value, rel, rng, skip, bounds=None):
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, (float, np.floating)) or (
            isinstance(value, np.ndarray) and value.dtype.kind == "f"):
        return _bounded(value, rel, rng, bounds)
    if isinstance(value, Layer):
        changes = {}
        for f in dataclasses.fields(value):
            low, high, _, _ = type(value)._ranges[f.name]
            changes[f.name] = _bounded(getattr(value, f.name), rel, rng, (low, high))
        return dataclasses.replace(value, **changes)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        changes = {f.name: _perturb(getattr(value, f.name), rel, rng, skip, BOUNDS.get(f.name))
                   for f in dataclasses.fields(value) if f.name not in skip and f.init}
        return dataclasses.replace(value, **changes)
    if isinstance(value, dict):
        return {key: _perturb(value[key], rel, rng, skip, BOUNDS.get(str(key), bounds))
                for key in sorted(value, key=str)}
    if isinstance(value, (list, tuple)):
        items = [_perturb(v, rel, rng, skip, bounds) for v in value]
        return type(value)(items) if isinstance(value, tuple) else items
    return value  # ints (counts, sizes) are not data


def perturbed(value, rel: float = PERTURBATION, seed: int = 0, *, skip=GRID_FIELDS):
    """A copy of ``value`` with every float multiplied by ``1 + rel u`` (module docstring);
    dataclass fields named in ``skip`` are left as they are."""
    return _perturb(value, rel, np.random.default_rng(seed), tuple(skip))


def movement(reference, perturbed_result, prefix: str = "") -> dict:
    """:func:`support.quantities.largest_changes` of the flattened results, by quantity name."""
    return largest_changes(flatten(perturbed_result, prefix), flatten(reference, prefix))
