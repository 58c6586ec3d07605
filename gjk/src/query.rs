//! The distance query: the paper's Numerical Algorithm (Section 6) run in the
//! pair's relative frame, with certified bounds, margins and warm start.

use std::cell::Cell;

use nalgebra::{Isometry3, Matrix3, Point3, Vector3};

use crate::Error;
use crate::johnson::{Simplex, Solution, Vertex};
use crate::shape::{Convex, Shape, robust_norm, shift_is_in_range};

/// How hard to work, and when to stop early.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Relative tolerance `ε` of the stopping rule (6.2), `g(v) <= ε·D²`. The
    /// default, 100 × machine epsilon, is the paper's; larger is faster and
    /// looser (the bounds in the answer say by how much). Must be finite and
    /// `>= 0`; 0 runs until round-off stops progress.
    pub tolerance: f64,
    /// Iteration cap (subalgorithm runs), at least 1. Polytopes converge in a
    /// few iterations; the cap only guards against a pathological input.
    pub max_iterations: u32,
    /// Early exit: stop as soon as the certified bounds decide that the
    /// distance (after radii) is greater than this margin ([`Status::Farther`])
    /// or at most this margin ([`Status::Closer`]). `None` runs to convergence.
    pub margin: Option<f64>,
    /// Use a warm start when one is given. Off, the query always starts from
    /// the single-point initialisation of Section 6.
    pub warm_start: bool,
    /// Arithmetic of the support search; everything else is f64 always.
    pub precision: Precision,
}

/// The arithmetic of the support search, the one step whose cost grows with the
/// number of vertices.
///
/// Whatever the choice, the simplex, Johnson's subalgorithm and the bounds
/// stay in f64 and the answer's vertices are the shapes' own, so the bounds
/// stay certified; `Single` widens them by what the f32 search may miss.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Precision {
    /// f64: the exact support point; the distance is exact to the tolerance.
    #[default]
    Double,
    /// An f32 scan (twice the vector lanes) for shapes of 16 to 63
    /// vertices, and of 64 to 1 023 whose size keeps them from the cube
    /// map, on CPUs without AVX2 and FMA, where the exact search is the
    /// portable scan of every vertex. Everywhere else the exact search is
    /// used, since it is the faster: the AVX2 scan, the cube map of 64 to
    /// 4 095 vertices and the block search all beat the f32 scan of every
    /// vertex (measured: 0.86× at 16 vertices, 0.58× at 256, 0.4× at 512;
    /// `docs/speed-accuracy.md`). Where the f32 scan is used, the support
    /// point may fall short of the true one by 2⁻²⁰ of the shape's size, so
    /// the distance is exact to the tolerance plus about 1e-6 times the two
    /// sizes' sum, and the lower bound is lowered by that much. The f32 copy
    /// it scans is made when the shape is built (12 bytes a vertex).
    Single,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            tolerance: 100.0 * f64::EPSILON,
            max_iterations: 128,
            margin: None,
            warm_start: true,
            precision: Precision::Double,
        }
    }
}

impl Options {
    fn validate(&self) -> Result<(), Error> {
        // One pair of comparisons: NaN fails both, infinity the second.
        if !(self.tolerance >= 0.0 && self.tolerance <= f64::MAX) {
            return Err(Error::InvalidOption("tolerance must be finite and >= 0"));
        }
        if self.max_iterations == 0 {
            return Err(Error::InvalidOption("max_iterations must be at least 1"));
        }
        if let Some(m) = self.margin
            && !m.is_finite()
        {
            return Err(Error::InvalidOption("margin must be finite"));
        }
        Ok(())
    }
}

/// How a query ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Status {
    /// The stopping rule `g <= ε·D²` held (or the cores were found to touch or
    /// intersect): the distance is exact to the tolerance.
    Converged,
    /// Early exit: the lower bound proved the distance greater than the margin.
    Farther,
    /// Early exit: the upper bound proved the distance at most the margin.
    Closer,
    /// The iteration cap was reached first; the bounds still hold.
    IterationCap,
    /// Round-off stopped progress before the tolerance was met, even with the
    /// Backup Procedure (step 5 of the Numerical Algorithm); the bounds hold.
    ToleranceNotMet,
}

/// One piece pair's final simplex: its pieces and vertex index pairs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
struct PieceSimplex {
    pieces: [u32; 2],
    len: u8,
    pairs: [[u32; 2]; 4],
}

impl PieceSimplex {
    fn pairs(&self) -> &[[u32; 2]] {
        &self.pairs[..(self.len as usize).min(4)]
    }

    /// Whether every index names a piece and vertex that `a` and `b` have
    /// (an empty entry always fits). Branch-free over the pairs: one
    /// comparison each, folded into one flag.
    fn fits(&self, a: &Shape, b: &Shape) -> bool {
        if self.len == 0 {
            return true;
        }
        let (Some(ca), Some(cb)) = (
            a.convex_piece(self.pieces[0] as usize),
            b.convex_piece(self.pieces[1] as usize),
        ) else {
            return false;
        };
        let (na, nb) = (ca.len(), cb.len());
        let mut ok = self.len <= 4;
        for &[i, j] in self.pairs() {
            ok &= (i as usize) < na;
            ok &= (j as usize) < nb;
        }
        ok
    }

    /// The index pairs of `mask`'s vertices in `simplex`.
    fn of(simplex: &Simplex, mask: u8, pieces: [u32; 2]) -> Self {
        let mut out = PieceSimplex {
            pieces,
            ..Default::default()
        };
        for (i, v) in simplex.vertices.iter().enumerate() {
            if mask & (1 << i) != 0 {
                out.pairs[out.len as usize] = [v.ia, v.ib];
                out.len += 1;
            }
        }
        out
    }
}

/// The final simplex of a query, as vertex index pairs (Section 8), plus the
/// pieces it belongs to. Keep it per object pair and hand it back with the next
/// query of the same pair: it changes the time, never the answer beyond `ε`.
///
/// For a compound it also keeps the runner-up piece pair's simplex, so that
/// along a motion both the nearest pair and the one most likely to take over
/// start warm (the paper warm-starts every convex pair of its Section 8 scene).
/// A runner-up that the nearest pair's normal proved farther without a run
/// has no simplex to keep; it starts cold on the query where it is run again.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct WarmStart {
    first: PieceSimplex,
    second: PieceSimplex,
}

impl WarmStart {
    /// A warm start from explicit `[vertex of A, vertex of B]` index pairs (at
    /// most 4; more return `None`) in the given pieces (`[0, 0]` for two convex
    /// shapes). Indices are checked against the shapes at query time.
    pub fn new(pieces: [u32; 2], pairs: &[[u32; 2]]) -> Option<Self> {
        if pairs.len() > 4 {
            return None;
        }
        let mut first = PieceSimplex {
            pieces,
            len: pairs.len() as u8,
            pairs: [[0; 2]; 4],
        };
        first.pairs[..pairs.len()].copy_from_slice(pairs);
        Some(WarmStart {
            first,
            second: PieceSimplex::default(),
        })
    }

    /// The `[vertex of A, vertex of B]` index pairs of the simplex.
    pub fn pairs(&self) -> &[[u32; 2]] {
        self.first.pairs()
    }

    /// The `[piece of A, piece of B]` the simplex belongs to.
    pub fn pieces(&self) -> [u32; 2] {
        self.first.pieces
    }

    /// The same simplexes for the query with A and B swapped.
    fn swapped(&self) -> WarmStart {
        let swap = |p: &PieceSimplex| PieceSimplex {
            pieces: [p.pieces[1], p.pieces[0]],
            len: p.len,
            pairs: p.pairs.map(|[i, j]| [j, i]),
        };
        WarmStart {
            first: swap(&self.first),
            second: swap(&self.second),
        }
    }

    /// The kept simplexes: the nearest pair's (possibly empty), then the
    /// runner-up's if any.
    fn entries(&self) -> impl Iterator<Item = &PieceSimplex> {
        std::iter::once(&self.first).chain((self.second.len > 0).then_some(&self.second))
    }

    /// The index pairs kept for the piece pair `pieces`, if any.
    fn for_pieces(&self, pieces: [u32; 2]) -> Option<&[[u32; 2]]> {
        self.entries()
            .find(|e| e.len > 0 && e.pieces == pieces)
            .map(|e| e.pairs())
    }
}

