//! Unit tests of the wire types.

use crate::*;
use nalgebra::{Isometry3, Vector3};
use std::mem::offset_of;

#[test]
fn names_carry_the_version() {
    assert_eq!(query_service_name("gjkd"), "gjkd/v4/query");
    assert_eq!(admin_service_name("x"), "x/v4/admin");
    assert_eq!(wake_service_name("x"), "x/v4/wake");
}

#[test]
fn error_codes_round_trip() {
    for (i, c) in ErrorCode::ALL.iter().enumerate() {
        assert_eq!(c.raw() as usize, i);
        assert_eq!(ErrorCode::from_raw(c.raw()), Some(*c));
    }
    assert_eq!(ErrorCode::from_raw(ErrorCode::ALL.len() as u32), None);
}

#[test]
fn pose_round_trips_bit_for_bit() {
    let iso = Isometry3::new(
        Vector3::new(1.25, -3.5, 1e-300),
        Vector3::new(0.3, -1.2, 2.0),
    );
    let back = Pose::from_isometry(&iso).to_isometry_unchecked();
    assert_eq!(back, iso);
}

#[test]
fn item_encodes_options() {
    let o = QueryOptions {
        tolerance: 1e-9,
        max_iterations: 7,
        margin: Some(0.5),
        warm_start: false,
        precision: Precision::Single,
        signed_distance: true,
    };
    let it = Item::distance(ObjectId::from_raw(3), ObjectId::from_raw(4), &o);
    assert_eq!(it.options(), o);
    assert_eq!(
        it.flags & item_flags::SIGNED_DISTANCE,
        item_flags::SIGNED_DISTANCE
    );
    assert_eq!(it.item_kind(), Some(ItemKind::Distance));
    assert_eq!(it.flags & item_flags::WARM_START, 0);
    assert_eq!(
        it.flags & item_flags::SINGLE_PRECISION,
        item_flags::SINGLE_PRECISION
    );
    let d = Item::distance(
        ObjectId::from_raw(3),
        ObjectId::from_raw(4),
        &QueryOptions::default(),
    );
    assert_eq!(d.flags & item_flags::SINGLE_PRECISION, 0);
    assert_eq!(d.flags & item_flags::SIGNED_DISTANCE, 0);
    assert_eq!(d.options().precision, Precision::Double);
}

#[test]
fn names_are_bounded_and_checked() {
    let mut r = AdminRequest::new(AdminOp::Lookup);
    assert!(r.set_name("ball"));
    assert_eq!(r.name(), Some("ball"));
    assert!(!r.set_name(&"x".repeat(MAX_NAME_LEN + 1)));
    r.name_len = 1000;
    assert_eq!(r.name(), None);
    r.name_len = 2;
    r.name[0] = 0xff;
    assert_eq!(r.name(), None);
}

#[test]
fn joint_items_carry_their_positions() {
    let q = [0.5, -1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0];
    let robot = ObjectId::from_raw(9);
    let base = Isometry3::translation(1.0, 2.0, 3.0);
    let it = Item::set_joints(robot, 2, &q, Some(&base), true);
    assert_eq!(it.item_kind(), Some(ItemKind::SetJoints));
    assert_eq!(it.joint_positions(), Some(&q[..]));
    assert_eq!(
        *it.joints(),
        JointsBody {
            positions: q,
            count: 9,
            first: 2
        }
    );
    assert_eq!((it.a, it.b), (9, 0));
    assert_eq!(it.flags, item_flags::POSE_A | item_flags::CLAMP);
    assert_eq!(it.pose_a, Pose::from_isometry(&base));
    let short = Item::set_joints(robot, 0, &[1.5], None, false);
    assert_eq!(short.joint_positions(), Some(&[1.5][..]));
    assert_eq!(short.flags, 0);
    let mut bad = short;
    bad.joints_mut().count = 10;
    assert_eq!(bad.joint_positions(), None);
    // No position at all: the base of a robot without moving joints.
    let base_only = Item::set_joints(robot, 0, &[], Some(&base), false);
    assert_eq!(base_only.joint_positions(), Some(&[][..]));
    assert_eq!(base_only.flags, item_flags::POSE_A);
}

