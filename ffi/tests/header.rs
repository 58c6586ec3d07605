//! The committed header is the one cbindgen generates from this crate, and
//! its constants agree with the Rust crates'.

use std::path::Path;
use std::sync::OnceLock;

/// The header cbindgen generates from this crate's sources now.
fn generated() -> &'static str {
    static HEADER: OnceLock<String> = OnceLock::new();
    HEADER.get_or_init(|| {
        let dir = env!("CARGO_MANIFEST_DIR");
        let config = cbindgen::Config::from_file(format!("{dir}/cbindgen.toml"))
            .expect("read cbindgen.toml");
        let mut out = Vec::new();
        cbindgen::Builder::new()
            .with_crate(dir)
            .with_config(config)
            .generate()
            .expect("cbindgen generates the header")
            .write(&mut out);
        String::from_utf8(out).expect("the header is UTF-8")
    })
}

fn committed_path() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("include/gjkd.h")
}

#[test]
fn committed_header_is_the_generated_one() {
    let path = committed_path();
    if std::env::var_os("GJKD_UPDATE_HEADER").is_some() {
        std::fs::write(&path, generated()).expect("write include/gjkd.h");
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated(),
        "ffi/include/gjkd.h differs from the header cbindgen generates from the crate; \
         refresh it with\n    GJKD_UPDATE_HEADER=1 cargo test -p gjkd-c --test header\n\
         and commit it"
    );
}

/// The value of `#define NAME value` in the header.
fn define(name: &str) -> String {
    let prefix = format!("#define {name} ");
    generated()
        .lines()
        .find_map(|l| l.strip_prefix(&prefix))
        .unwrap_or_else(|| panic!("no #define {name} in the header"))
        .trim()
        .to_owned()
}

#[test]
fn version_macro_matches_the_wire_protocol() {
    assert_eq!(
        define("GJKD_PROTOCOL_VERSION"),
        gjkd_proto::PROTOCOL_VERSION.to_string()
    );
    assert_eq!(
        gjkd_c::gjkd_protocol_version(),
        gjkd_proto::PROTOCOL_VERSION
    );
}

#[test]
fn limit_and_default_macros_match_the_rust_crates() {
    assert_eq!(
        define("GJKD_MAX_PIECES"),
        gjkd_proto::MAX_PIECES.to_string()
    );
    assert_eq!(
        define("GJKD_MAX_NAME_LEN"),
        gjkd_proto::MAX_NAME_LEN.to_string()
    );
    assert_eq!(
        define("GJKD_DEFAULT_MAX_ITERATIONS"),
        gjkd_proto::DEFAULT_MAX_ITERATIONS.to_string()
    );
    let tol: f64 = define("GJKD_DEFAULT_TOLERANCE").parse().expect("a number");
    assert_eq!(tol, gjkd_proto::DEFAULT_TOLERANCE);
}

#[test]
fn error_codes_in_the_header_are_the_wire_codes() {
    // Each wire code appears as `GJKD_CODE_<NAME> = <value>` with the name
    // the library reports for it.
    for code in gjkd_proto::ErrorCode::ALL {
        let name = unsafe { std::ffi::CStr::from_ptr(gjkd_c::gjkd_error_code_name(code.raw())) }
            .to_str()
            .expect("ASCII");
        let line = format!("{name} = {},", code.raw());
        assert!(
            generated().contains(&line),
            "{line} missing from the header"
        );
        let words =
            unsafe { std::ffi::CStr::from_ptr(gjkd_c::gjkd_error_code_describe(code.raw())) };
        assert_eq!(words.to_str().expect("ASCII"), code.describe());
    }
    let past = gjkd_proto::ErrorCode::ALL.len() as u32;
    let name = unsafe { std::ffi::CStr::from_ptr(gjkd_c::gjkd_error_code_name(past)) };
    assert_eq!(name.to_str().expect("ASCII"), "GJKD_CODE_UNKNOWN");
}

#[test]
fn query_statuses_in_the_header_are_the_wire_statuses() {
    for (name, status) in [
        ("GJKD_QUERY_CONVERGED", gjkd_proto::Status::Converged),
        ("GJKD_QUERY_FARTHER", gjkd_proto::Status::Farther),
        ("GJKD_QUERY_CLOSER", gjkd_proto::Status::Closer),
        ("GJKD_QUERY_ITERATION_CAP", gjkd_proto::Status::IterationCap),
        (
            "GJKD_QUERY_TOLERANCE_NOT_MET",
            gjkd_proto::Status::ToleranceNotMet,
        ),
    ] {
        let line = format!("{name} = {},", status.raw());
        assert!(
            generated().contains(&line),
            "{line} missing from the header"
        );
    }
}

