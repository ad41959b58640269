//! The published Mitsuba files kept in tests/corpus/fixtures (a licence-compatible part of
//! the corpus measured in docs/mitsuba-corpus.md): each opens with `--lenient`, and as written
//! each opens or is refused for the one reason listed here, with its file and line. A file
//! that starts to open, or is refused for something else, fails the test: the list is the
//! state of the reader on published files.

use foton_loader::mitsuba::read_xml;
use std::path::{Path, PathBuf};

/// Each fixture (relative to tests/corpus/fixtures) and, for one refused as written, the
/// line and what the error says.
const FIXTURES: &[(&str, Option<(u32, &str)>)] = &[
    (
        "BachiLi+lajolla_public/pixel_filter_test/pixel_filter_test.xml",
        None,
    ),
    ("RenderToolbox+mMitsuba/simpleScene.xml", None),
    (
        "RenderToolbox+mMitsuba/mitsubaPly/test.xml",
        Some((
            14,
            "`<texture type=\"vertexcolors\">`: this texture is not supported yet",
        )),
    ),
    ("mitsuba-renderer+mitsuba-blender/scenes/empty.xml", None),
    (
        "mitsuba-renderer+mitsuba-blender/scenes/film_hdrfilm.xml",
        None,
    ),
    (
        "mitsuba-renderer+mitsuba-blender/scenes/film_hdrfilm_crop.xml",
        None,
    ),
    (
        "mitsuba-renderer+mitsuba-blender/scenes/integrator_moment.xml",
        None,
    ),
    (
        "mitsuba-renderer+mitsuba-blender/scenes/integrator_path.xml",
        None,
    ),
    (
        "mitsuba-renderer+mitsuba-blender/scenes/rfilter_box.xml",
        None,
    ),
    (
        "mitsuba-renderer+mitsuba-blender/scenes/rfilter_gaussian.xml",
        None,
    ),
    (
        "mitsuba-renderer+mitsuba-blender/scenes/rfilter_tent.xml",
        None,
    ),
    (
        "mitsuba-renderer+mitsuba-blender/scenes/sampler_independent.xml",
        None,
    ),
    (
        "mitsuba-renderer+mitsuba-blender/scenes/sampler_multijitter.xml",
        None,
    ),
    (
        "mitsuba-renderer+mitsuba-blender/scenes/sampler_stratified.xml",
        None,
    ),
    ("mitsuba-renderer+mitsuba-blender/scenes/test1.xml", None),
];

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("corpus/fixtures")
}

#[test]
fn every_fixture_is_listed() {
    let mut found = Vec::new();
    let mut stack = vec![fixtures()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "xml") {
                let rel = p.strip_prefix(fixtures()).unwrap();
                found.push(rel.to_string_lossy().replace('\\', "/"));
            }
        }
    }
    found.sort();
    let mut listed: Vec<String> = FIXTURES.iter().map(|(f, _)| f.to_string()).collect();
    listed.sort();
    assert_eq!(found, listed);
}

#[test]
fn published_files_open_as_listed() {
    for (file, refusal) in FIXTURES {
        let path = fixtures().join(file);
        let written = read_xml(&path, &[], false);
        match (refusal, written) {
            (None, Ok(_)) => {}
            (None, Err(e)) => panic!("{file} does not open: {e}"),
            (Some((line, what)), Ok(_)) => {
                panic!(
                    "{file} opens as written: list it as opening (it was refused at {line}: {what})"
                )
            }
            (Some((line, what)), Err(e)) => {
                let e = e.to_string();
                let at = format!("{}:{line}:", path.display());
                assert!(e.contains(&at) && e.contains(what), "{file}: {e}");
            }
        }
        let (_, report) = read_xml(&path, &[], true)
            .unwrap_or_else(|e| panic!("{file} does not open with --lenient: {e}"));
        assert_eq!(
            report.left_out.is_empty(),
            refusal.is_none(),
            "{file}: lenient leaves out {:?}",
            report.left_out
        );
    }
}
