"""Made-up skin parameters as plain data and as TOML files a user writes (docs/baking.md).

A parameter file starts from presets and overrides what it names::

    name = "beige on skin 1"
    foundation = "medium_beige"      # lut_baker.model.presets.FOUNDATIONS (default paper_natural)
    skin = "jensen_skin1"            # lut_baker.model.presets.SKINS (default paper_bioplate)
    coverage = 0.8                   # [0, 1]
    absorption = [0.1, 0.24, 0.42]   # [0, 1], one number or R G B

    [film]                 # film top reflection (paper eq. 2): P_d, P_s in 1/sr, n in 1/degree, eta
    n = 0.04
    [film_transmission]    # film transmission (eq. 4): P_d, P_t in 1/sr, n, eta
    [skin_surface]         # skin surface reflection (eq. 2): P_d, P_s, n, eta
    [dipole]               # skin subsurface (eq. 6): sigma_s, sigma_a in 1/mm, g, eta

Values are albedo units (1/sr, docs/model.md §4) unless ``units = "counts"``: then ``[film]``,
``[film_transmission]`` and ``[skin_surface]`` must each be complete and are the paper's counts
(reflection at 3 s, transmission at 10 s, or ``reflection_shutter_s``/``transmission_shutter_s``),
normalised with the K they imply (:func:`lut_baker.model.made_up_skin.from_paper_counts`).

Functions
---------
- :func:`skin_to_dict` -- a :class:`~lut_baker.model.made_up_skin.MadeUpSkin` as JSON-ready data.
- :func:`skin_from_dict` -- the inverse.
- :func:`load_params` -- read and validate a TOML parameter file into a MadeUpSkin.
- :func:`read_mapping` -- read a TOML parameter file without interpreting it.
- :func:`params_from_mapping` -- a MadeUpSkin from a parsed mapping (presets when empty).
"""

from __future__ import annotations

import tomllib
from dataclasses import fields
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

from .layers import Dipole, ReflectionLayer, TransmissionLayer
from .made_up_skin import MadeUpSkin, from_paper_counts
from .presets import FOUNDATIONS, SKINS, made_up_skin, paper

__all__ = ["skin_to_dict", "skin_from_dict", "load_params", "read_mapping",
           "params_from_mapping", "LAYERS", "RECORD_KEYS", "SECTIONS"]

LAYERS = {
    "film": ReflectionLayer,
    "film_transmission": TransmissionLayer,
    "skin_reflection": ReflectionLayer,
    "dipole": Dipole,
}
"""The layers of a made-up skin (its fields) and their types."""
RECORD_KEYS = {"film": "film", "film_transmission": "film_transmission",
               "skin_reflection": "skin", "dipole": "dipole"}
"""Each layer's key in :func:`skin_to_dict`'s data (the bake records, sidecars and files of
every version keep the skin's reflection under ``skin``)."""
SECTIONS = {"film": "film", "film_transmission": "film_transmission",
            "skin_surface": "skin_reflection", "dipole": "dipole"}
"""Tables of a parameter file -> the layer they set (``skin`` names the skin preset)."""
TOP_LEVEL = {"name", "foundation", "skin", "coverage", "absorption", "units",
             "reflection_shutter_s", "transmission_shutter_s", "format"}
NUMBERS = {"coverage": "a number", "reflection_shutter_s": "a number of seconds",
           "transmission_shutter_s": "a number of seconds"}
"""Top-level keys that hold one number -> what the message asks for."""
RGB = "a number or 3 numbers [R, G, B]"


def skin_to_dict(skin: MadeUpSkin) -> dict:
    """Plain data (floats, lists, str) of a made-up skin, for metadata and sidecars."""
    data = {RECORD_KEYS[name]: getattr(skin, name).as_dict() for name in LAYERS}
    data.update(coverage=float(skin.coverage), absorption=np.asarray(skin.absorption).tolist(),
                K=None if skin.K is None else float(skin.K), name=skin.name)
    return data


def skin_from_dict(data: dict) -> MadeUpSkin:
    """Rebuild a :class:`MadeUpSkin` from :func:`skin_to_dict` data (validated)."""
    try:
        layers = {name: kind(**data[RECORD_KEYS[name]]) for name, kind in LAYERS.items()}
        return MadeUpSkin(**layers, coverage=data["coverage"], absorption=data["absorption"],
                          K=data.get("K"), name=data.get("name", "custom"))
    except (KeyError, TypeError) as error:
        raise ValueError(f"incomplete made-up skin parameters: {error}") from None


def _shown(value: object) -> str:
    """A parsed TOML value as it reads in the file (``true``, ``'text'``, ``[1, 2]``)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list):
        return "[" + ", ".join(map(_shown, value)) + "]"
    return repr(value)


def _is_number(value: object) -> bool:
    """An int or float of TOML (a boolean is not a number)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _check(key: str, value: Any, ok: bool, expected: str) -> Any:
    """``value`` if ``ok``, else ``ValueError`` naming ``key``, what it expects and the value."""
    if not ok:
        raise ValueError(f"{key}: expected {expected}, got {_shown(value)}")
    return value


