"""The import contract: what may import what, checked over every import statement.

Usage::

    python tools/check_imports.py               # one line per broken rule; exit 1 if any
    python tools/check_imports.py --root DIR    # check another tree laid out like this one

Rules (every ``import`` and ``from ... import`` counts, at module level or inside a function;
the add-on's ``from ..lut_baker.x import y`` in ``makeup_skin_addon/core.py`` is ``lut_baker.x``):

1. **Layers.** :data:`LAYERS` lists each package's layers, lowest first. A module may import from
   its own layer and the layers below, never from a higher one. In the add-on each module is a
   layer of its own, so two add-on modules cannot import each other.
2. **No cycle** among the project's modules.
3. **Third-party packages.** The runtime (lut_baker outside ``lut_baker.offline``) imports the
   standard library and numpy only, because Blender's Python has nothing else; the offline
   modules may also use scipy, matplotlib, OpenImageIO and colour-science; the add-on may use
   Blender's modules and numpy. Nothing outside ``lut_baker.offline`` imports it.

``tests/test_import_contract.py`` runs it on this tree and on small broken trees, one per rule.
"""

from __future__ import annotations

import argparse
import ast
import sys
from collections.abc import Iterable
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent

#: Per package, its layers lowest first; a layer is a tuple of module-name prefixes.
LAYERS: dict[str, list[tuple[str, ...]]] = {
    "lut_baker": [
        ("lut_baker", "lut_baker.numerics"),
        ("lut_baker.model",),
        ("lut_baker.evaluate",),
        ("lut_baker.tables",),
        ("lut_baker.bake",),
        ("lut_baker.closures",),
        ("lut_baker.auto_tier",),
        ("lut_baker.offline.atomic_files",),
        ("lut_baker.offline.exr_files", "lut_baker.offline.measured"),
        ("lut_baker.offline.validation",),
        ("lut_baker.offline.paper_figures",),
        ("lut_baker.offline.foundation_presets",),
        ("lut_baker.offline.foundations",),
        ("lut_baker.offline.cli", "lut_baker.offline", "lut_baker.__main__"),
    ],
    "makeup_skin_addon": [
        ("makeup_skin_addon.keys",),
        ("makeup_skin_addon.package",),
        ("makeup_skin_addon.core",),
        ("makeup_skin_addon.progress", "makeup_skin_addon.pages"),
        ("makeup_skin_addon.group_parts",),
        ("makeup_skin_addon.artist_shader",),
        ("makeup_skin_addon.node_maths",),
        ("makeup_skin_addon.surface_values",),
        ("makeup_skin_addon.node_copy",),
        ("makeup_skin_addon.skin_nodes",),
        ("makeup_skin_addon.convert",),
        ("makeup_skin_addon.storage",),
        ("makeup_skin_addon.bakes",),
        ("makeup_skin_addon.face_geometry",),
        ("makeup_skin_addon.surface_points",),
        ("makeup_skin_addon.mesh_attributes",),
        ("makeup_skin_addon.image_store",),
        ("makeup_skin_addon.image_texels",),
        ("makeup_skin_addon.skin_sampling",),
        ("makeup_skin_addon.sky_visibility",),
        ("makeup_skin_addon.skin_colour",),
        ("makeup_skin_addon.artist_skin",),
        ("makeup_skin_addon.shade",),
        ("makeup_skin_addon.skin_model",),
        ("makeup_skin_addon.matching",),
        ("makeup_skin_addon.node_algebra",),
        ("makeup_skin_addon.nodes",),
        ("makeup_skin_addon.tier_choice",),
        ("makeup_skin_addon.groups",),
        ("makeup_skin_addon.rebuild",),
        ("makeup_skin_addon.apply",),
        ("makeup_skin_addon.live",),
        ("makeup_skin_addon.on_load",),
        ("makeup_skin_addon.properties",),
        ("makeup_skin_addon.operators",),
        ("makeup_skin_addon.ui",),
        ("makeup_skin_addon",),
    ],
}

#: Third-party top-level packages allowed, by where the importing module lives.
ALLOWED_THIRD_PARTY = {
    "runtime": {"numpy"},
    "offline": {"numpy", "scipy", "matplotlib", "OpenImageIO", "colour"},
    "addon": {"numpy", "bpy", "bpy_extras", "bl_operators", "bl_ui", "mathutils", "addon_utils"},
}

PROJECT = tuple(LAYERS)


def module_name(path: Path, root: Path = REPO) -> str:
    """``lut_baker/model/layers.py`` -> ``lut_baker.model.layers`` (``__init__`` -> package)."""
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def is_package(path: Path) -> bool:
    return path.name == "__init__.py"


