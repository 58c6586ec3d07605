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

/// Each package of `cargo tree <args>` ("name vX.Y.Z") with the feature
/// sets it is built with (a package built for the host and for the target
/// can appear twice).
fn feature_sets(args: &[&str]) -> BTreeMap<String, BTreeSet<BTreeSet<String>>> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .current_dir(root())
        .args(["tree", "--prefix", "none", "-f", "{p}|{f}"])
        .args(args)
        .output()
        .expect("run cargo tree");
    assert!(
        out.status.success(),
        "cargo tree {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut sets: BTreeMap<String, BTreeSet<BTreeSet<String>>> = BTreeMap::new();
    for line in String::from_utf8(out.stdout).expect("UTF-8").lines() {
        let Some((package, features)) = line.split_once('|') else {
            continue;
        };
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
        sets.entry(id.join(" ")).or_default().insert(features);
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
        "normal,build",
    ]);
    let workspace = feature_sets(&["--workspace", "-e", "normal,build,dev"]);
    assert!(
        python.keys().any(|p| p.starts_with("parry3d-f64 ")),
        "the tree was read"
    );
    let mut differ = Vec::new();
    for (package, sets) in &python {
        if package.starts_with("pyo3") || package.starts_with("numpy ") {
            continue;
        }
        if package.starts_with("gjkd-python ") {
            continue;
        }
        let built = workspace.get(package).cloned().unwrap_or_default();
        for features in sets {
            if !built.contains(features) {
                differ.push(format!(
                    "{package}: the Python build asks {features:?}, the workspace builds {built:?}"
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