/// Everything a query returns. Distances are after radii; points are in world
/// coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Answer {
    /// The distance between the (rounded) shapes, `>= 0`.
    pub distance: f64,
    /// Certified lower bound on the true distance (Theorem 4.1, widened by a
    /// bound on floating-point error).
    pub lower: f64,
    /// Certified upper bound on the true distance.
    pub upper: f64,
    /// Nearest point on A. When the shapes overlap, the deepest point of A's
    /// surface along `normal` (so `point_b - point_a = -penetration·normal`).
    pub point_a: Point3<f64>,
    /// Nearest point on B, as `point_a`.
    pub point_b: Point3<f64>,
    /// Unit vector from A's nearest point towards B's; zero when the cores
    /// touch or intersect and no direction is defined.
    pub normal: Vector3<f64>,
    /// Lower bound on the penetration depth (the smallest translation that
    /// separates the shapes): 0 when separated, exact when only the rounded
    /// shells overlap, the inner radius of the final simplex (5.9) plus the
    /// radii when the cores intersect. For a compound, the largest of its
    /// piece pairs' bounds.
    pub penetration: f64,
    /// Subalgorithm iterations, summed over piece pairs for compounds.
    pub iterations: u32,
    /// How the query ended.
    pub status: Status,
    /// Whether the Backup Procedure (6.5) was needed.
    pub backup_used: bool,
    /// `[piece of A, piece of B]` that realise the distance (`[0, 0]` for two
    /// convex shapes). After an early exit on a margin, the pair nearest so
    /// far, which need not be the nearest of all.
    pub pieces: [u32; 2],
    /// The final simplex, for the next query of this pair.
    pub warm_start: WarmStart,
}

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
    /// bytes: 125 instructions, 4 % of a separated query of the paper's
    /// family (callgrind). Boxed, so that lending it moves a pointer, and the
    /// answer is returned outside the thread-local's closure, which would
    /// copy it twice more.
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
    // Any workspace gives the same answer: a fresh one serves the first
    // query of a thread, and any query while the thread's is out of reach
    // (during thread teardown).
    let mut ws = SPARE
        .try_with(Cell::take)
        .ok()
        .flatten()
        .unwrap_or_else(|| Box::new(Workspace::new()));
    let answer = distance_in(&mut ws, a, pose_a, b, pose_b, options, warm);
    // Dropped instead if the thread-local is gone.
    let _ = SPARE.try_with(|spare| spare.set(Some(ws)));
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
    let query = Query {
        a,
        pose_a,
        b,
        pose_b,
        options,
        warm,
        swapped: false,
    };
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
    let query = Query {
        a,
        pose_a,
        b,
        pose_b,
        options,
        warm,
        swapped: false,
    };
    distance_base(workspace, &query)
}

/// One query's inputs, handed whole between [`distance_in`]'s compiled
/// forms.
#[derive(Clone, Copy)]
struct Query<'q> {
    a: &'q Shape,
    pose_a: &'q Isometry3<f64>,
    b: &'q Shape,
    pose_b: &'q Isometry3<f64>,
    options: &'q Options,
    warm: Option<&'q WarmStart>,
    /// This is the second opinion of [`second_opinion`]: asked no further.
    swapped: bool,
}

/// [`distance_of`] for any CPU, out of line, so that [`distance_in`] stays
/// a few instructions of dispatch with no frame of its own.
#[inline(never)]
fn distance_base(workspace: &mut Workspace, query: &Query<'_>) -> Result<Answer, Error> {
    distance_of::<false>(workspace, query)
}

/// [`distance_of`] compiled for AVX2 and FMA: the same operations, each
/// rounded the same way (Rust never fuses a multiply and an add on its own,
/// and `mul_add` is exact either way), so the same answer bit for bit, in
/// fewer instructions (three-operand forms, wider moves): 5 to 9 % less
/// time on the paper's family, measured.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn distance_avx2(workspace: &mut Workspace, query: &Query<'_>) -> Result<Answer, Error> {
    distance_of::<true>(workspace, query)
}

/// The body of [`distance_in`], inlined into each of its compiled forms;
/// `AVX2` says which, so that the subalgorithm's out-of-line parts are
/// called in the same form.
#[inline(always)]
fn distance_of<const AVX2: bool>(
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
        && !(w.first.fits(a, b) && w.second.fits(a, b))
    {
        return Err(Error::WarmStartOutOfRange);
    }
    let warm = warm.filter(|w| options.warm_start && (w.first.len > 0 || w.second.len > 0));
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
    // `stuck`: the interval width beyond which the answer is asked again
    // the other way round (see `second_opinion`).
    let (answer, stuck) = match (a, b) {
        (Shape::Convex(ca), Shape::Convex(cb)) => {
            let place = Place {
                pose: pose_a,
                offset: None,
            };
            let place_b = Place {
                pose: pose_b,
                offset: None,
            };
            let pair = Pair::new(ca, cb, &rel, (place, place_b), options.precision);
            let simplex = &mut workspace.simplex;
            let warm_pairs = warm.and_then(|w| w.for_pieces([0, 0]));
            let run = pair.solve_retrying::<AVX2>(simplex, options, warm_pairs, f64::INFINITY);
            let stuck = if swapped {
                f64::INFINITY
            } else {
                pair.stuck_width(options.tolerance)
            };
            (pair.answer(&run, simplex, place, [0, 0]), stuck)
        }
        _ => {
            let (answer, stuck) = compound::<AVX2>(&mut workspace.simplex, query, &rel, warm);
            (answer, if swapped { f64::INFINITY } else { stuck })
        }
    };
    // The answer goes out as it was built unless one of the three rare
    // checks below needs to change it (kept out of line, so that the common
    // path neither copies nor rewrites it).
    if answer.lower > answer.upper || !is_finite(&answer) || answer.upper - answer.lower > stuck {
        return rare::<AVX2>(answer, workspace, query, stuck);
    }
    Ok(answer)
}

/// A query that ended with an interval wider than the tolerance (stuck,
/// its support point tied between far points by `v`'s round-off), asked
/// once more with the shapes swapped: B's frame rounds differently, and a
/// needle along a prism's edge (`mid_sets` seed 8554, pair 164, vertex
/// lists repeated) that stopped at 5.55e-5 of a truth below 1.6e-11 gives
/// 1.5e-11 that way. Unions too: their piece pairs run the same way, and
/// the needle as a union's piece stopped where it did alone. Both answers
/// are certified, so the nearer upper bound wins and the lower bounds
/// combine. Cold, as a warm start names the pairs the other way round;
/// rare, so out of line.
#[cold]
#[inline(never)]
fn second_opinion<const AVX2: bool>(
    first: Answer,
    workspace: &mut Workspace,
    query: &Query<'_>,
) -> Answer {
    let other = Query {
        a: query.b,
        pose_a: query.pose_b,
        b: query.a,
        pose_b: query.pose_a,
        options: query.options,
        warm: None,
        swapped: true,
    };
    let Ok(second) = distance_of::<AVX2>(workspace, &other) else {
        return first;
    };
    let lower = first.lower.max(second.lower);
    if lower > first.upper.min(second.upper) {
        // The two contradict each other (round-off beyond the slack):
        // neither is trusted over the other, and the first stands.
        return first;
    }
    let mut best = if second.upper < first.upper {
        Answer {
            point_a: second.point_b,
            point_b: second.point_a,
            normal: -second.normal,
            pieces: [second.pieces[1], second.pieces[0]],
            warm_start: second.warm_start.swapped(),
            ..second
        }
    } else {
        first
    };
    best.lower = lower;
    best.distance = best.distance.max(lower).min(best.upper);
    best.penetration = first.penetration.max(second.penetration);
    best.iterations = first.iterations.saturating_add(second.iterations);
    best.backup_used = first.backup_used || second.backup_used;
    best
}

