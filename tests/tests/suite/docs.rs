//! The docs cannot drift from what they describe. The Rust blocks of docs/plugins.md compile
//! (foton-core includes the file as doc-tests); here: the blocks that quote core's sources
//! ("as it is in `core/src/...`") are those sources, the `normals` listing is its file, and
//! the lists of integrators name the plugins `foton plugins` finds.

use foton_tests::{registry, repo_root};
use std::collections::BTreeSet;

/// The code of Rust text: comments (`//` to the end of the line, doc comments included) and
/// whitespace removed.
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

/// The Rust blocks of a Markdown text: (the text before the block, the block's lines without
/// rustdoc's hidden `# ` lines).
fn rust_blocks(markdown: &str) -> Vec<(String, String)> {
    let lines: Vec<&str> = markdown.lines().collect();
    let mut blocks = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        if lines[i].trim() == "```rust" {
            let before = lines[i.saturating_sub(4)..i].join("\n");
            let mut body = Vec::new();
            i += 1;
            while i < lines.len() && lines[i].trim() != "```" {
                let l = lines[i];
                if !(l.trim() == "#" || l.trim_start().starts_with("# ")) {
                    body.push(l);
                }
                i += 1;
            }
            blocks.push((before, body.join("\n")));
        }
        i += 1;
    }
    blocks
}

/// The source files a paragraph names in backticks (`core/src/integrator.rs`).
fn named_sources(text: &str) -> Vec<String> {
    text.split('`')
        .skip(1)
        .step_by(2)
        .filter(|s| s.ends_with(".rs") && !s.contains(' '))
        .map(str::to_string)
        .collect()
}

/// The top-level items of a block of Rust code: split where a line starts an item at the left
/// margin (after any doc comments and attributes).
fn items(block: &str) -> Vec<String> {
    let mut items: Vec<String> = Vec::new();
    let mut current = String::new();
    let mut in_item = false;
    for line in block.lines() {
        let starts = !line.starts_with(' ') && !line.starts_with('}') && !line.is_empty();
        let header = line.starts_with("///") || line.starts_with("#[");
        if starts && !header && in_item && !current.is_empty() {
            items.push(std::mem::take(&mut current));
        }
        if starts && !header {
            in_item = true;
        }
        current.push_str(line);
        current.push('\n');
    }
    if !current.trim().is_empty() {
        items.push(current);
    }
    items
}

#[test]
fn plugins_md_quotes_core_as_it_is() {
    let root = repo_root();
    let doc = std::fs::read_to_string(root.join("docs/plugins.md")).unwrap();
    let mut quoted = 0;
    for (before, block) in rust_blocks(&doc) {
        let sources = named_sources(&before);
        if sources.is_empty() || sources.iter().any(|s| s.starts_with("integrators/normals")) {
            continue;
        }
        let mut source = String::new();
        for s in &sources {
            let text = std::fs::read_to_string(root.join(s))
                .unwrap_or_else(|e| panic!("docs/plugins.md names {s}: {e}"));
            source.push_str(&code(&text));
        }
        for item in items(&block) {
            assert!(
                source.contains(&code(&item)),
                "docs/plugins.md quotes this from {sources:?}, but it is not there:\n{item}"
            );
        }
        quoted += 1;
    }
    // The trait, the render context, the typed capabilities and the declaration.
    assert!(quoted >= 4, "only {quoted} quotations of core found");
}

#[test]
fn plugins_md_lists_the_normals_plugin_as_it_is() {
    let root = repo_root();
    let doc = std::fs::read_to_string(root.join("docs/plugins.md")).unwrap();
    let (_, listing) = rust_blocks(&doc)
        .into_iter()
        .find(|(before, _)| before.contains("`integrators/normals/src/lib.rs`"))
        .expect("docs/plugins.md lists integrators/normals/src/lib.rs");
    let file = std::fs::read_to_string(root.join("integrators/normals/src/lib.rs")).unwrap();
    // The file less its module doc comment, which the section's prose says again.
    let body: String = file
        .lines()
        .skip_while(|l| l.starts_with("//!") || l.trim().is_empty())
        .collect::<Vec<_>>()
        .join("\n");
    assert_eq!(
        listing.trim_end(),
        body.trim_end(),
        "the normals listing drifted"
    );
}

/// The integrator plugins `foton plugins` finds (the tests' fixtures aside).
fn plugins() -> BTreeSet<String> {
    registry()
        .integrators
        .iter()
        .map(|p| p.name.clone())
        .filter(|n| !n.starts_with("panicky"))
        .collect()
}

fn markdown_files() -> Vec<std::path::PathBuf> {
    let root = repo_root();
    let mut files = vec![root.join("README.md")];
    for dir in ["docs", "integrators", "python", "core", "plugins", "tests"] {
        let mut stack = vec![root.join(dir)];
        while let Some(d) = stack.pop() {
            for entry in std::fs::read_dir(&d).into_iter().flatten().flatten() {
                let p = entry.path();
                if p.is_dir() {
                    stack.push(p);
                } else if p.extension().is_some_and(|e| e == "md") {
                    files.push(p);
                }
            }
        }
    }
    files
}

fn backticked(text: &str) -> BTreeSet<String> {
    text.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

#[test]
fn integrator_lists_name_the_plugins_foton_finds() {
    let plugins = plugins();
    assert!(plugins.len() >= 8, "plugins found: {plugins:?}");
    // The example plugin and ambient occlusion (geometry passes, not estimators of the
    // image) may be left out of prose that lists the estimators.
    let estimators: BTreeSet<String> = plugins
        .iter()
        .filter(|n| *n != "normals" && *n != "ao")
        .cloned()
        .collect();
    let (mut lists, mut tables) = (0, 0);
    for file in markdown_files() {
        let text = std::fs::read_to_string(&file).unwrap();
        let name = file.display();
        // A paragraph or table marked `<!-- integrators -->` lists them: a paragraph names
        // every estimator; a table has one row per plugin, named in its first column.
        for (i, _) in text.match_indices("<!-- integrators -->") {
            let block = text[i..].split_once('\n').map_or("", |(_, rest)| rest);
            let block = block.split("\n\n").next().unwrap();
            if block.starts_with('|') {
                let rows: BTreeSet<String> = block
                    .lines()
                    .skip(2)
                    .filter_map(|row| row.split('|').nth(1))
                    .flat_map(backticked)
                    .collect();
                assert_eq!(rows, plugins, "{name}: the table of integrators:\n{block}");
                tables += 1;
            } else {
                let named = backticked(block);
                let missing: Vec<_> = estimators.difference(&named).collect();
                assert!(
                    missing.is_empty(),
                    "{name}: the list misses {missing:?}:\n{block}"
                );
                lists += 1;
            }
        }
    }
    assert!(
        lists >= 3 && tables >= 1,
        "{lists} marked lists, {tables} tables found"
    );
}
