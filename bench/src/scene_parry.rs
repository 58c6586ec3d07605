//! The parry3d-f64 side of `gjkd bench scene-robot`: the same jobs done in
//! process the way a parry user would write them.
//!
//! The obstacles never move, so their world AABBs go into one
//! [`Bvh`], built once. Per step and link:
//!
//! - *clearance*: [`Bvh::find_best`](parry3d_f64::partitioning::Bvh::find_best),
//!   parry's best-first search, with the distance between the link's AABB
//!   and a node's AABB as the node's lower bound (so a subtree farther than
//!   the best distance found so far is never opened) and
//!   [`query::distance`] at the leaves;
//! - *within a margin*: the obstacles whose AABB meets the link's AABB
//!   grown by the margin ([`Bvh::intersect_aabb`](parry3d_f64::partitioning::Bvh::intersect_aabb)),
//!   each checked with [`query::closest_points()`]
//!   and the margin as its `max_dist`, which stops as soon as the pair is
//!   proved farther.

use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy, BvhNode};
use parry3d_f64::query::{self, ClosestPoints, NonlinearRigidMotion};
use parry3d_f64::shape::Shape;

use crate::BenchError;
use crate::scene_world::Body;

/// The obstacles, ready for parry queries.
pub struct ParryScene {
    bvh: Bvh,
    shapes: Vec<Box<dyn Shape>>,
    poses: Vec<Pose>,
}

/// Distance between two AABBs: a lower bound on the distance between
/// anything inside them.
fn aabb_gap(mins: Vector, maxs: Vector, other: &Aabb) -> f64 {
    (mins - other.maxs)
        .max(other.mins - maxs)
        .max(Vector::ZERO)
        .length()
}

impl ParryScene {
    /// The obstacles' shapes at their poses, and a BVH over their AABBs.
    ///
    /// # Errors
    /// When parry cannot build a hull.
    pub fn new(obstacles: &[(Body, nalgebra::Isometry3<f64>)]) -> Result<Self, BenchError> {
        let shapes = obstacles
            .iter()
            .map(|(b, _)| b.parry())
            .collect::<Result<Vec<_>, _>>()?;
        let poses: Vec<Pose> = obstacles
            .iter()
            .map(|(_, p)| gjkd_testkit::parry::parry_pose(p))
            .collect();
        let aabbs: Vec<Aabb> = shapes
            .iter()
            .zip(&poses)
            .map(|(s, p)| s.compute_aabb(p))
            .collect();
        let bvh = Bvh::from_leaves(BvhBuildStrategy::default(), &aabbs);
        Ok(ParryScene { bvh, shapes, poses })
    }

    /// The nearest obstacle to `link` at `pose` and its distance.
    pub fn clearance(&self, link: &dyn Shape, pose: &Pose) -> Option<(u32, f64)> {
        let aabb = link.compute_aabb(pose);
        self.bvh.find_best(
            f64::MAX,
            |node: &BvhNode, _| aabb_gap(node.mins(), node.maxs(), &aabb),
            |leaf, _| {
                let i = leaf as usize;
                query::distance(pose, link, &self.poses[i], &*self.shapes[i])
                    .ok()
                    .map(|d| d.distance)
            },
        )
    }

    /// Appends to `out` every obstacle within `margin` of `link` at `pose`.
    pub fn within(&self, link: &dyn Shape, pose: &Pose, margin: f64, out: &mut Vec<u32>) {
        let grown = link.compute_aabb(pose).loosened(margin);
        for leaf in self.bvh.intersect_aabb(&grown) {
            let i = leaf as usize;
            match query::closest_points(pose, link, &self.poses[i], &*self.shapes[i], margin) {
                Ok(ClosestPoints::Intersecting | ClosestPoints::WithinMargin(..)) => {
                    out.push(leaf);
                }
                Ok(ClosestPoints::Disjoint) | Err(_) => {}
            }
        }
    }
}

impl ParryScene {
    /// Whether `link`, moving by `motion` over times `[0, 1]`, touches an
    /// obstacle whose AABB meets `swept`: parry's nonlinear time of impact
    /// ([`query::cast_shapes_nonlinear`], conservative advancement per
    /// pair), stopping at the first impact found.
    pub fn impact(&self, link: &dyn Shape, motion: &NonlinearRigidMotion, swept: &Aabb) -> bool {
        self.bvh.intersect_aabb(swept).any(|leaf| {
            let i = leaf as usize;
            let still = NonlinearRigidMotion::constant_position(self.poses[i]);
            matches!(
                query::cast_shapes_nonlinear(
                    motion,
                    link,
                    &still,
                    &*self.shapes[i],
                    0.0,
                    1.0,
                    true
                ),
                Ok(Some(_))
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene_world::{Arm, Obstacles, joint_path};
    use gjkd_testkit::parry::parry_pose;

    /// Every pair by brute force with `query::distance`, no BVH.
    fn brute(scene: &ParryScene, link: &dyn Shape, pose: &Pose) -> Vec<f64> {
        scene
            .shapes
            .iter()
            .zip(&scene.poses)
            .map(|(s, p)| query::distance(pose, link, p, &**s).unwrap().distance)
            .collect()
    }

    #[test]
    fn pruned_answers_equal_brute_force() {
        let arm = Arm::new();
        let obstacles = Obstacles::new(&arm, 300, 20, 5);
        let scene = ParryScene::new(&obstacles.bodies).unwrap();
        let links: Vec<_> = arm.links.iter().map(|(b, _)| b.parry().unwrap()).collect();
        let mut poses = Vec::new();
        let margin = 0.2;
        let mut found_within = 0;
        for s in 0..20 {
            arm.link_poses(&joint_path(s as f64 / 20.0), &mut poses);
            for (link, pose) in links.iter().zip(&poses) {
                let pose = parry_pose(pose);
                let all = brute(&scene, &**link, &pose);
                let best = all.iter().copied().fold(f64::INFINITY, f64::min);
                let (i, d) = scene.clearance(&**link, &pose).unwrap();
                assert_eq!(d, best);
                assert_eq!(all[i as usize], best);
                let mut within = Vec::new();
                scene.within(&**link, &pose, margin, &mut within);
                within.sort_unstable();
                let expected: Vec<u32> = (0..all.len() as u32)
                    .filter(|&j| all[j as usize] <= margin)
                    .collect();
                assert_eq!(within, expected);
                found_within += within.len();
            }
        }
        assert!(
            found_within > 0,
            "the scene puts something within the margin"
        );
    }
}
