"""Errors are exceptions with the program's messages, and with their parts as attributes."""

from __future__ import annotations

import os
import shutil
import sys

import numpy as np
import pytest

import foton
from conftest import ROOT, SCENES, TINY, run_program

BOX = SCENES / "cornell-box.toml"


def program_error(program, *args) -> str:
    """The message the program prints after `error: `."""
    out = run_program(program, *args, check=False)
    assert out.returncode == 1, out.stderr
    line = next(l for l in out.stderr.splitlines() if l.startswith("error: "))
    return out.stderr[out.stderr.index(line) + len("error: "):].rstrip("\n")


def test_scene_error_from_the_file(program, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(BOX.read_text().replace("spp = 64", "spp = -4"))
    with pytest.raises(foton.SceneError) as e:
        foton.load(bad)
    err = e.value
    assert (err.file, err.key) == (str(bad), "render.spp")
    lines = bad.read_text().splitlines()
    assert lines[err.line - 1].startswith("spp = -4")
    assert err.column == 7
    assert "non-negative integer" in err.reason
    assert str(err) == f"{bad}:{err.line}:7: `render.spp`: {err.reason}"
    assert str(err) == program_error(program, "check", bad)
    assert isinstance(err, foton.FotonError)


def test_scene_error_from_an_integrator_parameter(program):
    with pytest.raises(foton.SceneError) as e:
        foton.load(SCENES / "caustics-area.toml", **{"render.integrator": "photon", "integrators.photon.k": 1})
    assert e.value.key == "integrators.photon.k"
    assert e.value.line is None and e.value.column is None
    assert str(e.value) == program_error(
        program, "check", SCENES / "caustics-area.toml", "--integrator", "photon",
        "--set", "integrators.photon.k=1",
    )


def test_syntax_error(tmp_path):
    with pytest.raises(foton.SceneError) as e:
        foton.loads("[render]\nspp = = 3\n", tmp_path)
    assert e.value.key is None
    assert e.value.line == 2
    assert e.value.file == str(tmp_path / "<string>")
    assert "TOML syntax error" in str(e.value)


def test_plugin_not_found(program):
    with pytest.raises(foton.PluginError) as e:
        foton.load(BOX, **TINY).render(integrator="no-such-integrator")
    assert e.value.file is None
    assert "no integrator plugin named `no-such-integrator`" in str(e.value)
    assert "available: " in str(e.value) and "path" in str(e.value)
    # The same message, but for the folders searched (the program's and the package's).
    message = program_error(program, "render", BOX, "--integrator", "no-such-integrator")
    assert str(e.value).splitlines()[0] == message.splitlines()[0]
    assert str(foton.PLUGIN_DIR) in str(e.value).splitlines()[1]


def test_integrator_named_by_the_scene_file_is_a_scene_error(tmp_path):
    bad = tmp_path / "s.toml"
    bad.write_text(BOX.read_text().replace('integrator = "path"', 'integrator = "nope"'))
    with pytest.raises(foton.SceneError) as e:
        foton.load(bad)
    assert e.value.key == "render.integrator"
    assert e.value.line == 7


def fixture_plugin(tmp_path):
    """The panicking test plugin of tests/fixtures/panicky, built by `cargo test --workspace`
    with the same profile as the package, as libfoton_panicky.so in a folder of its own."""
    build = foton.build_info()["build_id"]
    profile = "debug" if build.endswith("debug-assertions") else "release"
    lib = ROOT / "target" / profile / "deps" / "libpanicky_fixture.so"
    skip = pytest.fail if os.environ.get("CI") else pytest.skip
    if not lib.is_file():
        skip(f"{lib} is not built (cargo test --workspace builds it)")
    shutil.copy(lib, tmp_path / "libfoton_panicky.so")
    found = foton.plugins([tmp_path])
    if not any(p.name == "panicky" for p in found):
        skip(f"the fixture plugin is not usable (built from other sources?): {found.skipped}")
    return tmp_path / "libfoton_panicky.so"


def test_plugin_error_names_the_plugin_file(tmp_path, capfd):
    plugin = fixture_plugin(tmp_path)
    scene = foton.load(BOX, plugin_dirs=[tmp_path], **TINY)
    with pytest.raises(foton.PluginError) as e:
        scene.render(integrator="panicky")
    assert e.value.file == str(plugin)
    assert "panicked in render" in str(e.value)
    assert "deliberate panic in render (test fixture)" in e.value.reason
    with pytest.raises(foton.PluginError, match="panicked in create"):
        foton.load(BOX, plugin_dirs=[tmp_path], **{"render.integrator": "panicky",
                                                   "integrators.panicky.panic_in": "create"})
    # The process is fine after a plugin's panic.
    assert foton.load(BOX, **TINY).render(spp=1, progress=False).any()


def test_file_errors():
    with pytest.raises(foton.FileError) as e:
        foton.load(SCENES / "no-such-scene.toml")
    assert isinstance(e.value, OSError)
    assert e.value.path == str(SCENES / "no-such-scene.toml")
    with pytest.raises(foton.FileError, match="unsupported output format"):
        foton.write(np.zeros((2, 2, 3)), "x.bmp")


def test_render_errors_are_catchable_as_foton_error():
    for cls in (foton.SceneError, foton.PluginError, foton.FileError, foton.UsageError, foton.RenderError):
        assert issubclass(cls, foton.FotonError)
    assert issubclass(foton.UsageError, ValueError)
    assert sys.modules["foton._errors"].FotonError is foton.FotonError
