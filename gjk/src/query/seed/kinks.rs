//! What a Newton step keeps between iterations: the kinks it holds (a
//! side of a cylinder, an edge or face of a polytope), the constraints they
//! put on the direction, and the small linear systems solved on them.

use nalgebra::Vector3;

use crate::shape::cylinder;
use crate::support_map::{SeedForm, SupportMap};

/// One shape's support at a direction, in the pair frame (scaled).
#[derive(Clone, Copy)]
pub(super) struct Touch {
    /// The support point.
    pub(super) point: Vector3<f64>,
    /// The vertex index, or for a cylinder its cap (0 or 1): a change is a
    /// kink.
    pub(super) key: u32,
    /// The support Hessian `k·t·tᵀ`: zero for a polytope.
    pub(super) curvature: f64,
    pub(super) tangent: Vector3<f64>,
    /// A cylinder's axis (the difference of its caps): zero for a polytope,
    /// whose kinks are the differences of its vertices.
    pub(super) axis: Vector3<f64>,
    /// A cylinder's `|d_xy|` at the unit body direction `d` (the sine of
    /// its angle to the axis): infinite for a polytope.
    pub(super) rho: f64,
}

/// What one shape's kinks have shown: the support keys seen on either side
/// of each (a cylinder's two caps, a polytope's vertices), at most three.
#[derive(Clone, Copy, Default)]
pub(super) struct Kinks {
    pub(super) keys: [u32; 3],
    pub(super) len: usize,
}

impl Kinks {
    pub(super) fn has(&self, key: u32) -> bool {
        self.keys[..self.len].contains(&key)
    }

    pub(super) fn add(&mut self, key: u32) -> bool {
        if self.has(key) || self.len == 3 {
            return false;
        }
        self.keys[self.len] = key;
        self.len += 1;
        true
    }
}

/// The directions the answer's direction is known to be perpendicular to,
/// orthonormal, at most two.
#[derive(Clone, Copy, Default)]
pub(super) struct Constraints {
    pub(super) axes: [Vector3<f64>; 2],
    pub(super) len: usize,
}

impl Constraints {
    /// Adds the unit `axis`: as [`add`](Self::add), with no normalisation
    /// when it is the first.
    pub(super) fn add_axis(&mut self, axis: Vector3<f64>) {
        if self.len == 0 {
            self.axes[0] = axis;
            self.len = 1;
        } else {
            self.add(axis);
        }
    }

    /// Adds `c` (any length) unless it is (nearly) in the span of those
    /// already held.
    pub(super) fn add(&mut self, mut c: Vector3<f64>) {
        let length = c.norm();
        for axis in &self.axes[..self.len] {
            c -= *axis * axis.dot(&c);
        }
        let norm = c.norm();
        if self.len < 2 && norm > 1e-6 * length {
            self.axes[self.len] = c / norm;
            self.len += 1;
        }
    }

    /// `u` moved onto the directions perpendicular to every constraint,
    /// unit; `None` if it has no such part.
    pub(super) fn project(&self, u: &Vector3<f64>) -> Option<Vector3<f64>> {
        let p = self.project_unscaled(u);
        let norm = p.norm();
        (norm > 1e-12).then(|| p / norm)
    }

    /// [`project`](Self::project) without the normalisation.
    pub(super) fn project_unscaled(&self, u: &Vector3<f64>) -> Vector3<f64> {
        match self.len {
            0 => *u,
            1 => u - self.axes[0] * self.axes[0].dot(u),
            _ => {
                let n = self.axes[0].cross(&self.axes[1]);
                n * n.dot(u).signum()
            }
        }
    }
}

/// `(radius, half_height)` of a shape whose seed hook
/// ([`SupportMap::seed_form`]) names a cylinder, `None` for any other: the
/// seed's closed forms are the cylinder's, every other shape's features
/// are its support points.
#[inline(always)]
pub(super) fn cylinder_of<S: SupportMap + ?Sized>(shape: &S) -> Option<(f64, f64)> {
    match shape.seed_form()? {
        SeedForm::Cylinder {
            radius,
            half_height,
        } => Some((radius, half_height)),
    }
}

/// The support of `shape` (a body frame's centroid-relative coordinates)
/// at the body direction `d` (unit), by the cylinder's closed form with its
/// curvature, or the polytope's support search. `None` at a cylinder's
/// axis, where the curvature is unbounded.
#[inline(always)]
pub(super) fn body_touch<S: SupportMap + ?Sized>(shape: &S, d: &Vector3<f64>) -> Option<Touch> {
    let Some((r, h)) = cylinder_of(shape) else {
        let (index, point) = shape.local_support(d);
        return Some(Touch {
            point,
            key: index as u32,
            curvature: 0.0,
            tangent: Vector3::zeros(),
            axis: Vector3::zeros(),
            rho: f64::INFINITY,
        });
    };
    // |d| = 1: the squares neither overflow nor lose the direction.
    let rho = (d.x * d.x + d.y * d.y).sqrt();
    if rho.is_nan() || rho <= 1e-9 {
        return None;
    }
    let inv = 1.0 / rho;
    let (cx, sy) = (d.x * inv, d.y * inv);
    let top = d.z > 0.0;
    Some(Touch {
        point: Vector3::new(r * cx, r * sy, cylinder::negate_if(h, !top)),
        key: u32::from(top),
        curvature: r * inv,
        tangent: Vector3::new(-sy, cx, 0.0),
        axis: Vector3::z(),
        rho,
    })
}

/// A running Newton solve: the direction, each shape's kinks (a
/// cylinder's side, a polytope's vertices) and the edges they give.
#[derive(Default)]
pub(super) struct Solve {
    pub(super) u: Vector3<f64>,
    /// Whether the direction is held on each cylinder's side kink, and
    /// whether that kink was found not to hold the answer.
    pub(super) side: [bool; 2],
    pub(super) off_side: [bool; 2],
    /// Whether each polytope's held face was found not to hold the
    /// answer (see `let_go_of_face`): its vertex changes then add no edge.
    pub(super) off_face: [bool; 2],
    pub(super) kinks: [Kinks; 2],
    /// Edges of the polytopes' kinks (differences of their vertices).
    pub(super) edges: [Vector3<f64>; 2],
    pub(super) edge_count: usize,
    /// Where the answer met two held sides' face: each side's weight from
    /// the cap it was found at (`this_top`) towards the other.
    pub(super) face_weights: Option<[f64; 2]>,
    pub(super) this_top: [bool; 2],
    /// The constraints of the held kinks, kept from one step to the next.
    pub(super) held: Constraints,
    /// Where a warm start names two rims, each one's radial direction at
    /// its warm point (pair frame, any length): where the closed form
    /// starts on the rims' angles (see `seed::feature`).
    pub(super) rim_radials: [Vector3<f64>; 2],
}

impl Solve {
    /// The constraints: each held side's axis (`axes`, the cylinders'
    /// in the pair frame), then the polytope edges.
    pub(super) fn constraints(&self, axes: &[Vector3<f64>; 2]) -> Constraints {
        let mut out = Constraints::default();
        for (held, axis) in self.side.iter().zip(axes) {
            if *held {
                out.add_axis(*axis);
            }
        }
        for edge in &self.edges[..self.edge_count] {
            out.add(*edge);
        }
        out
    }
}
