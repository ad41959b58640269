"""`foton compare --reference`'s `flip` (mean LDR-FLIP, core/cli/src/compare/flip.rs) against
NVIDIA's own implementation, flip_evaluator (`pip install flip-evaluator`), on the same two sRGB
images: the render and the reference, both through the scene's exposure and tone map and the
sRGB curve, in [0, 1] (the montage's PNG values before 8-bit quantisation)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import foton
from conftest import SCENES, TINY, as_sets, run_program

flip_evaluator = pytest.importorskip("flip_evaluator")

# The tolerance between the program's mean and flip_evaluator's.
TOLERANCE = 0.002


def filmic(x: np.ndarray) -> np.ndarray:
    """foton_core::film::filmic (Narkowicz's ACES fit), in float32 as the program computes it."""
    x = np.maximum(x, np.float32(0))
    a, b, c, d, e = (np.float32(v) for v in (2.51, 0.03, 2.43, 0.59, 0.14))
    with np.errstate(invalid="ignore", over="ignore"):
        y = (x * (a * x + b)) / (x * (c * x + d) + e)
    y = np.where(np.isinf(x), np.float32(1), y)
    return np.minimum(y, np.float32(1))


def to_srgb(linear: np.ndarray, exposure: float, tonemap: str) -> np.ndarray:
    """DisplayTransform::map then srgb_encode (core/src/film.rs): linear radiance times
    2^exposure, tone mapped into [0, 1] (NaN -> 0), then the sRGB curve; float32."""
    x = np.nan_to_num(linear.astype(np.float32), nan=0.0, posinf=np.inf) * np.float32(2.0**exposure)
    x = np.maximum(x, np.float32(0))
    x = np.minimum(x, np.float32(1)) if tonemap == "clamp" else filmic(x)
    x = np.clip(x, 0, 1).astype(np.float32)
    return np.where(
        x <= np.float32(0.0031308),
        np.float32(12.92) * x,
        np.float32(1.055) * np.power(x, np.float32(1 / 2.4)) - np.float32(0.055),
    ).astype(np.float32)


@pytest.mark.parametrize(
    "display",
    [{}, {"film.exposure": 0.5, "film.tonemap": "filmic"}],
    ids=["clamp", "filmic"],
)
def test_compare_flip_equals_flip_evaluator(program, tmp_path, display):
    scene = SCENES / "cornell-box.toml"
    sets = as_sets({**TINY, **display})
    reference = tmp_path / "ref.exr"
    run_program(program, "render", scene, "--spp", 16, "-q", "-o", reference, *sets)
    out = tmp_path / "cmp.png"
    run_program(
        program, "compare", scene, "--integrators", "path,photon", "--spp", 2, "--seed", 3,
        "--reference", reference, "-o", out, "-q", *sets,
    )
    result = json.loads((tmp_path / "cmp.json").read_text())
    exposure = display.get("film.exposure", 0.0)
    tonemap = display.get("film.tonemap", "clamp")
    ref_srgb = to_srgb(foton.read(reference), exposure, tonemap)
    assert [e["name"] for e in result["integrators"]] == ["path", "photon"]
    for entry in result["integrators"]:
        ours = entry["flip"]
        assert isinstance(ours, float) and 0.0 < ours <= 1.0, entry
        render = foton.read(tmp_path / entry["image"])
        test_srgb = to_srgb(render, exposure, tonemap)
        _, theirs, _ = flip_evaluator.evaluate(ref_srgb, test_srgb, "LDR")
        assert abs(ours - theirs) <= TOLERANCE, (entry["name"], ours, theirs)
        print(f"{entry['name']} ({tonemap}): foton {ours:.6f}, flip_evaluator {theirs:.6f}")


def test_identical_to_the_reference_gives_zero(program, tmp_path):
    scene = SCENES / "cornell-box.toml"
    sets = as_sets(TINY)
    reference = tmp_path / "ref.exr"
    run_program(
        program, "render", scene, "--integrator", "path", "--spp", 2, "--seed", 3, "-q",
        "-o", reference, *sets,
    )
    out = tmp_path / "same.png"
    run_program(
        program, "compare", scene, "--integrators", "path", "--spp", 2, "--seed", 3,
        "--reference", reference, "-o", out, "-q", *sets,
    )
    result = json.loads((tmp_path / "same.json").read_text())
    assert result["integrators"][0]["flip"] == 0
