//! The distance query: the paper's Numerical Algorithm (Section 6) run in the
//! pair's relative frame, with certified bounds, margins and warm start.

mod answer;
mod between;
mod compound;
mod compound_between;
pub(crate) mod core_run;
mod full_step;
mod numerical_algorithm;
mod operands;
mod options;
mod pair;
mod penetration;
mod recovery;
mod seed;
mod warm_start;

use std::cell::Cell;

use nalgebra::Isometry3;

use crate::Error;
use crate::johnson::Simplex;
use crate::shape::{Shape, shift_is_in_range};
use crate::support_map::SupportMap;

pub use answer::Answer;
pub use between::{distance_between, distance_between_in};
pub use compound_between::{distance_between_compounds, distance_between_compounds_in};
pub use options::{Options, Precision, Status};
pub use warm_start::WarmStart;

use answer::all_finite;
use compound::search_compound;
use pair::{ConvexPair, PiecePlacement};
use recovery::recover_suspect_answer;

/// Scratch memory of a query (the simplex with its dot products and
/// cofactors), kept by a caller that makes many queries so that each one
/// skips setting it up: see [`distance_in`]. [`distance`] keeps one for each
/// thread. Holds no result; any workspace serves any query.
#[derive(Clone, Debug)]
pub struct Workspace {
    simplex: Simplex,
}

impl Workspace {
    /// A fresh workspace.
    pub const fn new() -> Self {
        Workspace {
            simplex: Simplex::empty(),
        }
    }
}

thread_local! {
    /// [`distance`]'s workspace, one a thread, lent out for each query. A
    /// fresh one would cost each query the zeroing and moving of its 800
    /// bytes, a visible share of a small query. Boxed, so that lending it
    /// moves a pointer, and the answer is returned outside the
    /// thread-local's closure, which would copy it twice more.
    static SPARE: Cell<Option<Box<Workspace>>> = const { Cell::new(None) };
}

impl Default for Workspace {
    fn default() -> Self {
        Self::new()
    }
}

/// The distance between `a` at `pose_a` and `b` at `pose_b`, with nearest points,
/// certified bounds and the simplex for a warm start.
///
/// # Errors
/// [`Error::NonFinitePose`] for a pose with NaN or infinity, or for shapes
/// more than 2^1000 (about 1e301) apart on an axis, where the arithmetic
/// could overflow, [`Error::InvalidOption`] for options out of their domain, and
/// [`Error::WarmStartOutOfRange`] for a warm start that names a piece or vertex
/// the shapes do not have.
pub fn distance(
    a: &Shape,
    pose_a: &Isometry3<f64>,
    b: &Shape,
    pose_b: &Isometry3<f64>,
    options: &Options,
    warm: Option<&WarmStart>,
) -> Result<Answer, Error> {
    // Written out, not through `with_spare_workspace`: the answer then
    // goes straight to the caller, where the closure's return cost a copy
    // of it (callgrind: 30 instructions and a memcpy a family query).
    let mut workspace = SPARE
        .try_with(Cell::take)
        .ok()
        .flatten()
        .unwrap_or_else(|| Box::new(Workspace::new()));
    let answer = distance_in(&mut workspace, a, pose_a, b, pose_b, options, warm);
    let _ = SPARE.try_with(|spare| spare.set(Some(workspace)));
    answer
}

/// `run` in the thread's spare workspace, lent out and put back, for
/// [`distance_between`].
#[inline(always)]
fn with_spare_workspace<R>(run: impl FnOnce(&mut Workspace) -> R) -> R {
    // Any workspace gives the same answer: a fresh one serves the first
    // query of a thread, and any query while the thread's is out of reach
    // (during thread teardown).
    let mut workspace = SPARE
        .try_with(Cell::take)
        .ok()
        .flatten()
        .unwrap_or_else(|| Box::new(Workspace::new()));
    let answer = run(&mut workspace);
    // Dropped instead if the thread-local is gone.
    let _ = SPARE.try_with(|spare| spare.set(Some(workspace)));
    answer
}

