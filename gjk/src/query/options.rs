//! What a query is asked to do: [`Options`] and [`Precision`], and how it
//! ended: [`Status`].

use crate::Error;

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
    /// When the cores intersect, grow the inner polytope behind
    /// [`Answer::penetration`](crate::Answer::penetration) by up to this many
    /// support points (EPA-style, at most 16), for a larger certified lower
    /// bound on the penetration depth; it stops early once the face nearest
    /// the origin is a face of `A - B`. 0, the default, keeps the inner
    /// radius of GJK's final tetrahedron (5.9) and costs nothing. Callers
    /// that keep overlapping pairs' answers across small motions (an
    /// overlap deeper than the motion needs no new query) gain; a single
    /// query pays a few support searches more. Pairs with a cylinder keep
    /// the plain bound.
    pub penetration_expansions: u32,
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
    /// vertex (`docs/speed-accuracy.md` has the figures). Where the f32
    /// scan is used, the support
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
            penetration_expansions: 0,
        }
    }
}

impl Options {
    #[inline]
    pub(super) fn validate(&self) -> Result<(), Error> {
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
