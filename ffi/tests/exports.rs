//! The shared library as the linker made it, before any install: its
//! soname carries the ABI version, and it exports the C API and nothing
//! else (a dependency's `#[no_mangle]` function would otherwise be
//! exported beside it); the robot functions are there exactly when the
//! `robots` feature is. Runs wherever `readelf` and `nm` are, without
//! CMake (`tests/install.rs` checks the installed copy).

mod common;

use std::process::Command;

/// `tool args... libgjkd_c.so`'s output, or `None` where the tool is
/// missing.
fn inspect(tool: &str, args: &[&str]) -> Option<String> {
    let lib = common::lib_dir().join("libgjkd_c.so");
    assert!(lib.exists(), "{} missing", lib.display());
    let out = Command::new(tool).args(args).arg(&lib).output().ok()?;
    assert!(
        out.status.success(),
        "{tool} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(String::from_utf8_lossy(&out.stdout).into_owned())
}

#[test]
fn the_soname_carries_the_abi_version() {
    let Some(dynamic) = inspect("readelf", &["-d"]) else {
        eprintln!("SKIPPED the_soname_carries_the_abi_version: readelf is not installed");
        return;
    };
    let soname = match env!("CARGO_PKG_VERSION_MAJOR") {
        "0" => format!("libgjkd_c.so.0.{}", env!("CARGO_PKG_VERSION_MINOR")),
        major => format!("libgjkd_c.so.{major}"),
    };
    let line = dynamic
        .lines()
        .find(|l| l.contains("(SONAME)"))
        .unwrap_or_else(|| panic!("no soname:\n{dynamic}"));
    assert!(line.ends_with(&format!("[{soname}]")), "{line}");
}

#[test]
fn only_the_c_api_is_exported() {
    let Some(symbols) = inspect("nm", &["-D", "--defined-only"]) else {
        eprintln!("SKIPPED only_the_c_api_is_exported: nm is not installed");
        return;
    };
    let names: Vec<&str> = symbols
        .lines()
        .filter_map(|l| l.split_whitespace().last())
        .collect();
    let stray: Vec<&&str> = names.iter().filter(|n| !n.starts_with("gjkd_")).collect();
    assert!(stray.is_empty(), "exported beside the C API: {stray:?}");
    // Every function of the header is there (a sample of each family).
    for f in [
        "gjkd_connect",
        "gjkd_register_box",
        "gjkd_distance",
        "gjkd_clearance",
        "gjkd_get_poses",
        "gjkd_last_error_code",
    ] {
        assert!(names.contains(&f), "{f} not exported: {names:?}");
    }
    assert_eq!(
        names.contains(&"gjkd_register_robot"),
        cfg!(feature = "robots"),
        "robot functions exported exactly with the `robots` feature"
    );
}
