//! `foton render --techniques` (issue 34, item 3): an estimator that combines sampling
//! techniques writes, besides the image, one EXR layer per technique (channels
//! `<technique>.R`, `.G`, `.B`), and the layers sum to the image, splats included, under the
//! same pixel filter and normalisation. Checked per pixel and channel on small renders, with
//! at least two layers lit (so that a layer that took everything would fail); integrators
//! without techniques refuse the option, as do outputs that cannot hold the layers.

use crate::bdpt::{CEILING_LIGHT, cornell};
use foton_loader::image::read_exr_channels;
use foton_tests::{foton_with_plugins, repo_root, temp_dir, write};
use std::collections::BTreeMap;
use std::path::Path;

/// Renders `scene` with `args` into `out` and reads its channels by name.
fn render_channels(scene: &Path, out: &Path, args: &[&str]) -> BTreeMap<String, Vec<f32>> {
    let mut all = vec![
        "render",
        scene.to_str().unwrap(),
        "-q",
        "--threads",
        "2",
        "-o",
        out.to_str().unwrap(),
    ];
    all.extend(args);
    let run = foton_with_plugins(&all);
    assert_eq!(run.code, 0, "{}{}", run.stdout, run.stderr);
    read_exr_channels(out).unwrap().2.into_iter().collect()
}

/// The layers' names (`<name>.R` ... channels, each with its three), checked against
/// `expected`; each layer's sum must be the image's R, G, B within float rounding, and at least
/// `lit` layers must hold light. Returns each layer's total.
fn assert_layers_sum_to_image(
    channels: &BTreeMap<String, Vec<f32>>,
    expected: &[String],
    lit: usize,
) -> BTreeMap<String, f64> {
    let mut names: Vec<String> = expected.to_vec();
    names.sort();
    let mut want: Vec<String> = vec!["B".into(), "G".into(), "R".into()];
    for n in &names {
        for c in ["R", "G", "B"] {
            want.push(format!("{n}.{c}"));
        }
    }
    want.sort();
    let have: Vec<String> = channels.keys().cloned().collect();
    assert_eq!(have, want, "the EXR's channels");
    let mut totals = BTreeMap::new();
    for c in ["R", "G", "B"] {
        let image = &channels[c];
        let mut sum = vec![0.0f64; image.len()];
        for n in &names {
            let layer = &channels[&format!("{n}.{c}")];
            for (s, v) in sum.iter_mut().zip(layer) {
                assert!(v.is_finite() && *v >= 0.0, "{n}.{c}: {v}");
                *s += *v as f64;
            }
            *totals.entry(n.clone()).or_insert(0.0) += layer.iter().map(|&v| v as f64).sum::<f64>();
        }
        for (i, (s, v)) in sum.iter().zip(image).enumerate() {
            let v = *v as f64;
            assert!(
                (s - v).abs() <= 1e-4 * v.abs() + 1e-6,
                "pixel {i} channel {c}: layers sum to {s}, the image is {v}"
            );
        }
    }
    let lit_layers = totals.values().filter(|&&t| t > 0.0).count();
    assert!(
        lit_layers >= lit,
        "only {lit_layers} layers lit: {totals:?}"
    );
    totals
}

/// bdpt's strategies of lengths 1 and 2 (`--techniques-depth 2`), then `rest`.
fn bdpt_names_depth_2() -> Vec<String> {
    ["s0t2", "s1t1", "s0t3", "s1t2", "s2t1", "rest"]
        .map(String::from)
        .to_vec()
}

/// bdpt: every (s, t) strategy's MIS-weighted share, the t = 1 ones splatted through a
/// gaussian filter's footprint; the image is the one a render without `--techniques` makes.
#[test]
fn bdpt_strategies_sum_to_the_image() {
    let dir = temp_dir("techniques-bdpt");
    let scene = write(
        &dir,
        "box.toml",
        &cornell("white", "white", "", CEILING_LIGHT),
    );
    let set = [
        "--integrator",
        "bdpt",
        "--spp",
        "4",
        "--set",
        "film.width=24",
        "--set",
        "film.height=24",
        "--set",
        "film.filter=\"gaussian\"",
    ];
    let mut args = set.to_vec();
    args.extend(["--techniques", "--techniques-depth", "2"]);
    let layered = render_channels(&scene, &dir.join("layers.exr"), &args);
    let totals = assert_layers_sum_to_image(&layered, &bdpt_names_depth_2(), 2);
    // Light tracing's and the connections' shares, and the longer paths pooled in `rest`.
    for name in ["s0t2", "s1t2", "s2t1", "rest"] {
        assert!(totals[name] > 0.0, "{name} is black: {totals:?}");
    }
    // The image itself is the plain render's, bit for bit.
    let plain = render_channels(&scene, &dir.join("plain.exr"), &set);
    for c in ["R", "G", "B"] {
        assert_eq!(layered[c], plain[c], "channel {c}");
    }
}

