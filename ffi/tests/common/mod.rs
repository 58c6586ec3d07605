//! Building C and C++ programs against this crate's shared library, with
//! the system compiler (`$CC` / `$CXX`, default `cc` / `c++`). (Linking the
//! static library is checked by `tests/install.rs`; statically linked, each
//! test program would take tens of megabytes.)

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `target/<profile>`, where cargo put `libgjkd_c.a` for this test run.
pub fn profile_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    exe.parent()
        .and_then(Path::parent)
        .expect("test executable lives in target/<profile>/deps")
        .to_path_buf()
}

/// Where the programs are built: under `target/<profile>`, out of the
/// source tree.
pub fn build_dir() -> PathBuf {
    let dir = profile_dir().join("gjkd-c-programs");
    std::fs::create_dir_all(&dir).expect("create the build folder");
    dir
}

/// The crate's folder.
pub fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The folder holding this build's `libgjkd_c.a` and `libgjkd_c.so`.
/// Cargo builds every crate type of the library before the tests, into
/// `deps/` (it copies them up to `target/<profile>` only for a
/// `cargo build` of the library itself).
pub fn lib_dir() -> PathBuf {
    let deps = profile_dir().join("deps");
    if deps.join("libgjkd_c.a").exists() {
        deps
    } else {
        profile_dir()
    }
}

/// The static library of this build.
pub fn static_lib() -> PathBuf {
    let lib = lib_dir().join("libgjkd_c.a");
    assert!(
        lib.exists(),
        "{} missing: cargo build -p gjkd-c",
        lib.display()
    );
    lib
}

/// Compiles `sources` (paths relative to the crate) into `name`, linked
/// with the shared library (found at run time through an rpath); C++ when
/// `cxx`. Panics with the compiler's
/// output on failure.
pub fn compile(sources: &[&str], name: &str, cxx: bool) -> PathBuf {
    let std = if cxx { "-std=c++17" } else { "-std=c99" };
    compile_with(sources, name, cxx, &[std])
}

/// [`compile`] with `flags` (the language standard among them) instead of
/// the default standard.
pub fn compile_with(sources: &[&str], name: &str, cxx: bool, flags: &[&str]) -> PathBuf {
    let (var, default) = if cxx { ("CXX", "c++") } else { ("CC", "cc") };
    let compiler = std::env::var(var).unwrap_or_else(|_| default.into());
    let exe = build_dir().join(name);
    let mut cmd = Command::new(&compiler);
    cmd.args(flags)
        .args(["-O2", "-Wall", "-Wextra", "-pedantic", "-Werror", "-g"])
        .arg("-I")
        .arg(crate_dir().join("include"));
    for s in sources {
        cmd.arg(crate_dir().join(s));
    }
    let lib_dir = static_lib()
        .parent()
        .expect("the library is in a folder")
        .to_path_buf();
    cmd.arg("-L")
        .arg(&lib_dir)
        .arg(format!("-Wl,-rpath,{}", lib_dir.display()))
        .args(["-lgjkd_c", "-lm", "-lpthread", "-o"])
        .arg(&exe);
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("run the compiler `{compiler}`: {e}"));
    assert!(
        out.status.success(),
        "{compiler} failed on {sources:?}:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    exe
}

/// Runs `exe` with `args`; its output, after checking it succeeded.
pub fn run_ok(exe: &Path, args: &[&str]) -> String {
    let out = run(exe, args);
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{} failed ({}):\n{stdout}\n{}",
        exe.display(),
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// Runs `exe` with `args`, finding its library by its own rpath only:
/// `cargo test` puts `target/<profile>` on LD_LIBRARY_PATH, which outranks
/// a runpath, and a `cargo build` of the library leaves an older copy there.
pub fn run(exe: &Path, args: &[&str]) -> Output {
    Command::new(exe)
        .args(args)
        .env_remove("IOX2_LOG_LEVEL")
        .env_remove("LD_LIBRARY_PATH")
        .output()
        .unwrap_or_else(|e| panic!("start {}: {e}", exe.display()))
}
