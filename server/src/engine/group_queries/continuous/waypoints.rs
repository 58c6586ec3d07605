//! A continuous path's waypoints: where each step of its items leaves the
//! rigid objects it poses and the robots it moves, computed without
//! touching the store (an error anywhere is found before anything is
//! asked).

use gjkd_proto::{ErrorCode, Item, ItemKind, item_flags};
use nalgebra::Isometry3;

use super::super::broadphase::Broadphase;
use super::super::path::{RobotOverlay, item_poses};
use crate::engine::checks::check_pose;
use crate::engine::objects::ObjectStore;
use crate::engine::robots::Robots;

/// A rigid object a path poses: its broadphase slot and its pose at every
/// waypoint (its stored pose before the path first poses it).
#[derive(Debug)]
pub(crate) struct RigidWay {
    /// Its slot.
    pub slot: u32,
    /// Its pose at each waypoint.
    pub poses: Vec<Isometry3<f64>>,
}

/// A robot a path moves: its joint positions and base at every waypoint.
#[derive(Debug)]
pub(crate) struct RobotWay {
    /// Its id.
    pub id: u64,
    /// Its number of joint positions.
    pub dof: usize,
    /// `positions[w * dof..][..dof]` at waypoint `w`.
    pub positions: Vec<f64>,
    /// Its base at each waypoint.
    pub bases: Vec<Isometry3<f64>>,
}

impl RobotWay {
    /// The joint positions at waypoint `w`.
    pub(crate) fn at(&self, w: usize) -> &[f64] {
        &self.positions[w * self.dof..(w + 1) * self.dof]
    }

    fn moves(&self, k: usize) -> bool {
        self.at(k) != self.at(k + 1) || self.bases[k] != self.bases[k + 1]
    }
}

/// Every waypoint of a continuous path.
#[derive(Debug, Default)]
pub(crate) struct Waypoints {
    /// Number of waypoints (steps of the items).
    pub count: usize,
    /// The rigid objects posed.
    pub rigid: Vec<RigidWay>,
    /// The robots moved.
    pub robots: Vec<RobotWay>,
}

/// Reads a continuous path's items (checked by the layout check) into its
/// waypoints, checking every pose and joint item as the query service
/// does; `clamp` clamps joint positions as the items' own flag.
///
/// # Errors
/// Those of the pose and joint items; [`ErrorCode::Malformed`] for fewer
/// than two waypoints, a segment along which nothing moves, or a robot's
/// link that the path also poses as a rigid object.
pub(crate) fn plan(
    store: &ObjectStore,
    robots: &Robots,
    bp: &Broadphase,
    overlay: &mut RobotOverlay,
    items: &[Item],
    clamp: bool,
) -> Result<Waypoints, ErrorCode> {
    overlay.reset();
    let mut w = Waypoints::default();
    let mut current: Vec<Isometry3<f64>> = Vec::new();
    let mut scratch = Vec::new();
    for item in items {
        match ItemKind::from_raw(item.kind) {
            Some(ItemKind::SetPose) => {
                if store.object(item.a).is_none() {
                    return Err(ErrorCode::UnknownObject);
                }
                let pose = check_pose(&item.pose_a)?;
                let slot = bp.slot(item.a).ok_or(ErrorCode::UnknownObject)?;
                let i = match w.rigid.iter().position(|r| r.slot == slot) {
                    Some(i) => i,
                    None => {
                        let stored = bp.entry(slot).pose;
                        w.rigid.push(RigidWay {
                            slot,
                            poses: vec![stored; w.count],
                        });
                        current.push(stored);
                        w.rigid.len() - 1
                    }
                };
                current[i] = pose;
            }
            Some(ItemKind::SetJoints) => {
                scratch.clear();
                item_poses(store, robots, overlay, item, clamp, &mut scratch)?;
                if !w.robots.iter().any(|r| r.id == item.a) {
                    let robot = robots.get(item.a).ok_or(ErrorCode::UnknownObject)?;
                    let dof = robot.positions.len();
                    w.robots.push(RobotWay {
                        id: item.a,
                        dof,
                        positions: robot.positions.repeat(w.count),
                        bases: vec![robot.base; w.count],
                    });
                }
            }
            _ => {}
        }
        if item.kind == ItemKind::Step as u32 || item.flags & item_flags::END_STEP != 0 {
            for (r, pose) in w.rigid.iter_mut().zip(&current) {
                r.poses.push(*pose);
            }
            for r in &mut w.robots {
                let (q, base) = overlay.state(r.id).ok_or(ErrorCode::Internal)?;
                r.positions.extend_from_slice(q);
                r.bases.push(*base);
            }
            w.count += 1;
        }
    }
    if w.count < 2 {
        return Err(ErrorCode::Malformed);
    }
    for r in &w.robots {
        let robot = robots.get(r.id).ok_or(ErrorCode::UnknownObject)?;
        let posed = robot
            .links
            .iter()
            .flatten()
            .filter_map(|&id| bp.slot(id))
            .any(|slot| w.rigid.iter().any(|g| g.slot == slot));
        if posed {
            return Err(ErrorCode::Malformed);
        }
    }
    for k in 0..w.count - 1 {
        let rigid = w.rigid.iter().any(|r| r.poses[k] != r.poses[k + 1]);
        if !rigid && !w.robots.iter().any(|r| r.moves(k)) {
            return Err(ErrorCode::Malformed);
        }
    }
    Ok(w)
}
