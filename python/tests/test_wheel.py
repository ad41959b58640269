"""The wheel installs into a clean virtual environment and renders with no environment variables.

The wheel is FOTON_WHEEL (.ci/run builds it); without it the test is skipped, except under CI.
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import venv
from pathlib import Path

import pytest

import foton
from conftest import SCENES, TINY

SCRIPT = """
import hashlib, sys
import foton
scene = foton.load(sys.argv[1], **{tiny!r})
image = scene.render(integrator="path", spp=2, seed=1, progress=False)
print(foton.__file__)
print(sorted(p.file.name for p in foton.plugins() if p.file.parent == foton.PLUGIN_DIR))
print(hashlib.sha256(image.tobytes()).hexdigest())
"""


def test_the_wheel_renders_in_a_clean_environment(tmp_path):
    wheel = os.environ.get("FOTON_WHEEL")
    if not wheel:
        if os.environ.get("CI"):
            pytest.fail("FOTON_WHEEL is not set")
        pytest.skip("FOTON_WHEEL (a built wheel) is not set")
    env_dir = tmp_path / "venv"
    venv.EnvBuilder(with_pip=True).create(env_dir)
    python = env_dir / "bin" / "python"
    subprocess.run([str(python), "-m", "pip", "install", "-q", "--disable-pip-version-check", wheel],
                   check=True, cwd=tmp_path)
    out = subprocess.run(
        [str(python), "-c", SCRIPT.format(tiny=TINY), str(SCENES / "cornell-box.toml")],
        env={},  # no PATH, no HOME, no FOTON_PLUGIN_PATH
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr
    module, plugins, digest = out.stdout.splitlines()[-3:]
    assert Path(module).resolve().is_relative_to(env_dir.resolve())
    assert plugins == str(sorted(f"libfoton_{n}.so" for n in ("ao", "bdpt", "normals", "path", "photon", "ppb", "sppm", "vcm", "vpm")))
    # The same image as this process's foton renders.
    here = foton.load(SCENES / "cornell-box.toml", **TINY).render(
        integrator="path", spp=2, seed=1, progress=False)
    assert digest == hashlib.sha256(here.tobytes()).hexdigest()
