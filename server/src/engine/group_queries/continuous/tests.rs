//! The links' motion bounds against their true motion: the vendored Panda
//! (prismatic fingers, one a mimic) and UR5 on random segments, every
//! link's bounding ball sampled (its centre and points on its surface),
//! moved by the model's forward kinematics at dense `s`: no point may
//! move farther between two values of `s` than the bound allows.

// The model tests' deterministic generator (the same motions every run).
#[path = "../../../../../model/tests/files.rs"]
mod files;

use files::Rng;

use gjkd_model::{LimitMode, PackagePath, RobotModel};
use nalgebra::{Isometry3, Point3, Vector3};

use super::super::broadphase::bounding_sphere;
use super::motion::{EndPoses, LinkBall, link_rate};

/// Samples of `s` per segment.
const DENSE: usize = 2_000;

fn model(name: &str) -> RobotModel {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../model/tests/data");
    let path = data.join(match name {
        "panda" => "example-robot-data/robots/panda_description/urdf/panda.urdf",
        _ => "example-robot-data/robots/ur_description/urdf/ur5_robot.urdf",
    });
    let urdf = std::fs::read_to_string(&path).unwrap();
    RobotModel::from_urdf_str(&urdf, path.parent(), &PackagePath::new([data])).unwrap()
}

/// The centre and points on the surface of a ball, in its link's frame.
fn ball_points(ball: &LinkBall) -> Vec<Point3<f64>> {
    let mut points = vec![ball.centre];
    for x in -1..=1 {
        for y in -1..=1 {
            for z in -1..=1 {
                let d = Vector3::new(f64::from(x), f64::from(y), f64::from(z));
                if d != Vector3::zeros() {
                    points.push(ball.centre + d.normalize() * ball.extent);
                }
            }
        }
    }
    points
}

/// Returns how much of the bound the truest motion used at most (the
/// largest ratio of a point's displacement to its bound).
fn check_robot(name: &str, seed: u64, segments: usize, step: f64) -> f64 {
    let model = model(name);
    let kinematics = &model.kinematics;
    let mut parent_joint = vec![None; kinematics.link_names().len()];
    for (j, joint) in kinematics.joints().iter().enumerate() {
        parent_joint[joint.child] = Some(j);
    }
    let limits: Vec<(f64, f64)> = kinematics
        .moving_joints()
        .map(|j| {
            (
                j.lower.max(-std::f64::consts::PI),
                j.upper.min(std::f64::consts::PI),
            )
        })
        .collect();
    let base = Isometry3::identity();
    let fk = |q: &[f64]| kinematics.link_poses(&base, q, LimitMode::Clamp).unwrap();
    let mut rng = Rng(seed);
    let mut most: f64 = 0.0;
    for _ in 0..segments {
        let q0: Vec<f64> = limits.iter().map(|&(lo, hi)| rng.uniform(lo, hi)).collect();
        let q1: Vec<f64> = q0
            .iter()
            .zip(&limits)
            .map(|(x, &(lo, hi))| (x + rng.uniform(-step, step)).clamp(lo, hi))
            .collect();
        let (start, end) = (fk(&q0), fk(&q1));
        let ends = EndPoses {
            start: &start,
            end: &end,
        };
        let samples: Vec<Vec<Isometry3<f64>>> = (0..=DENSE)
            .map(|i| {
                let s = i as f64 / DENSE as f64;
                let q: Vec<f64> = q0.iter().zip(&q1).map(|(a, b)| a + (b - a) * s).collect();
                fk(&q)
            })
            .collect();
        for (link, l) in model.links.iter().enumerate() {
            let Some(shape) = &l.shape else { continue };
            let (centre, extent, reach) = bounding_sphere(shape);
            let ball = LinkBall {
                centre,
                extent,
                reach,
            };
            let bound = link_rate(kinematics, &parent_joint, (&q0, &q1), &ends, link, &ball);
            for p in ball_points(&ball) {
                // The point at every sample, placed once.
                let at: Vec<Point3<f64>> = samples.iter().map(|poses| poses[link] * p).collect();
                for i in 1..=DENSE {
                    // Between neighbours, and from the start.
                    for (from, ds) in [(i - 1, 1.0 / DENSE as f64), (0, i as f64 / DENSE as f64)] {
                        let moved = (at[i] - at[from]).norm();
                        let allowed = bound.rate * ds;
                        assert!(
                            moved <= allowed,
                            "{name} link {} moved {moved} > {allowed} over {ds}",
                            l.name
                        );
                        if allowed > 0.0 {
                            most = most.max(moved / allowed);
                        }
                    }
                }
            }
        }
    }
    most
}

#[test]
fn panda_links_move_no_faster_than_their_bounds() {
    let used = check_robot("panda", 0x5a5a_1234, 6, 1.0);
    // Not so loose as to clear nothing: the truest motion uses a good part.
    assert!(used > 0.2, "the bound is {used} used at most");
}

#[test]
fn ur5_links_move_no_faster_than_their_bounds() {
    let used = check_robot("ur5", 0x00dd_ba11, 6, 1.0);
    assert!(used > 0.2, "the bound is {used} used at most");
}
