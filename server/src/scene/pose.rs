//! Poses in a scene file.

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use serde::Deserialize;

/// A pose in a scene file.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PoseSpec {
    /// Translation (default zero).
    #[serde(default)]
    pub translation: [f64; 3],
    /// Rotation quaternion `[i, j, k, w]`.
    pub quaternion: Option<[f64; 4]>,
    /// Rotation axis scaled by the angle, radians.
    pub axis_angle: Option<[f64; 3]>,
}

impl PoseSpec {
    /// The isometry.
    ///
    /// # Errors
    /// A message for both rotations given, a non-finite component or a zero
    /// quaternion.
    pub fn to_isometry(&self) -> Result<Isometry3<f64>, String> {
        let [x, y, z] = self.translation;
        let rotation = match (self.quaternion, self.axis_angle) {
            (Some(_), Some(_)) => return Err("give quaternion or axis_angle, not both".into()),
            (Some([i, j, k, w]), None) => {
                let q = Quaternion::new(w, i, j, k);
                if !q.coords.iter().all(|c| c.is_finite()) || q.norm() < 1e-12 {
                    return Err("quaternion must be finite and non-zero".into());
                }
                UnitQuaternion::from_quaternion(q)
            }
            (None, Some(v)) => UnitQuaternion::new(Vector3::from(v)),
            (None, None) => UnitQuaternion::identity(),
        };
        let iso = Isometry3::from_parts(Translation3::new(x, y, z), rotation);
        let finite = iso.translation.vector.iter().all(|c| c.is_finite())
            && iso.rotation.coords.iter().all(|c| c.is_finite());
        if !finite {
            return Err("pose is not finite".into());
        }
        Ok(iso)
    }
}