/// Whether every number of `answer` is finite. x·0 is NaN exactly when x is
/// infinite or NaN, and NaN survives the sums, whatever their order: a
/// balanced tree of sums, whose four-wide halves the compiler can vectorise.
#[inline(always)]
fn is_finite(answer: &Answer) -> bool {
    let z = |x: f64| x * 0.0;
    let (pa, pb, n) = (&answer.point_a, &answer.point_b, &answer.normal);
    let s1 = (z(answer.distance) + z(answer.lower)) + (z(answer.upper) + z(answer.penetration));
    let s2 = (z(pa.x) + z(pa.y)) + (z(pa.z) + z(pb.x));
    let s3 = (z(pb.y) + z(pb.z)) + (z(n.x) + z(n.y));
    ((s1 + s2) + (s3 + z(n.z))) == 0.0
}

/// The rare ends of [`distance_of`]: bounds that contradict each other, a
/// number that overflowed ([`repair`]), or a run stuck with an interval
/// wider than `stuck` ([`second_opinion`]).
#[cold]
#[inline(never)]
fn rare<const AVX2: bool>(
    answer: Answer,
    workspace: &mut Workspace,
    query: &Query<'_>,
    stuck: f64,
) -> Result<Answer, Error> {
    let answer = repair(answer, workspace, query)?;
    let converging = matches!(answer.status, Status::Converged | Status::ToleranceNotMet);
    if converging && answer.upper - answer.lower > stuck {
        return Ok(second_opinion::<AVX2>(answer, workspace, query));
    }
    Ok(answer)
}

/// Bounds that contradict each other, or a number that overflowed.
fn repair(
    mut answer: Answer,
    workspace: &mut Workspace,
    query: &Query<'_>,
) -> Result<Answer, Error> {
    if answer.lower > answer.upper {
        // The bounds contradict each other: round-off beyond the slack. The
        // one case fuzzing found (NaN weights from overflowing cofactors)
        // is handled in `solve`; this is the last line of defence. A cold
        // start is tried first; if that too is inconsistent, the lower
        // bound is given up (0) rather than returning an interval that
        // cannot hold.
        if query.warm.is_some() {
            let q = query;
            return distance_in(workspace, q.a, q.pose_a, q.b, q.pose_b, q.options, None);
        }
        answer.lower = 0.0;
        answer.distance = answer.distance.min(answer.upper);
        answer.status = Status::ToleranceNotMet;
    }
    if !is_finite(&answer) {
        // Finite inputs whose combination overflows f64 (coordinates near 1e308).
        return Err(Error::NonFinitePose);
    }
    Ok(answer)
}

/// Two convex pieces in the frame of A's piece, origin at A's centroid: the
/// quantities that do not change during one query.
struct Pair<'s> {
    a: &'s Convex,
    b: &'s Convex,
    /// Rotation of B's piece into A's piece frame.
    r: Matrix3<f64>,
    /// B's centroid minus A's centroid, in A's piece frame: `z̄2 - z̄1`,
    /// times `k`.
    t: Vector3<f64>,
    /// `D(K)` bounded by (6.4), times `k`.
    d: f64,
    /// Allowance for floating-point error in the bounds, times `k`.
    slack: f64,
    /// `slack` in the world's units.
    slack_world: f64,
    radii: f64,
    /// The power of two by which the run's frame is scaled, and its inverse.
    k: f64,
    inv_k: f64,
    /// Support search in f32 ([`Precision::Single`]).
    single: bool,
    /// How far below the true support value the f32 search may land, as a
    /// distance times `k`: 0 in f64.
    single_slack: f64,
}

/// Whether `iso` is the identity, exactly.
#[inline(always)]
fn is_identity(iso: &Isometry3<f64>) -> bool {
    let q = iso.rotation.coords;
    let t = iso.translation.vector;
    (q.w == 1.0 && q.x == 0.0 && q.y == 0.0 && q.z == 0.0) && t == Vector3::zeros()
}

/// B's centroid minus A's in A's piece frame, the centroids placed in the
/// world in double-double (see `crate::dd`): for a frame far from its
/// vertices, where the f64 offset would cancel.
#[inline(always)]
fn exact_centroid_gap(
    (pa, pb): (Place<'_>, Place<'_>),
    ca: &Point3<f64>,
    cb: &Point3<f64>,
) -> Vector3<f64> {
    let gap = crate::dd::centroid_gap((pa.pose, pa.offset), ca, (pb.pose, pb.offset), cb);
    // Into A's piece frame: the gap is small, so the rotation's rounding
    // costs only ε of it.
    let rotation = match pa.offset {
        Some(o) => pa.pose.rotation * o.rotation,
        None => pa.pose.rotation,
    };
    rotation.inverse_transform_vector(&gap)
}

/// `R·z`, each component `(r_i0·z_0 + r_i1·z_1) + r_i2·z_2`: nalgebra's
/// product term for term and in its order, so bit for bit the same, written
/// out so that the hot loop keeps it in scalar registers.
#[inline(always)]
fn rotate(r: &Matrix3<f64>, z: &Vector3<f64>) -> Vector3<f64> {
    let row = |i: usize| (r[(i, 0)] * z.x + r[(i, 1)] * z.y) + r[(i, 2)] * z.z;
    Vector3::new(row(0), row(1), row(2))
}

/// `Rᵀ·e`, as nalgebra's `tr_mul` (column dot products, in its order).
#[inline(always)]
fn rotate_back(r: &Matrix3<f64>, e: &Vector3<f64>) -> Vector3<f64> {
    let col = |j: usize| (r[(0, j)] * e.x + r[(1, j)] * e.y) + r[(2, j)] * e.z;
    Vector3::new(col(0), col(1), col(2))
}

/// Johnson's subalgorithm in the query's compiled form (see
/// [`distance_avx2`]).
#[inline(always)]
fn subalgorithm<const AVX2: bool>(simplex: &Simplex) -> Option<Solution> {
    #[cfg(target_arch = "x86_64")]
    if AVX2 {
        // SAFETY: AVX2 is true only below `distance_avx2`, which is entered
        // after the CPU was found to support AVX2 and FMA.
        return unsafe { simplex.solve_avx2() };
    }
    simplex.solve()
}

/// [`Simplex::reset`] in the query's compiled form (see [`distance_avx2`]).
#[inline(always)]
fn reset<const AVX2: bool>(simplex: &mut Simplex, points: &[Vertex]) {
    #[cfg(target_arch = "x86_64")]
    if AVX2 {
        // SAFETY: as in `subalgorithm`.
        unsafe { simplex.reset_avx2(points) };
        return;
    }
    simplex.reset(points);
}

/// [`Simplex::push`] in the query's compiled form (see [`distance_avx2`]).
#[inline(always)]
fn push<const AVX2: bool>(simplex: &mut Simplex, keep: u8, p: Vertex) {
    #[cfg(target_arch = "x86_64")]
    if AVX2 {
        // SAFETY: as in `subalgorithm`.
        unsafe { simplex.push_avx2(keep, p) };
        return;
    }
    simplex.push(keep, p);
}

/// Where a piece sits: its shape's pose and, for a compound's piece, its offset
/// in the shape's body frame.
#[derive(Clone, Copy)]
struct Place<'p> {
    pose: &'p Isometry3<f64>,
    offset: Option<&'p Isometry3<f64>>,
}

/// One convex pair's run of the Numerical Algorithm.
struct Run {
    /// Lower bound on the cores' penetration depth (5.9), 0 unless they touch
    /// or intersect.
    inner: f64,
    sol: Solution,
    /// `|v|`, zero when the cores touch or intersect.
    norm: f64,
    /// Best lower bound on the core distance seen, before slack.
    lower: f64,
    iterations: u32,
    exit: Exit,
    backup_used: bool,
}

/// What a run carries from one iteration to the next.
struct RunState {
    iterations: u32,
    /// The last iterate that led to a step, with `|v|²`.
    prev: Option<(Solution, f64)>,
    /// Best lower bound on the core distance seen, before slack.
    lower: f64,
    backup_used: bool,
    /// Steps taken without a measurable descent (see step 4) since the
    /// last real progress, and `|v|²` at the last of them.
    flat_steps: u32,
    level_v2: f64,
}

