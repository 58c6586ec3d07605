//! The run [`distance_between`](super::distance_between) and
//! [`distance_between_compounds`](super::distance_between_compounds) share:
//! options checked, the warm start checked against the operands, the
//! search, and the recovery of a suspect answer, generic over what the
//! operands are ([`Operands`]: two support maps, or two unions of them)
//! and monomorphised for each pair of types.

use nalgebra::Isometry3;

use super::recovery::recover_with;
use super::{Answer, Query, WarmStart, Workspace, is_suspect, relative_pose};
use crate::Error;
use crate::johnson::Simplex;

/// One side of a query [`run_in`] answers, against a `B`.
pub(super) trait Operands<B> {
    /// Whether `warm` names only pieces and indices `self` and `b` have.
    fn warm_fits(&self, b: &B, warm: &WarmStart) -> bool;

    /// The search: the answer and the width of bounds that count as stuck
    /// (infinite for a second opinion, which is asked no further).
    fn search<const AVX2: bool>(
        simplex: &mut Simplex,
        query: &Query<'_, Self, B>,
        rel: &Isometry3<f64>,
        warm: Option<&WarmStart>,
    ) -> (Answer, f64)
    where
        Self: Sized;
}

/// Answers `query` in `workspace`, in the CPU's best compiled form.
#[inline(always)]
pub(super) fn run_in<A: Operands<B>, B: Operands<A>>(
    workspace: &mut Workspace,
    query: &Query<'_, A, B>,
) -> Result<Answer, Error> {
    #[cfg(target_arch = "x86_64")]
    if crate::has_avx2_fma() {
        // SAFETY: the CPU supports AVX2 and FMA, checked just above.
        return unsafe { run_avx2(workspace, query) };
    }
    run_base(workspace, query)
}

cpu_forms! { entry
    /// [`run_body`] for any CPU, out of line, as `distance_base` is; its
    /// AVX2 form is `run_avx2` (see [`crate::cpu`]).
    #[inline(never)]
    fn run_base / run_avx2 <A: Operands<B>, B: Operands<A>> (
        workspace: &mut Workspace,
        query: &Query<'_, A, B>
    ) -> Result<Answer, Error> => run_body
}

/// The body of [`run_in`], inlined into each compiled form.
#[inline(always)]
fn run_body<const AVX2: bool, A: Operands<B>, B: Operands<A>>(
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
        ..
    } = query;
    options.validate()?;
    if let Some(w) = warm
        && !a.warm_fits(b, w)
    {
        return Err(Error::WarmStartOutOfRange);
    }
    let warm = warm.filter(|w| options.warm_start && (w.first.len > 0 || w.second.len > 0));
    let rel = relative_pose(pose_a, pose_b)?;
    let (answer, stuck_width) = A::search::<AVX2>(&mut workspace.simplex, query, &rel, warm);
    if is_suspect(&answer, stuck_width) {
        return recover::<AVX2, A, B>(answer, workspace, query, stuck_width);
    }
    Ok(answer)
}

/// The rare ends of [`run_body`], as `recover_suspect_answer`'s: a cold
/// run, or the pair asked the other way round.
#[cold]
#[inline(never)]
fn recover<const AVX2: bool, A: Operands<B>, B: Operands<A>>(
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
            run_in(workspace, &Query::new(a, pose_a, b, pose_b, options, None))
        },
        |workspace| run_body::<AVX2, B, A>(workspace, &query.swapped()),
    )
}
