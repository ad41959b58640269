"""The package's plugins, and the program's search path in front of them."""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest

import foton
from conftest import ROOT, SCENES, TINY

INTEGRATORS = {"path", "bdpt", "vcm", "photon", "sppm", "vpm", "ppb", "normals", "ao"}


def test_the_package_carries_the_integrators():
    found = foton.plugins()
    ours = {p.name for p in found if p.file.parent == foton.PLUGIN_DIR}
    assert ours == INTEGRATORS
    assert all(p.kind == "integrator" for p in found if p.name in INTEGRATORS)
    assert not [s for s in found.skipped if s[0].parent == foton.PLUGIN_DIR], found.skipped
    # The package's folder comes last, after the program's search path.
    assert found.search_path[-1] == foton.PLUGIN_DIR


def test_plugin_dirs_and_the_environment_come_first(tmp_path, monkeypatch):
    first, second = tmp_path / "first", tmp_path / "second"
    first.mkdir()
    second.mkdir()
    shutil.copy(foton.PLUGIN_DIR / "libfoton_normals.so", first)
    shutil.copy(foton.PLUGIN_DIR / "libfoton_path.so", second)
    monkeypatch.setenv("FOTON_PLUGIN_PATH", str(second))
    found = {p.name: p.file for p in foton.plugins([first])}
    assert found["normals"] == first / "libfoton_normals.so"
    assert found["path"] == second / "libfoton_path.so"
    assert found["photon"] == foton.PLUGIN_DIR / "libfoton_photon.so"
    search = foton.plugins([first]).search_path
    assert search.index(first) < search.index(second) < search.index(foton.PLUGIN_DIR)


def test_a_file_that_is_no_plugin_is_skipped_with_the_reason(tmp_path):
    (tmp_path / "libfoton_broken.so").write_bytes(b"not a library")
    found = foton.plugins([tmp_path])
    assert [(f.name, "cannot be loaded" in m) for f, m in found.skipped] == [("libfoton_broken.so", True)]
    with pytest.raises(foton.PluginError) as e:
        foton.load(SCENES / "cornell-box.toml", plugin_dirs=[tmp_path], **TINY).render(integrator="broken")
    assert "libfoton_broken.so: cannot be loaded" in str(e.value)


@pytest.fixture
def kernel_plugin(tmp_path):
    """The example C kernel plugin (plugins/epanechnikov), compiled into a folder of its own."""
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler")
    src = ROOT / "plugins"
    lib = tmp_path / "libfoton_epanechnikov.so"
    subprocess.run([cc, "-shared", "-fPIC", "-O2", f"-I{src}", "-o", str(lib),
                    str(src / "epanechnikov" / "epanechnikov.c")], check=True)
    return tmp_path


def test_a_third_party_kernel_plugin(kernel_plugin, monkeypatch):
    found = foton.plugins([kernel_plugin])
    assert ("epanechnikov", "kernel") in {(p.name, p.kind) for p in found}
    scene_file = SCENES / "caustics-area.toml"
    sets = dict(TINY, **{"render.integrator": "photon"})
    box = foton.load(scene_file, **sets).render(spp=1, progress=False)
    scene = foton.load(scene_file, plugin_dirs=[kernel_plugin], **sets)
    image = scene.render(spp=1, params={"kernel": "epanechnikov"}, progress=False)
    assert "kernel = epanechnikov" in scene.last_render["integrator"]
    assert image.any() and not np.array_equal(image, box)
    # Through FOTON_PLUGIN_PATH too, and unknown without it.
    monkeypatch.setenv("FOTON_PLUGIN_PATH", str(kernel_plugin))
    again = foton.load(scene_file, **sets).render(spp=1, params={"kernel": "epanechnikov"}, progress=False)
    assert np.array_equal(again, image)
    monkeypatch.delenv("FOTON_PLUGIN_PATH")
    with pytest.raises(foton.SceneError) as e:
        foton.load(scene_file, **sets).render(spp=1, params={"kernel": "epanechnikov"})
    assert e.value.key == "integrators.photon.kernel"


def test_build_info():
    info = foton.build_info()
    assert info["build_id"] and info["rustc"].startswith("rustc ")
    assert info["core_version"] == foton.__version__
    assert isinstance(info["plugin_api"], int)
