//! [`distance_between`]: the distance query of any two convex shapes known
//! by their [`SupportMap`]s, a shape defined outside the crate among them.
//! The same run as [`distance`](super::distance)'s convex pairs (the pair
//! code is generic and monomorphised for each pair of types), with the same
//! certified bounds, margins and warm start.

use nalgebra::Isometry3;

use super::recovery::recover_with;
use super::{
    Answer, Options, Query, WarmStart, Workspace, is_suspect, pair_answer, relative_pose,
    with_spare_workspace,
};
use crate::Error;
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
    let query = Query::new(a, pose_a, b, pose_b, options, warm);
    #[cfg(target_arch = "x86_64")]
    if crate::has_avx2_fma() {
        // SAFETY: the CPU supports AVX2 and FMA, checked just above.
        return unsafe { between_avx2(workspace, &query) };
    }
    between_base(workspace, &query)
}

cpu_forms! { entry
    /// [`between_body`] for any CPU, out of line, as `distance_base` is;
    /// its AVX2 form is `between_avx2` (see [`crate::cpu`]).
    #[inline(never)]
    fn between_base / between_avx2 <A: SupportMap, B: SupportMap> (
        workspace: &mut Workspace,
        query: &Query<'_, A, B>
    ) -> Result<Answer, Error> => between_body
}

/// The body of [`distance_between_in`], inlined into each compiled form.
#[inline(always)]
fn between_body<const AVX2: bool, A: SupportMap, B: SupportMap>(
    workspace: &mut Workspace,
    query: &Query<'_, A, B>,
) -> Result<Answer, Error> {
    let &Query {
        a,
        pose_a,
        b,
        pose_b,
        options,
        warm,
        swapped,
    } = query;
    options.validate()?;
    if let Some(w) = warm {
        let (count_a, count_b) = (a.index_count(), b.index_count());
        let fits = |kept: &super::warm_start::PieceSimplex| {
            kept.len == 0 || (kept.pieces == [0, 0] && kept.fits_counts(count_a, count_b))
        };
        if !(fits(&w.first) && fits(&w.second)) {
            return Err(Error::WarmStartOutOfRange);
        }
    }
    let warm = warm.filter(|w| options.warm_start && (w.first.len > 0 || w.second.len > 0));
    let rel = relative_pose(pose_a, pose_b)?;
    let (answer, stuck_width) = pair_answer::<AVX2, A, B>(
        &mut workspace.simplex,
        (a, pose_a),
        (b, pose_b),
        &rel,
        options,
        warm,
        swapped,
    );
    if is_suspect(&answer, stuck_width) {
        return recover_between::<AVX2, A, B>(answer, workspace, query, stuck_width);
    }
    Ok(answer)
}

/// The rare ends of [`between_body`], as `recover_suspect_answer`'s.
#[cold]
#[inline(never)]
fn recover_between<const AVX2: bool, A: SupportMap, B: SupportMap>(
    answer: Answer,
    workspace: &mut Workspace,
    query: &Query<'_, A, B>,
    stuck_width: f64,
) -> Result<Answer, Error> {
    recover_with(
        answer,
        workspace,
        query,
        stuck_width,
        |workspace| {
            let Query {
                a,
                pose_a,
                b,
                pose_b,
                options,
                ..
            } = *query;
            distance_between_in(workspace, a, pose_a, b, pose_b, options, None)
        },
        |workspace| between_body::<AVX2, B, A>(workspace, &query.swapped()),
    )
}
