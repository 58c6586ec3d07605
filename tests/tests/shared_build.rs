//! The README's test command builds the workspace (`cargo test`), then the
//! Python extension alone (`maturin develop`, in the same target directory).
//! Cargo reuses a crate built by the first only when the second resolves the
//! same features for it: one feature that a test-only dependency turns on
//! (a build tool's, a benchmark's) and the Python build does not, and the
//! second build compiles that crate and everything above it again, which
//! once cost the test command a minute and a half. Apart from pyo3's
//! `extension-module`, which only maturin turns on, every crate of the
//! Python build must resolve to features that the workspace build also has.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ lives in the workspace root")
        .to_path_buf()
}

/// Each package of `cargo tree <args>` ("name vX.Y.Z"), with `true` for a
/// copy built for the host (a procedural macro and what it uses), mapped
/// to the feature sets it is built with. Cargo builds a host copy and a
/// target copy of one crate apart, so their features are compared apart.
/// Build scripts' dependencies are not listed (`-e normal`).
type Sets = BTreeMap<(String, bool), BTreeSet<BTreeSet<String>>>;

fn feature_sets(args: &[&str]) -> Sets {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .current_dir(root())
        .args(["tree", "--prefix", "depth", "-f", "{p}|{f}"])
        .args(args)
        .output()
        .expect("run cargo tree");
    assert!(
        out.status.success(),
        "cargo tree {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut sets = Sets::new();
    // The depth of the procedural macro the current line is under, if any.
    let mut host_from: Option<usize> = None;
    for line in String::from_utf8(out.stdout).expect("UTF-8").lines() {
        let digits = line.chars().take_while(char::is_ascii_digit).count();
        let Ok(depth) = line[..digits].parse::<usize>() else {
            continue;
        };
        let Some((package, features)) = line[digits..].split_once('|') else {
            continue;
        };
        if host_from.is_some_and(|d| depth <= d) {
            host_from = None;
        }
        if host_from.is_none() && package.contains("(proc-macro)") {
            host_from = Some(depth);
        }
        // "name v1.2.3 (/path)" for path packages: the name and version
        // identify it.
        let id: Vec<&str> = package.split_whitespace().take(2).collect();
        let features = features
            .trim()
            .trim_end_matches("(*)")
            .split(',')
            .map(str::trim)
            .filter(|f| !f.is_empty())
            .map(str::to_owned)
            .collect();
        sets.entry((id.join(" "), host_from.is_some()))
            .or_default()
            .insert(features);
    }
    sets
}

#[test]
fn the_python_build_reuses_the_workspace_build() {
    let python = feature_sets(&[
        "-p",
        "gjkd-python",
        "--features",
        "pyo3/extension-module",
        "-e",
        "normal",
    ]);
    let workspace = feature_sets(&["--workspace", "-e", "normal,dev"]);
    assert!(
        python
            .keys()
            .any(|(p, host)| p.starts_with("parry3d-f64 ") && !host)
            && python
                .keys()
                .any(|(p, host)| p.starts_with("syn ") && *host),
        "the tree was read"
    );
    let mut differ = Vec::new();
    for ((package, host), sets) in &python {
        if package.starts_with("pyo3") || package.starts_with("numpy ") {
            continue;
        }
        if package.starts_with("gjkd-python ") {
            continue;
        }
        let built = workspace
            .get(&(package.clone(), *host))
            .cloned()
            .unwrap_or_default();
        let side = if *host { "host" } else { "target" };
        for features in sets {
            if !built.contains(features) {
                differ.push(format!(
                    "{package} ({side}): the Python build asks {features:?}, \
                     the workspace builds {built:?}"
                ));
            }
        }
    }
    assert!(
        differ.is_empty(),
        "maturin would rebuild these crates (and all above them) after cargo test; \
         ask the same features in python/Cargo.toml or drop the one a test-only \
         dependency adds:\n{}",
        differ.join("\n")
    );
}
