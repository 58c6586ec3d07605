//! Within along a path whose steps move only the group's members:
//! conservative advancement, so that a step costs little more than its
//! pairs' GJK runs.
//!
//! - Each member keeps a list of candidates found by one tree search with
//!   its box grown by a reach: while the member's [`Entry::travel`] since
//!   the search stays within the reach, every point of it stayed within
//!   the grown box, and the other objects do not move, so no object
//!   outside the list can come within the margin. The search is redone
//!   when the member has travelled farther.
//! - Each candidate keeps its pair's motion bound as it held at some step
//!   (the anchor) and the member's travel then: the travel since bounds
//!   how far any point moved, without a pose in sight, and widens the
//!   bound as [`widen_by`]. A pair far from the margin, or overlapping
//!   deeper than the member moved, is so settled in a few operations for
//!   as many steps as its gap allows. When the travel does not settle it,
//!   the pair is asked as [`within_of`](super::within::within_of) would
//!   ([`Ctx::settle_keeping`]: the kept bound widened by the poses
//!   themselves, then GJK), and the anchor moves to this step.
//!
//! Both are upper bounds on motion summed step by step: never tighter
//! than the poses' own bound, which is asked before any GJK run, so the
//! path runs GJK on no more pairs than asking each step alone.

use gjkd_proto::SceneRow;

use super::broadphase::{box_gap_squared, node_gap, sphere_gap, square_up};
use super::entry::{Entry, ROUND_OFF};
use super::motion_bound::{accepted, bounded_result, travelled, widen_by};
use super::pair::{Ask, Ctx, Outcome};
use super::rows::Rows;
use crate::engine::warm_cache::PairBound;

/// One object that may come within the margin of a member, and the
/// pair's anchor: its motion bound at the step it was kept, and the
/// member's travel then.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    slot: u32,
    travel: f64,
    bound: Option<PairBound>,
    /// The pair is beyond the margin while the member's travel since
    /// `quiet_from` is below `quiet` (a certified lower bound on their
    /// distance then, less the margin): it is not looked at.
    quiet: f64,
    quiet_from: f64,
    /// Whether `quiet` is from the pair's motion bound (else its boxes or
    /// spheres).
    quiet_by_bound: bool,
}

/// A member's candidates and how far they hold.
#[derive(Debug, Default)]
pub(crate) struct Lookahead {
    /// Whether `candidates` are from a search of this path.
    searched: bool,
    /// The member's travel at the search.
    travel: f64,
    /// How far the member may travel before the search is redone.
    reach: f64,
    candidates: Vec<Candidate>,
    /// The previous search's candidates, sorted by slot.
    previous: Vec<Candidate>,
}

impl Lookahead {
    /// Forgets the candidates (a new path).
    pub(crate) fn reset(&mut self) {
        self.searched = false;
        self.candidates.clear();
    }

    /// Searches the tree for the objects within `margin` of member `ea`
    /// (slot `a`) grown by its reach, keeping the anchors of those found
    /// again.
    fn search(&mut self, ctx: &Ctx<'_>, a: u32, ea: &Entry, margin: f64) {
        std::mem::swap(&mut self.previous, &mut self.candidates);
        self.previous.sort_unstable_by_key(|c| c.slot);
        self.candidates.clear();
        // The member's extent: farther, its box would be searched anew
        // after every move of its own size, which costs one search.
        self.reach = ea.extent;
        self.travel = ea.travel;
        self.searched = true;
        let limit = (margin + self.reach) * (1.0 + 4.0 * f64::EPSILON);
        let bp = ctx.bp;
        for leaf in bp
            .bvh()
            .leaves(|node| node_gap(&ea.mins, &ea.maxs, node) <= limit)
        {
            let eb = bp.entry(leaf);
            if leaf == a || !eb.live || ctx.group.contains(leaf) || ctx.group.allowed(ea.id, eb.id)
            {
                continue;
            }
            let kept = self.previous.binary_search_by_key(&leaf, |c| c.slot);
            self.candidates.push(match kept {
                Ok(i) => self.previous[i],
                Err(_) => Candidate {
                    slot: leaf,
                    travel: 0.0,
                    bound: None,
                    quiet: 0.0,
                    quiet_from: 0.0,
                    quiet_by_bound: false,
                },
            });
        }
    }
}

