//! Robot link poses for gradients: computed once per robot and path step
//! of a request, and the joint positions a path's steps give each robot.

use gjkd_model::{Kinematics, LimitMode};
use nalgebra::Isometry3;

/// Every link's pose of the robots a request's gradients need, one entry
/// per (robot, step), buffers reused from one request to the next.
#[derive(Debug, Default)]
pub(crate) struct LinkPoses {
    entries: Vec<Posed>,
    used: usize,
    positions: Vec<f64>,
}

#[derive(Debug, Default)]
struct Posed {
    robot: u64,
    step: u32,
    poses: Vec<Isometry3<f64>>,
}

impl LinkPoses {
    /// Forgets every entry (a new request, or poses changed).
    pub(crate) fn reset(&mut self) {
        self.used = 0;
    }

    /// The link poses of `robot` at `step`, computed from `base` and
    /// `positions` the first time they are asked; `None` if the positions
    /// cannot be posed (they were checked when set, so never).
    pub(crate) fn get(
        &mut self,
        robot: u64,
        step: u32,
        kinematics: &Kinematics,
        (base, positions): (&Isometry3<f64>, &[f64]),
    ) -> Option<&[Isometry3<f64>]> {
        let found = self.entries[..self.used]
            .iter()
            .position(|e| e.robot == robot && e.step == step);
        let at = match found {
            Some(at) => at,
            None => {
                if self.used == self.entries.len() {
                    self.entries.push(Posed::default());
                }
                let entry = &mut self.entries[self.used];
                self.positions.clear();
                self.positions.extend_from_slice(positions);
                // Positions were checked (and clamped if asked) when set.
                kinematics
                    .link_poses_into(
                        base,
                        &mut self.positions,
                        LimitMode::Clamp,
                        &mut entry.poses,
                    )
                    .ok()?;
                entry.robot = robot;
                entry.step = step;
                self.used += 1;
                self.used - 1
            }
        };
        Some(&self.entries[at].poses)
    }
}

/// The joint positions and base each robot a path moves has at each of
/// its steps, recorded as the path is planned.
#[derive(Debug, Default)]
pub(crate) struct StepConfigurations {
    entries: Vec<(u32, u64, Isometry3<f64>, usize, usize)>,
    values: Vec<f64>,
}

impl StepConfigurations {
    /// Forgets every step.
    pub(crate) fn clear(&mut self) {
        self.entries.clear();
        self.values.clear();
    }

    /// Records that `robot` is at `base` and `positions` at `step`.
    pub(crate) fn record(
        &mut self,
        step: u32,
        robot: u64,
        base: &Isometry3<f64>,
        positions: &[f64],
    ) {
        let start = self.values.len();
        self.values.extend_from_slice(positions);
        self.entries
            .push((step, robot, *base, start, positions.len()));
    }

    /// `robot`'s base and positions at `step`, if the path moved it by then.
    pub(crate) fn at(&self, robot: u64, step: u32) -> Option<(&Isometry3<f64>, &[f64])> {
        self.entries
            .iter()
            .rev()
            .find(|e| e.1 == robot && e.0 <= step)
            .map(|(_, _, base, start, len)| (base, &self.values[*start..start + len]))
    }
}
