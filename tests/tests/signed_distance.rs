//! The signed distance of a pair query, through a real server: the
//! README's example as written (service name changed), the answer of a pair
//! apart unchanged (its signed distance its distance), the default off, a
//! compound's deepest piece pair.

use gjkd_client::{Client, ClientError, Geometry, Piece, QueryOptions, result_flags};
use gjkd_e2e::Server;
use nalgebra::{Isometry3, Vector3};

#[test]
fn readme_signed_distance_example_runs() -> Result<(), ClientError> {
    let server = Server::start("doc-signed", &[]);
    let service = server.service.as_str();
    // --- from README.md, "Signed distance" ---

    let mut client = Client::connect(service)?;
    let crate_ = client.register_cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)?;
    let ball = client.register_sphere(0.5)?;
    client.set_pose(ball, &Isometry3::translation(0.8, 0.0, 0.0))?; // 0.7 into the face x = 1
    let options = QueryOptions {
        signed_distance: true,
        ..QueryOptions::default()
    };
    let answer = client.distance(crate_, ball, &options)?;
    let signed = answer.signed.expect("asked for");
    assert!((signed.value + 0.7).abs() < 1e-9);
    assert!(signed.lower <= -0.7 && -0.7 <= signed.upper);
    assert!((answer.normal - Vector3::x()).norm() < 1e-9); // B leaves along +x
    Ok(())
}

#[test]
fn apart_pairs_keep_their_answer_and_the_default_asks_nothing() -> Result<(), ClientError> {
    let server = Server::start("signed-apart", &[]);
    let mut client = Client::connect(&server.service)?;
    let bx = client.register_cuboid(Vector3::new(1.0, 1.0, 1.0), 0.1)?;
    let ball = client.register_sphere(0.5)?;
    let signed = QueryOptions {
        signed_distance: true,
        warm_start: false,
        ..QueryOptions::default()
    };
    let plain = QueryOptions::cold();
    client.set_pose(ball, &Isometry3::translation(3.0, 0.5, 0.0))?;
    let with = client.distance(bx, ball, &signed)?;
    let without = client.distance(bx, ball, &plain)?;
    assert!(without.signed.is_none());
    // Apart: every field of the distance's answer is the same, and the
    // signed distance is the distance with its interval.
    let s = with.signed.expect("asked for");
    assert_eq!(
        (s.value, s.lower, s.upper),
        (with.distance, with.lower, with.upper)
    );
    assert_eq!(
        (with.distance, with.point_a, with.point_b, with.normal),
        (
            without.distance,
            without.point_a,
            without.point_b,
            without.normal
        )
    );
    assert!((with.distance - 1.4).abs() < 1e-9);
    // Overlapping through the rounded box's face (x = 1.1): the distance
    // query says 0, the signed distance how deep.
    client.set_pose(ball, &Isometry3::translation(1.3, 0.2, 0.0))?;
    let with = client.distance(bx, ball, &signed)?;
    let s = with.signed.expect("asked for");
    assert_eq!(with.distance, 0.0);
    assert!((s.value + 0.3).abs() < 1e-9, "{s:?}");
    assert!(s.lower <= -0.3 && -0.3 <= s.upper);
    let gap = with.point_b - with.point_a - with.normal * s.value;
    assert!(gap.norm() < 1e-9, "{with:?}");
    // The row is flagged on the wire.
    let item = gjkd_client::Item::distance(bx, ball, &signed);
    let mut out = [gjkd_client::ItemResult::default()];
    client.query_batch(&[item], &mut out)?;
    assert_ne!(out[0].flags & result_flags::SIGNED_DISTANCE, 0);
    Ok(())
}

#[test]
fn a_compound_answers_its_deepest_piece_pair() -> Result<(), ClientError> {
    let server = Server::start("signed-compound", &[]);
    let mut client = Client::connect(&server.service)?;
    let pieces = [
        Piece {
            offset: Isometry3::translation(-2.0, 0.0, 0.0),
            geometry: Geometry::Sphere { radius: 0.5 },
        },
        Piece {
            offset: Isometry3::translation(2.0, 0.0, 0.0),
            geometry: Geometry::Sphere { radius: 0.6 },
        },
    ];
    let dumbbell = client.register_compound(&pieces)?;
    let long = client.register_cuboid(Vector3::new(3.0, 1.0, 1.0), 0.0)?;
    client.set_pose(long, &Isometry3::translation(0.0, 1.2, 0.0))?;
    let options = QueryOptions {
        signed_distance: true,
        ..QueryOptions::default()
    };
    let answer = client.distance(dumbbell, long, &options)?;
    let s = answer.signed.expect("asked for");
    // Each ball's centre 0.2 below the face y = 0.2: the larger 0.4 deep.
    assert!((s.value + 0.4).abs() < 1e-9, "{s:?}");
    assert_eq!(answer.pieces, [1, 0]);
    Ok(())
}
