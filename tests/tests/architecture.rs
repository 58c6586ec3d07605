//! `docs/architecture.md` names files and the functions in them; a map that
//! points at files that moved away misleads more than no map. Every path it
//! names must exist, every page it links to too, and every item it places
//! in a file ("`State::handle` (`server/src/engine/handlers/query.rs`)",
//! "`serve_queries` in `server/src/server.rs`") must be named in that file.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ lives in the workspace root")
        .to_path_buf()
}

/// The code spans of `text` (between single backticks, outside fenced
/// blocks), each with the text just before it.
fn code_spans(text: &str) -> Vec<(String, String)> {
    let mut spans = Vec::new();
    let mut in_fence = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_fence = !in_fence;
            continue;
        }
        if in_fence {
            continue;
        }
        let mut parts = line.split('`');
        let mut before = parts.next().unwrap_or_default().to_owned();
        while let (Some(code), Some(after)) = (parts.next(), parts.next()) {
            spans.push((before.clone(), code.to_owned()));
            before = after.to_owned();
        }
    }
    spans
}

/// Whether a code span is a path in the repository: a relative path of
/// plain characters with a folder in it.
fn is_path(code: &str) -> bool {
    code.contains('/')
        && !code.starts_with('/')
        && !code.contains("://")
        && code
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_-./".contains(c))
}

/// The relative links of `text`: `](target)` not starting with a scheme or
/// an anchor.
fn links(text: &str) -> Vec<String> {
    text.split("](")
        .skip(1)
        .filter_map(|rest| rest.split(')').next())
        .map(|target| target.split('#').next().unwrap_or_default().to_owned())
        .filter(|t| !t.is_empty() && !t.contains("://"))
        .collect()
}

#[test]
fn every_file_the_architecture_page_names_exists() {
    let root = root();
    let text = std::fs::read_to_string(root.join("docs/architecture.md")).expect("read the page");
    let spans = code_spans(&text);
    let paths: Vec<&str> = spans
        .iter()
        .map(|(_, c)| c.as_str())
        .filter(|c| is_path(c))
        .collect();
    // The page is a map of the code: it names the files of both paths, of
    // state and of every extension point.
    assert!(paths.len() >= 30, "only {} paths named", paths.len());
    let missing: Vec<&str> = paths
        .iter()
        .copied()
        .filter(|p| !root.join(p.trim_end_matches('/')).exists())
        .collect();
    assert!(missing.is_empty(), "named but missing: {missing:?}");

    let broken: Vec<String> = links(&text)
        .into_iter()
        .filter(|l| !root.join("docs").join(l).exists())
        .collect();
    assert!(broken.is_empty(), "broken links: {broken:?}");
}

#[test]
fn every_item_the_architecture_page_places_is_in_its_file() {
    let root = root();
    let text = std::fs::read_to_string(root.join("docs/architecture.md")).expect("read the page");
    let spans = code_spans(&text);
    let mut checked = 0;
    let mut misplaced = Vec::new();
    for pair in spans.windows(2) {
        let [(_, item), (between, file)] = pair else {
            continue;
        };
        let placed = matches!(between.trim(), "in" | "(");
        let identifier = item
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == ':');
        if !placed || !identifier || !is_path(file) || !file.ends_with(".rs") {
            continue;
        }
        // `Type::method` is found by its method, `gjk::distance_in` by its
        // function: the last segment is what the file defines.
        let name = item.rsplit("::").next().unwrap_or(item);
        let source = std::fs::read_to_string(root.join(file)).expect("a named file");
        checked += 1;
        if !source.contains(name) {
            misplaced.push(format!("`{item}` in `{file}`"));
        }
    }
    assert!(checked >= 10, "only {checked} items placed");
    assert!(misplaced.is_empty(), "not in their files: {misplaced:?}");
}

#[test]
fn the_checks_see_what_they_check() {
    let spans = code_spans("a `x/y.rs` b `F` in `a/b.rs`\n```\n`in/fence.rs`\n```\n");
    let codes: Vec<&str> = spans.iter().map(|(_, c)| c.as_str()).collect();
    assert_eq!(codes, ["x/y.rs", "F", "a/b.rs"]);
    assert_eq!(spans[2].0, " in ");
    assert!(is_path("server/src/"));
    assert!(!is_path("gjk::distance_in") && !is_path("https://x/y"));
    assert_eq!(
        links("[a](b.md) [c](https://d) [e](f.md#g)"),
        ["b.md", "f.md"]
    );
}