def _rgb(key: str, value: Any) -> Any:
    """A field value: one number or a list of 3 numbers."""
    ok = _is_number(value) or (isinstance(value, list) and len(value) == 3
                               and all(map(_is_number, value)))
    return _check(key, value, ok, RGB)


def _check_top_level(mapping: dict) -> None:
    """The value types of the top-level keys (their ranges are checked by the model)."""
    for key, expected in NUMBERS.items():
        if key in mapping:
            _check(key, mapping[key], _is_number(mapping[key]), expected)
    if "absorption" in mapping:
        _rgb("absorption", mapping["absorption"])
    if "name" in mapping:
        _check("name", mapping["name"], isinstance(mapping["name"], str), "text in quotes")


def _section(mapping: dict, name: str) -> dict:
    section = mapping.get(name, {})
    if not isinstance(section, dict):
        raise ValueError(f"[{name}] must be a table of fields")
    kind = LAYERS[SECTIONS[name]]
    allowed = {f.name for f in fields(kind)}
    unknown = sorted(set(section) - allowed)
    if unknown:
        raise ValueError(f"[{name}] has unknown field(s) {unknown}; allowed: {sorted(allowed)}")
    return {field: _rgb(f"[{name}] {field}", value) for field, value in section.items()}


def _layer(kind: type[ReflectionLayer] | type[TransmissionLayer] | type[Dipole], name: str,
           fields: dict) -> Any:
    try:
        return kind(**fields)
    except ValueError as error:
        raise ValueError(f"[{name}] {error}") from None
    except TypeError:
        missing = sorted(set(kind.__dataclass_fields__) - set(fields))
        raise ValueError(f"[{name}] is missing field(s) {missing}") from None


def params_from_mapping(mapping: dict) -> MadeUpSkin:
    """A :class:`MadeUpSkin` from a parsed parameter file (see the module docstring); with
    neither ``foundation`` nor ``skin`` the base is the paper's preset (named ``paper``)."""
    unknown = sorted(set(mapping) - TOP_LEVEL - set(SECTIONS))
    if unknown:
        raise ValueError(f"unknown key(s) {unknown}; allowed: "
                         f"{sorted(TOP_LEVEL | set(SECTIONS))}")
    _check_top_level(mapping)
    foundation = mapping.get("foundation", "paper_natural")
    skin_name = mapping.get("skin", "paper_bioplate")
    if not isinstance(foundation, str) or foundation not in FOUNDATIONS:
        raise ValueError(f"foundation must be one of {sorted(FOUNDATIONS)}, got {foundation!r}")
    if not isinstance(skin_name, str) or skin_name not in SKINS:
        raise ValueError(f"skin must be one of {sorted(SKINS)}, got {skin_name!r}")
    named = "foundation" in mapping or "skin" in mapping
    base = made_up_skin(foundation, skin_name) if named else paper()
    units = mapping.get("units", "albedo")
    sections = {SECTIONS[name]: (name, _section(mapping, name)) for name in SECTIONS}
    if units == "counts":
        film, film_transmission, skin = (
            _layer(LAYERS[field], *sections[field])
            for field in ("film", "film_transmission", "skin_reflection"))
        dipole = _layer(Dipole, "dipole", {**base.dipole.as_dict(), **sections["dipole"][1]})
        shutters = {key: mapping[key] for key in ("reflection_shutter_s", "transmission_shutter_s")
                    if key in mapping}
        base = from_paper_counts(film, film_transmission, skin, dipole, **shutters,
                                 name=base.name, absorption=base.absorption)
    elif units == "albedo":
        changed = {field: _layer(LAYERS[field], name, {**getattr(base, field).as_dict(), **values})
                   for field, (name, values) in sections.items() if values}
        base = base.replace(**changed)
    else:
        raise ValueError(f"units must be 'albedo' or 'counts', got {units!r}")
    changes = {key: mapping[key] for key in ("coverage", "absorption", "name") if key in mapping}
    try:
        return base.replace(**changes)
    except (ValueError, TypeError) as error:
        raise ValueError(str(error)) from None


def read_mapping(path: str | PathLike[str]) -> dict:
    """The parsed TOML of a parameter file; ``ValueError`` naming the file if it is missing or
    not TOML."""
    file = Path(path)
    try:
        with file.open("rb") as stream:
            return tomllib.load(stream)
    except FileNotFoundError:
        raise ValueError(f"parameter file {str(file)!r} does not exist") from None
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise ValueError(f"parameter file {str(file)!r} is not valid TOML: {error}") from None


def load_params(path: str | PathLike[str]) -> MadeUpSkin:
    """Read a TOML parameter file; ``ValueError`` naming the file and the problem if it is
    missing, not TOML, or holds an invalid value."""
    mapping = read_mapping(path)
    try:
        return params_from_mapping(mapping)
    except ValueError as error:
        raise ValueError(f"parameter file {str(path)!r}: {error}") from None