/// The joints view and the pair view share the body's bytes: the layout a
/// C or Python writer of raw items relies on.
#[test]
fn the_two_body_views_share_their_bytes() {
    let it = Item::set_joints(ObjectId::from_raw(1), 3, &[1.0, 2.0], None, false);
    let pair = it.pair();
    assert_eq!(pair.pose_b.translation, [1.0, 2.0, 0.0]);
    // count 2 and first 3 are the pair view's last two words.
    assert_eq!((pair.max_iterations, pair.reserved), (2, 3));
    assert_eq!(offset_of!(Item, body), 80);
    assert_eq!(
        offset_of!(JointsBody, count),
        offset_of!(PairBody, max_iterations)
    );
    assert_eq!(
        offset_of!(JointsBody, first),
        offset_of!(PairBody, reserved)
    );
}

#[test]
fn text_round_trips_through_chunks() {
    for text in ["", "a", &"<robot name=\"é\"/>".repeat(5), &"x".repeat(48)] {
        let packed = AdminChunk::pack_text(text);
        assert_eq!(packed.len(), text.len().div_ceil(TEXT_CHUNK_LEN));
        assert_eq!(AdminChunk::text_of(&packed, text.len() as u64), Some(text));
    }
    let packed = AdminChunk::pack_text("hello");
    assert_eq!(AdminChunk::text_of(&packed, 4), None, "non-zero padding");
    assert_eq!(AdminChunk::text_of(&packed, 30), None, "too few chunks");
    assert_eq!(AdminChunk::bytes(&packed)[..6], *b"hello\0");
    let bad_utf8 = AdminChunk::pack_text("é");
    assert_eq!(AdminChunk::text_of(&bad_utf8, 1), None, "cut inside a char");
}

#[test]
fn vertices_cast_to_chunks_and_back() {
    let v = [
        Vertex {
            x: 1.0,
            y: -2.0,
            z: 3.5,
        },
        Vertex {
            x: f64::MAX,
            y: 0.0,
            z: -0.0,
        },
    ];
    let chunks = AdminChunk::from_vertices(&v);
    assert_eq!(chunks.len(), 2);
    assert_eq!(AdminChunk::vertices(chunks), &v);
    assert_eq!(AdminChunk::bytes(chunks)[..8], 1.0f64.to_le_bytes());
}

#[test]
fn wire_sizes_are_stable() {
    assert_eq!(std::mem::size_of::<Pose>(), 56);
    assert_eq!(std::mem::size_of::<Item>(), 160);
    // 152 bytes of answer (the signed distance's three included); the
    // gradient (16 columns, count, flags, error bound) travels apart, in a
    // reply entry of the same size with its item's index.
    assert_eq!(std::mem::size_of::<crate::Gradient>(), 144);
    assert_eq!(std::mem::size_of::<ItemResult>(), 152);
    assert_eq!(std::mem::size_of::<crate::GradientRow>(), 152);
    assert_eq!(std::mem::size_of::<crate::ReplyEntry>(), 152);
    assert_eq!(std::mem::size_of::<crate::SceneRow>(), 336);
    assert_eq!(std::mem::size_of::<Vertex>(), 24);
    assert_eq!(std::mem::size_of::<AdminChunk>(), 24);
    assert_eq!(std::mem::size_of::<ItemBody>(), 80);
}

/// A stored pose is held to 2^998 per translation axis, so that any two
/// stored poses, however rotated, lie within the 2^1000 a query accepts.
#[test]
fn a_translation_beyond_max_translation_is_refused_when_set() {
    assert_eq!(MAX_TRANSLATION, 2f64.powi(998));
    let at = |x: f64| Pose {
        translation: [0.0, x, 0.0],
        rotation: [0.0, 0.0, 0.0, 1.0],
    };
    assert!(at(MAX_TRANSLATION).checked().is_ok());
    assert!(at(-MAX_TRANSLATION).checked().is_ok());
    for x in [1e305, -2.7e300, f64::MAX, f64::NAN, f64::INFINITY] {
        assert_eq!(at(x).checked(), Err(ErrorCode::NonFinitePose), "{x}");
    }
    // Two poses at the limit, on opposite corners and one rotated: the
    // relative translation a query computes stays within 2^1000.
    let corner = Isometry3::translation(MAX_TRANSLATION, MAX_TRANSLATION, MAX_TRANSLATION);
    let far = Isometry3::new(-corner.translation.vector, Vector3::new(0.3, -1.1, 0.7));
    let rel = far.inv_mul(&corner).translation.vector;
    assert!(rel.iter().all(|c| c.abs() <= 2f64.powi(1000)), "{rel}");
}