#[test]
fn every_function_is_documented() {
    // A declaration `... gjkd_xxx(` must follow a comment line.
    let lines: Vec<&str> = generated().lines().collect();
    let mut functions = 0;
    for (i, line) in lines.iter().enumerate() {
        let is_decl =
            !line.starts_with([' ', '/', '#', '}']) && line.contains("gjkd_") && line.contains('(');
        if is_decl {
            functions += 1;
            assert!(
                i > 0 && lines[i - 1].trim_start().starts_with("//"),
                "undocumented: {line}"
            );
        }
    }
    assert!(functions >= 23, "only {functions} functions found");
}

/// The C compiler lays out the header's mirrors of wire structs exactly as
/// Rust lays out the wire structs: a C file of `_Static_assert`s on
/// `sizeof` and `offsetof`, with the Rust figures written in, must compile.
/// (The crate's own const assertions check the Rust mirrors; this checks
/// what a C program sees.)
#[test]
fn c_sees_the_wire_layouts_rust_sends() {
    use gjkd_proto::{Item, ItemResult, Pose};
    use std::mem::{offset_of, size_of};
    let mut c = String::from("#include <stddef.h>\n#include \"gjkd.h\"\n");
    let mut check = |ty: &str, what: &str, rust: usize| {
        let expr = if what == "size" {
            format!("sizeof({ty})")
        } else {
            format!("offsetof({ty}, {what})")
        };
        c.push_str(&format!(
            "_Static_assert({expr} == {rust}, \"{ty} {what} differs from Rust's\");\n"
        ));
    };
    check("gjkd_pose", "size", size_of::<Pose>());
    check("gjkd_pose", "translation", offset_of!(Pose, translation));
    check("gjkd_pose", "rotation", offset_of!(Pose, rotation));
    check("gjkd_pair_query", "size", size_of::<Item>());
    check("gjkd_pair_query", "kind", offset_of!(Item, kind));
    check("gjkd_pair_query", "flags", offset_of!(Item, flags));
    check("gjkd_pair_query", "a", offset_of!(Item, a));
    check("gjkd_pair_query", "b", offset_of!(Item, b));
    check("gjkd_pair_query", "pose_a", offset_of!(Item, pose_a));
    check(
        "gjkd_pair_query",
        "pose_b",
        offset_of!(Item, body.pair.pose_b),
    );
    check(
        "gjkd_pair_query",
        "tolerance",
        offset_of!(Item, body.pair.tolerance),
    );
    check(
        "gjkd_pair_query",
        "margin",
        offset_of!(Item, body.pair.margin),
    );
    check(
        "gjkd_pair_query",
        "max_iterations",
        offset_of!(Item, body.pair.max_iterations),
    );
    check(
        "gjkd_pair_query",
        "reserved",
        offset_of!(Item, body.pair.reserved),
    );
    check("gjkd_result", "size", size_of::<ItemResult>());
    check("gjkd_result", "distance", offset_of!(ItemResult, distance));
    check("gjkd_result", "lower", offset_of!(ItemResult, lower));
    check("gjkd_result", "upper", offset_of!(ItemResult, upper));
    check(
        "gjkd_result",
        "penetration",
        offset_of!(ItemResult, penetration),
    );
    check("gjkd_result", "point_a", offset_of!(ItemResult, point_a));
    check("gjkd_result", "point_b", offset_of!(ItemResult, point_b));
    check("gjkd_result", "normal", offset_of!(ItemResult, normal));
    check("gjkd_result", "error", offset_of!(ItemResult, error));
    check("gjkd_result", "status", offset_of!(ItemResult, status));
    check(
        "gjkd_result",
        "iterations",
        offset_of!(ItemResult, iterations),
    );
    check("gjkd_result", "flags", offset_of!(ItemResult, flags));
    check("gjkd_result", "pieces", offset_of!(ItemResult, pieces));
    check(
        "gjkd_result",
        "signed_distance",
        offset_of!(ItemResult, signed_distance),
    );
    check(
        "gjkd_result",
        "signed_lower",
        offset_of!(ItemResult, signed_lower),
    );
    check(
        "gjkd_result",
        "signed_upper",
        offset_of!(ItemResult, signed_upper),
    );

    let dir = std::env::temp_dir().join(format!("gjkd-layout-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let file = dir.join("layout.c");
    std::fs::write(&file, &c).expect("write layout.c");
    let compiler = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let out = std::process::Command::new(&compiler)
        .args(["-std=c11", "-fsyntax-only", "-I"])
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("include"))
        .arg(&file)
        .output()
        .unwrap_or_else(|e| panic!("run {compiler}: {e}"));
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        out.status.success(),
        "the header's layouts differ from the wire's:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
