"""Shared fixtures: the repository's scenes at tiny sizes, and the `foton` program built with the
same build identifier as the installed package (to compare images with it bit for bit).

The program is FOTON_EXE, or else target/debug/foton or target/release/foton of this
repository, whichever has the package's build identifier. Without one, the tests that need it
are skipped, except under CI (CI=true), where they fail.
"""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import pytest

import foton

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "scenes"

# Small enough that each render takes a few milliseconds.
TINY = {
    "film.width": 40,
    "film.height": 30,
    "integrators.photon.global_photons": 3000,
    "integrators.photon.caustic_photons": 3000,
    "integrators.sppm.photons_per_iteration": 3000,
    "integrators.sppm.iterations": 2,
}


def as_sets(overrides: dict) -> list[str]:
    """The program's --set arguments for a dict of overrides (the package's own conversion)."""
    args = []
    for s in foton._overrides(overrides):
        args += ["--set", s]
    return args


def program_build_id(exe: Path) -> str | None:
    try:
        out = subprocess.run([str(exe), "plugins"], capture_output=True, text=True, timeout=60)
    except OSError:
        return None
    m = re.search(r", build (\S+)", out.stdout)
    return m.group(1) if m else None


def _find_program() -> Path | None:
    want = foton.build_info()["build_id"]
    if os.environ.get("FOTON_EXE"):
        exe = Path(os.environ["FOTON_EXE"])
        got = program_build_id(exe)
        if got != want:
            pytest.fail(f"FOTON_EXE={exe} has build {got}, the package {want}")
        return exe
    for profile in ("debug", "release"):
        exe = ROOT / "target" / profile / "foton"
        if exe.is_file() and program_build_id(exe) == want:
            return exe
    return None


@pytest.fixture(scope="session")
def program() -> Path:
    exe = _find_program()
    if exe is None:
        message = (
            "no foton program with the package's build identifier "
            f"({foton.build_info()['build_id']}): set FOTON_EXE, or build it with the "
            "package's profile"
        )
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip(message)
    return exe


def run_program(exe: Path, *args: str, check: bool = True) -> subprocess.CompletedProcess:
    """Runs the program with the package's plugin folder on its search path."""
    env = dict(os.environ, FOTON_PLUGIN_PATH=str(foton.PLUGIN_DIR))
    out = subprocess.run(
        [str(exe), *map(str, args)], capture_output=True, text=True, env=env, timeout=300
    )
    if check and out.returncode != 0:
        raise AssertionError(f"foton {' '.join(map(str, args))}: {out.returncode}\n{out.stderr}")
    return out
