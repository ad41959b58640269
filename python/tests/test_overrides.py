"""Every form of override: dotted keys, dicts merged key by key, render's arguments, loads."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import foton
from conftest import ROOT, SCENES, TINY, as_sets, run_program

BOX = SCENES / "cornell-box.toml"
CAUSTICS = SCENES / "caustics-area.toml"


def test_dotted_keys():
    scene = foton.load(BOX, **{"render.spp": 3, "render.seed": 9, "film.width": 20})
    assert (scene.spp, scene.seed, scene.width, scene.height) == (3, 9, 20, 256)


def test_dicts_merge_key_by_key():
    scene = foton.load(BOX, render={"spp": 3, "seed": 9}, film={"width": 20})
    assert (scene.spp, scene.seed, scene.width, scene.height) == (3, 9, 20, 256)
    # Nested, and beside dotted keys.
    scene = foton.load(CAUSTICS, integrators={"photon": {"k": 7}}, **{"render.integrator": "photon"})
    assert scene.integrator == "photon"
    assert scene.parameters["k"] == 7
    # Merged: the other keys of the table stay.
    assert scene.parameters["global_photons"] == 1000000


def test_dotted_keys_and_dicts_make_the_same_scene():
    a = foton.load(BOX, **{"render.spp": 2, "film.width": 24, "film.height": 16}).render(progress=False)
    b = foton.load(BOX, render={"spp": 2}, film={"width": 24, "height": 16}).render(progress=False)
    assert np.array_equal(a, b)


def test_value_types():
    scene = foton.load(
        CAUSTICS,
        **{
            "film.exposure": -1.25,  # float
            "film.tonemap": "clamp",  # str
            "render.integrator": "photon",
            "integrators.photon.final_gather": True,  # bool
            "integrators.photon.k": np.int64(12),  # numpy scalar
            "camera.position": (0.0, 1.0, 2.5),  # tuple -> array
            "camera.look_at": np.array([0.0, 1.0, 0.0]),  # numpy array -> array
        },
    )
    assert scene.display == {"exposure": -1.25, "tonemap": "clamp"}
    assert scene.parameters["final_gather"] is True
    assert scene.parameters["k"] == 12


def test_a_list_is_a_toml_array():
    with pytest.raises(foton.SceneError) as e:
        foton.load(BOX, **{"camera.position": [1.0, 2.0]})
    assert e.value.key == "camera.position"
    assert e.value.line is None  # from an override, not from the file


def test_strings_keep_quotes_backslashes_and_unicode(tmp_path):
    name = 'a "quoted" \\ back\tslash é.png'
    scene = foton.load(BOX, **{"film.output": name})
    assert scene.output.name == name


def test_render_arguments_are_the_programs_flags(program, tmp_path):
    # --integrator, --spp, --seed and --set integrators.NAME.KEY are render's arguments.
    out = tmp_path / "p.exr"
    run_program(program, "render", CAUSTICS, "--integrator", "photon", "--spp", 2, "--seed", 4,
                *as_sets(TINY), "--set", "integrators.photon.k=9",
                "--set", "integrators.photon.kernel=cone", "-q", "-o", out)
    scene = foton.load(CAUSTICS, **TINY)
    image = scene.render(integrator="photon", spp=2, seed=4, params={"k": 9, "kernel": "cone"},
                         progress=False)
    assert np.array_equal(image, foton.read(out))
    assert "k = 9" in scene.last_render["integrator"]
    assert "kernel = cone" in scene.last_render["integrator"]


def test_params_go_to_the_scenes_integrator_by_default():
    scene = foton.load(CAUSTICS, **TINY, **{"render.integrator": "photon"})
    a = scene.render(spp=1, params={"k": 5}, progress=False)
    assert "k = 5" in scene.last_render["integrator"]
    b = scene.render(spp=1, progress=False)
    assert "k = 200" in scene.last_render["integrator"]
    assert not np.array_equal(a, b)


def test_loads_text_with_base_dir_and_overrides():
    text = (SCENES / "cornell-box.toml").read_text()
    a = foton.loads(text, SCENES, **{"render.spp": 2, "film.width": 24, "film.height": 16})
    b = foton.load(BOX, **{"render.spp": 2, "film.width": 24, "film.height": 16})
    assert a.output == SCENES / "cornell-box.png"  # relative to base_dir
    assert a.file == SCENES / "<string>"
    assert np.array_equal(a.render(progress=False), b.render(progress=False))


def test_loads_resolves_meshes_against_base_dir():
    meshes = sorted(p.name for p in (SCENES / "meshes").iterdir() if p.suffix in (".obj", ".ply"))
    assert meshes, "the repository has example meshes"
    text = f"""
[film]
width = 8
height = 8
[camera]
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
fov = 40.0
[materials.white]
type = "diffuse"
reflectance = [0.5, 0.5, 0.5]
[[shapes]]
type = "mesh"
file = "meshes/{meshes[0]}"
material = "white"
[[lights]]
type = "point"
position = [0.0, 0.0, 5.0]
intensity = [1.0, 1.0, 1.0]
"""
    foton.loads(text, SCENES)  # found
    with pytest.raises(foton.SceneError) as e:
        foton.loads(text, ROOT / "docs")  # not there
    assert e.value.key == "shapes[0].file"
    assert str(ROOT / "docs" / "meshes") in e.value.reason


def test_unknown_fields_warn_and_strict_refuses(tmp_path):
    # In the file: a warning, an error with strict=True.
    text = Path(BOX).read_text().replace("[render]\n", "[render]\nspp_typo = 3\n", 1)
    typo = tmp_path / "typo.toml"
    typo.write_text(text)
    with pytest.warns(foton.FotonWarning, match="unknown field"):
        foton.load(typo)
    with pytest.raises(foton.SceneError) as e:
        foton.load(typo, strict=True)
    assert e.value.key == "render.spp_typo"
    # Set from Python, as with --set: nothing reads it, so it is an error naming what it meant.
    with pytest.raises(foton.UsageError, match="render.sppp.*did you mean `render.spp`"):
        foton.load(BOX, **{"render.sppp": 3})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        foton.load(BOX)  # no warning for a clean scene


def test_bad_overrides():
    with pytest.raises(TypeError, match="render.spp"):
        foton.load(BOX, **{"render.spp": object()})
    with pytest.raises(foton.UsageError, match="not a table"):
        foton.load(BOX, **{"render.spp.x": 1})
    with pytest.raises(foton.UsageError, match="empty key"):
        foton.load(BOX, **{"render..spp": 1})
    with pytest.raises(ValueError, match="threads"):
        foton.load(BOX, **TINY).render(threads=0)