/// With the default depth (5) and max_depth 8: the pyramid's rows 1 to 5 (2 + 3 + ... + 6
/// strategies) and `rest`; with a depth past max_depth + 1, no `rest`.
#[test]
fn bdpt_default_depth_names_the_pyramid() {
    let dir = temp_dir("techniques-bdpt-depth");
    let scene = write(
        &dir,
        "box.toml",
        &cornell("white", "white", "", CEILING_LIGHT),
    );
    let small = [
        "--integrator",
        "bdpt",
        "--spp",
        "1",
        "--set",
        "film.width=8",
        "--set",
        "film.height=8",
        "--techniques",
    ];
    let mut names = Vec::new();
    for k in 1..=5u32 {
        for s in 0..=k {
            names.push(format!("s{s}t{}", k + 1 - s));
        }
    }
    names.push("rest".into());
    assert_eq!(names.len(), 21);
    let grid = dir.join("grid.png");
    let mut args = small.to_vec();
    args.extend(["--techniques-grid", grid.to_str().unwrap()]);
    let channels = render_channels(&scene, &dir.join("a.exr"), &args);
    assert_layers_sum_to_image(&channels, &names, 2);
    // The pyramid: 5 rows of 6 cells, then `rest` and the image; 8 x 8 tiles under labels.
    let (w, h, _) = foton_loader::image::read_image(&grid).unwrap();
    assert!(w > 6 * 8 && h > 6 * 8, "{w} x {h}");
    let mut args = small.to_vec();
    args.extend(["--set", "render.max_depth=1"]);
    let channels = render_channels(&scene, &dir.join("b.exr"), &args);
    let short: Vec<String> = ["s0t2", "s1t1", "s0t3", "s1t2", "s2t1"]
        .map(String::from)
        .to_vec();
    assert_layers_sum_to_image(&channels, &short, 2);
}

/// What cannot show techniques refuses the option with the reason: an integrator that is one
/// estimator, a PNG, a part.
#[test]
fn techniques_are_refused_where_they_cannot_be_written() {
    let dir = temp_dir("techniques-refused");
    let scene = write(
        &dir,
        "box.toml",
        &cornell("white", "white", "", CEILING_LIGHT),
    );
    let scene = scene.to_str().unwrap();
    let out = dir.join("x.exr");
    let out = out.to_str().unwrap();
    let png = dir.join("x.png");
    let png = png.to_str().unwrap();
    for (args, reason) in [
        (
            vec!["--integrator", "path", "-o", out],
            "path has no techniques",
        ),
        (
            vec!["--integrator", "bdpt", "-o", png],
            "name the output .exr",
        ),
        (
            vec!["--integrator", "bdpt", "-o", out, "--part", "0/2"],
            "--techniques and --part",
        ),
    ] {
        let mut all = vec!["render", scene, "-q", "--techniques"];
        all.extend(args);
        let run = foton_with_plugins(&all);
        assert_ne!(run.code, 0, "{all:?} was not refused");
        assert!(run.stderr.contains(reason), "{all:?}: {}", run.stderr);
    }
    assert!(!Path::new(out).exists() && !Path::new(png).exists());
}

/// A Cornell box with a glass sphere (caustics) and a white one.
fn glass_box(dir: &Path) -> std::path::PathBuf {
    let glass = "\n[materials.glass]\ntype = \"dielectric\"\nior = 1.5\n";
    write(
        dir,
        "glass.toml",
        &cornell("glass", "white", glass, CEILING_LIGHT),
    )
}

