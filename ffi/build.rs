//! Links the C library: its versioned soname and the list of exported
//! symbols. The C header is not generated here but by the test
//! `tests/header.rs`, which compares cbindgen's output with the committed
//! `include/gjkd.h`: as a build dependency, cbindgen turned on features of
//! the build tools (`syn`'s `fold`) that the Python extension's build does
//! not, so `maturin develop` rebuilt every procedural macro and every crate
//! that derives with one instead of reusing what `cargo test` built.

/// The ABI version in the soname: the major version, or for `0.x`
/// versions `0.x` (Cargo's rule of which versions are compatible).
fn soname_version() -> String {
    let major = std::env::var("CARGO_PKG_VERSION_MAJOR").expect("cargo sets the version");
    let minor = std::env::var("CARGO_PKG_VERSION_MINOR").expect("cargo sets the version");
    if major == "0" {
        format!("0.{minor}")
    } else {
        major
    }
}

/// Links `soname` to `libgjkd_c.so` where cargo puts the library
/// (`target/<profile>` and its `deps`, three folders above `OUT_DIR`), so
/// that a program linked against the build tree, which records the
/// soname, finds the library there too (`LD_LIBRARY_PATH=target/release`),
/// as it would in an install. Best effort: the links are a convenience.
fn link_soname_in_build_tree(out: &str, soname: &str) {
    let Some(profile) = std::path::Path::new(out).ancestors().nth(3) else {
        return;
    };
    for dir in [profile.to_path_buf(), profile.join("deps")] {
        let link = dir.join(soname);
        if std::fs::symlink_metadata(&link).is_err() {
            #[cfg(unix)]
            let _ = std::os::unix::fs::symlink("libgjkd_c.so", &link);
        }
    }
}

fn main() {
    let dir = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let out = std::env::var("OUT_DIR").expect("cargo sets OUT_DIR");
    println!("cargo::rerun-if-changed=gjkd_c.map");
    if std::env::var("CARGO_CFG_TARGET_OS").is_ok_and(|os| os == "linux") {
        // A versioned soname, so that programs linked with the shared
        // library record its name and ABI version rather than the path it
        // was linked from, and a newer incompatible library can be
        // installed beside it.
        let soname = format!("libgjkd_c.so.{}", soname_version());
        println!("cargo::rustc-cdylib-link-arg=-Wl,-soname,{soname}");
        link_soname_in_build_tree(&out, &soname);
        // Only the gjkd_* functions are exported: a dependency's
        // #[no_mangle] functions (iceoryx2's logger hook) stay inside.
        println!("cargo::rustc-cdylib-link-arg=-Wl,--version-script={dir}/gjkd_c.map");
        println!("cargo::rustc-cdylib-link-arg=-Wl,--exclude-libs,ALL");
    }
}
