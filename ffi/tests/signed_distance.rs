//! The signed-distance example (`examples/signed_distance.c`), built with
//! the system compiler against the static library, run against a real
//! server; it checks its own answers against the analytic ones, and this
//! test what it printed.

mod common;

use gjkd_e2e::Server;

#[test]
fn signed_distance_example_answers_match_the_analytic_ones() {
    let exe = common::compile(&["examples/signed_distance.c"], "signed_distance", false);
    let server = Server::start("ffi-signed", &["--no-persist"]);
    let stdout = common::run_ok(&exe, &[&server.service]);
    for line in [
        "signed answered        yes",
        "signed box-ball        -0.700000000000",
        "interval holds -0.7    yes",
        "normal.x               1.000000000000",
        "point_b - point_a      -0.700000000000",
        "signed box-far ball    1.500000000000",
        "default has none       yes",
        "row flagged            yes",
        "row signed box-ball    -0.700000000000",
    ] {
        assert!(stdout.contains(line), "missing `{line}` in:\n{stdout}");
    }
    assert!(!stdout.contains("WRONG"), "{stdout}");
    assert_eq!(stdout.lines().last(), Some("ok"), "{stdout}");
}
