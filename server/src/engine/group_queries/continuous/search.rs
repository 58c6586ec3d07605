//! One pair's first contact along a segment: conservative advancement
//! (Schwarzer, Saha and Latombe) with certified bisection.
//!
//! A pose whose certified lower bound `l` exceeds the margin `m` clears
//! the poses within `(l - m) / rate` of it in `s`, `rate` the pair's
//! motion bound (or, where it proves more, its separation along the
//! normal against the motion along the normal); two such poses clear everything between them when their
//! two clearances together cover the gap. The search advances from `s = 0`
//! by those steps, probing ahead (where the distance's trend puts the
//! contact) and bisecting what the probe leaves unproved, until the
//! horizon is cleared or a pose within the margin brackets the first
//! contact to the caller's width. Every GJK run starts from the pair's
//! previous simplex.

use gjk::WarmStart;
use gjkd_proto::{ErrorCode, ItemResult};
use nalgebra::{Isometry3, Point3, Vector3};

use super::motion::Segment;
use crate::engine::pair_query::run_pair;

/// Deepest bisection: far below any `s` resolution a caller can ask.
const MAX_DEPTH: u32 = 200;

/// One side of a pair: a mover of the segment, or an object that stays.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Side {
    /// Mover `i` of the segment.
    Moving(usize),
    /// An object at this pose all along.
    Still(Isometry3<f64>),
}

/// A pair to search, its bounds, and its warm start.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Pair {
    /// Its slots, `a` the group's side.
    pub slots: (u32, u32),
    /// How each side moves.
    pub sides: (Side, Side),
    /// Bound on how fast the pair's distance changes with `s`.
    pub rate: f64,
    /// B's translation less A's, over the segment (rigid sides only).
    pub drift: Vector3<f64>,
    /// The speed of both sides in no known direction.
    pub spin: f64,
    /// Widening of every computed interval for the poses' round-off.
    pub slack: f64,
    /// Lower bound on the distance at `s = 0` from bounding spheres.
    pub sphere_gap: f64,
    /// Each side's bounding sphere: its centre in the side's body frame and
    /// its radius.
    pub balls: [(Point3<f64>, f64); 2],
    warm: Option<WarmStart>,
}

impl Pair {
    /// A pair with no warm start yet.
    pub(crate) fn new(
        slots: (u32, u32),
        sides: (Side, Side),
        (rate, drift, spin): (f64, Vector3<f64>, f64),
        slack: f64,
        sphere_gap: f64,
        balls: [(Point3<f64>, f64); 2],
    ) -> Self {
        Pair {
            slots,
            sides,
            rate,
            drift,
            spin,
            slack,
            sphere_gap,
            balls,
            warm: None,
        }
    }

    /// Bound on how fast the separation along unit `n` shrinks with `s`.
    fn rate_along(&self, n: &Vector3<f64>) -> f64 {
        ((self.drift.dot(n)).abs() + self.spin) * (1.0 + 1e-12) + f64::MIN_POSITIVE
    }
}

/// A first contact: everything before `lo` is clear, the pose at `hi` is
/// within the margin (`result`, its interval widened by the slack).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Hit {
    /// Start of the bracket.
    pub lo: f64,
    /// End of the bracket.
    pub hi: f64,
    /// The pair's answer at `hi`.
    pub result: ItemResult,
}

/// The answer at one `s`: its margin left (`lower - slack - m`, a hit when
/// `<= 0`), how far in `s` either side of it is certified clear, and the
/// row it would make.
#[derive(Clone, Copy, Debug)]
pub(super) struct Eval {
    /// The margin left: a hit when `<= 0`.
    pub gap: f64,
    reach: f64,
    /// The row it would make.
    pub result: ItemResult,
}

/// What one search works with.
pub(crate) struct Search<'s, 'a> {
    /// The segment's motions.
    pub segment: &'s mut Segment<'a>,
    /// gjk's scratch memory.
    pub workspace: &'s mut gjk::Workspace,
    /// Every pair query's options (no margin: the largest certified lower
    /// bound is what advances).
    pub options: gjk::Options,
    /// The margin.
    pub margin: f64,
    /// The widest bracket.
    pub bracket: f64,
    /// GJK runs so far.
    pub runs: u64,
    /// The current pair's horizon: no contact beyond it is asked.
    pub horizon: f64,
}

impl Search<'_, '_> {
    pub(super) fn side_pose(&mut self, side: Side, s: f64) -> Result<Isometry3<f64>, ErrorCode> {
        match side {
            Side::Moving(i) => self.segment.pose(i, s),
            Side::Still(pose) => Ok(pose),
        }
    }

    pub(super) fn eval(&mut self, pair: &mut Pair, s: f64) -> Eval {
        match self.try_eval(pair, s) {
            Ok(e) => e,
            Err(code) => Eval {
                gap: f64::NEG_INFINITY,
                reach: 0.0,
                result: ItemResult::error(code),
            },
        }
    }

