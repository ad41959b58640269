"""PEP 517 backend of the foton Python package: maturin, with the integrator plugins packaged.

maturin builds and packs only the extension module (``foton._foton``). The integrator plugins
are cdylibs of their own, which the extension loads at run time, and a plugin is loaded only
if it was built with the same foton-core, rustc and layout settings (debug assertions among
them) as the extension: its build identifier must be the extension's (docs/plugins.md).

So the extension's crate (python/Cargo.toml) depends on the plugin crates: the cargo command
maturin runs builds their cdylibs too, with the same profile, features and settings, into
``target/PROFILE/deps/``. This backend runs maturin once to build, copies those libraries into
``foton/plugins/``, and runs maturin again, which finds everything built and packs the wheel
with them.

The cargo profile is ``release`` unless chosen by the config setting ``profile``
(``pip install ./python --config-settings=profile=dev``) or the environment variable
``FOTON_PYTHON_PROFILE``. CI uses ``release``, whose artifacts ``cargo build --release`` and
``cargo test --release --workspace`` have already built. The libraries in the wheel are
stripped of their debug info (maturin's --strip for the extension, unless the build args say
otherwise; `strip --strip-debug` for the plugins).

Wheels are built from the repository (``pip install ./python``, ``pip wheel ./python``); there
is no sdist, since the plugins are built from the workspace around this folder.
"""

from __future__ import annotations

import json
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any, Mapping

import maturin

HERE = Path(__file__).resolve().parent.parent  # python/
PLUGIN_CRATES = ["foton-path", "foton-photon", "foton-sppm", "foton-vpm", "foton-ppb", "foton-bdpt", "foton-vcm", "foton-normals", "foton-ao"]
PLUGIN_DIR = HERE / "foton" / "plugins"

# maturin's backend runs the `maturin` command: in a virtual environment that is not activated
# (venv/bin/pip install --no-build-isolation ...), it is beside the interpreter.
if shutil.which("maturin") is None:
    os.environ["PATH"] = os.path.dirname(sys.executable) + os.pathsep + os.environ.get("PATH", "")


def _log(message: str) -> None:
    print(f"foton_build: {message}", file=sys.stderr, flush=True)


def _profile(config_settings: Mapping[str, Any] | None) -> str:
    profile = (config_settings or {}).get("profile") or os.environ.get("FOTON_PYTHON_PROFILE")
    return str(profile or "release")


def _maturin_settings(config_settings: Mapping[str, Any] | None, profile: str) -> dict[str, Any]:
    """The config settings for maturin: ours removed, ``--profile`` added to its build args."""
    settings = {k: v for k, v in (config_settings or {}).items() if k != "profile"}
    key = "maturin.build-args" if "maturin.build-args" in settings else "build-args"
    args = settings.get(key)
    if args is None:
        args = os.environ.get("MATURIN_PEP517_ARGS", "")
    if isinstance(args, str):
        args = shlex.split(args)
    args = list(args)
    strip = [] if any(a.startswith("--strip") for a in args) else ["--strip"]
    settings[key] = ["--profile", profile, *strip, *args]
    return settings


def _target_dir() -> Path:
    cargo = os.environ.get("CARGO", "cargo")
    metadata = subprocess.run(
        [cargo, "metadata", "--no-deps", "--format-version", "1",
         "--manifest-path", str(HERE / "Cargo.toml")],
        check=True,
        stdout=subprocess.PIPE,
    )
    return Path(json.loads(metadata.stdout)["target_directory"])


def _copy_plugins(profile: str) -> None:
    deps = _target_dir() / ("debug" if profile == "dev" else profile) / "deps"
    prefix, suffix = {"win32": ("", ".dll"), "darwin": ("lib", ".dylib")}.get(
        sys.platform, ("lib", ".so")
    )
    PLUGIN_DIR.mkdir(parents=True, exist_ok=True)
    for old in PLUGIN_DIR.glob("*foton_*"):
        old.unlink()
    for crate in PLUGIN_CRATES:
        name = prefix + crate.replace("-", "_") + suffix
        shutil.copy2(deps / name, PLUGIN_DIR / name)
        if shutil.which("strip"):
            # Debug info only (the build identifier, a string in the library, stays): a
            # wheel of dev libraries would be about 500 MB, of release ones 30 MB.
            subprocess.run(["strip", "--strip-debug", str(PLUGIN_DIR / name)], check=True)
        _log(f"packaging {deps / name}")


def _build(
    hook: Any,
    wheel_directory: str,
    config_settings: Mapping[str, Any] | None,
    metadata_directory: str | None,
) -> str:
    profile = _profile(config_settings)
    settings = _maturin_settings(config_settings, profile)
    _log(f"building the extension and the plugins (cargo profile `{profile}`)")
    with tempfile.TemporaryDirectory() as scratch:
        hook(scratch, settings, metadata_directory)
    _copy_plugins(profile)
    _log("packing the wheel")
    return hook(wheel_directory, settings, metadata_directory)


def build_wheel(
    wheel_directory: str,
    config_settings: Mapping[str, Any] | None = None,
    metadata_directory: str | None = None,
) -> str:
    return _build(maturin.build_wheel, wheel_directory, config_settings, metadata_directory)


def build_editable(
    wheel_directory: str,
    config_settings: Mapping[str, Any] | None = None,
    metadata_directory: str | None = None,
) -> str:
    return _build(maturin.build_editable, wheel_directory, config_settings, metadata_directory)


def build_sdist(sdist_directory: str, config_settings: Mapping[str, Any] | None = None) -> str:
    raise RuntimeError(
        "foton's Python package is built from the repository (pip install ./python): "
        "its plugins are built from the workspace around python/, which an sdist would not have"
    )


get_requires_for_build_wheel = maturin.get_requires_for_build_wheel
get_requires_for_build_editable = maturin.get_requires_for_build_editable
prepare_metadata_for_build_wheel = maturin.prepare_metadata_for_build_wheel
prepare_metadata_for_build_editable = maturin.prepare_metadata_for_build_editable
