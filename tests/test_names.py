"""One spelling in lut_baker's and the add-on's identifiers: "colour", as the project writes
it; the names that transcribe a Blender socket keep Blender's "Color", so that the socket can be
found (the Principled BSDF's Base Color, the node group's Skin Color), as the interface does
(docs/architecture.md), and so do Blender's own attributes and node types the add-on names.
Other libraries' own names (matplotlib's ``color=``) are theirs."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BLENDER_SOCKETS = {"base_color", "base_color_for_body", "skin_color"}
"""Identifiers that name a Blender socket: Base Color, Skin Color."""
BLENDER_API = {"color", "color_mode", "node_separate_color", "node_combine_color",
               "node_vertex_color"}
"""Identifiers that are Blender's: attributes the add-on sets on Blender's data (a colour
ramp's ``color_mode``, its elements' ``color``) and the handlers named after the node types
they evaluate (``SEPARATE_COLOR``, ``COMBINE_COLOR``, ``VERTEX_COLOR``)."""


def _defined_names(tree: ast.AST) -> set[str]:
    """The names a module defines: functions, classes, parameters, assigned variables and
    attributes (not the names it calls or the keywords it passes to other libraries)."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.arg):
            names.add(node.arg)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
            names.add(node.attr)
    return names


def test_lut_baker_spells_colour_but_for_blender_sockets():
    american = {f"{path.relative_to(ROOT)}: {name}"
                for path in sorted((ROOT / "lut_baker").rglob("*.py"))
                for name in _defined_names(ast.parse(path.read_text()))
                if "color" in name.lower() and name not in BLENDER_SOCKETS}
    assert not american, f"spell them 'colour': {sorted(american)}"


def test_the_addon_spells_colour_but_for_blenders_names():
    american = {f"{path.relative_to(ROOT)}: {name}"
                for path in sorted((ROOT / "makeup_skin_addon").rglob("*.py"))
                for name in _defined_names(ast.parse(path.read_text()))
                if "color" in name.lower() and name not in BLENDER_SOCKETS | BLENDER_API}
    assert not american, f"spell them 'colour': {sorted(american)}"


def test_the_check_sees_definitions():
    tree = ast.parse("def skin_colour(color, c=1):\n    tint_color = c\n    self.hue_color = 2\n"
                     "plot(color='red')\n")
    assert {"skin_colour", "color", "tint_color", "hue_color"} <= _defined_names(tree)
    assert "red" not in _defined_names(tree)