/// Writes the rows of member slot `a`'s pairs within the margin at step
/// `step`, the path having made `moves` moves so far; `look` is the
/// member's lookahead. Returns how many it found.
pub(crate) fn within_along(
    ctx: &mut Ctx<'_>,
    look: &mut Lookahead,
    a: u32,
    step: u32,
    moves: u32,
    rows: &mut Rows<'_>,
) -> u64 {
    let bp = ctx.bp;
    let ea = bp.entry(a);
    let m = ctx.q.margin;
    // Searched again past the reach, or if the travel is no number (an
    // overflow), never trusted then.
    let within_reach = travelled(ea.travel, look.travel, moves) <= look.reach;
    if !look.searched || !within_reach {
        look.search(ctx, a, ea, m);
    }
    let mut hits = 0;
    let m2 = square_up(m);
    for candidate in &mut look.candidates {
        if travelled(ea.travel, candidate.quiet_from, moves) < candidate.quiet {
            // Counted as its motion bound's answer, as when it is asked.
            ctx.counters.bounded += u64::from(candidate.quiet_by_bound);
            continue;
        }
        let eb = bp.entry(candidate.slot);
        let gap2 = box_gap_squared(&ea.mins, &ea.maxs, &eb.mins, &eb.maxs);
        let gap = if gap2 > m2 {
            gap2.sqrt() * (1.0 - 4.0 * f64::EPSILON)
        } else {
            sphere_gap(ea, eb)
        };
        if gap > m {
            candidate.quiet_from = ea.travel;
            candidate.quiet = slack(gap, m);
            candidate.quiet_by_bound = false;
            continue;
        }
        ctx.counters.candidates += 1;
        let settled = candidate
            .bound
            .as_ref()
            .and_then(|bound| by_travel(ctx, bound, candidate.travel, ea, eb, moves));
        let result = match settled {
            Some(outcome) => outcome,
            None => {
                candidate.travel = ea.travel;
                let keep = Some(&mut candidate.bound);
                ctx.settle_keeping(a, candidate.slot, Ask::Within(m), keep)
            }
        };
        if let Outcome::Answer(result) = result
            && (result.error != 0 || result.lower <= m)
        {
            hits += 1;
            rows.push(SceneRow {
                a: ea.id,
                b: eb.id,
                step,
                reserved: 0,
                result,
                gradient: gjkd_proto::Gradient::NONE,
                s_lo: 0.0,
                s_hi: 0.0,
            });
        } else if let Some(bound) = &candidate.bound {
            candidate.quiet_from = candidate.travel;
            candidate.quiet = slack(bound.lower, m);
            candidate.quiet_by_bound = true;
        }
    }
    hits
}

/// How far the member may travel while a pair whose certified lower bound
/// was `lower` stays beyond margin `m`, rounded down; 0 if it is not beyond.
fn slack(lower: f64, m: f64) -> f64 {
    if lower > m {
        (lower - m) * (1.0 - ROUND_OFF)
    } else {
        0.0
    }
}

/// The pair's outcome from its anchor (`bound`, kept when the member's
/// travel was `then`) widened by the member's travel since, when that
/// settles it as [`Ctx::settle_keeping`] would.
fn by_travel(
    ctx: &mut Ctx<'_>,
    bound: &PairBound,
    then: f64,
    ea: &Entry,
    eb: &Entry,
    moves: u32,
) -> Option<Outcome> {
    let q = ctx.q;
    let w = widen_by(bound, travelled(ea.travel, then, moves));
    let outcome = if w.lower > q.margin {
        Outcome::Ruled
    } else if !q.exact
        && (w.upper <= q.margin || accepted(&w, q.accept_absolute, q.accept_relative))
    {
        Outcome::Answer(bounded_result(bound, &w, ea, eb))
    } else {
        return None;
    };
    ctx.counters.bounded += 1;
    Some(outcome)
}
