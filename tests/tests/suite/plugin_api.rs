//! The plugin API version follows its interface: core/src/integrator.rs (the `Integrator`
//! trait and what it hands and returns), core/src/param.rs and core/src/part.rs (two of the
//! types it hands and returns, below it so that `kernel` and `film` need not import it) and
//! core/src/plugin/declaration.rs (what a plugin exports). Their code, comments and spacing aside, is hashed; each API version records the
//! hash of the interface it stands for. Changing the interface without a new version (and a
//! new line below) fails this test, with the line to add.

use foton_core::plugin::PLUGIN_API_VERSION;
use foton_tests::repo_root;

/// (version, hash of the interface's code). Version 1 (before typed capabilities) was not
/// recorded; versions 2 and 3 hashed integrator.rs and declaration.rs only (param.rs and
/// part.rs were still in integrator.rs).
const API_HISTORY: &[(u32, &str)] = &[
    (2, "89a1756a6d9e7e27"),
    (3, "d7d1a31965b3deb3"),
    (4, "4ec6c05c6b1adb2a"),
    (5, "4340326f85839737"),
];

/// The code of a Rust file: comments (`//` to the end of the line, outside strings) and
/// whitespace removed, so that editing documentation does not change the interface.
fn code(text: &str) -> String {
    let mut out = String::new();
    for line in text.lines() {
        let mut in_string = false;
        let mut prev = ' ';
        let mut kept = String::new();
        for c in line.chars() {
            if c == '"' && prev != '\\' {
                in_string = !in_string;
            }
            if !in_string && c == '/' && prev == '/' {
                kept.pop();
                break;
            }
            kept.push(c);
            prev = c;
        }
        out.extend(kept.chars().filter(|c| !c.is_whitespace()));
    }
    out
}

/// FNV-1a, 64 bits: stable across Rust versions (unlike `DefaultHasher`).
fn fnv(text: &str) -> String {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for b in text.bytes() {
        h = (h ^ b as u64).wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

fn interface_hash() -> String {
    let read = |p: &str| std::fs::read_to_string(repo_root().join(p)).unwrap();
    let files = [
        "core/src/integrator.rs",
        "core/src/param.rs",
        "core/src/part.rs",
        "core/src/plugin/declaration.rs",
    ];
    fnv(&files.iter().map(|f| code(&read(f))).collect::<String>())
}

#[test]
fn the_plugin_api_version_follows_its_interface() {
    let hash = interface_hash();
    let &(latest, recorded) = API_HISTORY.last().unwrap();
    assert_eq!(
        latest, PLUGIN_API_VERSION,
        "PLUGIN_API_VERSION is {PLUGIN_API_VERSION} but the history ends at {latest}"
    );
    assert_eq!(
        recorded,
        hash,
        "the plugin interface (integrator.rs, param.rs, part.rs, plugin/declaration.rs) changed: set PLUGIN_API_VERSION to {} and add ({}, \"{hash}\") to API_HISTORY",
        latest + 1,
        latest + 1
    );
}

#[test]
fn comments_do_not_count_and_code_does() {
    let a = "pub trait T { // a comment\n    fn f(&self); }\n";
    let b = "/// documented\npub trait T {\n    fn f(&self);\n}\n";
    assert_eq!(code(a), code(b));
    assert_ne!(code(a), code("pub trait T { fn f(&self, x: u8); }"));
    assert_eq!(code("let s = \"a//b\"; // c"), "lets=\"a//b\";");
}
