"""The built extension zip, installed with Blender's own operator: Apply from the installed
add-on renders made-up skin, and uninstalling leaves nothing registered.

Builds the zip with tools/build_extension.py and installs it into a temporary USER repository
(``BLENDER_USER_RESOURCES`` is a temporary folder, see conftest.py).  A script that installs and
enables it and never disables it ends cleanly (its own process).
"""

import contextlib
import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest
from support import sphere_scene
from support.process_exit import bpy_importable, run_to_exit

REPO_ROOT = Path(__file__).resolve().parent.parent
pytestmark = pytest.mark.bpy
REPO_MODULE = "makeup_skin_apply_repo"


def _build_extension():
    spec = importlib.util.spec_from_file_location(
        "build_extension", REPO_ROOT / "tools" / "build_extension.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def installed(bpy_factory, tmp_path_factory):
    """The add-on installed from its zip and enabled; uninstalled afterwards."""
    build = _build_extension()
    try:
        build.find_extension_tool()
    except build.BuildError as error:  # pragma: no cover - the venvs ship the tool
        pytest.skip(str(error))
    zip_path = build.build(REPO_ROOT, tmp_path_factory.mktemp("dist"))
    bpy = bpy_factory
    prefs = bpy.context.preferences
    repo_dir = tmp_path_factory.mktemp("repo")
    prefs.extensions.repos.new(name="Made-up Skin apply test", module=REPO_MODULE,
                               custom_directory=str(repo_dir), source="USER")
    pkg_id = build.manifest(REPO_ROOT)["id"]
    module = f"bl_ext.{REPO_MODULE}.{pkg_id}"
    result = bpy.ops.extensions.package_install_files(filepath=str(zip_path), repo=REPO_MODULE,
                                                       enable_on_install=True)
    assert result == {"FINISHED"}
    try:
        yield {"module": module, "pkg_id": pkg_id, "repo_dir": repo_dir}
    finally:
        import addon_utils

        repo_index = next(i for i, repo in enumerate(prefs.extensions.repos)
                          if repo.module == REPO_MODULE)
        with contextlib.suppress(RuntimeError):
            if module in prefs.addons:
                addon_utils.disable(module, default_set=True)
        with contextlib.suppress(RuntimeError):
            bpy.ops.extensions.package_uninstall(repo_index=repo_index, pkg_id=pkg_id)
        prefs.extensions.repos.remove(prefs.extensions.repos[repo_index])


@pytest.mark.slow  # renders
def test_apply_from_the_installed_extension(installed, tmp_path):
    import bpy

    assert installed["module"] in bpy.context.preferences.addons
    assert installed["module"] + ".makeup_skin_addon" in sys.modules
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)  # keeps it enabled
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=0.03)
    obj = bpy.context.active_object
    obj.data.materials.append(bpy.data.materials.new("Skin"))
    settings = obj.active_material.makeup_skin
    settings.foundation = "medium_beige"
    settings.tier = "LAYERED"
    settings.resolution = "preview"
    assert bpy.ops.makeup_skin.apply() == {"FINISHED"}
    material = obj.active_material
    group = material.node_tree.nodes["Made-up Skin"].node_tree
    assert group.name.startswith("Made-up Skin Layered")
    # The installed copy did the work: its modules live in the temporary repository.
    apply = sys.modules[installed["module"] + ".makeup_skin_addon.apply"]
    assert Path(apply.__file__).is_relative_to(installed["repo_dir"])
    assert apply.check_material(bpy.context, material)[0]  # re-bakes to its recorded hash
    # Reduced images are kept in the extension's own user folder.
    store = sys.modules[installed["module"] + ".makeup_skin_addon.image_store"]
    assert store.directory() == Path(bpy.utils.extension_path_user(
        installed["module"], path="reduced_images"))

    sphere_scene.light_and_camera(scene, 0.03, light_deg=0.0)
    sphere_scene.cycles_settings(scene, size=32, samples=8)
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.filepath = str(tmp_path / "installed.exr")
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(scene.render.filepath)
    pixels = np.array(image.pixels[:]).reshape(32, 32, 4)[..., :3]
    assert np.all(np.isfinite(pixels))
    # A beige foundation: the centre is lit and red exceeds blue.
    centre = pixels[12:20, 12:20].reshape(-1, 3).mean(axis=0)
    assert centre.sum() > 0.3 and centre[0] > centre[2]


@pytest.mark.slow  # the install's own check (test_extension_package.py, fast) asserts the same
def test_uninstall_leaves_nothing(installed):
    import bpy

    prefs = bpy.context.preferences
    store = sys.modules[installed["module"] + ".makeup_skin_addon.image_store"]
    store.save("entry", np.zeros((2, 2, 3), np.float32), "")  # a reduced image kept
    kept = store.directory()
    assert (kept / "entry.npz").is_file()
    repo_index = next(i for i, repo in enumerate(prefs.extensions.repos)
                      if repo.module == REPO_MODULE)
    assert bpy.ops.extensions.package_uninstall(repo_index=repo_index,
                                                pkg_id=installed["pkg_id"]) == {"FINISHED"}
    assert not kept.exists()  # the extension's user folder goes with it
    assert installed["module"] not in prefs.addons
    assert not hasattr(bpy.types.Material, "makeup_skin")
    assert [n for n in dir(bpy.types) if n.startswith(("MAKEUPSKIN", "MAKEUP_SKIN"))] == []
    assert not [m for m in sys.modules if m.startswith(installed["module"])]
    assert not (installed["repo_dir"] / installed["pkg_id"]).exists()


INSTALL_AND_EXIT = """
    import sys

    import bpy

    zip_path, repo_dir = sys.argv[1:]
    bpy.context.preferences.extensions.repos.new(
        name="Made-up Skin exit test", module="makeup_skin_exit_repo",
        custom_directory=repo_dir, source="USER")
    assert bpy.ops.extensions.package_install_files(
        filepath=zip_path, repo="makeup_skin_exit_repo", enable_on_install=True) == {"FINISHED"}
    assert hasattr(bpy.types.Material, "makeup_skin")
    print("installed, never disabled")
"""


def test_a_script_that_installs_and_never_disables_ends(tmp_path):
    """Enabled as an extension, the add-on is unregistered at exit by its own hook, and then
    Blender's exit disables it again: the process ends, exit code 0, with no error from the
    second unregister."""
    if not bpy_importable():  # pragma: no cover - CI has bpy
        pytest.skip("bpy is not importable; run with the venv from tools/venv.sh")
    build = _build_extension()
    try:
        build.find_extension_tool()
    except build.BuildError as error:  # pragma: no cover - the venvs ship the tool
        pytest.skip(str(error))
    zip_path = build.build(REPO_ROOT, tmp_path / "dist")
    done = run_to_exit(INSTALL_AND_EXIT, tmp_path / "user", str(zip_path), str(tmp_path / "repo"))
    assert done.returncode == 0, done.stderr
    assert "installed, never disabled" in done.stdout
    assert "Traceback" not in done.stderr, done.stderr