impl RunState {
    /// The nearer of `sol` (with `|v|² = v2`) and the last iterate that led
    /// to a step, whose vertices the step kept in their slots.
    #[inline(always)]
    fn nearer(&self, sol: Solution, v2: f64) -> Solution {
        match self.prev {
            Some((p, p2)) if p2 < v2 => p,
            _ => sol,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Exit {
    Status(Status),
    /// The lower bound passed the caller's cutoff: this pair cannot be the
    /// nearest of a compound.
    Pruned,
}

impl<'s> Pair<'s> {
    /// The pair at relative pose `rel = A⁻¹·B`. `world` holds where each
    /// piece sits (its shape's pose and a compound piece's offset), for the
    /// exact centroid offset of a frame far from its vertices.
    #[inline(always)]
    fn new(
        a: &'s Convex,
        b: &'s Convex,
        rel: &Isometry3<f64>,
        world: (Place<'_>, Place<'_>),
        precision: Precision,
    ) -> Self {
        let r = *rel.rotation.to_rotation_matrix().matrix();
        let rb = r * b.centroid().coords;
        let (ca, cb) = (a.centroid(), b.centroid());
        // Centroids far from their body origins (relative to the shapes'
        // sizes) make rb and the translation cancel: then the offset is
        // taken in world coordinates in double-double and rotated once.
        let (na, nb) = (a.centroid_norm(), b.centroid_norm());
        let far = na + nb > 16.0 * (a.size() + b.size());
        let (t, exact) = if far {
            (exact_centroid_gap(world, &ca, &cb), true)
        } else {
            (rb + rel.translation.vector - ca.coords, false)
        };
        // The run works in a frame scaled by a power of two that brings the
        // pair's sizes near 1: exact (every result is the unscaled one times
        // k, bit for bit), and the cofactors, products of up to three
        // squared lengths, then neither overflow nor underflow for shapes
        // anywhere from 1e-300 to 1e300 in size. Sizes within 2^±64 need no
        // scaling (k = 1): their cofactors stay within 2^±400.
        let m = a.size().max(b.size()).max(t.amax());
        let (k, inv_k) = if m > 5.4e-20 && m < 1.8e19 {
            (1.0, 1.0)
        } else {
            crate::shape::pow2_scale(m)
        };
        let t = t * k;
        let d = (a.size() + b.size()) * k + t.norm();
        let single = precision == Precision::Single;
        // The f32 search lands within SINGLE_SLACK·size·|η| of each shape's
        // support value; every direction it is given has |η| = |v|, so the
        // support value of K = A - B may be missed by this times |v|.
        let single_slack = if single {
            let of = |c: &Convex| if c.has_single() { c.size() } else { 0.0 };
            crate::shape::SINGLE_SLACK * (of(a) + of(b)) * k
        } else {
            0.0
        };
        // Every input to a dot product is at most `scale` in size; the sums of a
        // few products each carry a relative error of a few ε. 64 ε covers the
        // rotation, the centroid shift and the subalgorithm's weights with room.
        let scale = if exact {
            d
        } else {
            // |rb| = |z̄2|: a rotation keeps lengths.
            d + na * k + nb * k + crate::shape::robust_norm(&rel.translation.vector) * k
        };
        let slack = 64.0 * f64::EPSILON * scale;
        Pair {
            a,
            b,
            r,
            t,
            d,
            slack,
            slack_world: slack * inv_k,
            radii: a.radius() + b.radius(),
            k,
            inv_k,
            single,
            single_slack,
        }
    }

    /// `y = z1 - z2` for vertex `ia` of A and `ib` of B. The centroid-midpoint
    /// origin of (6.1) cancels in the difference; what matters is that both
    /// terms are small vectors relative to their centroids.
    #[inline(always)]
    fn vertex(&self, ia: usize, ib: usize) -> Vertex {
        let (za, zb) = (self.a.local(ia), rotate(&self.r, &self.b.local(ib)));
        // k is 1 but for shapes beyond 2^±64 in size: skip the products
        // then. Each point is scaled after the rotation, not through a
        // scaled matrix, whose entries could be subnormal.
        let y = if self.k != 1.0 {
            za * self.k - (zb * self.k + self.t)
        } else {
            za - (zb + self.t)
        };
        Vertex {
            y,
            ia: ia as u32,
            ib: ib as u32,
        }
    }

    /// `s_K(η) = s_A(η) - s_B(-η)` (3.8): one scan of each vertex set.
    #[inline(always)]
    fn support(&self, eta: &Vector3<f64>) -> Vertex {
        let eta_b = -rotate_back(&self.r, eta);
        let (ia, ib) = if self.single {
            (
                self.a.support_index_single(eta),
                self.b.support_index_single(&eta_b),
            )
        } else {
            (self.a.support_index(eta), self.b.support_index(&eta_b))
        };
        self.vertex(ia, ib)
    }

    /// The Numerical Algorithm, steps (1) to (6): one run, its lengths in the
    /// world's units (the simplex's points stay in the scaled frame).
    #[inline(always)]
    fn solve<const AVX2: bool>(
        &self,
        simplex: &mut Simplex,
        options: &Options,
        warm: Option<&[[u32; 2]]>,
        cutoff: f64,
    ) -> Run {
        let mut run = self.solve_scaled::<AVX2>(simplex, options, warm, cutoff);
        if self.inv_k != 1.0 {
            run.norm *= self.inv_k;
            run.lower *= self.inv_k;
            run.inner *= self.inv_k;
            run.sol.v *= self.inv_k;
        }
        run
    }

    /// [`solve`](Self::solve) in the scaled frame: every length in the
    /// returned run is `k` times the world's.
    ///
    /// The common iteration (the subalgorithm succeeds, the support point is
    /// new, `|v|` descends and no end is reached) is taken in this loop, which
    /// keeps few values live; any other outcome goes to [`step`](Self::step),
    /// out of line, which takes steps (3) to (6) in full from the same state.
    /// Both take the same decisions on the same values, so the split changes
    /// the time of a query, never its answer.
    #[inline(always)]
    fn solve_scaled<const AVX2: bool>(
        &self,
        simplex: &mut Simplex,
        options: &Options,
        warm: Option<&[[u32; 2]]>,
        cutoff: f64,
    ) -> Run {
        // Step (1): V0 from the warm start, else the single point s_K(z̄2 - z̄1).
        match warm {
            Some(pairs) => {
                let mut pts = [Vertex::default(); 4];
                for (p, &[i, j]) in pts.iter_mut().zip(pairs) {
                    *p = self.vertex(i as usize, j as usize);
                }
                reset::<AVX2>(simplex, &pts[..pairs.len()]);
            }
            None => simplex.start(self.support(&self.t)),
        }
        let eps_d = options.tolerance * self.d;
        // What the support search may miss is added to every test of g, so
        // that an f32 search stops where it can prove no more (0 in f64).
        let stop_d = eps_d + self.single_slack;
        let mut st = RunState {
            iterations: 0,
            prev: None,
            lower: 0.0,
            backup_used: false,
            flat_steps: 0,
            level_v2: f64::INFINITY,
        };
        loop {
            st.iterations += 1;
            // Step (2).
            let Some(sol) = subalgorithm::<AVX2>(simplex) else {
                st.backup_used = true;
                let sol = simplex.backup();
                match self.step::<AVX2>(simplex, options, cutoff, &mut st, sol, true, None) {
                    Some(run) => return run,
                    None => continue,
                }
            };
            let v2 = sol.v.norm_squared();
            let norm = v2.sqrt();
            // Overflow (NaN fails the first test) and touching cores. The
            // cores' meeting, the end of every intersecting query, is taken
            // here as `step` would take it, without its call.
            if !(norm > self.slack && norm.is_finite()) {
                if norm <= self.slack {
                    return self.finish(simplex, &st, Status::Converged, sol, 0.0);
                }
                match self.step::<AVX2>(simplex, options, cutoff, &mut st, sol, false, None) {
                    Some(run) => return run,
                    None => continue,
                }
            }
            // Step (3).
            let s = self.support(&-sol.v);
            let vs = sol.v.dot(&s.y);
            let lower = st.lower.max(vs / norm - self.single_slack);
            let g = v2 - vs;
            if g <= stop_d * norm || norm <= eps_d {
                return self.finish(simplex, &st, Status::Converged, sol, lower);
            }
            // Anything but a plain descent by a new point, and every other
            // way to end, is decided by `step`, from the start of step (3).
            let repeat = simplex.has_pair(simplex.all, s.ia, s.ib);
            let descends = match st.prev {
                None => true,
                Some((_, p2)) => v2 < p2,
            };
            if repeat
                || !descends
                || sol.mask == 0b1111
                || self.cut(lower, norm, cutoff, options.margin).is_some()
                || st.iterations >= options.max_iterations
            {
                match self.step::<AVX2>(simplex, options, cutoff, &mut st, sol, false, Some(s)) {
                    Some(run) => return run,
                    None => continue,
                }
            }
            // Step (4).
            st.lower = lower;
            st.prev = Some((sol, v2));
            push::<AVX2>(simplex, sol.mask, s);
        }
    }

    /// The early ends decided on the bounds alone, compared in the world's
    /// units: [`Exit::Pruned`] once the certified lower bound passes the
    /// caller's `cutoff` (this pair cannot be a compound's nearest), then,
    /// with a margin, [`Status::Farther`] or [`Status::Closer`] once the
    /// bounds decide it. `lower` is the run's lower bound, `norm` its `|v|`,
    /// both before slack and in the scaled frame.
    #[inline(always)]
    fn cut(&self, lower: f64, norm: f64, cutoff: f64, margin: Option<f64>) -> Option<Exit> {
        let lower_cert = (lower - self.slack) * self.inv_k - self.radii;
        if lower_cert > cutoff {
            return Some(Exit::Pruned);
        }
        let m = margin?;
        if lower_cert.max(0.0) > m {
            return Some(Exit::Status(Status::Farther));
        }
        if ((norm + self.slack) * self.inv_k - self.radii).max(0.0) <= m {
            return Some(Exit::Status(Status::Closer));
        }
        None
    }

    /// A run's end: its bounds and, when the cores touch or intersect, the
    /// penetration bound.
    #[inline(always)]
    fn finish(
        &self,
        simplex: &Simplex,
        st: &RunState,
        exit: Status,
        sol: Solution,
        lower: f64,
    ) -> Run {
        let norm = sol.v.norm();
        Run {
            inner: if norm <= self.slack {
                self.penetration(simplex, &sol)
            } else {
                0.0
            },
            sol,
            norm,
            lower,
            iterations: st.iterations,
            exit: Exit::Status(exit),
            backup_used: st.backup_used,
        }
    }

    /// Steps (3) to (6) of the Numerical Algorithm for the subalgorithm's
    /// `sol` (from the Backup Procedure when `by_backup`), in full: the ends,
    /// repeats, flat steps, refinement and the Backup Procedure. `support`,
    /// when given, is `s_K(-v)` already found for this `sol`. `None` once a
    /// point has been added to the simplex (the next iteration begins),
    /// `Some` when the run ends.
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    fn step<const AVX2: bool>(
        &self,
        simplex: &mut Simplex,
        options: &Options,
        cutoff: f64,
        st: &mut RunState,
        mut sol: Solution,
        mut by_backup: bool,
        mut support: Option<Vertex>,
    ) -> Option<Run> {
        let eps_d = options.tolerance * self.d;
        let stop_d = eps_d + self.single_slack;
        let mut refined = false;
        let mut inside_asked = false;
        let mut regrown = false;
        loop {
            let v2 = sol.v.norm_squared();
            let norm = v2.sqrt();
            if !norm.is_finite() {
                // The subalgorithm overflowed. Fuzzing found points
                // ~1e108 apart whose cofactors exceeded f64 (before the
                // run was scaled to sizes near 1; kept as a guard, see
                // gjk/tests/fuzz_regressions.rs), and NaN weights would
                // make every bound below meaningless. Keep the last
                // finite iterate, or else a single vertex: each is a
                // point of the hull, so |v| stays an upper bound.
                st.backup_used = true;
                let best = match st.prev {
                    Some((p, _)) => p,
                    None => {
                        let i = simplex.all.trailing_zeros().min(3) as usize;
                        let mut lambda = [0.0; 4];
                        lambda[i] = 1.0;
                        Solution {
                            mask: 1 << i,
                            v: simplex.vertices[i].y,
                            lambda,
                        }
                    }
                };
                return Some(Run {
                    inner: 0.0,
                    sol: best,
                    norm: best.v.norm(),
                    lower: st.lower,
                    iterations: st.iterations,
                    exit: Exit::Status(Status::ToleranceNotMet),
                    backup_used: st.backup_used,
                });
            }
            if norm <= self.slack {
                // v is the origin up to round-off: the cores touch or
                // intersect, and nothing finer can be certified.
                return Some(self.finish(simplex, st, Status::Converged, sol, 0.0));
            }
            // Step (3): the stopping rule, and the bounds of Theorem 4.1.
            let s = match support.take() {
                Some(s) => s,
                None => self.support(&-sol.v),
            };
            let vs = sol.v.dot(&s.y);
            st.lower = st.lower.max(vs / norm - self.single_slack);
            let lower = st.lower;
            let g = v2 - vs;
            // (6.2): g <= ε·D². Near contact that rule alone lets |v|
            // exceed the distance by up to √ε·D (nearly parallel edges do
            // this), so once it holds the run goes on while |v| still
            // descends, and stops early only when the certified interval,
            // of width g/|v|, is within ε·D. A support point already in V̂
            // leaves nothing to add: g is then the error of v itself.
            let paper_met = g <= eps_d * self.d + self.single_slack * norm;
            // The error of |v| is at most min(|v|, g/|v|): stop once that
            // is within ε·D, or within the round-off allowance when the
            // support point repeats a vertex of V̂. Beyond that, a repeat
            // means the subalgorithm's v is off by more than round-off
            // (a thin simplex: nearly parallel edges, or nearly collinear
            // points of K at contact): refinement, then steps (4) to (6).
            if g <= stop_d * norm || norm <= eps_d {
                return Some(self.finish(simplex, st, Status::Converged, sol, lower));
            }
            let repeat = simplex.has_pair(simplex.all, s.ia, s.ib);
            if repeat && g <= self.slack * norm {
                return Some(self.finish(simplex, st, Status::Converged, sol, lower));
            }
            // Cutoff and margin are the world's: compared there.
            match self.cut(lower, norm, cutoff, options.margin) {
                Some(Exit::Pruned) => {
                    let mut run = self.finish(simplex, st, Status::Converged, sol, lower);
                    run.exit = Exit::Pruned;
                    return Some(run);
                }
                Some(Exit::Status(status)) => {
                    return Some(self.finish(simplex, st, status, sol, lower));
                }
                None => {}
            }
            if st.iterations >= options.max_iterations {
                // Converged only where step (5) below would end the run
                // too: (6.2) alone holds for a |v| up to √ε·D off, which
                // a run without the cap goes on to remove (nearly parallel
                // edges 6.19e-6 apart, capped at 2 iterations, stopped at
                // 6.23e-6 called converged).
                let tight = norm - lower <= 4.0 * stop_d;
                let status = if paper_met && tight {
                    Status::Converged
                } else {
                    Status::IterationCap
                };
                // The nearer of the last two iterates (see step 5).
                let best = st.nearer(sol, v2);
                return Some(self.finish(simplex, st, status, best, lower));
            }
            // A step that does not descend refines v before it is taken or
            // given up (as a repeat does, below). Along a long thin edge of
            // K, v's error along the edge (ε times its length) can outweigh
            // v itself in the support search, and on a face of K normal to
            // v, whose points all tie, it alone picks the support point: a
            // needle of length 1.7 touching a lattice's face cycled between
            // two such points, each step level, and ended at 4.2e-10 against
            // a truth below 1.6e-17 (mid_sets seed 8593, pair 1844). The
            // refined v picks the point a step in exact arithmetic would.
            if !refined
                && !repeat
                && matches!(st.prev, Some((_, p2)) if v2 >= p2)
                && let Some(r) = simplex.refine(sol)
            {
                refined = true;
                sol = r;
                continue;
            }
            // Step (4): descend while |v| decreases and V̂ is not full. A
            // step that only grows V̂ by a dimension, with |v| unchanged at
            // round-off level, is also progress (nearly parallel edges give
            // such steps); a few are allowed before step (5) takes over.
            // The budget counts level steps since |v|² last fell by more
            // than 2⁻²⁰ (far above round-off) from one level step to the
            // next. On a curved set far larger than |v| (an ellipsoid of 451
            // points, size 5e5, 1.5e-3 from a disk), v's round-off, times
            // the points' distance, picks a support point that the next
            // subalgorithm drops: the step is level, its refined v leads
            // on, and the next step descends by a few per cent. Counted
            // over the whole run, four such pairs of steps ended it at
            // 1.548e-3, the truth 1.5335e-3 (mid_sets seed 8574, pair 7841).
            let budget = if v2 < st.level_v2 * (1.0 - 1.0 / 1_048_576.0) {
                0
            } else {
                st.flat_steps
            };
            let mut not_down = false;
            let descended = match st.prev {
                None => true,
                Some((_, p2)) if v2 < p2 => true,
                Some((p, p2)) => {
                    let grew = sol.mask.count_ones() > p.mask.count_ones();
                    let flat = grew && v2 <= p2 * (1.0 + 8.0 * f64::EPSILON);
                    // |v| up by no more than its round-off while the new
                    // support point, not yet in Y, lies beyond v's plane
                    // by more than the tolerance: near contact, Johnson's
                    // v of a new face can be εD worse than the refined v
                    // of the last, and stopping there leaves |v| at
                    // (6.2)'s √ε·D (nearly parallel edges touching).
                    let level = norm <= p2.sqrt() + self.slack;
                    not_down = true;
                    (flat || level) && budget < 4
                }
            };
            if descended && sol.mask.count_ones() <= 3 && !repeat {
                // Only a step taken counts against the budget: a repeat
                // refined within the iteration is the same step.
                if not_down {
                    st.flat_steps = budget + 1;
                    st.level_v2 = v2;
                }
                st.prev = Some((sol, v2));
                push::<AVX2>(simplex, sol.mask, s);
                return None;
            }
            // Stuck with four points and a face chosen: a nearly flat
            // tetrahedron's cofactors can reject it while it holds the
            // origin (a collinear set touching a face ended at 3.5e-10 on
            // objects of size 2, the support point repeating the dropped
            // vertex). Refinement and the Backup Procedure work from the same
            // cofactors; the exact orientation tests do not. Asked once.
            if simplex.all == 0b1111 && sol.mask != 0b1111 && !inside_asked {
                inside_asked = true;
                if let Some(lambda) = simplex.origin_weights() {
                    let origin = Solution {
                        mask: 0b1111,
                        v: Vector3::zeros(),
                        lambda,
                    };
                    return Some(self.finish(simplex, st, Status::Converged, origin, lower));
                }
            }
            // The support point repeats a vertex the subalgorithm dropped,
            // which exact arithmetic rules out while g > 0: its weight was
            // lost to round-off (see `Simplex::regrow`). The grown subset's
            // v goes back to step (3) if it is no farther than round-off
            // allows; its support point then leads on. Asked once.
            if repeat && !regrown {
                regrown = true;
                if let Some(r) = simplex.regrow(sol, s.ia, s.ib) {
                    let r2 = r.v.norm_squared();
                    if r2 <= v2 * (1.0 + 8.0 * f64::EPSILON) {
                        sol = r;
                        continue;
                    }
                }
            }
            // A repeat with g above round-off: v carries the error of a
            // thin simplex's cofactors, or of the Backup Procedure's
            // (which redoes them). One refinement step in V̂'s affine hull
            // removes it, and the refined v goes back to step (3); the
            // Backup Procedure comes after, if needed.
            let refined_sol = if repeat && !refined {
                refined = true;
                simplex.refine(sol)
            } else {
                None
            };
            // Step (5): round-off has the last word. The previous iterate,
            // if nearer, is still valid: its vertices kept their slots.
            // When (6.2) holds the paper would have stopped at step (3):
            // no Backup Procedure is needed to confirm that, unless the
            // support point repeats a point of Y (then (6.2) may hold
            // for a v that is off by up to √ε·D) and refinement is left,
            // or unless the interval is still wider than the tolerance:
            // near contact (6.2) holds for a v up to √ε·D off, and a
            // descent too small to show through v's round-off (|v| 1e9
            // times below |y|) stops the steps there. A cluster touching
            // a lattice surface ended so at 1.6e-13 in [0, 1.6e-13], the
            // truth 2e-17 (mid_sets seed 8526, pair 2624); the Backup
            // Procedure's subset leads on to it.
            let tight = norm - lower <= 4.0 * stop_d;
            if refined_sol.is_none() && (by_backup || (paper_met && !repeat && tight)) {
                let status = if paper_met {
                    Status::Converged
                } else {
                    Status::ToleranceNotMet
                };
                // A step that failed to descend (round-off in a
                // degenerate simplex) leaves the previous iterate, whose
                // slots the push kept, as the better upper bound.
                let best = st.nearer(sol, v2);
                return Some(self.finish(simplex, st, status, best, lower));
            }
            match refined_sol {
                Some(r) => sol = r,
                None => {
                    // Step (6): redo v_k with the Backup Procedure. Its v
                    // comes from the same kind of cofactors, so it may be
                    // refined once too: a cluster against a box surface
                    // (mid_sets seed 8531, pair 5372) ended at 4.7e-9 in
                    // [0, 4.7e-9] on the Backup Procedure's thin triangle,
                    // the support point repeating one of its vertices, while
                    // the refined v leads on to the truth, 4.8e-11.
                    sol = simplex.backup();
                    by_backup = true;
                    refined = false;
                    st.backup_used = true;
                }
            }
        }
    }

    /// [`solve`](Self::solve), then, when a warm start ended with a loose
    /// interval, once more cold ([`cold_again`](Self::cold_again)): single
    /// pairs and a compound's piece pairs alike. Only a run that meant to
    /// converge is asked again. A pruned run only had to prove that its pair
    /// cannot win; an early exit on the margin and the iteration cap end
    /// with a wide interval by the caller's own choice, and a cold run would
    /// spend a second budget to end as loose (warm queries with a margin took
    /// longer than without one, and came back with the cold run's coarser
    /// distance).
    #[inline(always)]
    fn solve_retrying<const AVX2: bool>(
        &self,
        simplex: &mut Simplex,
        options: &Options,
        warm: Option<&[[u32; 2]]>,
        cutoff: f64,
    ) -> Run {
        let run = self.solve::<AVX2>(simplex, options, warm, cutoff);
        let meant_to_converge = matches!(
            run.exit,
            Exit::Status(Status::Converged | Status::ToleranceNotMet)
        );
        if warm.is_some() && meant_to_converge && self.loose(&run, options.tolerance) {
            return self.cold_again::<AVX2>(run, simplex, options, cutoff);
        }
        run
    }

    /// Whether the run's certified interval is wider than the tolerance
    /// allows: (6.2) alone ended it, near contact.
    #[inline(always)]
    fn loose(&self, run: &Run, tolerance: f64) -> bool {
        let (lower, upper, _) = self.bounds(run);
        upper - lower > self.tight_width(tolerance)
    }

    /// The widest interval, in the world's units, that the tolerance allows
    /// a converged run: the slack at both ends and the 4 ε·D of step (5).
    #[inline(always)]
    fn tight_width(&self, tolerance: f64) -> f64 {
        2.0 * self.slack_world + 4.0 * tolerance * self.d * self.inv_k
    }

    /// The interval width so much beyond what the tolerance allows (100
    /// times [`tight_width`](Self::tight_width)) that a second opinion is worth a
    /// second run: a stuck run, not one that (6.2) ended a few round-offs
    /// short. At 1 time that width, 4.5 % of the randomised sweep's runs
    /// and 3 % of the paper's family's would be asked again; from 10 times
    /// on, none of the family's.
    #[inline(always)]
    fn stuck_width(&self, tolerance: f64) -> f64 {
        100.0 * self.tight_width(tolerance)
    }

    /// A warm run that ended with a loose interval (the warm simplex can sit
    /// on an edge of a flat K whose line passes 1e-9 of the size from the
    /// origin, coplanar sets touching, where no support point leads off it):
    /// the run once more from the single-point start. The cold run is kept
    /// whole, since the simplex now holds its points; the warm run's lower
    /// bound, certified too, still counts.
    #[cold]
    #[inline(never)]
    fn cold_again<const AVX2: bool>(
        &self,
        warm: Run,
        simplex: &mut Simplex,
        options: &Options,
        cutoff: f64,
    ) -> Run {
        let mut run = self.solve::<AVX2>(simplex, options, None, cutoff);
        run.lower = run.lower.max(warm.lower);
        run.iterations = run.iterations.saturating_add(warm.iterations);
        run.backup_used |= warm.backup_used;
        run
    }

    /// A lower bound on the cores' penetration depth once `v` is the origin.
    /// (5.9) needs a tetrahedron around the origin. When the run stopped on a
    /// smaller simplex with `v` exactly zero (the first support point was the
    /// origin, as for identical shapes), one is built from the supports in
    /// tetrahedral directions; when `v` is merely within round-off of zero the
    /// origin lies on a face of the simplex, usually a touching contact, and
    /// the bound is 0. Either way it is cut by the round-off allowance, since
    /// it must never exceed the truth.
    #[cold]
    fn penetration(&self, simplex: &Simplex, sol: &Solution) -> f64 {
        let inner = if sol.mask == 0b1111 {
            simplex.inner_radius(self.slack)
        } else if sol.v != Vector3::zeros() {
            0.0
        } else {
            // The two tetrahedra inscribed in a cube between them use all its
            // corners, so one holds any point near a corner of a box-like K.
            let dirs = [
                Vector3::new(1.0, 1.0, 1.0),
                Vector3::new(1.0, -1.0, -1.0),
                Vector3::new(-1.0, 1.0, -1.0),
                Vector3::new(-1.0, -1.0, 1.0),
            ];
            let mut tetra = Simplex::empty();
            let mut best = 0.0f64;
            for sign in [1.0, -1.0] {
                tetra.reset(&dirs.map(|d| self.support(&(d * sign))));
                if let Some(s) = tetra.solve()
                    && s.mask == 0b1111
                {
                    best = best.max(tetra.inner_radius(self.slack));
                }
            }
            best
        };
        (inner - self.slack).max(0.0)
    }

    /// The certified `(lower, upper)` bounds of a run, after radii, and the
    /// distance reported between them.
    #[inline]
    fn bounds(&self, run: &Run) -> (f64, f64, f64) {
        let upper = (run.norm + self.slack_world - self.radii).max(0.0);
        let lower = (run.lower - self.slack_world - self.radii).max(0.0);
        // Not `clamp`: it panics when round-off beyond the slack has put
        // `lower` above `upper`; `distance` repairs that case.
        let distance = (run.norm - self.radii).max(0.0).max(lower).min(upper);
        (lower, upper, distance)
    }

    /// Turn a run into an answer in world coordinates. `place_a` places A's
    /// piece (its shape's pose and, for a compound, the piece's offset); B's
    /// nearest point is placed with it, as A's point minus `v`.
    #[inline(always)]
    fn answer(&self, run: &Run, simplex: &Simplex, place_a: Place<'_>, pieces: [u32; 2]) -> Answer {
        let (pose_a, off_a) = (place_a.pose, place_a.offset);
        let mut lambda = run.sol.lambda;
        if run.sol.mask == 0b1111
            && let Some(l) = simplex.refine_origin(lambda, self.slack)
        {
            lambda = l;
        }
        let mut wa = Vector3::zeros();
        let mut pairs = [[0u32; 2]; 4];
        let mut len = 0;
        for (i, (vx, l)) in simplex.vertices.iter().zip(lambda).enumerate() {
            if run.sol.mask & (1 << i) != 0 {
                wa += self.a.local(vx.ia as usize) * l;
                pairs[len & 3] = [vx.ia, vx.ib];
                len += 1;
            }
        }
        // Both nearest points in A's piece frame: B's is A's minus v, since
        // v = Σλ(a_i - b_i) with the same weights. One placement serves both,
        // and their gap is v itself, not the difference of two placements.
        let (rot, shift) = match off_a {
            Some(o) if !is_identity(o) => (
                pose_a.rotation * o.rotation,
                pose_a.rotation * o.translation.vector + pose_a.translation.vector,
            ),
            _ => (pose_a.rotation, pose_a.translation.vector),
        };
        let core_a = Point3::from(rot * (self.a.centroid().coords + wa) + shift);
        // b - a = -v, in world coordinates.
        let gap = rot * -run.sol.v;
        let core_b = core_a + gap;
        let separated = run.norm > self.slack_world;
        let normal = if separated {
            gap * (1.0 / run.norm)
        } else {
            Vector3::zeros()
        };
        let (ra, rb) = (self.a.radius(), self.b.radius());
        let penetration = if !separated {
            run.inner + self.radii
        } else {
            (self.radii - run.norm).max(0.0)
        };
        let (lower, upper, distance) = self.bounds(run);
        Answer {
            distance,
            lower,
            upper,
            point_a: core_a + normal * ra,
            point_b: core_b - normal * rb,
            normal,
            penetration,
            iterations: run.iterations,
            status: match run.exit {
                Exit::Status(s) => s,
                Exit::Pruned => Status::Converged,
            },
            backup_used: run.backup_used,
            pieces,
            warm_start: WarmStart {
                first: PieceSimplex {
                    pieces,
                    len: len as u8,
                    pairs,
                },
                second: PieceSimplex::default(),
            },
        }
    }
}

/// A certified lower bound on the distance between piece `ca` placed by `oa`
/// and piece `cb` placed by `ob`, both in A's body frame: their gap along the
/// unit axis `n` (from A towards B), one support search on each, less what
/// round-off may hide. Any axis gives a lower bound (a separating plane); the
/// best pair's normal is a good one for the pieces beside it, and costs two
/// support searches where running the pair costs a set-up and an iteration
/// at least. NaN (from a NaN axis) passes no cutoff, so it skips nothing.
#[inline(always)]
fn axis_gap(
    ca: &Convex,
    oa: &Isometry3<f64>,
    cb: &Convex,
    ob: &Isometry3<f64>,
    n: &Vector3<f64>,
) -> f64 {
    let da = oa.rotation.inverse_transform_vector(n);
    let db = ob.rotation.inverse_transform_vector(n);
    let (ia, ib) = (ca.support_index(&da), cb.support_index(&-db));
    let top_a =
        (da.dot(&ca.centroid().coords) + da.dot(&ca.local(ia))) + n.dot(&oa.translation.vector);
    let bottom_b =
        (db.dot(&cb.centroid().coords) + db.dot(&cb.local(ib))) + n.dot(&ob.translation.vector);
    let gap = (bottom_b - top_a) - (ca.radius() + cb.radius());
    // Each product and sum above errs by a few ε of the magnitudes involved,
    // the rotated axes by a few ε of their length 1, and a support search may
    // miss the maximum by a near-tie's last bit: 64 ε of every magnitude, as
    // a pair's own slack. `n` is unit to a few ε, which scales the gap.
    let scale = ca.reach()
        + cb.reach()
        + robust_norm(&oa.translation.vector)
        + robust_norm(&ob.translation.vector)
        + ca.radius()
        + cb.radius();
    (gap - 64.0 * f64::EPSILON * scale) * (1.0 - 8.0 * f64::EPSILON)
}

/// (2.3), (2.8): the minimum over piece pairs. Pairs are visited warm pair
/// first, then by a bounding-sphere lower bound; each runs with the best upper
/// bound so far as its cutoff, so a pair that cannot win stops early, and a
/// pair proved beyond the cutoff before its run (by its sphere gap, or by its
/// gap along the best pair's normal, [`axis_gap`]) does not run at all.
/// With the answer, the interval width beyond which it counts as stuck (see
/// [`second_opinion`]).
///
/// Run out of line in the query's compiled form (see [`distance_avx2`]): a
/// function of its own is compiled for the baseline CPU unless it carries
/// the target features itself, and the piece pairs' runs, inlined in it,
/// took 12 % more instructions in SSE2 code (the Section 8 union, warm).
#[inline(always)]
fn compound<const AVX2: bool>(
    simplex: &mut Simplex,
    query: &Query<'_>,
    rel: &Isometry3<f64>,
    warm: Option<&WarmStart>,
) -> (Answer, f64) {
    #[cfg(target_arch = "x86_64")]
    if AVX2 {
        // SAFETY: as in `subalgorithm`.
        return unsafe { compound_avx2(simplex, query, rel, warm) };
    }
    compound_base(simplex, query, rel, warm)
}

/// [`compound_of`] for any CPU.
#[inline(never)]
fn compound_base(
    simplex: &mut Simplex,
    query: &Query<'_>,
    rel: &Isometry3<f64>,
    warm: Option<&WarmStart>,
) -> (Answer, f64) {
    compound_of::<false>(simplex, query, rel, warm)
}

/// [`compound_of`] compiled for AVX2 and FMA (see [`distance_avx2`]); out
/// of line, so that the convex pair's path around its call stays as it was.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline(never)]
fn compound_avx2(
    simplex: &mut Simplex,
    query: &Query<'_>,
    rel: &Isometry3<f64>,
    warm: Option<&WarmStart>,
) -> (Answer, f64) {
    compound_of::<true>(simplex, query, rel, warm)
}

/// The body of [`compound`], inlined into each of its compiled forms.
#[inline(always)]
fn compound_of<const AVX2: bool>(
    simplex: &mut Simplex,
    query: &Query<'_>,
    rel: &Isometry3<f64>,
    warm: Option<&WarmStart>,
) -> (Answer, f64) {
    let &Query {
        a,
        pose_a,
        b,
        pose_b,
        options,
        ..
    } = query;
    let (na, nb) = (a.piece_count(), b.piece_count());
    // Piece pairs with their sphere gaps: on the stack for the usual few
    // pieces, so a query allocates nothing.
    const ON_STACK: usize = 16;
    let mut small = [(0.0f64, 0u32, 0u32); ON_STACK];
    let mut large = Vec::new();
    let order: &mut [(f64, u32, u32)] = if na * nb <= ON_STACK {
        &mut small[..na * nb]
    } else {
        large.resize(na * nb, (0.0, 0, 0));
        &mut large
    };
    // B's pieces outside, so that each centre is placed in A's frame once;
    // the sort below orders the pairs the same whichever way they come.
    let mut slot = order.iter_mut();
    for j in 0..nb {
        let cb = b.convex_piece(j).expect("index below piece_count");
        let centre_b = rel * b.piece_centre(j).expect("index below piece_count");
        for i in 0..na {
            let ca = a.convex_piece(i).expect("index below piece_count");
            let centre_a = a.piece_centre(i).expect("index below piece_count");
            let gap = crate::shape::robust_norm(&(centre_b - centre_a))
                - (ca.size() + ca.radius())
                - (cb.size() + cb.radius());
            if let Some(o) = slot.next() {
                *o = (gap, i as u32, j as u32);
            }
        }
    }
    order.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
    // Warm piece pairs first, the nearest one in front: its upper bound then
    // prunes the others from their first iterations.
    if let Some(w) = warm {
        for e in [w.second, w.first] {
            if e.len > 0
                && let Some(pos) = order.iter().position(|&(_, i, j)| [i, j] == e.pieces)
            {
                order[..=pos].rotate_right(1);
            }
        }
    }

    let mut best: Option<Answer> = None;
    let mut lower = f64::INFINITY;
    let mut iterations = 0u32;
    let mut backup_used = false;
    let mut penetration = 0.0f64;
    let mut trouble: Option<Status> = None;
    // Whether a pair stopped on the margin before converging: only then is
    // the union's answer an early exit rather than a converged one.
    let mut early = false;
    // The widest interval a pair run to its end may have before the union's
    // answer is called stuck: the largest `stuck_width` among those pairs,
    // since every one of them may bound the union from below.
    let mut stuck = 0.0f64;
    // The two piece pairs with the smallest upper bounds, for the warm start.
    let mut kept: [(f64, PieceSimplex); 2] = [(f64::INFINITY, PieceSimplex::default()); 2];
    // The best pair's normal in A's body frame, once the best pair is
    // separated: a separating axis that may prove the next pairs farther.
    let mut axis: Option<Vector3<f64>> = None;
    for (k, &(gap, i, j)) in order.iter().enumerate() {
        let cutoff = best.as_ref().map_or(f64::INFINITY, |b| b.upper);
        // The sphere bound is rough (no slack): only skip on a clear margin.
        if gap > cutoff * (1.0 + 1e-9) + f64::MIN_POSITIVE {
            continue;
        }
        let (oa, ca) = a.piece(i as usize).expect("index below piece_count");
        let (offset_b, cb) = b.piece(j as usize).expect("index below piece_count");
        // An identity offset (a convex shape's, or a piece placed at its
        // compound's origin) changes nothing, to the bit: skip its products.
        let ob = if is_identity(&offset_b) {
            *rel
        } else {
            rel * offset_b
        };
        if let Some(n) = &axis
            && axis_gap(ca, &oa, cb, &ob, n) > cutoff * (1.0 + 1e-9)
        {
            continue;
        }
        let piece_rel = if is_identity(&oa) {
            ob
        } else {
            oa.inv_mul(&ob)
        };
        // Each piece's place in the world, for a piece far from its own
        // frame's origin (see `Pair::new`); a convex shape's identity
        // offset places its centroid exactly.
        let world = (
            Place {
                pose: pose_a,
                offset: Some(&oa),
            },
            Place {
                pose: pose_b,
                offset: Some(&offset_b),
            },
        );
        let pair = Pair::new(ca, cb, &piece_rel, world, options.precision);
        let warm_pairs = warm.and_then(|w| w.for_pieces([i, j]));
        let run = pair.solve_retrying::<AVX2>(simplex, options, warm_pairs, cutoff);
        let (pair_lower, pair_upper, pair_distance) = pair.bounds(&run);
        if pair_upper < kept[1].0 {
            let entry = (pair_upper, PieceSimplex::of(simplex, run.sol.mask, [i, j]));
            if pair_upper < kept[0].0 {
                kept = [entry, kept[0]];
            } else {
                kept[1] = entry;
            }
        }
        iterations = iterations.saturating_add(run.iterations);
        backup_used |= run.backup_used;
        lower = lower.min(pair_lower);
        // Separating the union means separating every piece pair: the
        // deepest pair's bound, whichever pair ends up named, bounds the
        // union's depth (a pair whose rounded shells alone overlap counts too).
        let pair_depth = if run.norm == 0.0 {
            run.inner + pair.radii
        } else {
            pair.radii - run.norm
        };
        penetration = penetration.max(pair_depth);
        let status = match run.exit {
            Exit::Pruned => continue,
            Exit::Status(s) => s,
        };
        stuck = stuck.max(pair.stuck_width(options.tolerance));
        early |= status == Status::Farther;
        if matches!(status, Status::IterationCap | Status::ToleranceNotMet)
            && trouble != Some(Status::ToleranceNotMet)
        {
            // ToleranceNotMet outranks IterationCap: it is the worse news.
            trouble = Some(status);
        }
        // Only a pair that becomes the best is turned into an answer.
        let better = best
            .as_ref()
            .is_none_or(|b| (pair_upper, pair_distance) < (b.upper, b.distance));
        if better || status == Status::Closer {
            let answer = pair.answer(
                &run,
                simplex,
                Place {
                    pose: pose_a,
                    offset: Some(&oa),
                },
                [i, j],
            );
            axis = (answer.normal != Vector3::zeros())
                .then(|| pose_a.rotation.inverse_transform_vector(&answer.normal));
            best = Some(answer);
        }
        if status == Status::Closer {
            // The pairs not visited still bound the union's distance from
            // below by their sphere gaps (shaded for round-off).
            let rest = order[k + 1..]
                .iter()
                .map(|o| o.0 - 1e-9 * o.0.abs())
                .fold(f64::INFINITY, f64::min);
            lower = lower.min(rest.max(0.0));
            break;
        }
    }
    let mut out = best.expect("the first pair is never skipped or pruned");
    out.warm_start.second = kept
        .iter()
        .map(|k| k.1)
        .find(|e| e.len > 0 && e.pieces != out.pieces)
        .unwrap_or_default();
    out.lower = lower.min(out.upper);
    out.iterations = iterations;
    out.backup_used = backup_used;
    out.penetration = out.penetration.max(penetration);
    // The margin is decided on the union's bounds, not on one pair's. A
    // union whose pairs all converged says so, as a convex pair that
    // converges before its margin decides does.
    out.status = match options.margin {
        _ if out.status == Status::Closer => Status::Closer,
        Some(m) if early && out.lower > m => Status::Farther,
        _ => match trouble {
            Some(t) => t,
            None if out.status == Status::Farther => Status::Converged,
            None => out.status,
        },
    };
    (out, stuck)
}
