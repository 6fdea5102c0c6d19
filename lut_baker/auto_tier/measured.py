"""The Auto tier's measured constants: render costs, noise and the paper preset's traits.

They live in ``measured.json`` beside this module, one section per benchmark that measures
them (each section's ``command``, run with ``--write``, rewrites it): ``cycles_costs``
(bench/stability_sweep.py --costs), ``eevee_costs`` (bench/eevee_tier.py --costs) and
``paper_traits`` (bench/stability_sweep.py --traits).  Numbers a benchmark measured are never
edited by hand, and a change of them is a diff of a data file.

- :func:`load` -- every section, as stored (keys are text: coverages and angles as ``"45"``,
  candidates by :attr:`~lut_baker.auto_tier.candidates.Candidate.name`).
- :func:`write_section` -- replace one section (the benchmarks' ``--write``).
- :func:`by_candidate`, :func:`by_number` -- a stored table keyed by candidates or numbers.
"""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, Protocol, TypeVar

__all__ = ["PATH", "SECTIONS", "load", "write_section", "by_candidate", "by_number"]

PATH = Path(__file__).with_name("measured.json")
"""The data file."""
SECTIONS = ("cycles_costs", "eevee_costs", "paper_traits")
"""Its sections, one per measuring command."""


class _Named(Protocol):
    """What :func:`by_candidate` reads of a candidate (a :class:`~.candidates.Candidate`)."""

    @property
    def name(self) -> str: ...


_Candidate = TypeVar("_Candidate", bound=_Named)


def load(path: Path = PATH) -> dict[str, Any]:
    """Every section of the data file at ``path``."""
    with open(path, encoding="utf-8") as handle:
        data: dict[str, Any] = json.load(handle)
    missing = [name for name in SECTIONS if name not in data]
    if missing:
        raise ValueError(f"{path} lacks the section(s) {missing}")
    return data


def write_section(name: str, section: Mapping[str, Any], path: Path = PATH) -> None:
    """Replace section ``name`` of the data file at ``path`` (the others are kept), written to
    a temporary file first so an interrupted write leaves the old file whole."""
    if name not in SECTIONS:
        raise ValueError(f"unknown section {name!r}; the sections are {SECTIONS}")
    data = load(path)
    data[name] = section
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as out:
            json.dump(data, out, indent=2)
            out.write("\n")
        os.replace(temporary, path)
    except BaseException:
        os.unlink(temporary)
        raise


def by_candidate(table: Mapping[str, Mapping[str, float]], candidates: Sequence[_Candidate]
                 ) -> dict[float, dict[_Candidate, float]]:
    """``{float coverage: {candidate: value}}`` from a stored ``{"1": {name: value}}``, for
    every one of ``candidates`` (a candidate the file lacks is an error: measure it)."""
    out: dict[float, dict[_Candidate, float]] = {}
    for coverage, row in table.items():
        missing = [c.name for c in candidates if c.name not in row]
        if missing:
            raise ValueError(f"measured.json lacks {missing} at coverage {coverage}")
        out[float(coverage)] = {c: float(row[c.name]) for c in candidates}
    return out


def by_number(table: Mapping[str, float]) -> dict[float, float]:
    """``{float: value}`` from a stored ``{"45": value}``."""
    return {float(key): value for key, value in table.items()}