/// photon: emission seen from the camera, direct light, the caustic map and the global map,
/// or the final gather in its place; the image is the plain render's, bit for bit.
#[test]
fn photon_terms_sum_to_the_image() {
    let dir = temp_dir("techniques-photon");
    let scene = glass_box(&dir);
    for final_gather in [false, true] {
        let gather = format!("integrators.photon.final_gather={final_gather}");
        let set = [
            "--integrator",
            "photon",
            "--spp",
            "2",
            "--set",
            "film.width=24",
            "--set",
            "film.height=24",
            "--set",
            "integrators.photon.global_photons=5000",
            "--set",
            "integrators.photon.caustic_photons=5000",
            "--set",
            "integrators.photon.gather_rays=2",
            "--set",
            &gather,
        ];
        let mut args = set.to_vec();
        args.push("--techniques");
        let layered = render_channels(&scene, &dir.join("layers.exr"), &args);
        let last = if final_gather {
            "final_gather"
        } else {
            "global"
        };
        let names = ["emission", "direct", "caustic", last].map(String::from);
        let totals = assert_layers_sum_to_image(&layered, &names, 4);
        assert!(totals[last] > 0.0, "{totals:?}");
        let plain = render_channels(&scene, &dir.join("plain.exr"), &set);
        for c in ["R", "G", "B"] {
            assert_eq!(
                layered[c], plain[c],
                "final_gather = {final_gather}, channel {c}"
            );
        }
    }
}

/// Renders `scene` into `dir` with `integrator` and `set` (`--set` values), with and without
/// `--techniques`: the layers are `names` and sum to the image, `lit` of them hold light,
/// and the image is the plain render's, bit for bit. Returns each layer's total.
fn check_integrator(
    scene: &Path,
    dir: &Path,
    integrator: &str,
    set: &[&str],
    names: &[&str],
    lit: &[&str],
) -> BTreeMap<String, f64> {
    let mut plain_args = vec!["--integrator", integrator];
    for s in set {
        plain_args.extend(["--set", s]);
    }
    let mut args = plain_args.clone();
    args.push("--techniques");
    let layered = render_channels(scene, &dir.join(format!("{integrator}-layers.exr")), &args);
    let names: Vec<String> = names.iter().map(|n| n.to_string()).collect();
    let totals = assert_layers_sum_to_image(&layered, &names, lit.len());
    for name in lit {
        assert!(
            totals[*name] > 0.0,
            "{integrator}: {name} is black: {totals:?}"
        );
    }
    let plain = render_channels(
        scene,
        &dir.join(format!("{integrator}-plain.exr")),
        &plain_args,
    );
    for c in ["R", "G", "B"] {
        assert_eq!(layered[c], plain[c], "{integrator}: channel {c}");
    }
    totals
}

/// vcm: connections, merges, camera paths reaching the light and light tracing (the splats).
#[test]
fn vcm_techniques_sum_to_the_image() {
    let dir = temp_dir("techniques-vcm");
    let scene = glass_box(&dir);
    let set = [
        "film.width=24",
        "film.height=24",
        "integrators.vcm.iterations=2",
        "film.filter=\"tent\"",
    ];
    let names = ["connection", "merging", "emission", "light_tracing"];
    check_integrator(&scene, &dir, "vcm", &set, &names, &names);
}

/// vpm in fog: emission, the surface estimates and the volume's (photon points, or photon
/// beams).
#[test]
fn vpm_techniques_sum_to_the_image() {
    let dir = temp_dir("techniques-vpm");
    let scene = repo_root().join("scenes/cornell-fog.toml");
    for (estimate, volume) in [("march", "volume_point"), ("beams", "beam")] {
        let estimate = format!("integrators.vpm.estimate=\"{estimate}\"");
        let set = [
            "film.width=16",
            "film.height=16",
            "render.spp=2",
            "integrators.vpm.global_photons=4000",
            "integrators.vpm.caustic_photons=2000",
            "integrators.vpm.volume_photons=4000",
            &estimate,
        ];
        let names = ["emission", "direct", "caustic", "global", volume];
        check_integrator(
            &scene,
            &dir,
            "vpm",
            &set,
            &names,
            &["direct", "global", volume],
        );
    }
}

/// ppb in fog: emission, the photon beams, direct light and the surface photons.
#[test]
fn ppb_techniques_sum_to_the_image() {
    let dir = temp_dir("techniques-ppb");
    let scene = repo_root().join("scenes/cornell-fog.toml");
    let set = [
        "film.width=16",
        "film.height=16",
        "integrators.ppb.iterations=2",
        "integrators.ppb.photons_per_iteration=1000",
        "integrators.ppb.surface_photons=4000",
    ];
    let names = ["emission", "beam", "direct", "surface"];
    check_integrator(
        &scene,
        &dir,
        "ppb",
        &set,
        &names,
        &["beam", "direct", "surface"],
    );
}
