//! Kernel plugins: the example in plugins/epanechnikov is compiled with the C compiler, found on
//! the plugin search path, normalised by core and used in a render; broken kernel plugins are
//! refused with clear errors.

use foton_core::kernel::NormalizedKernel;
use foton_core::plugin::Registry;
use foton_tests::stats::{Tolerance, assert_blocks_agree, film_of, rel_err};
use foton_tests::{foton, plugin_dir, repo_root, temp_dir, write};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Compiles C source into `dir/libfoton_<name>.so` with the system C compiler (always
/// present: Rust links with it).
fn compile(dir: &Path, name: &str, source: &Path) -> PathBuf {
    let out = dir.join(format!("libfoton_{name}.so"));
    let status = Command::new(std::env::var("CC").unwrap_or_else(|_| "cc".into()))
        .args(["-shared", "-fPIC", "-O2", "-I"])
        .arg(repo_root().join("plugins"))
        .arg("-o")
        .arg(&out)
        .arg(source)
        .status()
        .expect(
            "a C compiler (cc) is needed to build the kernel plugin; Rust needs it to link too",
        );
    assert!(status.success(), "cc failed on {}", source.display());
    out
}

fn epanechnikov(dir: &Path) -> PathBuf {
    compile(
        dir,
        "epanechnikov",
        &repo_root().join("plugins/epanechnikov/epanechnikov.c"),
    )
}

#[test]
fn example_kernel_plugin_is_found_and_normalised() {
    let dir = temp_dir("kernel-plugin");
    epanechnikov(&dir);
    let reg = Registry::discover(std::slice::from_ref(&dir));
    assert!(reg.problems.is_empty(), "{:?}", reg.problems);
    let plugin = reg
        .kernel("epanechnikov")
        .expect("the plugin is listed")
        .clone();
    let k = NormalizedKernel::new(Box::new(plugin)).unwrap();
    // Closed forms: over the unit disc the integral of 1 - t^2 is pi/2, over the unit ball 8 pi/15.
    assert!((k.weight_2d(0.0, 1.0) as f64 - 2.0 / PI).abs() < 1e-6);
    assert!((k.weight_3d(0.0, 1.0) as f64 - 15.0 / (8.0 * PI)).abs() < 1e-6);
    // And numerically, on a radius of 0.3, by the midpoint rule in polar coordinates.
    let r = 0.3f32;
    let n = 20_000;
    let (mut disc, mut ball) = (0.0f64, 0.0f64);
    for i in 0..n {
        let d = (i as f64 + 0.5) / n as f64 * r as f64;
        let dd = r as f64 / n as f64;
        disc += k.weight_2d(d as f32, r) as f64 * 2.0 * PI * d * dd;
        ball += k.weight_3d(d as f32, r) as f64 * 4.0 * PI * d * d * dd;
    }
    assert!(
        (disc - 1.0).abs() < 1e-3 && (ball - 1.0).abs() < 1e-3,
        "{disc} {ball}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn render_with_the_kernel_plugin_from_the_search_path() {
    let dir = temp_dir("kernel-render");
    epanechnikov(&dir);
    let scene = repo_root().join("scenes/caustics.toml");
    let out = dir.join("out.exr");
    let plugins = plugin_dir();
    let common = [
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--set",
        "film.width=24",
        "--set",
        "film.height=24",
        "--set",
        "render.spp=4",
        "--set",
        "integrators.photon.global_photons=50000",
        "--set",
        "integrators.photon.caustic_photons=50000",
        "--plugin-dir",
        dir.to_str().unwrap(),
        "--plugin-dir",
        plugins.to_str().unwrap(),
    ];
    let mut images = Vec::new();
    for kernel in ["epanechnikov", "box"] {
        let set = format!("integrators.photon.kernel={kernel}");
        let mut args = common.to_vec();
        args.extend(["--set", &set]);
        let run = foton(&args);
        assert_eq!(run.code, 0, "{}", run.stderr);
        assert!(
            run.stdout.contains(&format!("kernel = {kernel}")),
            "{}",
            run.stdout
        );
        let (w, h, px) = foton_loader::image::read_image(&out).unwrap();
        images.push(film_of(w, h, &px));
    }
    // Both kernels are normalised: the image means agree (the kernels only differ in blur).
    let (a, b) = (images[0].mean(), images[1].mean());
    assert!(rel_err(a, b) < 0.03, "{a} vs {b}");
    // And block by block (3x3 blocks of 8x8 pixels) at the same 3 %: the two renders share
    // their photons and camera samples, so what differs is the kernels' weighting inside
    // the same discs (4 standard errors of the block mean of the pixel-wise difference are
    // allowed on top). The floor (0.5 % of the image mean) is for blocks black in a channel.
    assert_blocks_agree(
        "epanechnikov vs box kernel",
        &images[0],
        &images[1],
        3,
        Tolerance {
            rel: 0.03,
            z: 4.0,
            floor: 0.005 * b.max_element() as f64,
        },
    );
    let _ = std::fs::remove_dir_all(dir);
}

fn broken_kernel(dir: &Path, name: &str, version: u32, weight: &str) -> PathBuf {
    let src = write(
        dir,
        &format!("{name}.c"),
        &format!(
            "#include \"foton_kernel.h\"\nstatic double w(double t) {{ return {weight}; }}\n\
             FOTON_KERNEL_EXPORT const FotonKernelPlugin foton_kernel_plugin = {{ {version}, \"{name}\", w }};\n"
        ),
    );
    compile(dir, name, &src)
}

fn render_with_kernel(dir: &Path, kernel: &str) -> foton_tests::Run {
    let scene = repo_root().join("scenes/caustics.toml");
    let out = dir.join("out.png");
    let set = format!("integrators.photon.kernel={kernel}");
    foton(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--set",
        &set,
        "--plugin-dir",
        dir.to_str().unwrap(),
        "--plugin-dir",
        plugin_dir().to_str().unwrap(),
    ])
}

#[test]
fn negative_or_non_finite_kernels_are_refused() {
    let dir = temp_dir("kernel-bad");
    broken_kernel(&dir, "negative", 1, "t - 0.5");
    broken_kernel(&dir, "infinite", 1, "1.0 / t");
    for name in ["negative", "infinite"] {
        let run = render_with_kernel(&dir, name);
        assert_eq!(run.code, 1);
        assert!(
            run.stderr.contains("integrators.photon.kernel"),
            "{}",
            run.stderr
        );
        assert!(
            run.stderr.contains(&format!("kernel `{name}` is invalid")),
            "{}",
            run.stderr
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn kernel_plugin_with_another_version_is_refused() {
    let dir = temp_dir("kernel-version");
    let file = broken_kernel(&dir, "future", 7, "1.0");
    let reg = Registry::discover(std::slice::from_ref(&dir));
    assert!(reg.kernel("future").is_none());
    let problem = reg
        .problems
        .iter()
        .find(|p| p.file == file)
        .expect("reported");
    assert!(
        problem.message.contains("kernel API version 7"),
        "{}",
        problem.message
    );
    let run = render_with_kernel(&dir, "future");
    assert_eq!(run.code, 1);
    assert!(
        run.stderr.contains("unknown kernel \"future\""),
        "{}",
        run.stderr
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn unknown_kernel_lists_the_kernels_found() {
    let dir = temp_dir("kernel-unknown");
    epanechnikov(&dir);
    let run = render_with_kernel(&dir, "triangle");
    assert_eq!(run.code, 1);
    for name in ["box", "cone", "gaussian", "epanechnikov (plugin)"] {
        assert!(run.stderr.contains(name), "{}", run.stderr);
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// A kernel plugin checked at 4097 points could return anything between them. These two give
/// Epanechnikov's 1 - t^2 at the checked points t = i / 4096 and a NaN or a negative weight
/// everywhere else: every integrator that reads kernels fails with an error that names the
/// kernel and the bad weight, instead of rendering with it (or, for `sppm`, keeping a NaN in
/// its pixel statistics).
#[test]
fn a_kernel_plugin_bad_between_the_checked_points_is_an_error() {
    let dir = temp_dir("kernel-between");
    for (name, elsewhere) in [("nan_between", "0.0 / 0.0"), ("negative_between", "-5.0")] {
        let weight =
            format!("(t * 4096.0 == (double)(long)(t * 4096.0)) ? 1.0 - t * t : {elsewhere}");
        broken_kernel(&dir, name, 1, &weight);
    }
    let scene = repo_root().join("scenes/caustics.toml");
    let out = dir.join("out.exr");
    for integrator in ["photon", "sppm"] {
        for (name, shown) in [("nan_between", "NaN"), ("negative_between", "-5")] {
            let set = format!("integrators.{integrator}.kernel={name}");
            // Only the rendering integrator's table: a --set nothing reads is an error.
            let budget = match integrator {
                "sppm" => [
                    "integrators.sppm.iterations=2",
                    "integrators.sppm.photons_per_iteration=5000",
                ],
                // Enough caustic photons for the scene's k (200).
                _ => [
                    "integrators.photon.global_photons=5000",
                    "integrators.photon.caustic_photons=50000",
                ],
            };
            let run = foton(&[
                "render",
                scene.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "--integrator",
                integrator,
                "--set",
                "film.width=8",
                "--set",
                "film.height=8",
                "--set",
                "render.spp=1",
                "--set",
                budget[0],
                "--set",
                budget[1],
                "--set",
                &set,
                "--plugin-dir",
                dir.to_str().unwrap(),
                "--plugin-dir",
                plugin_dir().to_str().unwrap(),
            ]);
            assert_eq!(run.code, 1, "{integrator}, {name}: {}", run.stderr);
            let expect = format!("kernel `{name}` returned w(");
            assert!(
                run.stderr.contains(&expect) && run.stderr.contains(&format!(") = {shown}")),
                "{integrator}, {name}: {}",
                run.stderr
            );
        }
    }
    let _ = std::fs::remove_dir_all(dir);
}
