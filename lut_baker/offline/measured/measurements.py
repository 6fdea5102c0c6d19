"""Measurements laid out as in the paper's experiments (docs/model.md §6): data types, CSV files,
the forward model of what the instrument records, and synthesis of the paper's protocols.

What a camera records (paper eqs. 1-4): ``I = f(wi, wo) (N.L)`` in counts, with ``f`` the layer's
BRDF (eq. 2) or BTDF (eq. 4) and ``N.L`` the cosine of incidence.  The subsurface profile
(4.1.3, 4.2.2) is "the ratio of scattered intensity to the lit pixel"; it is modelled as
``R(d) / R(0)`` (eq. 6): the lit pixel is the profile's own value at d = 0, so only the shape of
``R`` is measured (docs/model.md §4, "No double counting").

CSV files: one header line of column names carrying their units, then one sample per line;
lines starting with ``#`` are comments.  Columns (any order, extra columns ignored):

=================  ==============================================================
reflection         ``psi_deg`` (light-camera angle), ``alpha_deg`` (signed, 0 at the
                   mirror configuration) *or* ``theta_r_deg`` (signed camera angle,
                   ``alpha = theta_r + psi/2``), ``intensity_counts``
transmission       ``incidence_deg``, ``theta_t_deg`` (signed, from -z; equal to the
                   incidence straight through), ``intensity_counts``
profile            ``distance_mm``, ``ratio`` (to the lit pixel)
=================  ==============================================================

Functions and types
-------------------
- :class:`ReflectionData`, :class:`TransmissionData`, :class:`ProfileData` -- samples.
- :func:`reflection_counts` -- ``f_r (N.L)`` of a layer at a data set's geometry (eq. 2),
  the sample optionally tilted.
- :class:`ReflectionCounts` -- the same for many layers at one data set (cosines kept).
- :func:`transmission_counts` -- ``f_t (N.L)`` of a layer at a data set's geometry (eq. 4).
- :class:`TransmissionCounts` -- the same for many layers at one data set (cosines kept).
- :func:`profile_ratio` -- ``R(d) / R(0)`` of a dipole (eq. 6).
- :func:`read_measurements` -- a CSV file as one of the data types (kind from its columns).
- :func:`write_measurements` -- a data set as a CSV file.
- :func:`synthesize_reflection`, :func:`synthesize_transmission`, :func:`synthesize_profile`
  -- a protocol evaluated on a layer, with multiplicative noise.
- :func:`paper_protocols` -- the paper's four experiments on its fitted layers (docs/model.md §5,
  6).
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

from ...model.dipole import dipole_profile
from ...model.layers import Dipole, ReflectionLayer, TransmissionLayer, channel_axis
from ...model.microfacet import (
    reflection_cosines,
    transmission_cosines,
    ts_reflection_from_cosines,
    ts_transmission_from_cosines,
)
from ...model.presets import paper_layers
from ..atomic_files import replacing
from .protocols import (
    profile_distances,
    reflection_geometry,
    reflection_sweep,
    tilted,
    transmission_geometry,
    transmission_sweep,
)

__all__ = [
    "PAPER_RELATIVE_ANGLES_DEG",
    "PAPER_INCIDENCES_DEG",
    "MAX_NOISE",
    "ReflectionData",
    "TransmissionData",
    "ProfileData",
    "reflection_counts",
    "ReflectionCounts",
    "transmission_counts",
    "TransmissionCounts",
    "profile_ratio",
    "read_measurements",
    "write_measurements",
    "synthesize_reflection",
    "synthesize_transmission",
    "synthesize_profile",
    "paper_protocols",
]

PAPER_RELATIVE_ANGLES_DEG = (30.0, 60.0, 90.0, 120.0)
"""Light-camera angles psi of the reflection experiments (4.1.1, 4.2.1), degrees."""
PAPER_INCIDENCES_DEG = (0.0, 30.0, 60.0)
"""Incidence angles of the transmission experiment (4.1.2), degrees."""
MAX_NOISE = 0.1
"""Largest relative noise :func:`synthesize_reflection` and friends accept (keeps counts > 0)."""


def _groups(key: np.ndarray):
    """``(value, index array)`` for each distinct value of ``key``, in order of appearance."""
    _, first, inverse = np.unique(key, return_index=True, return_inverse=True)
    for group in np.argsort(first):
        yield key[first[group]], np.flatnonzero(inverse == group)


class _ReflectionDirections:
    """The unit vectors ``(N, 3)`` a :class:`ReflectionData` sets from its columns (not
    fields: no column of the file)."""

    wi: np.ndarray
    wo: np.ndarray


class _TransmissionDirections:
    """The unit vectors ``(N, 3)`` a :class:`TransmissionData` sets from its columns."""

    wi: np.ndarray
    wt: np.ndarray


@dataclass(frozen=True, eq=False)
class ReflectionData(_ReflectionDirections):
    """Reflection samples (docs/model.md §6): light-camera angle ``psi_deg``, signed ``alpha_deg``
    (degrees) and ``intensity_counts`` per sample.  ``wi``/``wo`` are the directions."""

    psi_deg: np.ndarray
    alpha_deg: np.ndarray
    intensity_counts: np.ndarray

    COLUMNS = ("psi_deg", "alpha_deg", "intensity_counts")
    KIND = "reflection"

    def __post_init__(self):
        _freeze(self)
        _directions(self, "psi_deg", "alpha_deg", "wo", reflection_geometry, (0.0, 180.0, True))
        if np.any(self.wi[:, 2] < 0.0) or np.any(self.wo[:, 2] < 0.0):
            raise ValueError("alpha_deg puts the light or the camera below the sample "
                             "(|alpha +- psi/2| must be <= 90 degrees)")


@dataclass(frozen=True, eq=False)
class TransmissionData(_TransmissionDirections):
    """Transmission samples (docs/model.md §6): ``incidence_deg``, signed ``theta_t_deg`` (degrees
    from -z) and ``intensity_counts`` per sample.  ``wi``/``wt`` are the directions."""

    incidence_deg: np.ndarray
    theta_t_deg: np.ndarray
    intensity_counts: np.ndarray

    COLUMNS = ("incidence_deg", "theta_t_deg", "intensity_counts")
    KIND = "transmission"

    def __post_init__(self):
        _freeze(self)
        if np.any(np.abs(self.theta_t_deg) > 90.0):
            raise ValueError("theta_t_deg must lie in [-90, 90] degrees")
        _directions(self, "incidence_deg", "theta_t_deg", "wt", transmission_geometry,
                    (0.0, 90.0, False))


@dataclass(frozen=True, eq=False)
class ProfileData:
    """Subsurface profile (docs/model.md §6): ``distance_mm`` from the lit pixel and the ``ratio``
    of the scattered intensity there to the lit pixel's."""

    distance_mm: np.ndarray
    ratio: np.ndarray

    COLUMNS = ("distance_mm", "ratio")
    KIND = "profile"

    def __post_init__(self):
        _freeze(self)
        if np.any(self.distance_mm < 0.0):
            raise ValueError("distance_mm must be >= 0 (mm)")


