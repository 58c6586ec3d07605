//! The steps of [`Convex::new`](super::Convex::new) that turn a vertex list
//! into what the support search reads: the checks, the centroid, the
//! centroid-relative scan arrays and the size bound of (6.4).

use nalgebra::{Point3, Vector3};

use super::reach::MAX_REACH;
use crate::Error;
use crate::numeric::pow2_scale;

/// The checks of [`Convex::new`] on its input, before any arithmetic.
pub(super) fn check_input(vertices: &[Point3<f64>], radius: f64) -> Result<(), Error> {
    if vertices.is_empty() {
        return Err(Error::EmptyVertices);
    }
    if u32::try_from(vertices.len()).is_err() {
        return Err(Error::TooManyVertices(vertices.len()));
    }
    if let Some(index) = vertices
        .iter()
        .position(|v| !v.coords.iter().all(|c| c.is_finite()))
    {
        return Err(Error::NonFiniteVertex(index));
    }
    if !(radius.is_finite() && (0.0..=MAX_REACH).contains(&radius)) {
        return Err(Error::InvalidRadius(radius));
    }
    Ok(())
}

/// The mean of `vertices` (at least one), in two passes around the first
/// vertex: summing raw coordinates of a set far from the origin would lose
/// the digits that matter.
pub(super) fn centroid_of(vertices: &[Point3<f64>]) -> Result<Point3<f64>, Error> {
    let base = vertices[0];
    let count = vertices.len() as f64;
    let mean_offset = vertices
        .iter()
        .fold(Vector3::zeros(), |acc, v| acc + (v - base))
        / count;
    let centroid = base + mean_offset;
    if !centroid.coords.iter().all(|c| c.is_finite()) {
        // Finite vertices whose spread overflows f64.
        return Err(Error::NonFiniteVertex(0));
    }
    Ok(centroid)
}

/// The scan arrays: each coordinate of every vertex relative to the
/// centroid, one array per axis.
pub(super) type ScanArrays = (Vec<f64>, Vec<f64>, Vec<f64>);

/// `vertices` relative to `centroid`, as scan arrays, and the largest
/// coordinate among them (absolute).
pub(super) fn relative_coordinates(
    vertices: &[Point3<f64>],
    centroid: &Point3<f64>,
) -> Result<(ScanArrays, f64), Error> {
    let len = vertices.len();
    let (mut xs, mut ys, mut zs) = (
        Vec::with_capacity(len),
        Vec::with_capacity(len),
        Vec::with_capacity(len),
    );
    let mut widest: f64 = 0.0;
    for v in vertices {
        let d = v - centroid;
        widest = widest.max(d.amax());
        xs.push(d.x);
        ys.push(d.y);
        zs.push(d.z);
    }
    if !widest.is_finite() {
        return Err(Error::NonFiniteVertex(0));
    }
    Ok(((xs, ys, zs), widest))
}

/// The largest length among the scan arrays' points, `D(coZ - z̄)` of
/// (6.4), whose largest coordinate is `widest`. Squared lengths are scaled
/// by a power of two (exact), so that sets near 1e-300 or 1e300 neither
/// underflow to a size of 0 nor overflow.
pub(super) fn largest_length(
    xs: &[f64],
    ys: &[f64],
    zs: &[f64],
    widest: f64,
) -> Result<f64, Error> {
    let (scale, inv_scale) = pow2_scale(widest);
    let mut size2: f64 = 0.0;
    for ((x, y), z) in xs.iter().zip(ys).zip(zs) {
        size2 = size2.max(Vector3::new(x * scale, y * scale, z * scale).norm_squared());
    }
    let size = size2.sqrt() * inv_scale;
    if !size.is_finite() {
        return Err(Error::NonFiniteVertex(0));
    }
    Ok(size)
}
