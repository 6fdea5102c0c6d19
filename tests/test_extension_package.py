"""The extension zip: validates, builds, installs into Blender, enables, and uninstalls cleanly.

Uses the extension tool shipped in the pip ``bpy`` through ``tools/build_extension.py`` and
installs into a temporary USER repository (``BLENDER_USER_RESOURCES`` is a temporary folder, see
``conftest.py``).
"""

import contextlib
import importlib
import importlib.util
import pkgutil
import sys
import zipfile
from pathlib import Path

import pytest
from support.addon_steps import registered_classes

pytestmark = pytest.mark.bpy

REPO_ROOT = Path(__file__).resolve().parent.parent
REPO_MODULE = "makeup_skin_test_repo"  # the temporary repository's module name


def _load_build_extension():
    spec = importlib.util.spec_from_file_location(
        "build_extension", REPO_ROOT / "tools" / "build_extension.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


build_extension = _load_build_extension()
PKG_ID = build_extension.manifest(REPO_ROOT)["id"]
ADDON_MODULE = f"bl_ext.{REPO_MODULE}.{PKG_ID}"


@pytest.fixture(scope="module")
def extension_tool():
    try:
        return build_extension.find_extension_tool()
    except build_extension.BuildError as exc:
        pytest.skip(str(exc))


@pytest.fixture(scope="module")
def extension_zip(extension_tool, tmp_path_factory):
    return build_extension.build(REPO_ROOT, tmp_path_factory.mktemp("dist"))


def test_the_oldest_blender_allowed_is_the_oldest_tested():
    """The manifest's ``blender_version_min`` is the oldest Blender line the tests run on
    (``requirements/bpy<line>.txt``, tools/test.sh): an older one is not known to work."""
    lines = []
    for path in (REPO_ROOT / "requirements").glob("bpy*.txt"):
        pins = [line for line in path.read_text().splitlines() if line.startswith("bpy==")]
        lines.append(tuple(int(part) for part in pins[0].removeprefix("bpy==").split(".")[:2]))
    minimum = build_extension.manifest(REPO_ROOT)["blender_version_min"]
    assert tuple(int(part) for part in minimum.split(".")[:2]) == min(lines), (minimum, lines)


def test_manifest_validates(extension_tool):
    output = build_extension.validate(REPO_ROOT)
    assert "Success" in output


def test_zip_contents(extension_zip):
    assert extension_zip.name == f"{PKG_ID}-0.1.0.zip"
    assert build_extension.check_zip(extension_zip, REPO_ROOT) == []
    names = zipfile.ZipFile(extension_zip).namelist()
    assert "makeup_skin_addon/convert.py" in names
    assert "lut_baker/__init__.py" in names
    assert "lut_baker/closures/fitting.py" in names
    # the runtime's data files: the Auto tier's measurements, the table of EEVEE's GGX, the
    # Principled BSDF's measured albedo
    assert {"lut_baker/auto_tier/measured.json", "lut_baker/closures/eevee_ltc.json",
            "lut_baker/closures/principled_albedo.json"} <= set(names)
    assert not [n for n in names if n.startswith("tests/") or "/tests/" in n]
    assert not [n for n in names if n.startswith("data/")]  # published measurements stay out
    # the runtime only: no scipy-backed validation, no command line
    assert not [n for n in names if n.startswith(("lut_baker/offline/", "lut_baker/__main__"))]


def _repo_index(bpy, module):
    repos = bpy.context.preferences.extensions.repos
    return next(i for i, repo in enumerate(repos) if repo.module == module)


@contextlib.contextmanager
def _without_repo_on_path():
    """Hide the source tree's ``lut_baker``, so only the installed copy can be imported: the
    checkout's root leaves ``sys.path``, and so does ``tests`` (pytest's ``pythonpath``), whose
    folder of tests named ``lut_baker`` would otherwise import as an empty namespace package."""
    saved_path = sys.path[:]
    saved_modules = {
        k: v for k, v in sys.modules.items() if k == "lut_baker" or k.startswith("lut_baker.")
    }
    hidden = {REPO_ROOT, REPO_ROOT / "tests"}
    sys.path[:] = [p for p in sys.path if Path(p or ".").resolve() not in hidden]
    for name in saved_modules:
        del sys.modules[name]
    try:
        yield
    finally:
        sys.path[:] = saved_path
        for name in [k for k in sys.modules if k == "lut_baker" or k.startswith("lut_baker.")]:
            del sys.modules[name]
        sys.modules.update(saved_modules)


def _import_installed_lut_baker():
    """Import every module of the installed ``lut_baker``; absolute self-imports fail here."""
    with _without_repo_on_path():
        package = importlib.import_module(f"{ADDON_MODULE}.lut_baker")
        for info in pkgutil.walk_packages(package.__path__, prefix=package.__name__ + "."):
            leaf = info.name.rpartition(".")[2]
            if leaf == "__main__" or leaf == "tests" or ".tests." in info.name:
                continue
            importlib.import_module(info.name)
        leaked = [k for k in sys.modules if k == "lut_baker" or k.startswith("lut_baker.")]
    assert not leaked, f"installed lut_baker imported the top-level package: {leaked}"
    return package


def test_install_enable_uninstall(bpy_factory, extension_zip, tmp_path):
    import addon_utils

    bpy = bpy_factory
    prefs = bpy.context.preferences
    repo_dir = tmp_path / "repo"
    repo_dir.mkdir()
    prefs.extensions.repos.new(
        name="Made-up Skin test",
        module=REPO_MODULE,
        custom_directory=str(repo_dir),
        source="USER",
    )
    try:
        result = bpy.ops.extensions.package_install_files(
            filepath=str(extension_zip), repo=REPO_MODULE, enable_on_install=True
        )
        assert result == {"FINISHED"}
        assert (repo_dir / PKG_ID / "blender_manifest.toml").is_file()
        assert (repo_dir / PKG_ID / "lut_baker" / "__init__.py").is_file()

        # Enabled under the root package name, its operators registered; no preferences.
        assert ADDON_MODULE in prefs.addons
        assert addon_utils.check(ADDON_MODULE) == (True, True)
        registered = registered_classes(ADDON_MODULE)
        assert "MAKEUPSKIN_OT_apply" in [c.__name__ for c in registered]
        assert not [c for c in registered if issubclass(c, bpy.types.AddonPreferences)]

        # The bundled lut_baker imports itself relatively (it is bl_ext.<repo>.<id>.lut_baker).
        lut_baker = _import_installed_lut_baker()
        assert Path(lut_baker.__file__).is_relative_to(repo_dir)

        result = bpy.ops.extensions.package_uninstall(
            repo_index=_repo_index(bpy, REPO_MODULE), pkg_id=PKG_ID
        )
        assert result == {"FINISHED"}

        assert ADDON_MODULE not in prefs.addons
        assert not [a.module for a in prefs.addons if a.module.startswith(ADDON_MODULE)]
        assert registered_classes(ADDON_MODULE) == []
        assert not hasattr(bpy.types.Material, "makeup_skin")  # its property went too
        assert [n for n in dir(bpy.types) if n.startswith(("MAKEUPSKIN", "MAKEUP_SKIN"))] == []
        assert not [m for m in sys.modules if m == ADDON_MODULE or m.startswith(ADDON_MODULE + ".")]
        assert not (repo_dir / PKG_ID).exists()
    finally:
        with contextlib.suppress(StopIteration, RuntimeError):
            if ADDON_MODULE in prefs.addons:
                addon_utils.disable(ADDON_MODULE, default_set=True)
            prefs.extensions.repos.remove(prefs.extensions.repos[_repo_index(bpy, REPO_MODULE)])