def _directions(data, key: str, angle: str, second: str, geometry, valid: tuple) -> None:
    """Set ``data.wi`` and ``data.<second>`` from :mod:`lut_baker.offline.measured.protocols`'
    ``geometry``, one experiment per distinct value of the column ``key`` (within ``valid = (low,
    high, low_open)`` degrees; high is always open)."""
    low, high, low_open = valid
    wi = np.empty(getattr(data, angle).shape + (3,))
    other = np.empty_like(wi)
    for value, index in _groups(getattr(data, key)):
        if not ((value > low) if low_open else (value >= low)) or not value < high:
            bracket = "(" if low_open else "["
            raise ValueError(f"{key} must lie in {bracket}{low:g}, {high:g}) degrees, "
                             f"got {value:g}")
        sweep = geometry(value, getattr(data, angle)[index])
        wi[index], other[index] = sweep.wi, getattr(sweep, second)
    object.__setattr__(data, "wi", wi)
    object.__setattr__(data, second, other)


def _freeze(data) -> None:
    """Check and store a data set's columns as read-only 1-D float arrays of one length, all
    finite, with the measured column (the last) > 0 (relative residuals need it)."""
    columns = [f.name for f in fields(data)]
    arrays = [np.array(getattr(data, name), dtype=float).ravel() for name in columns]
    if len({a.size for a in arrays}) != 1:
        raise ValueError(f"columns {', '.join(columns)} must have the same length")
    if arrays[0].size == 0:
        raise ValueError("no samples")
    for name, array in zip(columns, arrays, strict=True):
        if not np.all(np.isfinite(array)):
            raise ValueError(f"{name} must be finite numbers")
        array.setflags(write=False)
        object.__setattr__(data, name, array)
    if np.any(arrays[-1] <= 0.0):
        row = int(np.argmax(arrays[-1] <= 0.0))
        raise ValueError(f"{columns[-1]} must be > 0 (sample {row + 1} is {arrays[-1][row]:g})")


