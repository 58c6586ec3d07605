//! What a scene answer's written rows get besides their distance, at
//! their step's poses, once the step is answered: the signed distance
//! (with [`scene_flags::SIGNED_DISTANCE`](gjkd_proto::scene_flags::SIGNED_DISTANCE))
//! and the gradient (with
//! [`scene_flags::GRADIENTS`](gjkd_proto::scene_flags::GRADIENTS)). A row
//! answered without its nearest points (from a motion bound, or by an
//! early exit at the margin) is asked again to convergence first for its
//! gradient; the signed distance of a pair that may overlap is computed
//! once and read by both.

use gjkd_proto::{ErrorCode, SceneRow, Status};

use super::Question;
use crate::engine::gradient::{self, Side, Stance};
use crate::engine::pair_query::run_pair;
use crate::engine::signed_pair::add_signed_distance;
use crate::engine::state::State;

impl State {
    /// Fills the signed distance and the gradient, as asked, of every row
    /// of `rows` (one step's, written into the caller's buffer) that
    /// answers a pair; `path` says whether the robots stand where the
    /// path's step put them.
    pub(super) fn finish_rows(&mut self, q: &Question, rows: &mut [SceneRow], path: bool) {
        if !(q.gradients || q.signed) {
            return;
        }
        let engine = &mut self.groups;
        let bp = &engine.broadphase;
        for row in rows {
            if row.b == 0 || row.result.error != ErrorCode::Ok as u32 {
                continue;
            }
            let side = |id: u64| {
                let object = self.store.object(id)?;
                let pose = match bp.slot(id) {
                    Some(slot) => &bp.entry(slot).pose,
                    None => &object.pose,
                };
                Some(Side {
                    id,
                    shape: &object.shape,
                    pose,
                })
            };
            let (Some(a), Some(b)) = (side(row.a), side(row.b)) else {
                continue;
            };
            let approximate = matches!(
                Status::from_raw(row.result.status),
                Some(Status::Closer | Status::Farther | Status::Bounded)
            );
            if q.gradients && approximate {
                let mut options = q.options;
                options.margin = None;
                match run_pair(
                    &mut self.workspace,
                    (a.shape, a.pose),
                    (b.shape, b.pose),
                    &options,
                    None,
                ) {
                    Ok((result, _)) => row.result = result,
                    Err(code) => {
                        row.result.error = code as u32;
                        continue;
                    }
                }
            }
            let depth = if q.signed {
                match add_signed_distance(
                    &mut row.result,
                    (a.shape, a.pose),
                    (b.shape, b.pose),
                    &q.options,
                ) {
                    Ok(depth) => depth,
                    Err(code) => {
                        row.result.error = code as u32;
                        continue;
                    }
                }
            } else {
                None
            };
            if !q.gradients {
                continue;
            }
            let stance = Stance {
                steps: path.then_some(&engine.step_configurations),
                step: row.step,
                base: q.gradient_base,
            };
            if let Err(code) = gradient::fill(
                &mut row.result,
                &mut row.gradient,
                a,
                b,
                &self.robots,
                &mut engine.link_poses,
                stance,
                depth.as_ref(),
            ) {
                row.result.error = code as u32;
            }
        }
    }
}
