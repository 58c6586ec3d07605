//! The signed distance, with a certified penetration depth: for
//! overlapping shapes, the distance from the origin to the boundary of
//! `K = A - B` (the shortest translation that separates them, the paper's
//! `d⁺` of (2.12)), by an expanding polytope (EPA) started from the
//! distance query's final simplex and grown by support points of `K`
//! through the [`SupportMap`](crate::SupportMap) trait.
//!
//! One concern a file: [`frame`] (the pair's frame and its support points),
//! [`polytope`] (the closed surface and its certified inner radius),
//! [`expand`] (the expansion and its interval), [`ties`] (whether its
//! direction is unique), [`piece_pair`] (one convex
//! pair: rounded shapes, the cores' run), this file (unions, the entry
//! points).

mod expand;
mod frame;
mod options;
mod piece_pair;
mod polytope;
mod signed;
mod ties;

use nalgebra::Isometry3;

pub use options::DepthOptions;
pub use signed::SignedDistance;

use crate::query::core_run::Placed;
use crate::support_map::SupportMap;
use crate::{Answer, Error, Shape, Status, Workspace, distance, distance_between};
use piece_pair::piece_signed_distance;

/// The signed distance between `a` at `pose_a` and `b` at `pose_b`:
/// positive apart (the distance), negative overlapping (minus the
/// penetration depth), with a certified interval, witness points and the
/// normal along which B leaves A. For unions, the least over piece pairs
/// (the deepest overlap, or the distance when none overlaps).
///
/// ```
/// use gjk::{Convex, DepthOptions, Shape, signed_distance};
/// use nalgebra::{Isometry3, Vector3};
///
/// let a: Shape = Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)?.into();
/// let b: Shape = Convex::sphere(0.5)?.into();
/// // The ball's centre 0.2 inside A's face x = 1: 0.7 deep.
/// let pose_b = Isometry3::translation(0.8, 0.0, 0.0);
/// let sd = signed_distance(&a, &Isometry3::identity(), &b, &pose_b, &DepthOptions::default())?;
/// assert!((sd.value + 0.7).abs() < 1e-9);
/// assert!(sd.lower <= -0.7 && -0.7 <= sd.upper);
/// assert!((sd.normal - Vector3::x()).norm() < 1e-9);
/// # Ok::<(), gjk::Error>(())
/// ```
///
/// # Errors
/// As [`distance`], and [`Error::InvalidOption`] for depth options out of
/// their domain.
pub fn signed_distance(
    a: &Shape,
    pose_a: &Isometry3<f64>,
    b: &Shape,
    pose_b: &Isometry3<f64>,
    options: &DepthOptions,
) -> Result<SignedDistance, Error> {
    let converged = options.converged_distance()?;
    let answer = distance(a, pose_a, b, pose_b, &converged, None)?;
    signed_distance_after(&answer, a, pose_a, b, pose_b, options)
}

/// [`signed_distance`] for a caller that already holds the distance
/// query's [`Answer`] for these shapes and poses: when it proves them apart
/// (its lower bound positive, and not an early exit on a margin) it is
/// the signed distance, at no further cost; otherwise the piece pairs that
/// may overlap are expanded.
///
/// # Errors
/// As [`signed_distance`].
pub fn signed_distance_after(
    answer: &Answer,
    a: &Shape,
    pose_a: &Isometry3<f64>,
    b: &Shape,
    pose_b: &Isometry3<f64>,
    options: &DepthOptions,
) -> Result<SignedDistance, Error> {
    options.validate()?;
    if let Some(apart) = proven_apart(answer) {
        return Ok(apart);
    }
    if matches!(answer.status, Status::Farther | Status::Closer) {
        // A margin's answer bounds nothing the pieces need: ask again.
        return signed_distance(a, pose_a, b, pose_b, options);
    }
    let mut workspace = Workspace::new();
    let mut best: Option<SignedDistance> = None;
    for i in 0..a.piece_count() {
        for j in 0..b.piece_count() {
            let (Some((offset_a, convex_a)), Some((offset_b, convex_b))) = (a.piece(i), b.piece(j))
            else {
                continue;
            };
            let pa = Placed {
                convex: convex_a,
                pose: pose_a,
                offset: &offset_a,
            };
            let pb = Placed {
                convex: convex_b,
                pose: pose_b,
                offset: &offset_b,
            };
            // A pair whose bounding spheres are farther apart than the
            // answer's upper bound has a signed distance above the least.
            if sphere_gap(&pa, &pb) > answer.upper {
                continue;
            }
            let pieces = [i as u32, j as u32];
            let warm = (answer.pieces == pieces).then_some(&answer.warm_start);
            let sd = piece_signed_distance(&mut workspace, pa, pb, pieces, options, warm);
            best = Some(match best {
                Some(old) => SignedDistance {
                    lower: old.lower.min(sd.lower),
                    upper: old.upper.min(sd.upper),
                    expansions: old.expansions + sd.expansions,
                    converged: old.converged && sd.converged,
                    // Two piece pairs as deep (their intervals meet) along
                    // different directions: either's is a shortest
                    // separating translation.
                    tied: (if sd.value < old.value {
                        sd.tied
                    } else {
                        old.tied
                    }) || (sd.lower <= old.upper
                        && old.lower <= sd.upper
                        && ties::far(&sd.normal, &old.normal)),
                    ..if sd.value < old.value { sd } else { old }
                },
                None => sd,
            });
        }
    }
    // The answer's own pair always passes the sphere test (its gap is at
    // most its distance), so some pair ran.
    best.ok_or(Error::EmptyCompound)
}