/// [`distance`] in a caller's [`Workspace`]: the same answer, bit for bit.
/// `distance` lends itself its thread's workspace; this form is for a
/// caller that holds its own (a server's loop), which also saves the
/// thread-local's lookup.
///
/// ```
/// use gjk::{Convex, Options, Shape, Workspace, distance_in};
/// use nalgebra::Isometry3;
///
/// let ball: Shape = Convex::sphere(1.0)?.into();
/// let mut ws = Workspace::new();
/// for x in [3.0, 4.0, 5.0] {
///     let pose = Isometry3::translation(x, 0.0, 0.0);
///     let answer = distance_in(
///         &mut ws, &ball, &Isometry3::identity(), &ball, &pose, &Options::default(), None,
///     )?;
///     assert!((answer.distance - (x - 2.0)).abs() < 1e-12);
/// }
/// # Ok::<(), gjk::Error>(())
/// ```
///
/// # Errors
/// As [`distance`].
pub fn distance_in(
    workspace: &mut Workspace,
    a: &Shape,
    pose_a: &Isometry3<f64>,
    b: &Shape,
    pose_b: &Isometry3<f64>,
    options: &Options,
    warm: Option<&WarmStart>,
) -> Result<Answer, Error> {
    let query = Query::new(a, pose_a, b, pose_b, options, warm);
    #[cfg(target_arch = "x86_64")]
    if crate::has_avx2_fma() {
        // SAFETY: the CPU supports AVX2 and FMA, checked just above.
        return unsafe { distance_avx2(workspace, &query) };
    }
    distance_base(workspace, &query)
}

/// [`distance_in`] in the form compiled for any CPU, whatever this one
/// has: for the test that both compiled forms give the same answer bit for
/// bit (on a CPU with AVX2 and FMA, `distance_in` runs the other form).
/// Not part of the API.
///
/// # Errors
/// As [`distance`].
#[doc(hidden)]
pub fn distance_in_baseline(
    workspace: &mut Workspace,
    a: &Shape,
    pose_a: &Isometry3<f64>,
    b: &Shape,
    pose_b: &Isometry3<f64>,
    options: &Options,
    warm: Option<&WarmStart>,
) -> Result<Answer, Error> {
    let query = Query::new(a, pose_a, b, pose_b, options, warm);
    distance_base(workspace, &query)
}

/// One query's inputs, handed whole between [`distance_in`]'s compiled
/// forms: two [`Shape`]s, or for [`distance_between`] any two
/// [`SupportMap`](crate::SupportMap)s.
struct Query<'q, A = Shape, B = Shape> {
    a: &'q A,
    pose_a: &'q Isometry3<f64>,
    b: &'q B,
    pose_b: &'q Isometry3<f64>,
    options: &'q Options,
    warm: Option<&'q WarmStart>,
    /// This is the second opinion of
    /// [`second_opinion`](recovery::second_opinion): asked no further.
    swapped: bool,
}

// By hand: derived, they would ask `A` and `B` to be `Copy` too.
impl<A, B> Clone for Query<'_, A, B> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<A, B> Copy for Query<'_, A, B> {}

impl<'q, A, B> Query<'q, A, B> {
    /// A query asked the way round its caller gave it.
    #[inline(always)]
    fn new(
        a: &'q A,
        pose_a: &'q Isometry3<f64>,
        b: &'q B,
        pose_b: &'q Isometry3<f64>,
        options: &'q Options,
        warm: Option<&'q WarmStart>,
    ) -> Self {
        Query {
            a,
            pose_a,
            b,
            pose_b,
            options,
            warm,
            swapped: false,
        }
    }

    /// The same query with A and B swapped, cold: the second opinion of
    /// [`second_opinion`](recovery::second_opinion), asked no further.
    #[inline(always)]
    fn swapped(&self) -> Query<'q, B, A> {
        Query {
            a: self.b,
            pose_a: self.pose_b,
            b: self.a,
            pose_b: self.pose_a,
            options: self.options,
            warm: None,
            swapped: true,
        }
    }
}

cpu_forms! { entry
    /// [`distance_body`] for any CPU, out of line, so that [`distance_in`]
    /// stays a few instructions of dispatch with no frame of its own; its
    /// AVX2 form is `distance_avx2` (see [`crate::cpu`]).
    #[inline(never)]
    fn distance_base / distance_avx2 (
        workspace: &mut Workspace,
        query: &Query<'_>
    ) -> Result<Answer, Error> => distance_body
}

