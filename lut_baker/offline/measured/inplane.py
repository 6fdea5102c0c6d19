"""In-plane reflectance files: one geometry per row, spectral or RGB (docs/model.md §6).

The layout is that of the published foundation measurements (data/lanza2024/README.md):
plain text, tab-separated, no header, one row per geometry::

    theta_i <TAB> theta_o <TAB> v_1 <TAB> ... <TAB> v_k

with ``theta_i`` the incidence (degrees, ``0 <= theta_i < 90``), ``theta_o`` the signed viewing
angle (degrees, ``|theta_o| < 90``; positive on the specular side, so ``theta_o = theta_i`` is
the mirror direction) and either ``k = 81`` spectral reflectance factors at 380..780 nm (5 nm)
or ``k = 3`` linear RGB ones.  Blank lines and lines starting with ``#`` are skipped.  A bad
file raises one ``ValueError`` line naming the file, the line and the problem.

Functions and types
-------------------
- :class:`InPlaneData` -- angles and values of one file, and its layout.
- :func:`read_inplane` -- read and check a file.
- :func:`write_inplane` -- write angles and values in the same layout.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..atomic_files import write_text
from .spectra import WAVELENGTHS_NM, spectra_to_rgb

__all__ = ["SPECTRAL_SAMPLES", "InPlaneData", "read_inplane", "write_inplane"]

SPECTRAL_SAMPLES = WAVELENGTHS_NM.size
"""Spectral columns of a spectral file (81: 380..780 nm in 5 nm steps)."""
_LAYOUTS = {2 + SPECTRAL_SAMPLES: "spectral", 2 + 3: "rgb"}


@dataclass(frozen=True, eq=False)
class InPlaneData:
    """One file's rows: ``theta_i_deg``, ``theta_o_deg`` ``(N,)`` (degrees) and ``values``
    ``(N, 81)`` spectral or ``(N, 3)`` RGB reflectance factors; ``layout`` says which."""

    theta_i_deg: np.ndarray
    theta_o_deg: np.ndarray
    values: np.ndarray
    layout: str

    @property
    def rgb(self) -> np.ndarray:
        """Linear Rec.709 RGB reflectance factors ``(N, 3)`` (spectra converted by
        :func:`~lut_baker.offline.measured.spectra.spectra_to_rgb`)."""
        return spectra_to_rgb(self.values) if self.layout == "spectral" else self.values

    @property
    def incidences_deg(self) -> np.ndarray:
        """The distinct incidences, ascending."""
        return np.unique(self.theta_i_deg)


def _number(text: str, path, line: int, column: int) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{path}: line {line}, column {column}: not a number: {text!r}") from None
    if not np.isfinite(value):
        raise ValueError(f"{path}: line {line}, column {column}: not a finite number: {text!r}")
    return value


def read_inplane(path) -> InPlaneData:
    """Read an in-plane file (module docstring); every problem is one ``ValueError`` line."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise ValueError(f"{path}: cannot read: {error}") from None
    rows, width = [], None
    for line, raw in enumerate(text.splitlines(), start=1):
        stripped = raw.strip()
        if not stripped or stripped.startswith("#"):
            continue
        cells = stripped.split("\t")
        if width is None:
            if len(cells) not in _LAYOUTS:
                raise ValueError(f"{path}: line {line}: {len(cells)} tab-separated columns; "
                                 f"expected {2 + SPECTRAL_SAMPLES} (theta_i, theta_o, 81 spectral "
                                 f"values) or 5 (theta_i, theta_o, R, G, B)")
            width = len(cells)
        elif len(cells) != width:
            raise ValueError(f"{path}: line {line}: {len(cells)} tab-separated columns, but "
                             f"the first row has {width}")
        values = [_number(cell, path, line, column)
                  for column, cell in enumerate(cells, start=1)]
        _check_row(values, path, line)
        rows.append(values)
    if not rows or width is None:  # (set together)
        raise ValueError(f"{path}: no data rows")
    table = np.array(rows, dtype=float)
    return InPlaneData(table[:, 0], table[:, 1], table[:, 2:], _LAYOUTS[width])


def _check_row(values: list[float], path, line: int) -> None:
    theta_i, theta_o = values[0], values[1]
    if not 0.0 <= theta_i < 90.0:
        raise ValueError(f"{path}: line {line}: theta_i = {theta_i:g} degrees is out of range "
                         f"[0, 90)")
    if not -90.0 < theta_o < 90.0:
        raise ValueError(f"{path}: line {line}: theta_o = {theta_o:g} degrees is out of range "
                         f"(-90, 90)")
    if min(values[2:]) < 0.0:
        raise ValueError(f"{path}: line {line}: negative reflectance {min(values[2:]):g}")


def write_inplane(path, theta_i_deg, theta_o_deg, values) -> Path:
    """Write rows ``theta_i, theta_o, values...`` (``values`` ``(N, 81)`` or ``(N, 3)``) in the
    layout :func:`read_inplane` reads, with full float precision."""
    values = np.atleast_2d(np.asarray(values, dtype=float))
    table = np.column_stack([np.asarray(theta_i_deg, float), np.asarray(theta_o_deg, float),
                             values])
    if table.shape[1] not in _LAYOUTS:
        raise ValueError(f"values need 81 spectral or 3 RGB columns, got {values.shape[1]}")
    return write_text(path, "".join("\t".join(repr(float(v)) for v in row) + "\n"
                                    for row in table))
