//! The photon pass counts each light path once at a plastic's coat: `photon` with and
//! without final gathering, `sppm` and `vpm` against the path tracer in a closed box of
//! coated walls.

use foton_tests::render_toml;
use foton_tests::stats::rel_err;

/// A closed box of emitting walls (emission 1) of `material` (a TOML body), 12 x 12 pixels,
/// with `extra` appended (the integrators' tables).
fn emitting_box(integrator: &str, material: &str, extra: &str) -> String {
    let diffuse = "[materials.wall]\ntype = \"diffuse\"\nreflectance = [0.5, 0.5, 0.5]\n";
    let toml = foton_tests::closed_box(integrator, 12, 0.5, 1.0, "");
    assert!(toml.contains(diffuse));
    toml.replace(diffuse, &format!("[materials.wall]\n{material}\n")) + extra
}

/// A smooth plastic whose coat (index 3) reflects a quarter of the light and more: a coat
/// counted twice, or not at all, moves the image by about 10%.
const BRIGHT_COAT: &str = "type = \"plastic\"\ndiffuse_reflectance = [0.5, 0.5, 0.5]\nior = 3.0";

/// `photon` (its table's `photon` lines, with each `direct` mode; without final gathering
/// also without a caustic map) against the path tracer on a closed box of `material` walls: the image means within
/// 3% (the image's corners, where the estimates darken within a radius of the box's edges, are
/// 5-8% dark by blocks, as in a diffuse box). Measured on the diffuse box, 100k photons
/// without final gathering come out 3% dark overall, so those runs use 400k.
fn photon_agrees_with_path_in_a_box(material: &str, photon: &str) {
    let path = render_toml(
        "plastic-path",
        &emitting_box("path", material, ""),
        &["render.spp=256"],
        2,
    );
    let gather = photon.contains("final_gather = true");
    let (photons, spp) = if gather {
        (100000, "render.spp=16")
    } else {
        (400000, "render.spp=4")
    };
    for direct in ["nee", "photons"] {
        // Without a caustic budget the global pass's L S+ D photons are the caustic map
        // (final gathering, which does not read the indirect map at x) or in the indirect
        // map: either way counted once.
        for caustic in [photons, 0] {
            let table = format!(
                "[integrators.photon]\nglobal_photons = {photons}\ncaustic_photons = {caustic}\n\
                 k = 50\ndirect = \"{direct}\"\n{photon}\n"
            );
            let toml = emitting_box("photon", material, &table);
            let film = render_toml("plastic-photon", &toml, &[spp], 2);
            let (a, b) = (film.mean(), path.mean());
            let what = format!("photon ({photon:?}, direct {direct}, caustic_photons {caustic})");
            assert!(rel_err(a, b) < 0.03, "{what}: {a} against path {b}");
        }
    }
}

/// Final gathering at a smooth plastic: the camera walk follows the delta coat (with its
/// probability) and estimates the diffuse base at the visible point, so the gather rays must
/// sample the base only, and the light the coat reflects from a light onto a diffuse point
/// (L S D, S the coat) must reach the caustic map, which is what the gather rays, which do not
/// count emission, rely on. A gather ray that followed the coat again counted its reflection
/// twice (13% too bright); with only that fixed, the L S(coat) D photons, classed indirect
/// and kept in the indirect map that final gathering does not read at x, were lost (9% too
/// dark).
#[test]
fn final_gather_counts_a_plastic_coat_once() {
    let gather = "final_gather = true\ngather_rays = 8";
    photon_agrees_with_path_in_a_box(BRIGHT_COAT, gather);
}

/// Without final gathering the indirect map at x reads the L S(coat) D photons when they are
/// classed indirect, the caustic map when they are classed caustic: either way each path
/// once. A rough plastic (a glossy coat, no delta part) is followed by sampling (alpha 0.3,
/// below `glossy_roughness`) with final gathering where the walk ends.
#[test]
fn photon_counts_plastic_coats_once_without_and_with_final_gathering() {
    photon_agrees_with_path_in_a_box(BRIGHT_COAT, "");
    let rough = "type = \"roughplastic\"\ndistribution = \"ggx\"\nalpha = 0.3\n\
                 diffuse_reflectance = [0.5, 0.5, 0.5]\nior = 3.0";
    photon_agrees_with_path_in_a_box(rough, "final_gather = true\ngather_rays = 8");
}

/// `sppm` and `vpm` share the photon pass's classification: in the box of bright-coated
/// plastic they agree with the path tracer (image means within 3%).
#[test]
fn sppm_and_vpm_count_a_plastic_coat_once() {
    let path = render_toml(
        "plastic-path",
        &emitting_box("path", BRIGHT_COAT, ""),
        &["render.spp=256"],
        2,
    );
    for (integrator, table, spp) in [
        (
            "sppm",
            "[integrators.sppm]\niterations = 32\nphotons_per_iteration = 10000\n",
            "render.spp=1",
        ),
        (
            "vpm",
            "[integrators.vpm]\nglobal_photons = 100000\ncaustic_photons = 100000\nk = 50\n",
            "render.spp=4",
        ),
    ] {
        let toml = emitting_box(integrator, BRIGHT_COAT, table);
        let film = render_toml("plastic-photon", &toml, &[spp], 2);
        let (a, b) = (film.mean(), path.mean());
        assert!(rel_err(a, b) < 0.03, "{integrator}: {a} against path {b}");
    }
}
