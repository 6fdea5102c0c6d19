"""The parameter types of the made-up skin model's layers (paper section 2; docs/model.md §2).

Every layer parameter may be a scalar or an RGB triple (docs/model.md §1); the types validate
their ranges on construction and are immutable.  The formulas that evaluate them live in
:mod:`lut_baker.model.microfacet` (eqs. 2, 4) and :mod:`lut_baker.model.dipole` (eqs. 5, 6).

Types and functions
-------------------
- :class:`ReflectionLayer` -- Torrance-Sparrow reflecting layer (eq. 2).
- :class:`TransmissionLayer` -- the film's transmission (eq. 4).
- :class:`Dipole` -- the skin's subsurface scattering (eq. 6).
- :class:`Layer` -- their shared base: validation, channels, scaling.
- :func:`check_parameter` -- one finite scalar or RGB triple within a range, or ``ValueError``.
- :func:`channel_axis` -- a per-direction array with the layer's channel axis.

References
----------
Baba, Mukaigawa, Yagi, "Reflection Model for Made-up Skin Consisting of Double-layered Structure
of Cosmetic and Skin" (Osaka University).  Jensen, Marschner, Levoy, Hanrahan, "A Practical Model
for Subsurface Light Transport", SIGGRAPH 2001.
"""

from __future__ import annotations

from dataclasses import Field, dataclass, fields
from typing import Any, Self, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "ReflectionLayer",
    "TransmissionLayer",
    "Dipole",
    "Layer",
    "check_parameter",
    "channel_axis",
]


def check_parameter(name: str, value: ArrayLike, low: float, high: float, *, low_open: bool,
                    high_open: bool) -> NDArray[np.float64]:
    """Validate one parameter: a finite scalar or RGB triple within ``[low, high]`` (open at an
    end where ``low_open``/``high_open``); returns it as a read-only float array."""
    array = np.asarray(value, dtype=float)
    if array.shape not in ((), (3,)):
        raise ValueError(f"{name} must be a float or an RGB triple, got shape {array.shape}")
    below = array <= low if low_open else array < low
    above = array >= high if high_open else array > high
    if not np.all(np.isfinite(array)) or np.any(below) or np.any(above):
        lo = "(" if low_open else "["
        hi = ")" if high_open else "]"
        raise ValueError(f"{name} must lie in {lo}{low:g}, {high:g}{hi}, got {value!r}")
    array = array.copy()
    array.setflags(write=False)
    return array


def _fields(layer: Layer) -> tuple[Field, ...]:
    """The dataclass fields of a layer (every subclass of :class:`Layer` is a dataclass)."""
    return fields(cast(Any, layer))


class Layer:
    """Shared behaviour of the parameter types: validation and channel shape."""

    _ranges: dict[str, tuple[float, float, bool, bool]] = {}

    def __post_init__(self) -> None:
        for field in _fields(self):
            low, high, low_open, high_open = self._ranges[field.name]
            checked = check_parameter(
                field.name, getattr(self, field.name), low, high,
                low_open=low_open, high_open=high_open,
            )
            object.__setattr__(self, field.name, checked)

    @property
    def channels(self) -> tuple[int, ...]:
        """``()`` when every field is scalar, ``(3,)`` when any is RGB."""
        return (3,) if any(getattr(self, f.name).shape == (3,) for f in _fields(self)) else ()

    def channel(self, index: int) -> Self:
        """The same layer restricted to one RGB channel (scalars stay as they are)."""
        values = {
            f.name: (v[index] if (v := getattr(self, f.name)).shape == (3,) else v)
            for f in _fields(self)
        }
        return type(self)(**values)

    def scaled(self, **factors: ArrayLike) -> Self:
        """A copy with the named fields multiplied by ``factors`` (scalar or RGB)."""
        values = {f.name: getattr(self, f.name) for f in _fields(self)}
        for name, factor in factors.items():
            values[name] = values[name] * np.asarray(factor, dtype=float)
        return type(self)(**values)

    def as_dict(self) -> dict:
        """Fields as plain floats or lists, for metadata and parameter files."""
        return {f.name: getattr(self, f.name).tolist() for f in _fields(self)}


_POSITIVE = (0.0, np.inf, True, True)
_NON_NEGATIVE = (0.0, np.inf, False, True)


@dataclass(frozen=True, eq=False)
class ReflectionLayer(Layer):
    """Torrance-Sparrow reflecting layer (paper eq. 2).

    ``P_d``, ``P_s``: diffuse and specular scale (any consistent unit; counts in the paper,
    1/sr once normalised); ``n``: roughness in 1/degree (the lobe's 1/e half-width is 1/n
    degrees); ``eta``: relative refractive index.
    """

    P_d: Any
    P_s: Any
    n: Any
    eta: Any

    _ranges = {"P_d": _NON_NEGATIVE, "P_s": _NON_NEGATIVE, "n": _POSITIVE, "eta": _POSITIVE}


@dataclass(frozen=True, eq=False)
class TransmissionLayer(Layer):
    """Thin transmitting film (paper eq. 4): diffuse ``P_d`` plus a lobe ``P_t`` of roughness
    ``n`` (1/degree) around the straight-through direction, with Fresnel transmission at
    ``eta``."""

    P_d: Any
    P_t: Any
    n: Any
    eta: Any

    _ranges = {"P_d": _NON_NEGATIVE, "P_t": _NON_NEGATIVE, "n": _POSITIVE, "eta": _POSITIVE}


@dataclass(frozen=True, eq=False)
class Dipole(Layer):
    """Dipole subsurface scattering (paper eq. 6): ``sigma_s``, ``sigma_a`` in 1/mm, phase
    asymmetry ``g`` in (-1, 1), relative refractive index ``eta`` >= 1 (the ``F_dr`` fit of
    eq. 6 holds for eta >= 1)."""

    sigma_s: Any
    sigma_a: Any
    g: Any = 0.0
    eta: Any = 1.3

    _ranges = {
        "sigma_s": _NON_NEGATIVE,
        "sigma_a": _NON_NEGATIVE,
        "g": (-1.0, 1.0, True, True),
        "eta": (1.0, np.inf, False, True),
    }

    def __post_init__(self) -> None:
        super().__post_init__()
        if np.any(self.sigma_s * (1.0 - self.g) + self.sigma_a <= 0.0):
            raise ValueError(
                "sigma_s * (1 - g) + sigma_a must be > 0 (1/mm): the medium must interact"
            )


def channel_axis(x: np.ndarray, layer: Layer) -> np.ndarray:
    """Append a channel axis to a per-direction (or per-distance) array when the layer is RGB."""
    return x[..., None] if layer.channels else x
