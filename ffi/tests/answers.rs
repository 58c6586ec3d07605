//! The C API's answers are the Rust client's, field for field and bit for
//! bit: a batch written into the caller's arrays (split into chunks the
//! server takes), one pair, and pose updates, against a server whose batch
//! limit is small enough that the batch is split.

use std::ptr::null;

use gjkd_c::*;
use gjkd_e2e::Server;
use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use rust_client::{Item, ItemResult, ObjectId, QueryOptions};

use gjkd_status::GJKD_OK;

const MAX_BATCH: usize = 7;

fn pose_of(iso: &Isometry3<f64>) -> gjkd_pose {
    let t = iso.translation.vector;
    let q = iso.rotation.coords;
    gjkd_pose {
        translation: [t.x, t.y, t.z],
        rotation: [q.x, q.y, q.z, q.w],
    }
}

/// A pose that differs from row to row, with a rotation.
fn pose(i: usize) -> Isometry3<f64> {
    let f = i as f64;
    Isometry3::from_parts(
        Translation3::new(3.0 + 0.37 * f, 0.5 * (f * 0.9).sin(), -0.25 * f),
        UnitQuaternion::from_euler_angles(0.3 * f, -0.2 * f, 0.11 * f),
    )
}

fn ok(status: gjkd_status) {
    assert_eq!(status, GJKD_OK, "{:?}", unsafe {
        std::ffi::CStr::from_ptr(gjkd_last_error())
    });
}

/// Registers, through the C API, one object of each kind.
fn register_zoo(c: *mut gjkd_client) -> Vec<gjkd_id> {
    let mut ids = vec![0; 5];
    let cube: Vec<f64> = (0..8)
        .flat_map(|i| [i & 1, i & 2, i & 4].map(|b| if b == 0 { -0.4 } else { 0.4 }))
        .collect();
    let bead = gjkd_shape {
        kind: gjkd_shape_kind::GJKD_SHAPE_SPHERE as u32,
        radius: 0.3,
        a: [0.0; 3],
        b: [0.0; 3],
        vertices: null(),
        vertex_count: 0,
    };
    let pieces = [
        gjkd_piece {
            offset: pose_of(&Isometry3::translation(-1.0, 0.0, 0.0)),
            shape: bead,
        },
        gjkd_piece {
            offset: pose_of(&Isometry3::translation(1.0, 0.0, 0.0)),
            shape: bead,
        },
    ];
    // SAFETY: valid pointers, live handle.
    unsafe {
        ok(gjkd_register_sphere(c, 0.5, null(), null(), &mut ids[0]));
        ok(gjkd_register_box(
            c,
            [1.0, 0.5, 0.25].as_ptr(),
            0.05,
            null(),
            null(),
            &mut ids[1],
        ));
        ok(gjkd_register_capsule(
            c,
            [0.0, -1.0, 0.0].as_ptr(),
            [0.0, 1.0, 0.0].as_ptr(),
            0.2,
            null(),
            null(),
            &mut ids[2],
        ));
        ok(gjkd_register_polytope(
            c,
            cube.as_ptr(),
            8,
            0.0,
            null(),
            null(),
            &mut ids[3],
        ));
        ok(gjkd_register_compound(
            c,
            pieces.as_ptr(),
            2,
            null(),
            null(),
            &mut ids[4],
        ));
    }
    ids
}

/// The arrays of a batch of `n` rows.
struct Arrays {
    distance: Vec<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    penetration: Vec<f64>,
    point_a: Vec<f64>,
    point_b: Vec<f64>,
    normal: Vec<f64>,
    status: Vec<u32>,
    iterations: Vec<u32>,
    pieces: Vec<u32>,
    error: Vec<u32>,
    warm: Vec<bool>,
}

impl Arrays {
    fn new(n: usize) -> Self {
        Arrays {
            distance: vec![f64::NAN; n],
            lower: vec![f64::NAN; n],
            upper: vec![f64::NAN; n],
            penetration: vec![f64::NAN; n],
            point_a: vec![f64::NAN; 3 * n],
            point_b: vec![f64::NAN; 3 * n],
            normal: vec![f64::NAN; 3 * n],
            status: vec![99; n],
            iterations: vec![99; n],
            pieces: vec![99; 2 * n],
            error: vec![99; n],
            warm: vec![true; n],
        }
    }

    fn view(&mut self) -> gjkd_results {
        gjkd_results {
            distance: self.distance.as_mut_ptr(),
            lower: self.lower.as_mut_ptr(),
            upper: self.upper.as_mut_ptr(),
            penetration: self.penetration.as_mut_ptr(),
            point_a: self.point_a.as_mut_ptr(),
            point_b: self.point_b.as_mut_ptr(),
            normal: self.normal.as_mut_ptr(),
            status: self.status.as_mut_ptr(),
            iterations: self.iterations.as_mut_ptr(),
            pieces: self.pieces.as_mut_ptr(),
            error: self.error.as_mut_ptr(),
            warm_started: self.warm.as_mut_ptr(),
        }
    }