def imported_modules(source: str, name: str, package: bool,
                     known: set[str]) -> Iterable[tuple[str, int]]:
    """``(module, line)`` for every import in ``source`` (module ``name``), relative ones
    resolved; ``from p import x`` names module ``p.x`` when that module exists in ``known``."""
    base_parts = name.split(".") if package else name.split(".")[:-1]
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, node.lineno
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                keep = len(base_parts) - (node.level - 1)
                stem = ".".join(base_parts[:keep] + ([node.module] if node.module else []))
            else:
                stem = node.module or ""
            for alias in node.names:
                candidate = f"{stem}.{alias.name}"
                yield (candidate if candidate in known else stem), node.lineno


def layer_of(module: str) -> tuple[str, int] | None:
    """``(package, layer index)`` of a project module (the longest matching prefix)."""
    best = None
    for package, layers in LAYERS.items():
        for index, prefixes in enumerate(layers):
            for prefix in prefixes:
                # a package's own name matches itself only, not everything inside it
                inside = prefix not in LAYERS and module.startswith(prefix + ".")
                if module == prefix or inside:
                    if best is None or len(prefix) > best[0]:
                        best = (len(prefix), package, index)
    return None if best is None else (best[1], best[2])


def kind_of(module: str) -> str:
    if module.startswith("makeup_skin_addon"):
        return "addon"
    if module.startswith("lut_baker.offline") or module == "lut_baker.__main__":
        return "offline"
    return "runtime"


def collect(root: Path = REPO, packages: Iterable[str] = PROJECT) -> dict[str, tuple[Path, str]]:
    """Module name -> (path, source) for every ``.py`` of ``packages`` under ``root``."""
    sources = {}
    for package in packages:
        for path in sorted((root / package).rglob("*.py")):
            if "__pycache__" not in path.parts:
                sources[module_name(path, root)] = (path, path.read_text())
    return sources


def problems(sources: dict[str, tuple[Path, str]], root: Path = REPO) -> list[str]:
    """One sentence per broken rule in ``sources`` (from :func:`collect`)."""
    known = set(sources)
    found, graph = [], {name: set() for name in sources}
    stdlib = set(sys.stdlib_module_names)
    for name, (path, source) in sorted(sources.items()):
        where = path.relative_to(root) if path.is_relative_to(root) else path
        here = layer_of(name)
        kind = kind_of(name)
        for target, line in imported_modules(source, name, is_package(path), known):
            top = target.split(".")[0]
            if top in PROJECT:
                if top == "lut_baker" and kind == "addon":
                    target_kind = kind_of(target)
                    if target_kind == "offline":
                        found.append(f"{where}:{line}: the add-on imports offline {target}")
                    continue
                resolved = max((m for m in known if target == m or target.startswith(m + ".")),
                               key=len, default=None)
                if resolved is None:
                    continue
                if resolved != name:
                    graph[name].add(resolved)
                there = layer_of(resolved)
                if kind != "offline" and kind_of(resolved) == "offline":
                    found.append(f"{where}:{line}: {name} imports offline {resolved}")
                elif here and there and here[0] == there[0]:
                    higher = there[1] > here[1]
                    same_addon = (here[0] == "makeup_skin_addon" and there[1] == here[1]
                                  and resolved != name)
                    if higher or same_addon:
                        found.append(f"{where}:{line}: {name} (layer {here[1]}) imports "
                                     f"{resolved} (layer {there[1]})")
            elif top not in stdlib and top != "__future__":
                if top not in ALLOWED_THIRD_PARTY[kind]:
                    found.append(f"{where}:{line}: {kind} module {name} imports {top}")
        if here is None and name.split(".")[0] in PROJECT:
            found.append(f"{where}: {name} is in no layer of tools/check_imports.py LAYERS")
    found = list(dict.fromkeys(found))  # one line per (place, rule), however many names
    found += [f"import cycle: {' -> '.join(cycle)}" for cycle in cycles(graph)]
    return found


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """One cycle (as a closed path) per strongly connected component of more than one module."""
    index, low, stack, on_stack, out = {}, {}, [], set(), []

    def visit(node: str) -> None:  # Tarjan's algorithm
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for nxt in sorted(graph.get(node, ())):
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in on_stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                out.append(sorted(component) + [sorted(component)[0]])

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", type=Path, default=REPO, help="the tree to check")
    root = parser.parse_args(argv).root.resolve()
    found = problems(collect(root, [p for p in PROJECT if (root / p).is_dir()]), root)
    for line in found:
        print(line)
    print(f"import contract: {len(found)} problem(s)" if found else "import contract: kept")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
