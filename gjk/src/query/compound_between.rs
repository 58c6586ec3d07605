//! [`distance_between_compounds`]: the distance between two unions of
//! convex pieces of any [`SupportMap`] types, (2.3) and (2.8). The same
//! search over piece pairs as [`distance`](crate::distance)'s compounds
//! (warm pairs first, each pair cut off by the best upper bound so far,
//! pairs proved farther by a bounding sphere or a separating axis not run),
//! monomorphised for each pair of piece types, with the same certified
//! bounds, margins and warm start.

use nalgebra::Isometry3;

use super::compound::search_compound;
use super::operands::{Operands, run_in};
use super::{Answer, Options, Query, WarmStart, Workspace, with_spare_workspace};
use crate::Error;
use crate::johnson::Simplex;
use crate::shape::Compound;
use crate::support_map::SupportMap;

/// The distance between the compounds `a` at `pose_a` and `b` at `pose_b`,
/// their pieces known by their [`SupportMap`]s: the least distance over
/// piece pairs, with the pieces that realise it
/// ([`Answer::pieces`]), its nearest points, certified bounds (the lower
/// bound is the least over the piece pairs' lower bounds, so it holds for
/// the union) and a warm start that names the nearest piece pair and the
/// runner-up. A single shape is a compound of one piece at the identity.
/// For two compounds of [`Convex`](crate::Convex) pieces the answer is
/// [`distance`](crate::distance)'s, bit for bit.
///
/// ```
/// use gjk::{Compound, Convex, Options, distance_between_compounds};
/// use nalgebra::Isometry3;
///
/// // Two balls side by side against one ball: the nearer of the two wins.
/// let ball = Convex::sphere(0.5)?;
/// let pair = Compound::new(vec![
///     (Isometry3::translation(-2.0, 0.0, 0.0), ball.clone()),
///     (Isometry3::translation(2.0, 0.0, 0.0), ball.clone()),
/// ])?;
/// let one = Compound::new(vec![(Isometry3::identity(), ball)])?;
/// let answer = distance_between_compounds(
///     &pair, &Isometry3::identity(), &one, &Isometry3::translation(4.0, 0.0, 0.0),
///     &Options::default(), None,
/// )?;
/// assert_eq!(answer.pieces, [1, 0]);
/// assert!((answer.distance - 1.0).abs() < 1e-12);
/// # Ok::<(), gjk::Error>(())
/// ```
///
/// # Errors
/// As [`distance`](crate::distance): [`Error::WarmStartOutOfRange`] for a
/// warm start naming a piece the compounds do not have, or an index not
/// below its piece's [`index_count`](SupportMap::index_count).
pub fn distance_between_compounds<A: SupportMap, B: SupportMap>(
    a: &Compound<A>,
    pose_a: &Isometry3<f64>,
    b: &Compound<B>,
    pose_b: &Isometry3<f64>,
    options: &Options,
    warm: Option<&WarmStart>,
) -> Result<Answer, Error> {
    with_spare_workspace(|workspace| {
        distance_between_compounds_in(workspace, a, pose_a, b, pose_b, options, warm)
    })
}

/// [`distance_between_compounds`] in a caller's [`Workspace`]: the same
/// answer, bit for bit.
///
/// # Errors
/// As [`distance_between_compounds`].
pub fn distance_between_compounds_in<A: SupportMap, B: SupportMap>(
    workspace: &mut Workspace,
    a: &Compound<A>,
    pose_a: &Isometry3<f64>,
    b: &Compound<B>,
    pose_b: &Isometry3<f64>,
    options: &Options,
    warm: Option<&WarmStart>,
) -> Result<Answer, Error> {
    run_in(workspace, &Query::new(a, pose_a, b, pose_b, options, warm))
}

impl<A: SupportMap, B: SupportMap> Operands<Compound<B>> for Compound<A> {
    fn warm_fits(&self, b: &Compound<B>, warm: &WarmStart) -> bool {
        warm.first.fits_shapes(self, b) && warm.second.fits_shapes(self, b)
    }

    #[inline(always)]
    fn search<const AVX2: bool>(
        simplex: &mut Simplex,
        query: &Query<'_, Compound<A>, Compound<B>>,
        rel: &Isometry3<f64>,
        warm: Option<&WarmStart>,
    ) -> (Answer, f64) {
        let (answer, stuck_width) = search_compound::<AVX2, _, _>(simplex, query, rel, warm);
        (
            answer,
            if query.swapped {
                f64::INFINITY
            } else {
                stuck_width
            },
        )
    }
}
