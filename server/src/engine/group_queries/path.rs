//! Pose and joint items of a scene request: the poses each sets, computed
//! without touching the store, so that a request is checked whole before
//! anything changes and a path's steps move the objects in a scratch
//! overlay only.

use gjkd_model::LimitMode;
use gjkd_proto::{ErrorCode, Item, ItemKind, item_flags};
use nalgebra::Isometry3;

use crate::engine::checks::check_pose;
use crate::engine::gradient::StepConfigurations;
use crate::engine::objects::ObjectStore;
use crate::engine::robots::{Robots, joint_code};

/// One robot's joint positions and base as a request's items leave them.
#[derive(Debug, Default)]
struct RobotState {
    id: u64,
    positions: Vec<f64>,
    base: Isometry3<f64>,
}

/// The robots a request moves, as its items leave them; buffers reused.
#[derive(Debug, Default)]
pub(crate) struct RobotOverlay {
    robots: Vec<RobotState>,
    used: usize,
    /// Scratch of forward kinematics.
    poses: Vec<Isometry3<f64>>,
    positions: Vec<f64>,
}

impl RobotOverlay {
    /// Starts from the stored positions of every robot.
    pub(crate) fn reset(&mut self) {
        self.used = 0;
    }

    /// Records where every robot the request has moved so far stands at
    /// path step `step`, for the step's gradients.
    pub(crate) fn record(&self, step: u32, out: &mut StepConfigurations) {
        for robot in &self.robots[..self.used] {
            out.record(step, robot.id, &robot.base, &robot.positions);
        }
    }

    /// Robot `id`'s joint positions and base as the items so far leave
    /// them, if an item moved it.
    pub(crate) fn state(&self, id: u64) -> Option<(&[f64], &Isometry3<f64>)> {
        self.robots[..self.used]
            .iter()
            .find(|r| r.id == id)
            .map(|r| (r.positions.as_slice(), &r.base))
    }

    /// The overlay index of robot `id`, started from its stored state.
    fn index_of(&mut self, robots: &Robots, id: u64) -> Result<usize, ErrorCode> {
        if let Some(i) = self.robots[..self.used].iter().position(|r| r.id == id) {
            return Ok(i);
        }
        let robot = robots.get(id).ok_or(ErrorCode::UnknownObject)?;
        if self.used == self.robots.len() {
            self.robots.push(RobotState::default());
        }
        let state = &mut self.robots[self.used];
        state.id = id;
        state.positions.clear();
        state.positions.extend_from_slice(&robot.positions);
        state.base = robot.base;
        self.used += 1;
        Ok(self.used - 1)
    }
}

/// Appends to `out` the object poses that pose item `item` sets (a
/// [`ItemKind::SetPose`] or [`ItemKind::SetJoints`]), the robots' joint
/// positions taken from and left in `overlay`; `clamp` clamps joint
/// positions as the item's own flag. Checks as the query service does.
///
/// # Errors
/// Those of a pose or joint item of the query service: see
/// [`crate::engine::robots::set_joints`]; [`ErrorCode::Malformed`] for any other
/// kind.
pub(crate) fn item_poses(
    store: &ObjectStore,
    robots: &Robots,
    overlay: &mut RobotOverlay,
    item: &Item,
    clamp: bool,
    out: &mut Vec<(u64, Isometry3<f64>)>,
) -> Result<(), ErrorCode> {
    match ItemKind::from_raw(item.kind) {
        Some(ItemKind::SetPose) => {
            if store.object(item.a).is_none() {
                return Err(ErrorCode::UnknownObject);
            }
            out.push((item.a, check_pose(&item.pose_a)?));
            Ok(())
        }
        Some(ItemKind::SetJoints) => joint_poses(store, robots, overlay, item, clamp, out),
        _ => Err(ErrorCode::Malformed),
    }
}

fn joint_poses(
    store: &ObjectStore,
    robots: &Robots,
    overlay: &mut RobotOverlay,
    item: &Item,
    clamp: bool,
    out: &mut Vec<(u64, Isometry3<f64>)>,
) -> Result<(), ErrorCode> {
    let values = item.joint_positions().ok_or(ErrorCode::Malformed)?;
    // `b` is no field of a joint update: refused, not ignored.
    if item.b != 0 {
        return Err(ErrorCode::Malformed);
    }
    let index = overlay.index_of(robots, item.a)?;
    let robot = robots.get(item.a).ok_or(ErrorCode::UnknownObject)?;
    let state = &mut overlay.robots[index];
    let count = values.len();
    let first = item.joints().first as usize;
    let end = first.checked_add(count).ok_or(ErrorCode::Malformed)?;
    if end > state.positions.len() {
        return Err(ErrorCode::Malformed);
    }
    let base = if item.flags & item_flags::POSE_A != 0 {
        check_pose(&item.pose_a)?
    } else {
        state.base
    };
    let mode = if clamp || item.flags & item_flags::CLAMP != 0 {
        LimitMode::Clamp
    } else {
        LimitMode::Reject
    };
    let positions = &mut overlay.positions;
    positions.clear();
    positions.extend_from_slice(&state.positions);
    positions[first..end].copy_from_slice(values);
    robot
        .kinematics
        .link_poses_into(&base, positions, mode, &mut overlay.poses)
        .map_err(joint_code)?;
    if robot
        .links
        .iter()
        .flatten()
        .any(|&id| store.object(id).is_none())
    {
        return Err(ErrorCode::UnknownObject);
    }
    state.positions.copy_from_slice(positions);
    state.base = base;
    for (id, pose) in robot.links.iter().zip(&overlay.poses) {
        if let Some(id) = id {
            out.push((*id, *pose));
        }
    }
    Ok(())
}
