//! The example scenes and the scenes written by other tooling (copied unchanged from
//! shared/scenes into scenes/) load without unknown fields and render.

use foton_tests::stats::{Tolerance, assert_blocks_agree};
use foton_tests::{render_file, repo_root};

fn scene_files() -> Vec<std::path::PathBuf> {
    let mut files: Vec<_> = std::fs::read_dir(repo_root().join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_scene_loads_with_no_unknown_field() {
    let files = scene_files();
    assert!(files.len() >= 3, "{files:?}");
    for file in files {
        let scene = foton_loader::load(&file, &[]).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            scene.unused().is_empty(),
            "{}: unused {:?}",
            file.display(),
            scene.unused()
        );
        assert!(!scene.lights().is_empty(), "{}", file.display());
    }
}

#[test]
fn cornell_point_from_other_tooling_matches_our_cornell_box() {
    // The same box, spheres and light; cornell_point allows 64 bounces where ours stops at 16,
    // which adds (well) under one percent.
    let small = ["film.width=32", "film.height=32", "render.spp=16"];
    let theirs = render_file(&repo_root().join("scenes/cornell_point.toml"), &small, 2);
    let ours = render_file(&repo_root().join("scenes/cornell-box.toml"), &small, 2);
    let (a, b) = (theirs.mean(), ours.mean());
    for c in 0..3 {
        assert!(a[c] > 0.01, "lit: {a}");
        assert!((a[c] - b[c]).abs() < 0.01 * b[c], "{a} vs {b}");
    }
    // Region by region too (4x4 blocks of 8x8 pixels), at the same 1 %: both renders use
    // the same seed, so their noise is the same but for the paths longer than 16 bounces
    // (none at 16 spp: measured bit for bit equal; the standard error of the pixel-wise
    // difference measures what would be left, and 4 of it are allowed on top). The floor
    // (0.5 % of the image mean) is for blocks black in a channel.
    assert_blocks_agree(
        "cornell_point vs cornell-box",
        &theirs,
        &ours,
        4,
        Tolerance {
            rel: 0.01,
            z: 4.0,
            floor: 0.005 * b.max_element() as f64,
        },
    );
}

#[test]
fn fog_box_from_other_tooling_parses_its_media() {
    let scene = foton_loader::load(&repo_root().join("scenes/fog_box.toml"), &[]).unwrap();
    assert!(scene.has_media());
    let fog = scene.media().iter().find(|m| m.name == "fog").unwrap();
    assert_eq!(fog.value.sigma_t(glam::Vec3::ZERO), glam::Vec3::splat(1.05));
    // The closed cube mesh carries the fog as its interior.
    assert_eq!(
        scene
            .objects()
            .iter()
            .filter(|o| o.interior.is_some())
            .count(),
        1
    );
    // `path` renders it: the fog in front of the back wall scatters light towards the camera
    // and dims the wall behind it.
    let small = ["film.width=32", "film.height=32", "render.spp=16"];
    let fog = render_file(&repo_root().join("scenes/fog_box.toml"), &small, 2);
    let clear = render_file(
        &repo_root().join("scenes/fog_box.toml"),
        &[
            &small[..],
            &["media.fog.sigma_s=[0, 0, 0]", "media.fog.sigma_a=[0, 0, 0]"],
        ]
        .concat(),
        2,
    );
    assert!(fog.mean().is_finite() && fog.mean().min_element() > 0.0);
    assert_ne!(fog.pixels(), clear.pixels());
}