/// The body of [`distance_in`], inlined into each of its compiled forms;
/// `AVX2` says which, so that the subalgorithm's out-of-line parts are
/// called in the same form.
#[inline(always)]
fn distance_body<const AVX2: bool>(
    workspace: &mut Workspace,
    query: &Query<'_>,
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
    if let Some(w) = warm
        && !(w.first.fits_shapes(a, b) && w.second.fits_shapes(a, b))
    {
        return Err(Error::WarmStartOutOfRange);
    }
    let warm = warm.filter(|w| options.warm_start && (w.first.len > 0 || w.second.len > 0));
    let rel = relative_pose(pose_a, pose_b)?;
    // `stuck_width`: the interval width beyond which the answer is asked again
    // the other way round (see `second_opinion`).
    let (answer, stuck_width) = match (a, b) {
        (Shape::Convex(convex_a), Shape::Convex(convex_b)) => pair_answer::<AVX2, _, _>(
            &mut workspace.simplex,
            (convex_a, pose_a),
            (convex_b, pose_b),
            &rel,
            options,
            warm,
            swapped,
        ),
        _ => {
            let (answer, stuck_width) =
                search_compound::<AVX2, _, _>(&mut workspace.simplex, query, &rel, warm);
            (answer, if swapped { f64::INFINITY } else { stuck_width })
        }
    };
    // The answer goes out as it was built unless one of the three rare
    // checks below needs to change it (kept out of line, so that the common
    // path neither copies nor rewrites it).
    if is_suspect(&answer, stuck_width) {
        return recover_suspect_answer::<AVX2>(answer, workspace, query, stuck_width);
    }
    Ok(answer)
}

/// `a⁻¹·b`, the pose of B in A's frame, or [`Error::NonFinitePose`].
#[inline(always)]
fn relative_pose(
    pose_a: &Isometry3<f64>,
    pose_b: &Isometry3<f64>,
) -> Result<Isometry3<f64>, Error> {
    // a⁻¹·b: the translations are subtracted before rotating, so poses far from
    // the world origin cancel exactly when the objects are near each other.
    let rel = pose_a.inv_mul(pose_b);
    if !shift_is_in_range(&rel) {
        // Every component of either pose reaches `rel` through a product with
        // a unit quaternion's components or a difference of translations, so
        // NaN or infinity anywhere in the inputs shows here; so do finite
        // poses whose difference overflows f64 (coordinates near 1e308). With
        // shapes built within MAX_REACH, a shift within MAX_SHIFT keeps every
        // magnitude of the query far from overflow (fuzzing found a shape of
        // size 1.6e308 given a lower bound of 1e300 against a true distance
        // of 0, before shapes were held to MAX_REACH).
        return Err(Error::NonFinitePose);
    }
    Ok(rel)
}

/// Whether an answer needs one of the three rare checks of
/// `recover_suspect_answer` (kept out of line, so that the common path
/// neither copies nor rewrites it): contradicting bounds, a number that
/// overflowed, or an interval wider than `stuck_width`.
#[inline(always)]
fn is_suspect(answer: &Answer, stuck_width: f64) -> bool {
    answer.lower > answer.upper || !all_finite(answer) || answer.upper - answer.lower > stuck_width
}

/// One convex pair's answer, whatever the shapes' types (two [`Convex`]
/// pieces of [`distance`], or any two support maps of
/// [`distance_between`]), with the interval width beyond which it is asked
/// again swapped (infinite for the swapped query itself): the pair set up in
/// A's frame, the Numerical Algorithm run (warm, or rerun cold), the
/// penetration deepened and the answer built. `warm` is the query's warm
/// start, already filtered by the options.
///
/// [`Convex`]: crate::Convex
#[inline(always)]
fn pair_answer<const AVX2: bool, A: SupportMap, B: SupportMap>(
    simplex: &mut Simplex,
    (a, pose_a): (&A, &Isometry3<f64>),
    (b, pose_b): (&B, &Isometry3<f64>),
    rel: &Isometry3<f64>,
    options: &Options,
    warm: Option<&WarmStart>,
    swapped: bool,
) -> (Answer, f64) {
    let place_a = PiecePlacement {
        pose: pose_a,
        offset: None,
    };
    let place_b = PiecePlacement {
        pose: pose_b,
        offset: None,
    };
    let pair = ConvexPair::new(a, b, rel, (place_a, place_b), options.precision);
    let warm_pairs = warm.and_then(|w| w.for_pieces([0, 0]));
    let mut run = pair.solve_or_rerun_cold::<AVX2>(simplex, options, warm_pairs, f64::INFINITY);
    pair.deepen(&mut run, simplex, options);
    let stuck_width = if swapped {
        f64::INFINITY
    } else {
        pair.stuck_width(options.tolerance)
    };
    (pair.to_answer(&run, simplex, place_a, [0, 0]), stuck_width)
}