# --------------------------------------------------------------------------------------------
# Forward model
# --------------------------------------------------------------------------------------------
def reflection_counts(data: ReflectionData, layer: ReflectionLayer,
                      tilt_deg: float = 0.0) -> np.ndarray:
    """What the camera records, ``I = f_r(wi, wo) (N.L)`` (paper eqs. 1, 2), at the samples'
    geometry; in the unit of ``layer.P_d`` (counts for the paper's values).

    ``tilt_deg``: the sample sits tilted by that angle in the plane (an offset of alpha,
    :func:`~lut_baker.offline.measured.protocols.tilted`), so it reflects ``f_r`` at the
    tilted directions; ``N.L`` stays the nominal one, as in data normalised by a white
    reference measured in the same mount (whose own cosine cancels the sample's: reflectance
    factors ``R = pi f_r`` at the sample's angles)."""
    return ReflectionCounts(data)(layer, tilt_deg)


class ReflectionCounts:
    """:func:`reflection_counts` at one data set's geometry for many layers: the cosines of
    eq. 2 are computed once per tilt (the last one is kept; a fit changes the layer far more
    often than the tilt).  ``layer`` may be any object with the fields ``P_d``, ``P_s``, ``n``,
    ``eta`` and ``channels``."""

    def __init__(self, data: ReflectionData):
        self._wi, self._wo = data.wi, data.wo
        self._tilt: float | None = None
        self._cosines: tuple[np.ndarray, ...] | None = None

    def __call__(self, layer, tilt_deg: float = 0.0) -> np.ndarray:
        tilt = float(tilt_deg)
        cosines = self._cosines
        if cosines is None or tilt != self._tilt:
            wi, wo = (self._wi, self._wo) if tilt == 0.0 else (tilted(self._wi, tilt),
                                                                 tilted(self._wo, tilt))
            cosines = self._cosines = reflection_cosines(wi, wo)
            self._tilt = tilt
        n_dot_h, v_dot_h, n_dot_v, n_dot_l = (channel_axis(c, layer) for c in cosines)
        value = ts_reflection_from_cosines(n_dot_h, v_dot_h, n_dot_v, n_dot_l, layer)
        nominal = channel_axis(self._wi[:, 2], layer)
        return np.where((n_dot_l >= 0.0) & (n_dot_v >= 0.0), value * nominal, 0.0)


def transmission_counts(data: TransmissionData, layer: TransmissionLayer) -> np.ndarray:
    """What the camera below the film records, ``I = f_t(wi, wt) (N.L)`` (paper eqs. 3, 4)."""
    return TransmissionCounts(data)(layer)


