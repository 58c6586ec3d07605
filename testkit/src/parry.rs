//! The same world geometry handed to parry3d-f64, converted through plain
//! arrays, for the benches and examples that set gjk beside it.

use gjk::Convex;
use nalgebra::Isometry3;
use parry3d_f64::math::{Pose, Rot3, Vector};
use parry3d_f64::shape::{ConvexPolyhedron, Cuboid, Segment, Shape, Triangle};

/// An nalgebra isometry as a parry (glam) pose: same translation, same unit
/// quaternion.
pub fn parry_pose(p: &Isometry3<f64>) -> Pose {
    let q = p.rotation.quaternion();
    let t = p.translation.vector;
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rot3::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

fn vector(v: &nalgebra::Point3<f64>) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

/// Family member `index` of [`crate::paper::family`] as the parry shape a parry
/// user would pick: `Segment` for the segment, `Triangle` for the triangle,
/// `Cuboid` for the (origin-centred, axis-aligned) box, and
/// `ConvexPolyhedron::from_convex_hull` for the rest. Same geometry, same body
/// frame.
pub fn parry_shape(index: usize, c: &Convex) -> Box<dyn Shape> {
    let v = c.vertices();
    match index {
        0 => Box::new(Segment::new(vector(&v[0]), vector(&v[1]))),
        1 => Box::new(Triangle::new(vector(&v[0]), vector(&v[1]), vector(&v[2]))),
        2 => {
            let h = v[7]; // the (+, +, +) corner
            Box::new(Cuboid::new(Vector::new(h.x, h.y, h.z)))
        }
        _ => {
            let pts: Vec<Vector> = v.iter().map(vector).collect();
            let hull = ConvexPolyhedron::from_convex_hull(&pts).expect("a 3D hull");
            assert_eq!(
                hull.points().len(),
                v.len(),
                "every vertex of family member {index} is a hull vertex"
            );
            Box::new(hull)
        }
    }
}

/// The whole family as parry shapes.
pub fn parry_family(family: &[Convex]) -> Vec<Box<dyn Shape>> {
    family
        .iter()
        .enumerate()
        .map(|(i, c)| parry_shape(i, c))
        .collect()
}
