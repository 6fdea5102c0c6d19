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


def _modules(package: str) -> list[str]:
    """Every module of ``package`` as a path relative to it (``model/layers.py``), packages'
    ``__init__.py`` and the ``__main__`` entry point left out."""
    return sorted(p.relative_to(ROOT / package).as_posix() for p in (ROOT / package).rglob("*.py")
                  if p.name not in ("__init__.py", "__main__.py") and "__pycache__" not in p.parts)


def test_every_module_has_its_line_in_the_architecture_page():
    """docs/architecture.md lists each module with what it holds: a new module needs its line."""
    page = (ROOT / "docs" / "architecture.md").read_text()
    missing = [f"{package}/{module}" for package in ("lut_baker", "makeup_skin_addon")
               for module in _modules(package) if f"`{module}`" not in page]
    assert not missing, f"not in docs/architecture.md: {missing}"


def test_every_module_has_a_test_module():
    """Tests mirror the packages: ``lut_baker/model/layers.py`` is tested by
    ``tests/lut_baker/model/test_layers.py`` (the add-on's modules without bpy state, package
    and keys, are exercised through every add-on test)."""
    untested = [f"{package}/{module}" for package in ("lut_baker", "makeup_skin_addon")
                for module in _modules(package)
                if not (TESTS / package / Path(module).parent
                        / f"test_{Path(module).name}").exists()
                and module not in ("package.py", "keys.py")]
    assert not untested, f"no test module mirrors: {untested}"
