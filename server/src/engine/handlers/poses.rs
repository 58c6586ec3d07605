//! The pose service's handler: stored poses read back, one entry an id.

use gjkd_proto::{ErrorCode, Pose, StoredPose};

use crate::engine::state::State;

impl State {
    /// Answers one pose request: `out[i]` is the stored pose of `ids[i]`,
    /// or [`ErrorCode::UnknownObject`] for an id the store does not hold
    /// (the other ids are answered all the same, as a query batch's items
    /// are). A robot link's stored pose is the one its robot's last joint
    /// update computed. `out` must be as long as `ids`; a short buffer
    /// answers only what fits. Changes nothing.
    pub fn poses(&self, ids: &[u64], out: &mut [StoredPose]) {
        for (&id, entry) in ids.iter().zip(out.iter_mut()) {
            *entry = match self.object(id) {
                Some(object) => StoredPose {
                    id,
                    error: ErrorCode::Ok as u32,
                    reserved: 0,
                    pose: Pose::from_isometry(&object.pose),
                },
                None => StoredPose {
                    id,
                    error: ErrorCode::UnknownObject as u32,
                    reserved: 0,
                    pose: Pose::IDENTITY,
                },
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use gjkd_proto::{AdminChunk, AdminOp, AdminRequest, Item, ItemResult, ObjectId, Vertex};
    use gjkd_proto::{WaitMode, shape_kind};
    use nalgebra::{Isometry3, Vector3};

    use super::*;
    use crate::engine::state::Limits;

    fn ball(s: &mut State) -> u64 {
        let mut req = AdminRequest::new(AdminOp::Register);
        req.shape = shape_kind::CONVEX;
        req.piece_count = 1;
        req.pieces[0].vertex_count = 1;
        req.pieces[0].rounding = 0.5;
        let reply = s.handle_admin(1, &req, AdminChunk::from_vertices(&[Vertex::default()]));
        assert_eq!(reply.error, 0);
        reply.id
    }

    #[test]
    fn stored_poses_come_back_bit_for_bit_and_unknown_ids_alone_fail() {
        let mut s = State::new(Limits::default(), WaitMode::Spin, 1);
        let (a, b) = (ball(&mut s), ball(&mut s));
        // A pose with every bit in use: an irrational rotation, a
        // translation that is not a short binary fraction.
        let pose = Isometry3::new(
            Vector3::new(0.1, -2.0 / 3.0, 1e-7),
            Vector3::new(0.3, -1.1, 0.7),
        );
        let mut result = [ItemResult::default()];
        s.handle(
            1,
            &[Item::set_pose(ObjectId::from_raw(a), &pose)],
            &mut result,
        );
        assert_eq!(result[0].error, 0);
        let unknown = b + 1000;
        let mut out = [StoredPose::default(); 3];
        s.poses(&[a, unknown, b], &mut out);
        assert_eq!(out[0].id, a);
        assert_eq!(out[0].pose(), Ok(Pose::from_isometry(&pose)));
        let sent = Pose::from_isometry(&pose);
        let back = out[0].pose;
        for (x, y) in sent
            .translation
            .iter()
            .chain(&sent.rotation)
            .zip(back.translation.iter().chain(&back.rotation))
        {
            assert_eq!(x.to_bits(), y.to_bits());
        }
        assert_eq!(out[1].id, unknown);
        assert_eq!(out[1].pose(), Err(ErrorCode::UnknownObject));
        // B never moved: the identity it was registered at.
        assert_eq!(out[2].pose(), Ok(Pose::IDENTITY));
    }
}