    /// Row `i` equals `r`, bit for bit.
    #[track_caller]
    fn assert_row(&self, i: usize, r: &ItemResult) {
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(self.distance[i].to_bits(), r.distance.to_bits(), "row {i}");
        assert_eq!(self.lower[i].to_bits(), r.lower.to_bits(), "row {i}");
        assert_eq!(self.upper[i].to_bits(), r.upper.to_bits(), "row {i}");
        assert_eq!(
            self.penetration[i].to_bits(),
            r.penetration.to_bits(),
            "row {i}"
        );
        assert_eq!(
            bits(&self.point_a[3 * i..3 * i + 3]),
            bits(&r.point_a),
            "row {i}"
        );
        assert_eq!(
            bits(&self.point_b[3 * i..3 * i + 3]),
            bits(&r.point_b),
            "row {i}"
        );
        assert_eq!(
            bits(&self.normal[3 * i..3 * i + 3]),
            bits(&r.normal),
            "row {i}"
        );
        assert_eq!(self.status[i], r.status, "row {i}");
        assert_eq!(self.iterations[i], r.iterations, "row {i}");
        assert_eq!(self.pieces[2 * i..2 * i + 2], r.pieces, "row {i}");
        assert_eq!(self.error[i], r.error, "row {i}");
        let warm = r.flags & gjkd_proto::result_flags::WARM_STARTED != 0;
        assert_eq!(self.warm[i], warm, "row {i}");
    }
}

#[test]
fn batches_and_single_pairs_equal_the_rust_clients_answers() {
    let max = MAX_BATCH.to_string();
    let server = Server::start("ffi-answers", &["--no-persist", "--max-batch", &max]);
    let service = std::ffi::CString::new(server.service.clone()).unwrap();
    let mut c = std::ptr::null_mut();
    // SAFETY: valid pointers.
    ok(unsafe { gjkd_connect(service.as_ptr(), 2.0, 10.0, &mut c) });
    let ids = register_zoo(c);
    let mut rust = server.client(std::time::Duration::from_secs(2));

    // Every ordered pair of the zoo, each with its own poses: more rows
    // than the server takes at once, so the call sends several chunks.
    let mut pairs = Vec::new();
    let (mut poses_a, mut poses_b) = (Vec::new(), Vec::new());
    let mut items = Vec::new();
    let cold = QueryOptions::cold();
    for (i, &a) in ids.iter().enumerate() {
        for (j, &b) in ids.iter().enumerate() {
            let (pa, pb) = (pose(i), pose(10 + 3 * j + i));
            pairs.extend([a, b]);
            poses_a.push(pose_of(&pa));
            poses_b.push(pose_of(&pb));
            let (oa, ob) = (ObjectId::from_raw(a), ObjectId::from_raw(b));
            items.push(Item::distance_at(oa, &pa, ob, &pb, &cold));
        }
    }
    // One id no server gave out, failing alone in its row.
    pairs.extend([ids[0], 0xdead]);
    poses_a.push(pose_of(&pose(0)));
    poses_b.push(pose_of(&pose(1)));
    items.push(Item::distance_at(
        ObjectId::from_raw(ids[0]),
        &pose(0),
        ObjectId::from_raw(0xdead),
        &pose(1),
        &cold,
    ));
    let n = items.len();
    assert!(n > 3 * MAX_BATCH);
    let mut want = vec![ItemResult::default(); n];
    for chunk in (0..n).step_by(MAX_BATCH) {
        let end = n.min(chunk + MAX_BATCH);
        rust.query_batch(&items[chunk..end], &mut want[chunk..end])
            .expect("the Rust client answers");
    }
    let mut got = Arrays::new(n);
    let mut options = gjkd_query_options_default();
    options.warm_start = false;
    let view = got.view();
    // SAFETY: arrays of n rows, 2n ids, n poses each.
    ok(unsafe {
        gjkd_distances(
            c,
            pairs.as_ptr(),
            n,
            poses_a.as_ptr(),
            poses_b.as_ptr(),
            &options,
            &view,
        )
    });
    for (i, r) in want.iter().enumerate() {
        got.assert_row(i, r);
    }
    assert_eq!(
        got.error[n - 1],
        gjkd_error_code::GJKD_CODE_UNKNOWN_OBJECT as u32
    );
    assert!(
        got.pieces.contains(&1),
        "a compound's second piece is named"
    );

    // One pair at stored poses, set in one call through the C API: the
    // box (half extents 1, 0.5, 0.25, rounded by 0.05) at the origin and
    // the ball (radius 0.5) at x = 3 are 3 - 1.05 - 0.5 apart.
    let stored = [
        pose_of(&Isometry3::identity()),
        pose_of(&Isometry3::translation(3.0, 0.0, 0.0)),
    ];
    let moved = [ids[1], ids[0]];
    // SAFETY: two ids, two poses.
    ok(unsafe { gjkd_set_poses(c, moved.as_ptr(), stored.as_ptr(), 2) });
    let mut answer = gjkd_answer::default();
    // SAFETY: valid pointers.
    ok(unsafe { gjkd_distance(c, ids[1], ids[0], null(), null(), &options, &mut answer) });
    assert!((answer.distance - 1.45).abs() < 1e-12, "{answer:?}");
    assert!((answer.point_a[0] - 1.05).abs() < 1e-12, "{answer:?}");
    assert!((answer.point_b[0] - 2.5).abs() < 1e-12, "{answer:?}");
    let (oa, ob) = (ObjectId::from_raw(ids[1]), ObjectId::from_raw(ids[0]));
    let want = rust
        .distance(oa, ob, &cold)
        .expect("the Rust client answers");
    assert_eq!(answer.distance.to_bits(), want.distance.to_bits());
    assert_eq!(answer.point_a, <[f64; 3]>::from(want.point_a.coords));
    assert_eq!(answer.point_b, <[f64; 3]>::from(want.point_b.coords));
    assert_eq!(answer.normal, <[f64; 3]>::from(want.normal));
    assert_eq!((answer.lower, answer.upper), (want.lower, want.upper));
    assert_eq!(answer.status, want.status.map_or(0, |s| s.raw()));
    assert_eq!(answer.iterations, want.iterations);
    // SAFETY: a live handle.
    ok(unsafe { gjkd_close(c) });
}
