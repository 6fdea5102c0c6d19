"""Validate and build the Blender extension zip with Blender's own extension tool.

Usage::

    python tools/build_extension.py [--source-dir .] [--output-dir dist] [--validate-only]

Run it with a Python that has the pip ``bpy`` installed (``$(tools/venv.sh)/bin/python``): the
tool is ``bpy/<version>/scripts/addons_core/bl_pkg/cli/blender_ext.py`` inside that package, the
same script ``blender --command extension validate|build`` runs. It is a plain script, so it is
run in a subprocess and bpy itself is never imported here. ``MAKEUP_SKIN_BLENDER_EXT`` may point
at another copy of ``blender_ext.py``.

After building, the zip is checked: it holds the root ``__init__.py``, the manifest and every
``.py`` of ``makeup_skin_addon/`` and of ``lut_baker/`` outside ``lut_baker/offline/``, and nothing
offline or from development (tests, caches, tools, ...). On success the zip path is the last line on
stdout; on failure the exit status is 1 and the tool's own message is on stderr.

Functions (importable, e.g. by the tests):

- :func:`find_extension_tool` -- path of ``blender_ext.py``.
- :func:`validate` -- run ``blender_ext.py validate``.
- :func:`build` -- run ``blender_ext.py build`` and :func:`check_zip`; return the zip path.
- :func:`check_zip` -- list what is wrong with a built zip.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

__all__ = [
    "ADDON_PACKAGES",
    "BuildError",
    "REPO_ROOT",
    "build",
    "check_zip",
    "find_extension_tool",
    "manifest",
    "validate",
]

REPO_ROOT = Path(__file__).resolve().parent.parent

#: Python packages that must ship complete (every ``.py`` outside ``tests/`` and
#: :data:`OFFLINE`).
ADDON_PACKAGES = ("makeup_skin_addon", "lut_baker")

#: What must not ship: lut_baker's offline part (scipy, matplotlib, the command line).
OFFLINE = ("lut_baker/offline/", "lut_baker/__main__.py")

#: The only top-level entries a zip may have; anything else is development clutter that the
#: manifest's ``paths_exclude_pattern`` should have left out.
ALLOWED_TOP_LEVEL = {"__init__.py", "blender_manifest.toml", "LICENSE", "LICENSE.txt"} | {
    f"{p}/" for p in ADDON_PACKAGES
}

_TOOL_GLOB = "*/scripts/addons_core/bl_pkg/cli/blender_ext.py"


class BuildError(RuntimeError):
    """Validation, build or zip check failed; the message says why."""


def _version_key(path: Path) -> tuple[int, ...]:
    # <bpy>/<major.minor>/scripts/...: prefer the newest if several are present.
    version = path.parents[4].name
    return tuple(int(x) for x in version.split(".") if x.isdigit())


def find_extension_tool() -> Path:
    """Return the path of ``blender_ext.py`` shipped inside the installed pip ``bpy``.

    Raises
    ------
    BuildError
        If ``bpy`` is not installed in this interpreter or has no extension tool.
    """
    override = os.environ.get("MAKEUP_SKIN_BLENDER_EXT")
    if override:
        path = Path(override)
        if not path.is_file():
            raise BuildError(f"MAKEUP_SKIN_BLENDER_EXT={override} is not a file")
        return path
    spec = importlib.util.find_spec("bpy")  # locates bpy without importing it
    if spec is None or spec.origin is None:
        raise BuildError(
            f"bpy is not installed for {sys.executable}; run this with the venv's python: "
            '"$(tools/venv.sh)/bin/python" tools/build_extension.py'
        )
    bpy_dir = Path(spec.origin).parent
    tools = sorted(bpy_dir.glob(_TOOL_GLOB), key=_version_key)
    if not tools:
        raise BuildError(f"no {_TOOL_GLOB} under {bpy_dir}")
    return tools[-1]


def manifest(source_dir: Path | str = REPO_ROOT) -> dict:
    """Return the parsed ``blender_manifest.toml`` of ``source_dir``."""
    with open(Path(source_dir) / "blender_manifest.toml", "rb") as fh:
        return tomllib.load(fh)


def _run_tool(*args: str) -> str:
    tool = find_extension_tool()
    proc = subprocess.run(
        [sys.executable, str(tool), *args],
        capture_output=True,
        text=True,
        check=False,
    )
    output = (proc.stdout + proc.stderr).strip()
    if proc.returncode != 0:
        raise BuildError(f"blender_ext.py {args[0]} failed (exit {proc.returncode}):\n{output}")
    return output


def validate(source_dir: Path | str = REPO_ROOT) -> str:
    """Run ``blender_ext.py validate`` on ``source_dir``; return its output.

    Raises
    ------
    BuildError
        With the validator's message if the manifest or layout is invalid.
    """
    return _run_tool("validate", str(Path(source_dir).resolve()))


def check_zip(zip_path: Path | str, source_dir: Path | str = REPO_ROOT) -> list[str]:
    """Return the problems of a built extension zip (an empty list if it is fine).

    Every ``.py`` and ``.json`` file (the runtime's data, e.g. the measured foundation presets)
    of :data:`ADDON_PACKAGES` in ``source_dir`` (outside ``tests/``,
    ``__pycache__/`` and :data:`OFFLINE`) must be in the zip, and nothing outside
    :data:`ALLOWED_TOP_LEVEL`, nothing of :data:`OFFLINE`, no ``tests/`` folder and no compiled
    Python.
    """
    source_dir = Path(source_dir)
    with zipfile.ZipFile(zip_path) as zf:
        names = set(zf.namelist())
    problems = []
    for required in ("__init__.py", "blender_manifest.toml"):
        if required not in names:
            problems.append(f"missing {required}")
    for package in ADDON_PACKAGES:
        sources = [
            p.relative_to(source_dir).as_posix()
            for pattern in ("*.py", "*.json")  # modules and the runtime's data files
            for p in (source_dir / package).rglob(pattern)
            if not {"tests", "__pycache__"} & set(p.relative_to(source_dir).parts)
            and not p.relative_to(source_dir).as_posix().startswith(OFFLINE)
        ]
        if not sources:
            problems.append(f"no {package}/*.py in {source_dir}")
        problems += [f"missing {s}" for s in sorted(sources) if s not in names]
    for name in sorted(names):
        parts = name.split("/")
        top = parts[0] + ("/" if len(parts) > 1 else "")
        if top not in ALLOWED_TOP_LEVEL:
            problems.append(f"unexpected {name} (add it to paths_exclude_pattern)")
        elif name.startswith(OFFLINE):
            problems.append(f"offline module shipped: {name}")
        elif "tests" in parts[:-1] or "__pycache__" in parts or name.endswith((".pyc", ".pyo")):
            problems.append(f"development file shipped: {name}")
    return problems


def build(
    source_dir: Path | str = REPO_ROOT,
    output_dir: Path | str | None = None,
) -> Path:
    """Validate ``source_dir``, build the zip into ``output_dir`` and check it.

    Parameters
    ----------
    source_dir
        Folder holding ``blender_manifest.toml`` (the repository root).
    output_dir
        Where to write ``<id>-<version>.zip``; created if missing. Default ``<source_dir>/dist``.

    Returns
    -------
    Path
        The zip file.

    Raises
    ------
    BuildError
        With the tool's message if validation or building fails, or the list of problems
        :func:`check_zip` found (the zip is then deleted).
    """
    source_dir = Path(source_dir).resolve()
    output_dir = Path(output_dir) if output_dir is not None else source_dir / "dist"
    output_dir = output_dir.resolve()
    output_dir.mkdir(parents=True, exist_ok=True)  # the tool does not create it
    validate(source_dir)
    info = manifest(source_dir)
    zip_path = output_dir / f"{info['id']}-{info['version']}.zip"
    _run_tool("build", "--source-dir", str(source_dir), "--output-dir", str(output_dir))
    if not zip_path.is_file():
        raise BuildError(f"blender_ext.py build succeeded but {zip_path} is missing")
    problems = check_zip(zip_path, source_dir)
    if problems:
        zip_path.unlink()  # never leave an unshippable zip where it could be picked up
        raise BuildError(f"{zip_path} is not shippable:\n  " + "\n  ".join(problems))
    return zip_path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--source-dir", type=Path, default=REPO_ROOT)
    parser.add_argument("--output-dir", type=Path, default=None, help="default: SOURCE/dist")
    parser.add_argument("--validate-only", action="store_true")
    args = parser.parse_args(argv)
    try:
        if args.validate_only:
            print(validate(args.source_dir))
        else:
            print(build(args.source_dir, args.output_dir))
    except BuildError as exc:
        print(f"build_extension: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
