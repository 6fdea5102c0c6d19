"""The tests' own layout: test folders mirror the packages without ``__init__.py`` (pytest runs
with ``--import-mode=importlib``), and none of them can shadow the packages they test."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TESTS = ROOT / "tests"


def test_packages_come_from_the_repository_root():
    """``tests`` is on ``sys.path`` (for ``support``), and it holds folders named like the
    packages: without an ``__init__.py`` they are namespace portions, which a package found on
    ``sys.path`` always beats.  (Located, not imported: the add-on imports bpy, which only the
    fixtures of tests/conftest.py may do.)"""
    for name in ("lut_baker", "makeup_skin_addon"):
        spec = importlib.util.find_spec(name)
        assert Path(spec.origin).resolve() == ROOT / name / "__init__.py", spec


def test_only_the_helper_package_has_an_init():
    inits = sorted(p.relative_to(TESTS).as_posix() for p in TESTS.rglob("__init__.py"))
    assert inits == ["support/__init__.py"]
    assert not (TESTS / "lut_baker.py").exists() and not (TESTS / "makeup_skin_addon.py").exists()
