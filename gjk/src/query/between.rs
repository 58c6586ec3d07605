//! [`distance_between`]: the distance query of any two convex shapes known
//! by their [`SupportMap`]s, a shape defined outside the crate among them.
//! The same run as [`distance`](super::distance)'s convex pairs (the pair
//! code is generic and monomorphised for each pair of types), with the same
//! certified bounds, margins and warm start.

use nalgebra::Isometry3;

use super::operands::{Operands, run_in};
use super::{Answer, Options, Query, WarmStart, Workspace, pair_answer, with_spare_workspace};
use crate::Error;
use crate::johnson::Simplex;
use crate::support_map::SupportMap;

/// The distance between the convex shapes `a` at `pose_a` and `b` at
/// `pose_b`, each known by its [`SupportMap`], with nearest points, certified
/// bounds and the simplex for a warm start: what [`distance`](crate::distance)
/// gives for two [`Convex`](crate::Convex) shapes, bit for bit, for any
/// support maps, a shape of the caller's own among them.
///
/// A warm start's pieces are `[0, 0]` and its indices those the shapes'
/// [`local_support`](SupportMap::local_support) returned.
///
/// ```
/// use gjk::{Convex, Options, distance_between};
/// use nalgebra::Isometry3;
///
/// let ball = Convex::sphere(1.0)?;
/// let far = Isometry3::translation(3.0, 0.0, 0.0);
/// let answer =
///     distance_between(&ball, &Isometry3::identity(), &ball, &far, &Options::default(), None)?;
/// assert_eq!(answer.distance, 1.0);
/// # Ok::<(), gjk::Error>(())
/// ```
///
/// # Errors
/// As [`distance`](crate::distance); [`Error::WarmStartOutOfRange`] for a
/// warm start whose pieces are not `[0, 0]` or whose indices are not below
/// the shapes' [`index_count`](SupportMap::index_count).
pub fn distance_between<A: SupportMap, B: SupportMap>(
    a: &A,
    pose_a: &Isometry3<f64>,
    b: &B,
    pose_b: &Isometry3<f64>,
    options: &Options,
    warm: Option<&WarmStart>,
) -> Result<Answer, Error> {
    with_spare_workspace(|workspace| {
        distance_between_in(workspace, a, pose_a, b, pose_b, options, warm)
    })
}

/// [`distance_between`] in a caller's [`Workspace`]: the same answer, bit
/// for bit, as [`distance_in`](crate::distance_in) is to
/// [`distance`](crate::distance).
///
/// # Errors
/// As [`distance_between`].
pub fn distance_between_in<A: SupportMap, B: SupportMap>(
    workspace: &mut Workspace,
    a: &A,
    pose_a: &Isometry3<f64>,
    b: &B,
    pose_b: &Isometry3<f64>,
    options: &Options,
    warm: Option<&WarmStart>,
) -> Result<Answer, Error> {
    run_in(workspace, &Query::new(a, pose_a, b, pose_b, options, warm))
}

impl<A: SupportMap, B: SupportMap> Operands<B> for A {
    /// A single shape's warm start names pieces `[0, 0]`.
    fn warm_fits(&self, b: &B, warm: &WarmStart) -> bool {
        let (count_a, count_b) = (self.index_count(), b.index_count());
        let fits = |kept: &super::warm_start::PieceSimplex| {
            kept.len == 0 || (kept.pieces == [0, 0] && kept.fits_counts(count_a, count_b))
        };
        fits(&warm.first) && fits(&warm.second)
    }

    #[inline(always)]
    fn search<const AVX2: bool>(
        simplex: &mut Simplex,
        query: &Query<'_, A, B>,
        rel: &Isometry3<f64>,
        warm: Option<&WarmStart>,
    ) -> (Answer, f64) {
        pair_answer::<AVX2, A, B>(
            simplex,
            (query.a, query.pose_a),
            (query.b, query.pose_b),
            rel,
            query.options,
            warm,
            query.swapped,
        )
    }
}
