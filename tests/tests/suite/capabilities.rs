//! What the tools ask an integrator through its trait: its parameters (and the description
//! built from them), how a time budget scales it, and the photon maps it builds. Checked for
//! every integrator plugin against what it reads from the scene: no tool parses a description
//! or copies a default.

use foton_cli::prepare;
use foton_core::integrator::{ParamValue, Work, describe};
use foton_tests::{plugin_dir, repo_root};
use std::sync::atomic::AtomicBool;

const SCENE: &str = "scenes/cornell-box.toml";

fn prepared(integrator: &str, sets: &[String]) -> foton_cli::Prepared {
    let mut all = vec![format!("render.integrator=\"{integrator}\"")];
    all.extend_from_slice(sets);
    prepare(&repo_root().join(SCENE), &all, &[plugin_dir()], true)
        .unwrap_or_else(|e| panic!("{integrator}: {e}"))
}

/// Every parameter an integrator reports is a key of its `[integrators.NAME]` table (set back
/// with --strict, which refuses unknown keys) and comes back with the value it was set to;
/// `describe()` is built from them.
#[test]
fn parameters_are_the_keys_of_the_integrators_table_and_round_trip() {
    for name in [
        "path", "bdpt", "vcm", "photon", "sppm", "vpm", "ppb", "normals", "ao",
    ] {
        let p = prepared(name, &[]);
        assert_eq!(p.integrator.name(), name);
        let params = p.integrator.parameters();
        assert!(!params.is_empty(), "{name} reports no parameter");
        assert_eq!(p.integrator.describe(), describe(name, &params));
        // Set each to a different value of its own type where one is obviously valid, so that
        // a reported value that is not the one in force would show.
        let sets: Vec<String> = params
            .iter()
            .filter_map(|q| {
                let value = match &q.value {
                    ParamValue::Int(n) => (n + 1).to_string(),
                    ParamValue::Float(x) => (x * 0.5).to_string(),
                    ParamValue::Bool(b) => (!b).to_string(),
                    // Choices (kernel, direct, estimate) and "auto": set as they are.
                    ParamValue::Str(s) if s == "auto" => return None,
                    ParamValue::Str(s) => format!("{s:?}"),
                };
                Some(format!("integrators.{name}.{}={value}", q.name))
            })
            .collect();
        let q = prepared(name, &sets);
        for (before, after) in params.iter().zip(q.integrator.parameters()) {
            assert_eq!(before.name, after.name);
            let expected = match &before.value {
                ParamValue::Int(n) => ParamValue::Int(n + 1),
                ParamValue::Float(x) => ParamValue::Float(((x * 0.5) as f32) as f64),
                ParamValue::Bool(b) => ParamValue::Bool(!b),
                other => other.clone(),
            };
            assert_eq!(after.value, expected, "{name}.{}", before.name);
        }
    }
    // A kernel's own parameter is reported when that kernel is chosen.
    let p = prepared(
        "photon",
        &[
            "integrators.photon.kernel=\"cone\"".into(),
            "integrators.photon.cone_c=2.5".into(),
        ],
    );
    let params = p.integrator.parameters();
    assert!(
        params
            .iter()
            .any(|q| q.name == "cone_c" && q.value == ParamValue::Float(2.5)),
        "{params:?}"
    );
}

/// `budget()`: path counts samples; photon and vpm scale their photon budgets (keys that are
/// their parameters, with the values in force); sppm counts iterations under a key that is
/// its parameter.
#[test]
fn budgets_name_real_scene_keys() {
    let p = prepared("path", &[]);
    let b = p.integrator.budget();
    assert_eq!(b.work, Work::Samples);
    assert!(b.scaled.is_empty());

    for name in ["photon", "vpm"] {
        let p = prepared(name, &[format!("integrators.{name}.global_photons=12345")]);
        let b = p.integrator.budget();
        assert_eq!(b.work, Work::Samples);
        let params = p.integrator.parameters();
        assert!(
            b.scaled
                .contains(&(format!("integrators.{name}.global_photons"), 12345))
        );
        for (key, value) in &b.scaled {
            let short = key.strip_prefix(&format!("integrators.{name}.")).unwrap();
            let param = params.iter().find(|q| q.name == short).unwrap();
            assert_eq!(param.value, ParamValue::Int(*value as i64), "{key}");
        }
    }

    let p = prepared("sppm", &["integrators.sppm.iterations=7".into()]);
    match p.integrator.budget().work {
        Work::Iterations { key } => {
            assert_eq!(key, "integrators.sppm.iterations");
            assert!(
                p.integrator
                    .parameters()
                    .iter()
                    .any(|q| q.name == "iterations" && q.value == ParamValue::Int(7))
            );
        }
        other => panic!("sppm: {other:?}"),
    }
}

