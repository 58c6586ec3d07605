//! `ffi/install.sh` installs a package that CMake's `find_package(gjkd)`
//! and pkg-config find: the example project `examples/cmake` is configured
//! against it, built, and its programs (shared and static) run against a
//! real server. Skipped, saying so, where cmake or pkg-config is missing.
// The example project's C++ program registers a robot: the library's
// `robots` feature.
#![cfg(feature = "robots")]

mod common;

use std::path::Path;
use std::process::Command;

use gjkd_e2e::Server;

fn present(tool: &str) -> bool {
    Command::new(tool)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

#[track_caller]
fn ok(cmd: &mut Command) -> String {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("start {cmd:?}: {e}"));
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{cmd:?} failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// Installs this build's libraries into a fresh `dir/prefix`.
fn install(dir: &Path) -> std::path::PathBuf {
    let prefix = dir.join("prefix");
    let _ = std::fs::remove_dir_all(&prefix);
    common::static_lib();
    ok(Command::new("bash")
        .arg(common::crate_dir().join("install.sh"))
        .arg("--from")
        .arg(common::lib_dir())
        .arg(&prefix));
    for f in [
        "include/gjkd.h",
        "include/gjkd.hpp",
        "lib/libgjkd_c.so",
        "lib/libgjkd_c.a",
        "lib/cmake/gjkd/gjkdConfig.cmake",
        "lib/cmake/gjkd/gjkdConfigVersion.cmake",
        "lib/pkgconfig/gjkd.pc",
    ] {
        assert!(prefix.join(f).exists(), "{f} not installed");
    }
    // Versioned: the file, its soname's link, the linker's link; and only
    // the C API exported.
    let version = env!("CARGO_PKG_VERSION");
    let soname = format!(
        "libgjkd_c.so.{}.{}",
        env!("CARGO_PKG_VERSION_MAJOR"),
        env!("CARGO_PKG_VERSION_MINOR")
    );
    let lib = prefix.join("lib");
    assert!(lib.join(format!("libgjkd_c.so.{version}")).is_file());
    for link in [soname.as_str(), "libgjkd_c.so"] {
        let target = std::fs::read_link(lib.join(link)).expect("a link");
        assert_eq!(target, Path::new(&format!("libgjkd_c.so.{version}")));
    }
    if present("readelf") {
        let dynamic = ok(Command::new("readelf")
            .arg("-d")
            .arg(lib.join("libgjkd_c.so")));
        assert!(dynamic.contains(&format!("[{soname}]")), "{dynamic}");
    }
    if present("nm") {
        let symbols = ok(Command::new("nm")
            .args(["-D", "--defined-only"])
            .arg(lib.join("libgjkd_c.so")));
        let stray: Vec<&str> = symbols
            .lines()
            .filter(|l| {
                !l.split_whitespace()
                    .last()
                    .is_some_and(|s| s.starts_with("gjkd_"))
            })
            .collect();
        assert!(stray.is_empty(), "exported beside the C API: {stray:?}");
        assert!(symbols.contains(" T gjkd_connect"), "{symbols}");
    }
    prefix
}

#[test]
fn find_package_and_pkg_config_find_the_installed_library() {
    if !present("cmake") {
        eprintln!(
            "SKIPPED find_package_and_pkg_config_find_the_installed_library: cmake is not installed"
        );
        return;
    }
    let dir = common::build_dir().join("install-test");
    let prefix = install(&dir);
    let build = dir.join("build");
    let _ = std::fs::remove_dir_all(&build);
    ok(Command::new("cmake")
        .arg("-S")
        .arg(common::crate_dir().join("examples/cmake"))
        .arg("-B")
        .arg(&build)
        .arg(format!("-DCMAKE_PREFIX_PATH={}", prefix.display())));
    ok(Command::new("cmake").arg("--build").arg(&build));
    let server = Server::start("ffi-install", &["--no-persist"]);
    for exe in ["basic", "basic_cpp", "basic_static"] {
        let stdout = common::run_ok(&build.join(exe), &[&server.service]);
        assert_eq!(stdout.lines().last(), Some("ok"), "{exe}:\n{stdout}");
        assert!(
            stdout.contains("box-sphere             1.500000000000"),
            "{stdout}"
        );
    }
    let stdout = common::run_ok(&build.join("pair_rows"), &[&server.service]);
    assert_eq!(stdout.lines().last(), Some("ok"), "pair_rows:\n{stdout}");
    // A version newer than the installed one is refused.
    let too_new = dir.join("too-new");
    std::fs::create_dir_all(&too_new).unwrap();
    std::fs::write(
        too_new.join("CMakeLists.txt"),
        "cmake_minimum_required(VERSION 3.16)\nproject(t NONE)\nfind_package(gjkd 9.0 REQUIRED)\n",
    )
    .unwrap();
    let refused = Command::new("cmake")
        .arg("-S")
        .arg(&too_new)
        .arg("-B")
        .arg(too_new.join("build"))
        .arg(format!("-DCMAKE_PREFIX_PATH={}", prefix.display()))
        .output()
        .expect("run cmake");
    assert!(
        !refused.status.success(),
        "find_package(gjkd 9.0) succeeded"
    );

    if present("pkg-config") {
        let flags = ok(Command::new("pkg-config")
            .args(["--cflags", "--libs", "gjkd"])
            .env("PKG_CONFIG_PATH", prefix.join("lib/pkgconfig")));
        let include = format!("-I{}", prefix.join("include").display());
        assert!(
            flags.contains(&include) && flags.contains("-lgjkd_c"),
            "{flags}"
        );
    } else {
        eprintln!("pkg-config is not installed: gjkd.pc not checked");
    }
    // The copies of the static library are large: leave nothing behind.
    drop(server);
    let _ = std::fs::remove_dir_all(&dir);
}