    fn try_eval(&mut self, pair: &mut Pair, s: f64) -> Result<Eval, ErrorCode> {
        let pa = self.side_pose(pair.sides.0, s)?;
        let pb = self.side_pose(pair.sides.1, s)?;
        let a = self
            .segment
            .shape(pair.slots.0)
            .ok_or(ErrorCode::UnknownObject)?;
        let b = self
            .segment
            .shape(pair.slots.1)
            .ok_or(ErrorCode::UnknownObject)?;
        self.runs += 1;
        let (mut result, next) = run_pair(
            self.workspace,
            (a, &pa),
            (b, &pb),
            &self.options,
            pair.warm.as_ref(),
        )?;
        pair.warm = Some(next);
        let lower = result.lower - pair.slack;
        result.lower = lower.max(0.0);
        result.upper += pair.slack;
        result.distance = result.distance.clamp(result.lower, result.upper);
        // A NaN (never expected) reads as a possible contact.
        let gap = lower - self.margin;
        let gap = if gap.is_nan() { f64::NEG_INFINITY } else { gap };
        let mut reach = if gap > 0.0 { gap / pair.rate } else { 0.0 };
        if gap > 0.0 {
            // The separation along the normal, against the motion along it.
            let n: Vector3<f64> = result.normal.into();
            let along = gjk::separation_bound(a, &pa, b, &pb, &n) - pair.slack - self.margin;
            if along > 0.0 {
                reach = reach.max(along / pair.rate_along(&n));
            }
        }
        Ok(Eval { gap, reach, result })
    }

    /// The pair's first contact in `[0, horizon]`, or `None` when that is
    /// certified clear.
    pub(crate) fn first_contact(&mut self, pair: &mut Pair, horizon: f64) -> Option<Hit> {
        self.horizon = horizon;
        let mut ex = self.eval(pair, 0.0);
        if ex.gap <= 0.0 {
            return Some(Hit {
                lo: 0.0,
                hi: 0.0,
                result: ex.result,
            });
        }
        let mut x = 0.0;
        let mut trend: Option<(f64, f64)> = None;
        loop {
            let step = ex.reach;
            if x + step >= horizon {
                return None;
            }
            // Probe where the distance's trend meets the margin, at least
            // two steps on: a hit there brackets the contact at once.
            let mut y = x + 2.0 * step;
            if let Some((sp, gp)) = trend
                && gp > ex.gap
            {
                let closing = (gp - ex.gap) / (x - sp);
                y = y.max(x + 1.25 * ex.gap / closing);
            }
            let y = y.min(horizon);
            let ey = self.eval(pair, y);
            if let Some(hit) = self.between(pair, x, ex, y, ey, 0) {
                return Some(hit);
            }
            trend = Some((x, ex.gap));
            (x, ex) = (y, ey);
        }
    }

    /// The first contact in `[x, y]`, `x` clear (`ex.gap > 0`), or `None`
    /// when `[x, y]` is certified clear.
    fn between(
        &mut self,
        pair: &mut Pair,
        x: f64,
        ex: Eval,
        y: f64,
        ey: Eval,
        depth: u32,
    ) -> Option<Hit> {
        // Clear up to `a` by `x`'s bound, from `b` by `y`'s.
        let a = x + ex.reach;
        let (from, to) = if ey.gap <= 0.0 {
            if y - a <= self.bracket {
                let lo = a.min(y);
                // A pose within the margin only by the interval's round-off
                // (a crossing of the margin, where the distance is the
                // margin itself): the bracket's far end, further into the
                // contact, is within it beyond doubt more often.
                let z = lo + self.bracket;
                if ey.result.upper > self.margin && z > y && z <= self.horizon {
                    let ez = self.eval(pair, z);
                    if ez.gap <= 0.0 && ez.result.upper <= self.margin {
                        return Some(Hit {
                            lo,
                            hi: z,
                            result: ez.result,
                        });
                    }
                }
                return Some(Hit {
                    lo,
                    hi: y,
                    result: ey.result,
                });
            }
            (a, y)
        } else {
            let b = y - ey.reach;
            if a >= b {
                return None;
            }
            (a, b)
        };
        let mid = from + 0.5 * (to - from);
        if !(x < mid && mid < y) || depth >= MAX_DEPTH {
            // Nothing left to split: a contact too grazing to decide, kept
            // as a contact rather than certified clear.
            return Some(Hit {
                lo: a.min(y),
                hi: y,
                result: ey.result,
            });
        }
        let em = self.eval(pair, mid);
        if let Some(hit) = self.between(pair, x, ex, mid, em, depth + 1) {
            return Some(hit);
        }
        self.between(pair, mid, em, y, ey, depth + 1)
    }
}