class TransmissionCounts:
    """:func:`transmission_counts` at one data set's geometry for many layers (the cosines of
    eq. 4 computed once); ``layer`` may be any object with the fields ``P_d``, ``P_t``, ``n``,
    ``eta`` and ``channels``."""

    def __init__(self, data: TransmissionData):
        self._cosines = transmission_cosines(data.wi, data.wt)
        self._n_dot_l = data.wi[:, 2]

    def __call__(self, layer) -> np.ndarray:
        n_dot_h, v_dot_h, crossing = (channel_axis(c, layer) for c in self._cosines)
        value = ts_transmission_from_cosines(n_dot_h, v_dot_h, layer)
        return np.where(crossing, value, 0.0) * channel_axis(self._n_dot_l, layer)


def profile_ratio(distance_mm, dipole: Dipole) -> np.ndarray:
    """Scattered intensity relative to the lit pixel, ``R(d) / R(0)`` (paper eq. 6)."""
    return dipole_profile(distance_mm, dipole) / dipole_profile(0.0, dipole)


# --------------------------------------------------------------------------------------------
# CSV files
# --------------------------------------------------------------------------------------------
_KINDS = (ReflectionData, TransmissionData, ProfileData)


def read_measurements(path) -> ReflectionData | TransmissionData | ProfileData:
    """Read a CSV file of measurements; the kind follows from the header's columns (module
    docstring).  Any problem (no file, empty, missing column, non-numeric cell) raises
    ``ValueError`` with one line naming the file and the problem."""
    path = Path(path)
    try:
        with path.open(newline="", encoding="utf-8") as handle:
            rows = [row for row in csv.reader(handle)
                    if row and any(cell.strip() for cell in row)
                    and not row[0].lstrip().startswith("#")]
    except FileNotFoundError:
        raise ValueError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError) as error:
        raise ValueError(f"{path}: cannot read ({error})") from None
    if not rows:
        raise ValueError(f"{path}: empty file (expected a header line of column names)")
    header = [cell.strip() for cell in rows[0]]
    kind = _kind_of(header, path)
    names = list(kind.COLUMNS)
    if kind is ReflectionData and "alpha_deg" not in header:
        names[1] = "theta_r_deg"
    index = [header.index(name) for name in names]
    if len(rows) == 1:
        raise ValueError(f"{path}: no data rows after the header")
    values = np.empty((len(rows) - 1, len(names)))
    for line, row in enumerate(rows[1:], start=2):
        for column, (name, i) in enumerate(zip(names, index, strict=True)):
            cell = row[i].strip() if i < len(row) else ""
            try:
                values[line - 2, column] = float(cell)
            except ValueError:
                raise ValueError(f"{path}: row {line}, column {name}: not a number: "
                                 f"{cell!r}") from None
    if names[1] == "theta_r_deg":  # alpha = theta_r + psi / 2 (protocols.reflection_geometry)
        values[:, 1] += values[:, 0] / 2.0
    try:
        return kind(*values.T)
    except ValueError as error:
        raise ValueError(f"{path}: {error}") from None


def _kind_of(header: list[str], path: Path):
    """The data type whose columns the header holds, or a ``ValueError`` naming what's missing."""
    best, missing = None, None
    for kind in _KINDS:
        wanted = list(kind.COLUMNS)
        if kind is ReflectionData and "theta_r_deg" in header:
            wanted[1] = "theta_r_deg"
        absent = [name for name in wanted if name not in header]
        if not absent:
            return kind
        if len(absent) < len(wanted) and (missing is None or len(absent) < len(missing)):
            best, missing = kind, absent
    if best is None or missing is None:  # (set together)
        expected = "; ".join(",".join(kind.COLUMNS) for kind in _KINDS)
        raise ValueError(f"{path}: unknown columns {','.join(header)!r}; expected one of: "
                         f"{expected}")
    alternative = " (or theta_r_deg)" if missing == ["alpha_deg"] else ""
    raise ValueError(f"{path}: missing column {', '.join(missing)}{alternative} "
                     f"(a {best.KIND} file needs {','.join(best.COLUMNS)})")


