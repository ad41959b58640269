//! `coateddiffuse` and `coatedconductor` (pbrt-v4's layered materials, whose BSDF values and
//! pdfs are random-walk estimates) in a render: `bdpt`, which evaluates them at its
//! connections and compares their pdfs from both ends of a path, agrees block by block with
//! `path`, which mostly samples them. Their lobes' own tests (sampling, energy, reciprocity)
//! are in core/src/material/layered/tests.rs.

use crate::bdpt::{CEILING_LIGHT, cornell};
use foton_tests::render_toml;
use foton_tests::stats::{Tolerance, assert_blocks_agree};

const TOLERANCE: Tolerance = Tolerance {
    rel: 0.0,
    z: 4.5,
    floor: 1e-4,
};

const MATERIALS: &str = r#"
[materials.coated]
type = "coateddiffuse"
reflectance = [0.7, 0.35, 0.2]

[materials.milky]
type = "coateddiffuse"
reflectance = [0.2, 0.5, 0.8]
roughness = 0.05
albedo = [0.8, 0.8, 0.8]
thickness = 0.2
g = 0.3

[materials.copper]
type = "coatedconductor"
interface_roughness = 0.02
conductor_roughness = 0.1

[materials.gold]
type = "coatedconductor"
conductor_material = "Au"
conductor_roughness = 0.05
"#;

fn render(scene: &str, integrator: &str, spp: u32) -> foton_core::film::Film {
    let sets = [
        format!("render.integrator=\"{integrator}\""),
        format!("render.spp={spp}"),
    ];
    let refs: Vec<&str> = sets.iter().map(String::as_str).collect();
    render_toml(&format!("coated-{integrator}"), scene, &refs, 2)
}

/// A smooth coat over a diffuse base (a delta reflection beside the walk) and a rough one
/// over a scattering slab; a rough coat over copper and a smooth one over rough gold.
#[test]
fn bdpt_agrees_with_path_on_coated_materials() {
    for (a, b) in [("coated", "milky"), ("copper", "gold")] {
        let scene = cornell(a, b, MATERIALS, CEILING_LIGHT);
        let reference = render(&scene, "path", 1024);
        let film = render(&scene, "bdpt", 128);
        assert_blocks_agree(
            &format!("bdpt against path, spheres of {a} and {b}"),
            &film,
            &reference,
            4,
            TOLERANCE,
        );
    }
}
