"""`foton compare --report` (and `foton.compare(..., report=)`) as a user sees it: the page
opened from disk in headless Chromium through its WebDriver (Debian's `chromium` and
`chromium-driver`; skipped with the reason where they are absent, failed under CI): no error in
its console, nothing loaded from anywhere else, `fotonReport.tabs` in order and
`fotonReport.pixel` equal to the EXRs' values to half-float precision, and its error views'
means equal to the JSON's numbers."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

import foton
import webdriver
from conftest import SCENES, TINY, as_sets, run_program


@pytest.fixture(scope="module")
def browser():
    why = webdriver.missing()
    if why:
        if os.environ.get("CI"):
            pytest.fail(why)
        pytest.skip(why)
    with webdriver.Browser() as b:
        yield b


def as_half(a: np.ndarray) -> np.ndarray:
    """The values the page stores: the nearest half floats."""
    return a.astype(np.float16).astype(np.float32)


def check_page(browser, page, tabs: dict[str, np.ndarray]) -> None:
    """The page loads without console errors or outside resources, with `tabs` in order and
    each tab's pixels those of its image."""
    browser.log()  # drop what an earlier page left
    browser.open(page)
    log = browser.log()
    assert not [e for e in log if e.get("level") in ("SEVERE", "WARNING")], log
    assert browser.script("return performance.getEntriesByType('resource').length") == 0
    assert browser.script("return window.fotonReport.tabs") == list(tabs)
    rng = np.random.default_rng(7)
    for name, image in tabs.items():
        h, w, _ = image.shape
        points = [(0, 0), (w - 1, h - 1), (w // 2, h // 3)] + [
            (int(rng.integers(w)), int(rng.integers(h))) for _ in range(5)
        ]
        for x, y in points:
            got = browser.script("return window.fotonReport.pixel(arguments[0], arguments[1], arguments[2])", name, x, y)
            want = as_half(image[y, x])
            assert np.array_equal(np.float32(got), want), (name, x, y, got, image[y, x])


def test_compare_report_in_a_browser(program, browser, tmp_path):
    scene = SCENES / "cornell-box.toml"
    sets = as_sets(TINY)
    reference = tmp_path / "ref.exr"
    run_program(program, "render", scene, "--spp", 16, "-q", "-o", reference, *sets)
    out, page = tmp_path / "cmp.png", tmp_path / "cmp.html"
    run_program(
        program, "compare", scene, "--integrators", "path,bdpt,photon", "--spp", 2, "--seed", 3,
        "--reference", reference, "-o", out, "--report", page, "-q", *sets,
    )
    result = json.loads((tmp_path / "cmp.json").read_text())
    renders = {e["name"]: foton.read(tmp_path / e["image"]) for e in result["integrators"]}
    check_page(browser, page, {**renders, "reference": foton.read(reference)})

    # Keys switch tabs; `m` steps through the views: image, then the error images, whose
    # means are the JSON's numbers (relative squared error: rel_mse; FLIP: flip) up to the
    # half floats the page holds.
    browser.key("2")
    assert browser.script("return document.querySelector('#tabs button.on').textContent") == "2bdpt"
    bdpt = next(e for e in result["integrators"] if e["name"] == "bdpt")
    means = {}
    for _ in range(5):
        browser.key("m")
        mode = browser.script("return document.getElementById('mode').value")
        text = browser.script("return document.getElementById('bar-mean').textContent")
        means[mode] = float(text.removeprefix("mean "))
    assert list(means) == ["abs", "rel", "relsq", "smape", "flip"]
    assert means["relsq"] == pytest.approx(bdpt["rel_mse"], rel=0.02)
    assert means["flip"] == pytest.approx(bdpt["flip"], rel=0.01, abs=1e-4)
    assert not [e for e in browser.log() if e.get("level") in ("SEVERE", "WARNING")]


def test_technique_layers_in_the_report(program, browser, tmp_path):
    """`--techniques`: the page holds each technique's layer, as the EXR does, and they sum to
    the image (up to the half floats the page stores)."""
    scene = SCENES / "cornell-box.toml"
    out, page = tmp_path / "t.png", tmp_path / "t.html"
    run_program(
        program, "compare", scene, "--integrators", "path,bdpt", "--spp", 2, "--techniques",
        "--techniques-depth", 3, "-o", out, "--report", page, "-q", *as_sets(TINY),
    )
    browser.log()
    browser.open(page)
    assert browser.script("return window.fotonReport.layers('path')") == []
    names = browser.script("return window.fotonReport.layers('bdpt')")
    assert names[:3] == ["s0t2", "s1t1", "s0t3"] and names[-1] == "rest", names
    image = foton.read(tmp_path / "t-bdpt.exr")
    h, w, _ = image.shape
    for x, y in [(w // 2, h // 2), (3, h - 4), (w // 3, h // 5)]:
        layers = np.array(
            [browser.script("return window.fotonReport.layerPixel('bdpt', arguments[0], arguments[1], arguments[2])", n, x, y) for n in names],
            dtype=np.float64,
        )
        total = layers.sum(axis=0)
        want = image[y, x].astype(np.float64)
        # Each layer is rounded to a half float (relative 2^-11).
        tolerance = np.abs(layers).sum(axis=0) * 2.0**-10 + 1e-6
        assert np.all(np.abs(total - want) <= tolerance), (x, y, total, want)
    assert not [e for e in browser.log() if e.get("level") in ("SEVERE", "WARNING")]


def test_python_compare_writes_the_same_report(browser, tmp_path):
    rng = np.random.default_rng(1)
    reference = rng.random((12, 20, 3), dtype=np.float32) * 2
    images = {
        "brighter": reference * 1.1,
        "noisy": reference + rng.normal(0, 0.1, reference.shape).astype(np.float32),
    }
    page = tmp_path / "py.html"
    errors = foton.compare(images, reference, report=page)
    assert errors["brighter"].bias == pytest.approx(0.1, rel=1e-4)
    check_page(browser, page, {**images, "reference": reference})
    with pytest.raises(ValueError, match="reference"):
        foton.compare({"reference": reference}, reference, report=tmp_path / "no.html")


def test_report_must_be_html(program, tmp_path):
    out = run_program(
        program, "compare", SCENES / "cornell-box.toml", "--integrators", "path", "--spp", 1,
        "--report", tmp_path / "r.png", "-o", tmp_path / "c.png", "-q", *as_sets(TINY),
        check=False,
    )
    assert out.returncode != 0
    assert "FILE.html" in out.stderr
