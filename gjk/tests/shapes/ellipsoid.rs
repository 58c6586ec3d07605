//! An ellipsoid `x²/a² + y²/b² + z²/c² <= 1`, a shape the crate does not
//! have, defined for the tests alone through the public [`SupportMap`]
//! trait: its support function is analytic, `s(d) = A²d / |A d|` with
//! `A = diag(a, b, c)`. With it, the distance from its surface to a point
//! by a dense minimisation, independent of GJK.

use std::cell::RefCell;

use gjk::SupportMap;
use nalgebra::{Point3, Vector3};

/// An ellipsoid centred at its body origin. A curved shape has no vertex
/// list for the indices of its support points to name, so it keeps the
/// points it has handed out and names each by its position: the query
/// rebuilds its nearest points and a warm start from the indices alone.
pub struct Ellipsoid {
    axes: Vector3<f64>,
    handed_out: RefCell<Vec<Vector3<f64>>>,
}

impl Ellipsoid {
    pub fn new(a: f64, b: f64, c: f64) -> Self {
        Ellipsoid {
            axes: Vector3::new(a, b, c),
            handed_out: RefCell::new(Vec::new()),
        }
    }

    /// The analytic support point, body frame.
    pub fn support_of(&self, d: &Vector3<f64>) -> Vector3<f64> {
        let scaled = self.axes.component_mul(d);
        let norm = scaled.norm();
        if !(norm > 0.0 && norm.is_finite()) {
            // No direction: any point of the shape is a support point.
            return Vector3::new(0.0, 0.0, -self.axes.z);
        }
        self.axes.component_mul(&scaled) / norm
    }

    /// The support value `h(d) = |A d|`.
    #[allow(dead_code)]
    pub fn support_value(&self, d: &Vector3<f64>) -> f64 {
        self.axes.component_mul(d).norm()
    }

    /// The surface point of angles `(theta, phi)`.
    pub fn surface(&self, theta: f64, phi: f64) -> Vector3<f64> {
        Vector3::new(
            self.axes.x * theta.sin() * phi.cos(),
            self.axes.y * theta.sin() * phi.sin(),
            self.axes.z * theta.cos(),
        )
    }
}

impl SupportMap for Ellipsoid {
    fn local_support(&self, dir: &Vector3<f64>) -> (usize, Vector3<f64>) {
        let point = self.support_of(dir);
        let mut handed_out = self.handed_out.borrow_mut();
        handed_out.push(point);
        (handed_out.len() - 1, point)
    }

    fn local_point(&self, index: usize) -> Vector3<f64> {
        self.handed_out.borrow()[index]
    }

    fn centre(&self) -> Point3<f64> {
        Point3::origin()
    }

    fn rounding(&self) -> f64 {
        0.0
    }

    fn size(&self) -> f64 {
        self.axes.max()
    }

    fn index_count(&self) -> usize {
        self.handed_out.borrow().len()
    }
}

/// The distance from the ellipsoid's surface to the point `q` (body
/// frame), by a dense grid over the angles and a pattern search from its
/// best cell: independent of GJK and of the support function.
#[allow(dead_code)]
pub fn surface_distance(egg: &Ellipsoid, q: &Vector3<f64>) -> f64 {
    let at = |theta: f64, phi: f64| (egg.surface(theta, phi) - q).norm();
    let (n_theta, n_phi) = (200, 400);
    let (mut best, mut t, mut p) = (f64::INFINITY, 0.0, 0.0);
    for i in 0..=n_theta {
        let theta = std::f64::consts::PI * i as f64 / n_theta as f64;
        for j in 0..n_phi {
            let phi = std::f64::consts::TAU * j as f64 / n_phi as f64;
            let d = at(theta, phi);
            if d < best {
                (best, t, p) = (d, theta, phi);
            }
        }
    }
    let mut step = 0.05;
    while step > 1e-13 {
        let mut moved = false;
        for (dt, dp) in [(step, 0.0), (-step, 0.0), (0.0, step), (0.0, -step)] {
            let d = at(t + dt, p + dp);
            if d < best {
                (best, t, p, moved) = (d, t + dt, p + dp, true);
            }
        }
        if !moved {
            step *= 0.5;
        }
    }
    best
}