/// The signed distance of an answer that proves its shapes apart (its
/// lower bound positive, and not an early exit on a margin): the answer
/// itself, at no further cost.
fn proven_apart(answer: &Answer) -> Option<SignedDistance> {
    let early = matches!(answer.status, Status::Farther | Status::Closer);
    (answer.lower > 0.0 && !early).then(|| SignedDistance {
        value: answer.distance,
        lower: answer.lower,
        upper: answer.upper,
        point_a: answer.point_a,
        point_b: answer.point_b,
        normal: answer.normal,
        pieces: answer.pieces,
        expansions: 0,
        converged: answer.status == Status::Converged,
        tied: false,
    })
}

/// [`signed_distance`] of any two convex shapes known by their
/// [`SupportMap`]s, a shape defined outside the crate among them: the
/// distance by [`distance_between`], and for overlapping shapes the
/// expansion of `A - B` through the same trait.
///
/// ```
/// use gjk::{Convex, DepthOptions, signed_distance_between};
/// use nalgebra::Isometry3;
///
/// let ball = Convex::sphere(1.0)?;
/// let near = Isometry3::translation(1.5, 0.0, 0.0);
/// let sd = signed_distance_between(&ball, &Isometry3::identity(), &ball, &near, &DepthOptions::default())?;
/// assert!((sd.value + 0.5).abs() < 1e-9);
/// assert!(sd.lower <= -0.5 && -0.5 <= sd.upper);
/// # Ok::<(), gjk::Error>(())
/// ```
///
/// # Errors
/// As [`signed_distance`].
pub fn signed_distance_between<A: SupportMap, B: SupportMap>(
    a: &A,
    pose_a: &Isometry3<f64>,
    b: &B,
    pose_b: &Isometry3<f64>,
    options: &DepthOptions,
) -> Result<SignedDistance, Error> {
    let converged = options.converged_distance()?;
    let answer = distance_between(a, pose_a, b, pose_b, &converged, None)?;
    if let Some(apart) = proven_apart(&answer) {
        return Ok(apart);
    }
    let body = Isometry3::identity();
    let (pa, pb) = (
        Placed {
            convex: a,
            pose: pose_a,
            offset: &body,
        },
        Placed {
            convex: b,
            pose: pose_b,
            offset: &body,
        },
    );
    let warm = Some(&answer.warm_start);
    Ok(piece_signed_distance(
        &mut Workspace::new(),
        pa,
        pb,
        [0, 0],
        options,
        warm,
    ))
}

/// A lower bound on the distance between two placed pieces: their
/// centroids' distance less their reaches, less what round-off may hide.
fn sphere_gap(a: &Placed<'_>, b: &Placed<'_>) -> f64 {
    let ca = a.pose * (a.offset * a.convex.centroid());
    let cb = b.pose * (b.offset * b.convex.centroid());
    let reach = a.convex.size() + a.convex.radius() + b.convex.size() + b.convex.radius();
    let magnitude = ca.coords.abs().sum() + cb.coords.abs().sum() + reach;
    (cb - ca).norm() - reach - 64.0 * f64::EPSILON * magnitude
}
