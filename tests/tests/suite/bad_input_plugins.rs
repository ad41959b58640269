//! Bad input, plugins: files that are not foton plugins, plugins built against another
//! foton-core or plugin API, and plugins that panic. The helpers and the base scene are
//! bad_input.rs's.

use crate::bad_input::{BASE, CREATE_PANIC, RENDER_PANIC, SceneFile, assert_error, foton, show};
use foton_tests::{Run, plugin_dir, temp_dir, write};
use std::path::{Path, PathBuf};

// ---------------------------------------------------------------------------------------------
// Plugins
// ---------------------------------------------------------------------------------------------

fn lib_name(stem: &str) -> String {
    format!(
        "{}foton_{stem}{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    )
}

/// A real shared library that is not a foton plugin: a proc-macro library cargo built next to
/// the test executable, or else the system's libm. None if neither can be found.
fn some_shared_library() -> Option<PathBuf> {
    let (prefix, suffix) = (std::env::consts::DLL_PREFIX, std::env::consts::DLL_SUFFIX);
    let mut candidates: Vec<PathBuf> = std::fs::read_dir(plugin_dir())
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name().and_then(|n| n.to_str()).is_some_and(|n| {
                // Not the Python extension (lib_foton.so, after a wheel build): it needs the
                // interpreter's symbols and cannot be loaded by a program.
                n.starts_with(prefix)
                    && n.ends_with(suffix)
                    && !n.starts_with("libfoton")
                    && !n.starts_with("lib_foton")
            })
        })
        .collect();
    candidates.sort();
    if let Some(p) = candidates.into_iter().next() {
        return Some(p);
    }
    for p in [
        "/lib/x86_64-linux-gnu/libm.so.6",
        "/usr/lib/x86_64-linux-gnu/libm.so.6",
        "/lib/aarch64-linux-gnu/libm.so.6",
        "/usr/lib64/libm.so.6",
        "/lib64/libm.so.6",
    ] {
        if Path::new(p).is_file() {
            return Some(p.into());
        }
    }
    let out = std::process::Command::new("ldconfig")
        .arg("-p")
        .output()
        .ok()?;
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter(|l| l.trim_start().starts_with("libm.so"))
        .filter_map(|l| l.split(" => ").nth(1))
        .map(|p| PathBuf::from(p.trim()))
        .find(|p| p.is_file())
}

/// A C string literal for `s` (NULL for None).
fn c_literal(s: Option<&str>) -> String {
    let Some(s) = s else {
        return "NULL".into();
    };
    let mut out = String::from("\"");
    for b in s.bytes() {
        match b {
            b'"' | b'\\' => {
                out.push('\\');
                out.push(b as char);
            }
            0x20..=0x7e => out.push(b as char),
            _ => out.push_str(&format!("\\{b:03o}")),
        }
    }
    out.push('"');
    out
}

/// What a C imitation of an integrator plugin declares.
struct FakeDeclaration<'a> {
    api_version: u32,
    core_version: Option<&'a str>,
    rustc_version: Option<&'a str>,
    build_id: Option<&'a str>,
    name: &'a str,
}

