//! The objects every transport of `gjkd bench latency` answers about: two
//! boxes for the single pair and one more box per batch item, each item at
//! a pose of its own. The in-process baseline and the socket server child
//! (`gjkd bench uds-server`) build them through the same admin handler in
//! the same order, so the ids the bench sends name the same objects
//! everywhere; the iceoryx2 transports register the same boxes through the
//! client.

use gjkd_proto::{
    AdminChunk, AdminOp, AdminRequest, Item, ItemResult, ObjectId, Vertex, WaitMode, shape_kind,
};
use gjkd_server::engine::{Limits, State};
use nalgebra::{Isometry3, Vector3};

/// Half extents of every box.
pub(crate) const HALF: [f64; 3] = [0.5, 0.4, 0.3];

/// The batch item `k`: box 0 against box `k + 1` at a pose of its own, so
/// that every item is its own warm-start entry, as a robot's links against
/// its obstacles would be.
pub(crate) fn batch_pose(k: usize) -> Isometry3<f64> {
    Isometry3::new(
        Vector3::new(1.5 + 0.001 * k as f64, 0.2, -0.1),
        Vector3::new(0.1, 0.003 * k as f64, 0.3),
    )
}

/// The pose of the single pair's second box (the first stays at the
/// origin).
pub(crate) fn single_pose() -> Isometry3<f64> {
    Isometry3::new(Vector3::new(1.6, 0.3, 0.1), Vector3::new(0.2, 0.4, 0.1))
}

/// A state with the bench's objects, registered through the admin handler
/// exactly as a client's requests would be. Deterministic: the socket server
/// child builds the same one, so these ids name its objects too.
pub(crate) fn local_state(max_batch: usize) -> (State, ObjectId, ObjectId, Vec<ObjectId>) {
    let mut state = State::new(Limits::default(), WaitMode::Block, 0x5eed);
    let mut reg = AdminRequest::new(AdminOp::Register);
    reg.shape = shape_kind::CONVEX;
    reg.piece_count = 1;
    reg.pieces[0].vertex_count = 8;
    let verts: Vec<Vertex> = (0..8)
        .map(|i| Vertex {
            x: if i & 1 == 0 { -HALF[0] } else { HALF[0] },
            y: if i & 2 == 0 { -HALF[1] } else { HALF[1] },
            z: if i & 4 == 0 { -HALF[2] } else { HALF[2] },
        })
        .collect();
    let mut reg_one = || {
        ObjectId::from_raw(
            state
                .handle_admin(1, &reg, AdminChunk::from_vertices(&verts))
                .id,
        )
    };
    let a = reg_one();
    let b = reg_one();
    let boxes: Vec<ObjectId> = (0..=max_batch).map(|_| reg_one()).collect();
    let mut set = [Item::set_pose(b, &single_pose())];
    let mut out = [ItemResult::default()];
    state.handle(0, &set, &mut out);
    set[0] = Item::set_pose(a, &Isometry3::identity());
    state.handle(0, &set, &mut out);
    (state, a, b, boxes)
}
