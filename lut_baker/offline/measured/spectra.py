"""Reflectance spectra to linear Rec.709 RGB (colour-science; docs/model.md §4).

The measured spectra of published foundations (380-780 nm, 5 nm) become the per-channel
reflectance factors the model's layers take (docs/model.md §4: per-channel parameters).  The
conversion is linear: CIE 1931 2-degree observer and the D65 illuminant give XYZ by plain
integration (``colour.sd_to_XYZ(..., method="Integration")``), normalised so that the perfect
white reflector has ``Y = 1``; colour-science's sRGB (Rec.709) primaries turn XYZ into linear
RGB.  The illuminant integrated over the observer's functions is not exactly sRGB's tabulated
white point, so a last per-channel scale (a few parts in 10^4) makes the perfect white reflector
(all ones) exactly ``(1, 1, 1)``: reflectance factors stay reflectance factors in every channel.

Functions
---------
- :data:`WAVELENGTHS_NM` -- the measured grid, 380..780 nm in 5 nm steps (81 samples).
- :func:`spectra_to_rgb` -- reflectance spectra ``(..., 81)`` to linear Rec.709 RGB ``(..., 3)``.
- :func:`luminance` -- Rec.709 luminance ``Y`` of linear RGB.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

__all__ = ["WAVELENGTHS_NM", "REC709_LUMINANCE", "spectra_to_rgb", "luminance"]

WAVELENGTHS_NM = np.linspace(380.0, 780.0, 81)
"""Wavelengths (nm) of the spectral columns: 380, 385, ..., 780."""
WAVELENGTHS_NM.setflags(write=False)

REC709_LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
"""Rec.709 luminance weights of linear R, G, B (they sum to 1, so white stays 1)."""
REC709_LUMINANCE.setflags(write=False)


def _colour():
    try:
        import colour
    except ModuleNotFoundError as error:
        raise ModuleNotFoundError("spectra to RGB need colour-science "
                                  "(pip install colour-science)") from error
    return colour


def observer_and_illuminant():
    """The CIE 1931 2-degree observer and D65, both on :data:`WAVELENGTHS_NM`."""
    colour = _colour()
    shape = colour.SpectralShape(380.0, 780.0, 5.0)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    illuminant = colour.SDS_ILLUMINANTS["D65"].copy().align(shape)
    return cmfs, illuminant


def xyz_to_rec709_matrix() -> np.ndarray:
    """colour-science's XYZ -> linear sRGB (Rec.709 primaries, D65) matrix."""
    return np.array(_colour().RGB_COLOURSPACES["sRGB"].matrix_XYZ_to_RGB, dtype=float)


@lru_cache(maxsize=1)
def _weights() -> np.ndarray:
    cmfs, illuminant = observer_and_illuminant()
    xyz_bar = np.asarray(cmfs.values, float)  # (81, 3)
    power = np.asarray(illuminant.values, float)  # (81,)
    weighted = xyz_bar * power[:, None]
    to_xyz = weighted / np.sum(weighted[:, 1])  # white reflector -> Y = 1
    to_rgb = to_xyz @ xyz_to_rec709_matrix().T  # (81, 3)
    to_rgb = to_rgb / np.sum(to_rgb, axis=0)  # white reflector -> (1, 1, 1) exactly
    to_rgb.setflags(write=False)
    return to_rgb


def spectra_to_rgb(spectra) -> np.ndarray:
    """Reflectance spectra ``(..., 81)`` on :data:`WAVELENGTHS_NM` to linear Rec.709 RGB
    ``(..., 3)`` (CIE 1931 2-degree observer, D65; a flat spectrum of value v gives v, v, v)."""
    spectra = np.asarray(spectra, dtype=float)
    if spectra.shape[-1:] != WAVELENGTHS_NM.shape:
        raise ValueError(f"spectra need {WAVELENGTHS_NM.size} samples (380..780 nm, 5 nm) on "
                         f"the last axis, got shape {spectra.shape}")
    # Written as white + (spectra - white) so that the white reflector's (1, 1, 1) is exact
    # rather than a sum of 81 rounded weights.
    return 1.0 + (spectra - 1.0) @ _weights()


def luminance(rgb) -> np.ndarray:
    """Rec.709 luminance of linear RGB ``(..., 3)``."""
    return np.asarray(rgb, dtype=float) @ REC709_LUMINANCE