/// Compiles a C library exporting `FOTON_INTEGRATOR_PLUGIN` with the layout of
/// `foton_core::plugin::IntegratorDeclaration` into `dir/libfoton_STEM.so`. Panics with a clear
/// message when there is no C compiler.
fn build_c_plugin(dir: &Path, stem: &str, decl: &FakeDeclaration<'_>) -> PathBuf {
    let source = format!(
        r#"#include <stddef.h>
#include <stdint.h>
struct foton_integrator_declaration {{
    uint32_t api_version;
    const char *core_version;
    const char *rustc_version;
    const char *build_id;
    const char *name;
    const char *description;
    void (*create)(void);
}};
static void create(void) {{}}
const struct foton_integrator_declaration FOTON_INTEGRATOR_PLUGIN = {{
    {api}, {core}, {rustc}, {build}, {name}, "a C imitation of a plugin (test)", create
}};
"#,
        api = decl.api_version,
        core = c_literal(decl.core_version),
        rustc = c_literal(decl.rustc_version),
        build = c_literal(decl.build_id),
        name = c_literal(Some(decl.name)),
    );
    let src = write(dir, &format!("{stem}.c"), &source);
    let lib = dir.join(lib_name(stem));
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let output = std::process::Command::new(&cc)
        .args(["-shared", "-fPIC", "-o"])
        .arg(&lib)
        .arg(&src)
        .output()
        .unwrap_or_else(|e| {
            panic!(
                "cannot run the C compiler `{cc}` ({e}); these tests need one to build fake \
                 plugins (install cc, or set CC)"
            )
        });
    assert!(
        output.status.success(),
        "`{cc} -shared -fPIC` failed on {}:\n{}",
        src.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    lib
}

/// The line of `foton plugins --plugin-dir DIR` that reports `file` as skipped.
fn skipped_line(dir: &Path, file: &Path) -> String {
    let run = foton(&["plugins", "--plugin-dir", dir.to_str().unwrap()]);
    assert_eq!(run.code, 0, "{}", show(&run));
    let shown = file.display().to_string();
    run.stdout
        .lines()
        .find(|l| l.contains(&shown))
        .unwrap_or_else(|| panic!("{shown} is not listed:\n{}", show(&run)))
        .to_string()
}

/// `foton render SCENE --integrator NAME --plugin-dir DIR` must fail, naming `file` and `words`.
fn assert_integrator_refused(dir: &Path, name: &str, file: &Path, words: &[&str]) {
    let scene = SceneFile::new(&format!("refused-{name}"), BASE);
    let run = scene.render(&["--integrator", name, "--plugin-dir", dir.to_str().unwrap()]);
    let shown = file.display().to_string();
    let mut needles = vec![
        format!("no integrator plugin named `{name}`"),
        format!("skipped {shown}"),
    ];
    needles.extend(words.iter().map(|w| w.to_string()));
    let needles: Vec<&str> = needles.iter().map(String::as_str).collect();
    assert_error(&run, &needles);
}

#[test]
fn files_that_are_not_foton_plugins_are_skipped_with_a_reason() {
    let dir = temp_dir("not-plugins");
    let garbage = write(
        &dir,
        &lib_name("garbage"),
        "this is not a shared library, just text long enough to hold an ELF header\n",
    );
    let line = skipped_line(&dir, &garbage);
    assert!(
        line.starts_with("skipped") && line.contains("cannot be loaded"),
        "{line}"
    );
    assert_integrator_refused(&dir, "garbage", &garbage, &["cannot be loaded"]);

    match some_shared_library() {
        Some(real) => {
            let fake = dir.join(lib_name("fake"));
            std::fs::copy(&real, &fake).unwrap();
            let line = skipped_line(&dir, &fake);
            assert!(
                line.starts_with("skipped")
                    && line.contains("not a foton plugin")
                    && line.contains("FOTON_INTEGRATOR_PLUGIN"),
                "{} (a copy of {}) is not skipped as not a plugin: {line}",
                fake.display(),
                real.display()
            );
            assert_integrator_refused(&dir, "fake", &fake, &["not a foton plugin"]);
        }
        None => eprintln!(
            "no shared library found to copy (no proc-macro library next to the test \
             executable, no libm): only the garbage file was tried"
        ),
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Core bug: the reason given for a file that cannot be loaded is libloading's bare
/// "dlopen failed": the dynamic loader's own explanation (here "invalid ELF header"), which is
/// the error's `source()`, is dropped.
#[test]
fn unloadable_plugin_reason_says_why() {
    let dir = temp_dir("garbage-reason");
    let garbage = write(
        &dir,
        &lib_name("garbage"),
        "this is not a shared library, just text long enough to hold an ELF header\n",
    );
    let line = skipped_line(&dir, &garbage);
    assert!(
        line.contains("ELF header"),
        "the reason does not say what is wrong with the file: {line}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn plugin_built_against_another_core_is_refused() {
    let core = foton_core::CORE_VERSION;
    let rustc = foton_core::RUSTC_VERSION;
    let build = foton_core::BUILD_ID;
    let cases = [
        (
            "othercore",
            FakeDeclaration {
                api_version: foton_core::plugin::PLUGIN_API_VERSION,
                core_version: Some("0.0.0-other"),
                rustc_version: Some(rustc),
                build_id: Some(build),
                name: "othercore",
            },
            "foton-core version",
            "0.0.0-other",
            core,
        ),
        (
            "otherrustc",
            FakeDeclaration {
                api_version: foton_core::plugin::PLUGIN_API_VERSION,
                core_version: Some(core),
                rustc_version: Some("rustc 0.0.0-other"),
                build_id: Some(build),
                name: "otherrustc",
            },
            "rustc version",
            "rustc 0.0.0-other",
            rustc,
        ),
        (
            "otherbuild",
            FakeDeclaration {
                api_version: foton_core::plugin::PLUGIN_API_VERSION,
                core_version: Some(core),
                rustc_version: Some(rustc),
                build_id: Some("0000000000000000-other"),
                name: "otherbuild",
            },
            "core build identifier",
            "0000000000000000-other",
            build,
        ),
    ];
    let dir = temp_dir("other-core");
    for (stem, decl, what, theirs, ours) in &cases {
        let lib = build_c_plugin(&dir, stem, decl);
        let expected = format!("built against {what} `{theirs}`, but this foton has `{ours}`");
        let line = skipped_line(&dir, &lib);
        assert!(
            line.starts_with("skipped") && line.contains(&expected),
            "expected `{expected}` in: {line}"
        );
        assert_integrator_refused(&dir, stem, &lib, &[&expected, "rebuild the plugin"]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn plugin_with_another_api_version_is_refused() {
    let dir = temp_dir("other-api");
    let decl = FakeDeclaration {
        api_version: 999,
        core_version: Some(foton_core::CORE_VERSION),
        rustc_version: Some(foton_core::RUSTC_VERSION),
        build_id: Some(foton_core::BUILD_ID),
        name: "api999",
    };
    let lib = build_c_plugin(&dir, "api999", &decl);
    let expected = format!(
        "plugin API version 999, but this foton expects {}",
        foton_core::plugin::PLUGIN_API_VERSION
    );
    let line = skipped_line(&dir, &lib);
    assert!(line.contains(&expected), "expected `{expected}` in: {line}");
    assert_integrator_refused(&dir, "api999", &lib, &[&expected]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn plugin_declaration_with_a_null_version_is_refused() {
    let dir = temp_dir("null-version");
    let decl = FakeDeclaration {
        api_version: foton_core::plugin::PLUGIN_API_VERSION,
        core_version: None,
        rustc_version: Some(foton_core::RUSTC_VERSION),
        build_id: Some(foton_core::BUILD_ID),
        name: "nullcore",
    };
    let lib = build_c_plugin(&dir, "nullcore", &decl);
    let line = skipped_line(&dir, &lib);
    assert!(
        line.contains("its declaration has no foton-core version"),
        "{line}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `foton render` with the `panicky` plugin set to panic in `panic_in`.
fn render_panicky(name: &str, panic_in: &str) -> (SceneFile, Run) {
    let scene = SceneFile::new(name, BASE);
    let set = format!("integrators.panicky.panic_in={panic_in}");
    let run = scene.render(&["--integrator", "panicky", "--set", &set]);
    (scene, run)
}

/// After a plugin panicked, the process is still alive and renders normally.
fn assert_still_works(scene: &SceneFile) {
    let run = scene.render(&[]);
    assert_eq!(run.code, 0, "after a plugin panic:\n{}", show(&run));
}

#[test]
fn panic_in_plugin_create_is_an_error() {
    // The value quoted as TOML, and bare (taken as a string).
    for value in ["\"create\"", "create"] {
        let (scene, run) = render_panicky("panic-create", value);
        assert_error(&run, &["panicked", CREATE_PANIC]);
        assert_still_works(&scene);
    }
}

#[test]
fn panic_in_plugin_render_is_an_error() {
    let (scene, run) = render_panicky("panic-render", "\"render\"");
    assert_error(&run, &["panicked", RENDER_PANIC, "panicky"]);
    assert!(!scene.dir.join("out.png").exists(), "an image was written");
    assert_still_works(&scene);
}

/// Core bug: a panic in a plugin's `create` is reported as "render failed: integrator creation
/// panicked: ..." without saying which plugin (or file) panicked.
#[test]
fn panic_in_plugin_create_names_the_plugin() {
    let (_scene, run) = render_panicky("panic-create-name", "\"create\"");
    assert_error(&run, &["panicked", CREATE_PANIC]);
    assert!(
        run.stderr.contains("panicky") || run.stderr.contains("foton_test_panicky"),
        "the error does not say which plugin panicked:\n{}",
        show(&run)
    );
}

#[test]
fn bad_plugin_parameter_is_a_scene_error() {
    let scene = SceneFile::new(
        "panicky-bad-parameter",
        &format!("{BASE}\n[integrators.panicky]\npanic_in = \"elsewhere\"\n"),
    );
    let run = scene.render(&["--integrator", "panicky"]);
    scene.assert_scene_error(
        &run,
        "panic_in = \"elsewhere\"",
        "integrators.panicky.panic_in",
        &["unknown value \"elsewhere\"", "create, render"],
    );
}
