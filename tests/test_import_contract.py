"""The import contract (tools/check_imports.py): this tree keeps it, and each rule catches the
break it names, in a small tree written for the purpose."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
CHECKER = ROOT / "tools" / "check_imports.py"


def check(root: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(CHECKER), "--root", str(root)],
                          capture_output=True, text=True, timeout=60)


def test_this_tree_keeps_the_contract():
    result = check(ROOT)
    assert result.returncode == 0, result.stdout


def write_tree(root: Path, files: dict[str, str]) -> Path:
    for name, source in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(source)
    for package in {p.parent for p in root.rglob("*.py")}:
        (package / "__init__.py").touch()
    return root


BREAKS = {
    "scipy inside a runtime function": (
        {"lut_baker/bake.py": "def f():\n    import scipy.optimize\n"},
        "runtime module lut_baker.bake imports scipy"),
    "the runtime reaching offline": (
        {"lut_baker/bake.py": "from .offline.validation import compare\n",
         "lut_baker/offline/validation/compare.py": ""},
        "lut_baker.bake imports offline lut_baker.offline.validation.compare"),
    "a lower layer importing a higher one": (
        {"lut_baker/model/presets.py": "from ..bake import bake\n", "lut_baker/bake.py": ""},
        "lut_baker.model.presets (layer 1) imports lut_baker.bake (layer 4)"),
    "the add-on reaching offline": (
        {"makeup_skin_addon/core.py": "from ..lut_baker.offline.cli import main\n",
         "lut_baker/offline/cli/main.py": ""},
        "the add-on imports offline lut_baker.offline.cli.main"),
    "two add-on modules importing each other in functions": (
        {"makeup_skin_addon/live.py": "def f():\n    from . import apply\n",
         "makeup_skin_addon/apply.py": "def g():\n    from . import live\n"},
        "import cycle: makeup_skin_addon.apply -> makeup_skin_addon.live"),
    "a module outside every layer": (
        {"makeup_skin_addon/helpers.py": ""},
        "makeup_skin_addon.helpers is in no layer"),
}


@pytest.mark.parametrize("name", list(BREAKS))
def test_each_rule_catches_its_break(tmp_path, name):
    files, expected = BREAKS[name]
    result = check(write_tree(tmp_path, files))
    assert result.returncode == 1
    assert expected in result.stdout, result.stdout
