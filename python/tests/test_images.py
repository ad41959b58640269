"""write, read and compare: the program's files and the program's error figures."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import foton
from conftest import SCENES, TINY, as_sets, run_program


def test_exr_round_trip_is_exact(tmp_path):
    rng = np.random.default_rng(1)
    image = rng.exponential(size=(5, 7, 3)).astype(np.float32)
    image[0, 0] = [0.0, 1e-30, 65504.0 * 4]
    foton.write(image, tmp_path / "a.exr")
    back = foton.read(tmp_path / "a.exr")
    assert back.dtype == np.float32 and back.shape == (5, 7, 3)
    assert np.array_equal(back, image)


def test_write_takes_any_float_array_and_checks_its_shape(tmp_path):
    image = np.linspace(0, 1, 4 * 6 * 3).reshape(4, 6, 3)  # float64, converted
    foton.write(image[:, ::2], tmp_path / "a.exr")  # not contiguous: made so
    assert np.array_equal(foton.read(tmp_path / "a.exr"), image[:, ::2].astype(np.float32))
    with pytest.raises(ValueError, match=r"\(height, width, 3\)"):
        foton.write(np.zeros((4, 6)), tmp_path / "b.exr")
    with pytest.raises(ValueError, match="tone map"):
        foton.write(np.zeros((4, 6, 3)), tmp_path / "b.png", tonemap="aces")


def test_png_is_srgb_through_exposure_and_tonemap(tmp_path):
    image = np.array([[[0.0, 0.5, 1.0], [2.0, 0.214, 0.0031308]]], dtype=np.float32)
    foton.write(image, tmp_path / "a.png")
    back = foton.read(tmp_path / "a.png")
    # 8-bit sRGB of the clamped values, decoded: within half a step of 8-bit sRGB.
    expected = np.minimum(image, 1.0)
    assert np.allclose(back, expected, atol=0.004)
    assert back[0, 1, 0] == 1.0  # 2.0 clamps to white
    foton.write(image, tmp_path / "dark.png", exposure=-1.0)
    assert np.allclose(foton.read(tmp_path / "dark.png")[0, 0], [0.0, 0.25, 0.5], atol=0.004)
    foton.write(image, tmp_path / "filmic.png", tonemap="filmic")
    assert foton.read(tmp_path / "filmic.png")[0, 1, 0] < 1.0


def test_to_display_is_what_a_png_holds(tmp_path):
    rng = np.random.default_rng(3)
    image = rng.exponential(size=(6, 5, 3)).astype(np.float32)
    for exposure, tonemap in [(0.0, "clamp"), (-1.5, "filmic")]:
        shown = foton.to_display(image, exposure, tonemap)
        assert shown.dtype == np.uint8 and shown.shape == (6, 5, 3)
        foton.write(image, tmp_path / "a.png", exposure=exposure, tonemap=tonemap)
        png = foton.read(tmp_path / "a.png")  # decoded back to linear
        encoded = np.where(png <= 0.0031308, 12.92 * png, 1.055 * png ** (1 / 2.4) - 0.055)
        assert np.array_equal(np.round(encoded * 255).astype(np.uint8), shown)


def test_compare_gives_the_figures_of_foton_compare_json(program, tmp_path):
    scene = SCENES / "caustics-area.toml"
    ref = tmp_path / "ref.exr"
    run_program(program, "render", scene, "--integrator", "path", "--spp", 8, "--seed", 99,
                *as_sets(TINY), "-q", "-o", ref)
    out = tmp_path / "cmp.png"
    run_program(program, "compare", scene, "--integrators", "path,photon,sppm", "--spp", 2,
                "--reference", ref, *as_sets(TINY), "-q", "-o", out)
    report = json.loads((tmp_path / "cmp.json").read_text())
    renders = {e["name"]: foton.read(tmp_path / e["image"]) for e in report["integrators"]}
    figures = foton.compare(renders, ref)
    assert set(figures) == {"path", "photon", "sppm"}
    for entry in report["integrators"]:
        ours = figures[entry["name"]]
        assert isinstance(ours, foton.Errors)
        # The same numbers, to the last bit (the JSON prints the shortest exact decimal).
        assert ours.rel_mse == entry["rel_mse"]
        assert ours.bias == entry["bias"]
        assert ours.rel_mse > 0


def test_compare_forms():
    rng = np.random.default_rng(2)
    ref = rng.random((4, 5, 3), dtype=np.float32)
    x = ref * 1.1
    one = foton.compare(x, ref)
    assert one.rel_mse > 0 and math.isclose(one.bias, 0.1, rel_tol=1e-5)
    assert foton.compare([x, ref], ref) == [one, foton.Errors(0.0, 0.0)]
    assert foton.compare({"a": x}, ref) == {"a": one}
    # A black reference has no bias (null in the program's JSON).
    assert math.isnan(foton.compare(x, np.zeros_like(ref)).bias)
    with pytest.raises(ValueError, match="shape"):
        foton.compare(x[:2], ref)


def test_compare_reads_a_reference_file(tmp_path):
    ref = np.ones((2, 3, 3), dtype=np.float32)
    foton.write(ref, tmp_path / "r.exr")
    assert foton.compare(ref * 2, tmp_path / "r.exr") == foton.compare(ref * 2, ref)
    with pytest.raises(foton.FileError):
        foton.read(tmp_path / "missing.exr")