def write_measurements(path, data, comments: tuple[str, ...] = ()) -> Path:
    """Write a data set as CSV (header of unit-carrying column names, ``# comment`` lines
    first); values to 7 significant digits.  Returns the path."""
    path = Path(path)
    columns = [getattr(data, name) for name in data.COLUMNS]
    with replacing(path) as temporary, temporary.open("w", newline="",
                                                      encoding="utf-8") as handle:
        for comment in comments:
            handle.write(f"# {comment}\n")
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(data.COLUMNS)
        writer.writerows([f"{v:.7g}" for v in row] for row in zip(*columns, strict=True))
    return path


# --------------------------------------------------------------------------------------------
# Synthesis
# --------------------------------------------------------------------------------------------
def _noisy(values: np.ndarray, noise: float, rng) -> np.ndarray:
    """``values (1 + noise e)`` with ``e`` standard normal: multiplicative noise."""
    if not 0.0 <= noise <= MAX_NOISE:
        raise ValueError(f"noise must lie in [0, {MAX_NOISE:g}] (relative), got {noise!r}")
    rng = np.random.default_rng(rng)
    return values * (1.0 + noise * rng.standard_normal(values.shape))


def synthesize_reflection(layer: ReflectionLayer, relative_angles_deg=PAPER_RELATIVE_ANGLES_DEG,
                          noise: float = 0.0, rng=None) -> ReflectionData:
    """The reflection experiment (docs/model.md §6) at each ``psi`` on the paper's alpha steps,
    evaluated on a scalar ``layer`` with relative noise ``noise`` (``rng``: seed or Generator)."""
    sweeps = [reflection_sweep(psi) for psi in relative_angles_deg]
    psi = np.concatenate([np.full(s.alpha_deg.shape, s.relative_angle_deg) for s in sweeps])
    alpha = np.concatenate([s.alpha_deg for s in sweeps])
    exact = ReflectionData(psi, alpha, np.ones_like(alpha))
    return ReflectionData(psi, alpha, _noisy(reflection_counts(exact, layer), noise, rng))


def synthesize_transmission(layer: TransmissionLayer, incidences_deg=PAPER_INCIDENCES_DEG,
                            noise: float = 0.0, rng=None) -> TransmissionData:
    """The transmission experiment (docs/model.md §6) at each incidence on the paper's beta
    steps."""
    sweeps = [transmission_sweep(incidence) for incidence in incidences_deg]
    incidence = np.concatenate([np.full(s.theta_t_deg.shape, s.incidence_deg) for s in sweeps])
    theta_t = np.concatenate([s.theta_t_deg for s in sweeps])
    exact = TransmissionData(incidence, theta_t, np.ones_like(theta_t))
    return TransmissionData(incidence, theta_t,
                            _noisy(transmission_counts(exact, layer), noise, rng))


def synthesize_profile(dipole: Dipole, distance_mm=None, noise: float = 0.0,
                       rng=None) -> ProfileData:
    """The pencil-beam profile (docs/model.md §6): ``R(d)/R(0)`` at ``distance_mm`` (default
    :func:`lut_baker.offline.measured.protocols.profile_distances`, 0 to 3 mm by 0.05)."""
    d = profile_distances() if distance_mm is None else np.asarray(distance_mm, float)
    return ProfileData(d, _noisy(profile_ratio(d, dipole), noise, rng))


def paper_protocols(noise: float = 0.02, seed=None) -> dict:
    """The paper's experiments on its fitted layers in counts (docs/model.md §5, 6):
    ``{"film_reflection", "film_transmission", "skin_reflection", "skin_profile"}`` -> data set.
    The four draw independent noise from one seed."""
    film, film_transmission, skin, dipole = paper_layers()
    rngs = np.random.default_rng(seed).spawn(4)
    return {
        "film_reflection": synthesize_reflection(film, noise=noise, rng=rngs[0]),
        "film_transmission": synthesize_transmission(film_transmission, noise=noise, rng=rngs[1]),
        "skin_reflection": synthesize_reflection(skin, noise=noise, rng=rngs[2]),
        "skin_profile": synthesize_profile(dipole, noise=noise, rng=rngs[3]),
    }
