//! Generates the C header from this crate into `OUT_DIR/gjkd.h`; the test
//! `tests/header.rs` compares it with the committed `include/gjkd.h`.

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

fn main() {
    let dir = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let out = std::env::var("OUT_DIR").expect("cargo sets OUT_DIR");
    println!("cargo::rerun-if-changed=src");
    println!("cargo::rerun-if-changed=cbindgen.toml");
    println!("cargo::rerun-if-changed=gjkd_c.map");
    if std::env::var("CARGO_CFG_TARGET_OS").is_ok_and(|os| os == "linux") {
        // A versioned soname, so that programs linked with the shared
        // library record its name and ABI version rather than the path it
        // was linked from, and a newer incompatible library can be
        // installed beside it.
        println!(
            "cargo::rustc-cdylib-link-arg=-Wl,-soname,libgjkd_c.so.{}",
            soname_version()
        );
        // Only the gjkd_* functions are exported: a dependency's
        // #[no_mangle] functions (iceoryx2's logger hook) stay inside.
        println!("cargo::rustc-cdylib-link-arg=-Wl,--version-script={dir}/gjkd_c.map");
        println!("cargo::rustc-cdylib-link-arg=-Wl,--exclude-libs,ALL");
    }
    let config =
        cbindgen::Config::from_file(format!("{dir}/cbindgen.toml")).expect("read cbindgen.toml");
    cbindgen::Builder::new()
        .with_crate(&dir)
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header")
        .write_to_file(format!("{out}/gjkd.h"));
}
