//! A rigid pose as it travels on the wire.

use iceoryx2::prelude::ZeroCopySend;
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};

use crate::ErrorCode;

/// Quaternions whose squared norm is this close to 1 are taken as they are:
/// that is what nalgebra's own normalisation yields, and re-normalising them
/// would change the last bits of every answer relative to an in-process call.
const UNIT_ROUNDING: f64 = 8.0 * f64::EPSILON;

/// How far off unit length a rotation quaternion may be and still be
/// accepted (it is normalised then).
pub const UNIT_TOLERANCE: f64 = 1e-6;

/// The largest magnitude of a pose's translation component: 2^998, about
/// 2.68e300. A query refuses two objects whose relative translation, in
/// the first one's frame, exceeds 2^1000 on an axis (its arithmetic could
/// overflow beyond); two translations within 2^998 per axis differ by at
/// most sqrt(3) * 2^999 < 2^1000 along any axis, however rotated, so a pose
/// accepted when it is stored never makes a later query refuse it.
pub const MAX_TRANSLATION: f64 = 2.6787715179656683e300;

/// A rigid pose on the wire: translation and rotation quaternion `[i, j, k, w]`
/// (nalgebra's coordinate order), in f64.
#[derive(Clone, Copy, Debug, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.Pose")]
pub struct Pose {
    /// Translation.
    pub translation: [f64; 3],
    /// Unit quaternion `[i, j, k, w]`.
    pub rotation: [f64; 4],
}

impl Pose {
    /// The identity pose.
    pub const IDENTITY: Pose = Pose {
        translation: [0.0; 3],
        rotation: [0.0, 0.0, 0.0, 1.0],
    };

    /// The wire form of `iso`, bit for bit.
    pub fn from_isometry(iso: &Isometry3<f64>) -> Self {
        let t = iso.translation.vector;
        let q = iso.rotation.coords;
        Pose {
            translation: [t.x, t.y, t.z],
            rotation: [q.x, q.y, q.z, q.w],
        }
    }

    /// The isometry with exactly these components. The quaternion is taken as
    /// it is, without normalising: check it first (the server does).
    pub fn to_isometry_unchecked(&self) -> Isometry3<f64> {
        let [x, y, z] = self.translation;
        let [i, j, k, w] = self.rotation;
        Isometry3::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::new_unchecked(Quaternion::new(w, i, j, k)),
        )
    }

    /// The isometry of this pose as the server takes it: finite, every
    /// translation component within [`MAX_TRANSLATION`], and a rotation
    /// quaternion within [`UNIT_TOLERANCE`] of unit length (normalised
    /// unless it already is, to round-off).
    ///
    /// # Errors
    /// [`ErrorCode::NonFinitePose`], [`ErrorCode::BadQuaternion`].
    pub fn checked(&self) -> Result<Isometry3<f64>, ErrorCode> {
        // `<=` is false for NaN, so this also refuses NaN translations.
        if !(self.translation.iter().all(|c| c.abs() <= MAX_TRANSLATION)
            && self.rotation.iter().all(|c| c.is_finite()))
        {
            return Err(ErrorCode::NonFinitePose);
        }
        let [i, j, k, w] = self.rotation;
        let q = Quaternion::new(w, i, j, k);
        let n2 = q.norm_squared();
        let rotation = if (n2 - 1.0).abs() <= UNIT_ROUNDING {
            UnitQuaternion::new_unchecked(q)
        } else if (n2.sqrt() - 1.0).abs() <= UNIT_TOLERANCE {
            UnitQuaternion::new_normalize(q)
        } else {
            return Err(ErrorCode::BadQuaternion);
        };
        let [x, y, z] = self.translation;
        Ok(Isometry3::from_parts(Translation3::new(x, y, z), rotation))
    }
}

impl Default for Pose {
    fn default() -> Self {
        Pose::IDENTITY
    }
}

impl From<&Isometry3<f64>> for Pose {
    fn from(iso: &Isometry3<f64>) -> Self {
        Pose::from_isometry(iso)
    }
}
