"""Images from Python are the program's images, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

import foton
from conftest import SCENES, TINY, as_sets, run_program

CASES = [
    # scene, integrator, spp, seed, integrator parameters
    ("caustics-area.toml", "path", 2, 3, {}),
    ("caustics-area.toml", "photon", 2, 5, {"k": 10}),
    ("caustics-area.toml", "sppm", 1, 7, {}),
    ("cornell-fog.toml", "vpm", 1, 1, {"global_photons": 2000, "caustic_photons": 0, "volume_photons": 2000}),
    ("cornell-box.toml", "normals", 1, 0, {}),
]


@pytest.mark.parametrize("scene_name, integrator, spp, seed, params", CASES)
def test_image_equals_the_programs_bit_for_bit(program, tmp_path, scene_name, integrator, spp, seed, params):
    scene_file = SCENES / scene_name
    overrides = {k: v for k, v in TINY.items() if k.startswith("film.") or k.split(".")[1] == integrator}
    out = tmp_path / "program.exr"
    args = ["render", scene_file, "--integrator", integrator, "--spp", spp, "--seed", seed]
    args += as_sets(overrides)
    args += as_sets({f"integrators.{integrator}.{k}": v for k, v in params.items()})
    run_program(program, *args, "-q", "-o", out)
    expected = foton.read(out)

    scene = foton.load(scene_file, **overrides)
    image = scene.render(integrator=integrator, spp=spp, seed=seed, params=params, progress=False)
    assert image.dtype == np.float32
    assert image.shape == (30, 40, 3)
    assert image.any(), "a black image proves little"
    # Bit for bit: compare the float32 bit patterns, so that NaNs and -0.0 count too.
    assert image.view(np.uint32).tobytes() == expected.view(np.uint32).tobytes()

    # And the EXR written from Python is the program's file, byte for byte.
    ours = tmp_path / "python.exr"
    foton.write(image, ours)
    assert ours.read_bytes() == out.read_bytes()


def test_png_is_the_programs_png(program, tmp_path):
    scene_file = SCENES / "caustics-area.toml"  # exposure -0.5, filmic: the display matters
    out = tmp_path / "program.png"
    run_program(program, "render", scene_file, "--integrator", "path", "--spp", 2,
                *as_sets({"film.width": 40, "film.height": 30}), "-q", "-o", out)
    scene = foton.load(scene_file, **{"film.width": 40, "film.height": 30})
    image = scene.render(integrator="path", spp=2, progress=False)
    assert scene.display == {"exposure": -0.5, "tonemap": "filmic"}
    ours = tmp_path / "python.png"
    foton.write(image, ours, **scene.display)
    assert ours.read_bytes() == out.read_bytes()
    plain = tmp_path / "plain.png"
    foton.write(image, plain)
    assert plain.read_bytes() != out.read_bytes()


def test_the_image_does_not_depend_on_threads():
    scene = foton.load(SCENES / "caustics-area.toml", **TINY)
    one = scene.render(integrator="photon", spp=2, threads=1, progress=False)
    two = scene.render(integrator="photon", spp=2, threads=2, progress=False)
    assert np.array_equal(one, two)
    assert scene.last_render["threads"] == 2


def test_seed_and_spp_change_the_image_and_repeat_it():
    scene = foton.load(SCENES / "cornell-box.toml", **TINY)
    a = scene.render(spp=2, seed=1, progress=False)
    assert np.array_equal(a, scene.render(spp=2, seed=1, progress=False))
    assert not np.array_equal(a, scene.render(spp=2, seed=2, progress=False))
    assert not np.array_equal(a, scene.render(spp=3, seed=1, progress=False))
    # The scene's own settings again after renders with others.
    assert scene.spp == 64 and scene.seed == 0


def test_sampler_is_the_programs_and_a_misspelt_one_is_refused(program, tmp_path):
    scene = foton.load(SCENES / "cornell-box.toml", **TINY)
    sobol = scene.render(spp=4, sampler="sobol", progress=False)
    assert scene.last_render["sampler"] == "sobol"
    out = tmp_path / "program.exr"
    sets = as_sets({k: v for k, v in TINY.items() if k.startswith("film.")})
    run_program(program, "render", SCENES / "cornell-box.toml", "--spp", 4, "--set", 'render.sampler="sobol"', *sets, "-q", "-o", out)
    assert np.array_equal(sobol, foton.read(out))
    assert not np.array_equal(sobol, scene.render(spp=4, sampler="independent", progress=False))
    assert np.array_equal(sobol, scene.render(spp=4, progress=False))  # the file names none: sobol
    assert scene.sampler == "sobol"
    with pytest.raises(foton.SceneError, match='did you mean "sobol"'):
        scene.render(spp=4, sampler="sobl", progress=False)


def test_the_array_is_a_writable_view_of_one_buffer():
    image = foton.load(SCENES / "cornell-box.toml", **TINY).render(spp=1, progress=False)
    assert image.flags.c_contiguous and image.flags.writeable
    # numpy's array is a view of the bytearray the pixels were written into: no other copy.
    base = image.base
    while isinstance(base, np.ndarray):
        base = base.base
    if isinstance(base, memoryview):
        base = base.obj
    assert isinstance(base, bytearray)
    assert len(base) == image.nbytes
    image[0, 0] = 7.0
    assert image[0, 0, 1] == 7.0


def test_last_render_reports_the_work():
    scene = foton.load(SCENES / "caustics-area.toml", **TINY)
    scene.render(integrator="path", spp=3, progress=False)
    info = scene.last_render
    assert info["samples"] == 40 * 30 * 3
    assert info["spp"] == 3 and info["iterations"] == 0
    assert info["integrator"].startswith("path(")
    assert info["seconds"] > 0 and info["rays"] > 0 and not info["interrupted"]
    scene.render(integrator="sppm", progress=False)
    assert scene.last_render["iterations"] == 2
    assert scene.last_render["photons"] == 2 * 3000


def test_scene_attributes():
    scene = foton.load(SCENES / "caustics-area.toml", **{"render.spp": 5})
    assert scene.file == SCENES / "caustics-area.toml"
    assert (scene.width, scene.height, scene.spp, scene.seed) == (256, 256, 5, 0)
    assert scene.max_depth == 16
    assert scene.integrator == "sppm"
    assert scene.description.startswith("sppm(")
    assert scene.parameters["iterations"] == 64
    assert scene.output == SCENES / "caustics-area.png"
    assert "256x256" in repr(scene)


def test_a_time_limit_chooses_the_samples_as_the_program_does(tmp_path):
    # render.time (Mitsuba's timeout) bounds the samples: a million per pixel would take
    # minutes, 0.3 s far fewer; never more than the scene's spp, which a minute leaves as it is.
    scene = foton.load(SCENES / "cornell-box.toml", **{"film.width": 16, "film.height": 12, "render.time": 0.3})
    image = scene.render(spp=1_000_000, progress=False)
    spp = scene.last_render["spp"]
    assert 1 <= spp < 1_000_000
    # The image is the one that many samples render without the limit.
    plain = foton.load(SCENES / "cornell-box.toml", **{"film.width": 16, "film.height": 12})
    assert image.view(np.uint32).tobytes() == plain.render(spp=spp, progress=False).view(np.uint32).tobytes()
    roomy = foton.load(SCENES / "cornell-box.toml", **{"film.width": 16, "film.height": 12, "render.time": 60})
    roomy.render(spp=2, progress=False)
    assert roomy.last_render["spp"] == 2
