//! Inputs written by hand, or copied from a failing run as it printed them.

use gjk::{Convex, Shape};
use nalgebra::Isometry3;

use crate::reference::{P, V};

/// A pose from nalgebra's printed form: quaternion `[i, j, k, w]`, then the
/// translation, for inputs copied from a failing run.
pub fn printed_pose(q: [f64; 4], t: [f64; 3]) -> Isometry3<f64> {
    // As printed: already unit, to the last bit; normalising again would move
    // the pose off the case that failed.
    let q =
        nalgebra::UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(q[3], q[0], q[1], q[2]));
    Isometry3::from_parts(nalgebra::Translation3::new(t[0], t[1], t[2]), q)
}

/// A convex point set with radius 0, from plain coordinates.
pub fn points(p: &[[f64; 3]]) -> Shape {
    let p: Vec<P> = p.iter().map(|&c| P::from(c)).collect();
    Convex::new(p, 0.0).expect("finite points").into()
}

/// A point from its coordinates, as written.
pub fn p(x: f64, y: f64, z: f64) -> P {
    P::new(x, y, z)
}

/// A vector from its coordinates, as written.
pub fn v(x: f64, y: f64, z: f64) -> V {
    V::new(x, y, z)
}