/// `bias()`: the unbiased integrators say nothing; the biased-but-consistent ones (density
/// estimation, `vcm` when it merges) say what shrinks their bias, and every scene key they name
/// is one of their parameters (so that `--set` takes it).
#[test]
fn biased_integrators_name_the_keys_that_shrink_their_bias() {
    for name in ["path", "bdpt", "normals", "ao"] {
        assert_eq!(prepared(name, &[]).integrator.bias(), None, "{name}");
    }
    for mode in ["bpt", "lt"] {
        let p = prepared("vcm", &[format!("integrators.vcm.mode=\"{mode}\"")]);
        assert_eq!(p.integrator.bias(), None, "vcm {mode}");
    }
    for (name, sets) in [
        ("photon", vec![]),
        ("vpm", vec![]),
        ("sppm", vec![]),
        ("ppb", vec![]),
        ("vcm", vec![]),
        ("vcm", vec!["integrators.vcm.mode=\"ppm\"".to_string()]),
    ] {
        let p = prepared(name, &sets);
        let bias = p
            .integrator
            .bias()
            .unwrap_or_else(|| panic!("{name}: no bias"));
        let prefix = format!("integrators.{name}.");
        let keys: Vec<&str> = bias
            .split(|c: char| !(c.is_alphanumeric() || c == '.' || c == '_'))
            .filter_map(|w| w.strip_prefix(&prefix))
            .collect();
        assert!(!keys.is_empty(), "{name}: {bias}");
        let params = p.integrator.parameters();
        for key in keys {
            assert!(
                params.iter().any(|q| q.name == key),
                "{name}: {key} in {bias}"
            );
        }
    }
}

/// `photon_maps()`: the maps as the integrator stores them, with the budgets in force.
#[test]
fn photon_maps_are_the_integrators_own() {
    let cancel = AtomicBool::new(false);
    let ctx =
        foton_core::integrator::RenderContext::new(2, &cancel, &foton_core::integrator::NoProgress);
    let p = prepared(
        "photon",
        &[
            "integrators.photon.global_photons=20000".into(),
            "integrators.photon.caustic_photons=3000".into(),
        ],
    );
    let maps = p.integrator.photon_maps(&p.scene, &ctx).unwrap();
    let names: Vec<&str> = maps.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["global", "caustic"]);
    assert_eq!((maps[0].emitted, maps[1].emitted), (20000, 3000));
    assert!(!maps[0].photons.is_empty());
    let power = p.scene.total_power();
    let stored: glam::Vec3 = maps[0]
        .photons
        .iter()
        .map(|ph| ph.power)
        .sum::<glam::Vec3>();
    // Every stored photon of the global map is on a surface (a unit normal).
    assert!(
        maps[0]
            .photons
            .iter()
            .all(|ph| (ph.normal.length() - 1.0).abs() < 0.02)
    );
    assert!(stored.x > 0.0, "{stored}");
    // Each diffuse hit stores the photon again: the total is the lights' power times the mean
    // number of diffuse hits, about 1 / (1 - rho) = 3 in this box (less what leaves through
    // its open front); a flux not divided by the photons emitted would be far outside.
    assert!(stored.x < 5.0 * power.x, "{stored} against {power}");

    let p = prepared("path", &[]);
    assert!(p.integrator.photon_maps(&p.scene, &ctx).unwrap().is_empty());
    let p = prepared("vpm", &["integrators.vpm.global_photons=5000".into()]);
    let names: Vec<String> = p
        .integrator
        .photon_maps(&p.scene, &ctx)
        .unwrap()
        .into_iter()
        .map(|m| m.name)
        .collect();
    assert_eq!(names, ["global", "caustic", "volume"]);
}

/// `ppb`'s maps count the photons of the passes that filled them: its surface photons come
/// from a pass of `surface_photons` (when that is more than `photons_per_iteration`), its
/// beams from a pass of `photons_per_iteration`.
#[test]
fn ppb_photon_maps_count_their_own_passes() {
    let cancel = AtomicBool::new(false);
    let ctx =
        foton_core::integrator::RenderContext::new(2, &cancel, &foton_core::integrator::NoProgress);
    let p = prepared(
        "ppb",
        &[
            "integrators.ppb.photons_per_iteration=500".into(),
            "integrators.ppb.surface_photons=4000".into(),
        ],
    );
    let maps = p.integrator.photon_maps(&p.scene, &ctx).unwrap();
    let names: Vec<&str> = maps.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["iteration", "beams"]);
    assert_eq!((maps[0].emitted, maps[1].emitted), (4000, 500));
    // The surface photons' flux is the lights' power over the 4000 emitted, times the mean
    // number of diffuse hits (about 3 in this box): over 500 it would be eight times that.
    let stored: glam::Vec3 = maps[0].photons.iter().map(|ph| ph.power).sum();
    let power = p.scene.total_power();
    assert!(
        stored.x > 0.0 && stored.x < 5.0 * power.x,
        "{stored} against {power}"
    );
}
