//! Clearance: for each member of the group, the nearest object outside it
//! (or, with the group's own pairs asked for, the nearest object but the
//! member itself and its allowed partners).
//!
//! Branch and bound over the tree (parry's `find_best`: nearer child
//! first), each candidate's lower bound (box, then bounding sphere, then
//! motion bound) against the best certified upper bound so far: a
//! candidate is skipped only when it cannot be nearer than the best.
//!
//! The member's nearest object of its last clearance (for this client) is
//! tried first, so that its bound prunes the search from the start.
//!
//! A candidate answered from an accepted motion bound is approximate: it is
//! kept as the answer only if no other approximate candidate has a lower
//! bound below its own (such ones are run by GJK first), so that the
//! reported interval always reaches down to the nearest distance.

use std::cell::RefCell;

use gjkd_proto::{ItemResult, SceneRow};

use super::broadphase::{node_gap_squared, root_up, sphere_gap, square_up};
use super::motion_bound::{accepted, bounded_result};
use super::pair::{Ask, Ctx};

/// The search's state: the best certified candidate so far (slot and
/// answer) and the candidates answered from accepted motion bounds (slot,
/// lower bound).
struct Search<'c, 'a> {
    ctx: &'c mut Ctx<'a>,
    best: Option<(u32, ItemResult)>,
    approximate: &'c mut Vec<(u32, f64)>,
}

impl Search<'_, '_> {
    /// Keeps `r` (for slot `leaf`) if it is the best so far.
    fn offer(&mut self, leaf: u32, r: ItemResult) {
        if r.error == 0 && self.best.as_ref().is_none_or(|(_, b)| r.upper < b.upper) {
            self.best = Some((leaf, r));
        }
    }

    /// Candidate `leaf` of member `a` against the search's bound
    /// `best_cost`: returns the certified upper bound it brings, if lower.
    fn visit(&mut self, a: u32, leaf: u32, best_cost: f64) -> Option<f64> {
        let ctx = &mut *self.ctx;
        let q = ctx.q;
        let (ea, eb) = (ctx.bp.entry(a), ctx.bp.entry(leaf));
        if let Some((bound, w)) = ctx.widened(a, leaf) {
            if w.lower >= best_cost {
                ctx.counters.bounded += 1;
                return None;
            }
            if !q.exact && accepted(&w, q.accept_absolute, q.accept_relative) {
                let r = bounded_result(bound, &w, ea, eb);
                ctx.counters.bounded += 1;
                self.approximate.push((leaf, r.lower));
                self.offer(leaf, r);
                return (r.upper < best_cost).then_some(r.upper);
            }
        }
        let warm = ctx.warm(a, leaf);
        let r = ctx.run(a, leaf, Ask::Below(best_cost), warm);
        self.offer(leaf, r);
        (r.error == 0 && r.upper < best_cost).then_some(r.upper)
    }

    /// Runs by GJK the approximate candidates whose lower bound is below
    /// the best's, until there is none.
    fn settle_ties(&mut self, a: u32) {
        while let Some((best_slot, best)) = self.best {
            let below = self
                .approximate
                .iter()
                .enumerate()
                .filter(|(_, (leaf, lower))| *leaf != best_slot && *lower < best.lower)
                .min_by(|x, y| x.1.1.total_cmp(&y.1.1))
                .map(|(i, &(leaf, _))| (i, leaf));
            let Some((i, leaf)) = below else {
                break;
            };
            self.approximate.swap_remove(i);
            let warm = self.ctx.warm(a, leaf);
            let r = self.ctx.run(a, leaf, Ask::Below(f64::INFINITY), warm);
            self.offer(leaf, r);
        }
        self.approximate.clear();
    }
}

/// The clearance row of member slot `a` at path step `step`, with
/// `approximate` as scratch; `seed`, the member's nearest object last time
/// (for this client), is tried first so that its bound prunes the rest.
pub(crate) fn clearance_of(
    ctx: &mut Ctx<'_>,
    a: u32,
    step: u32,
    seed: Option<u64>,
    approximate: &mut Vec<(u32, f64)>,
) -> SceneRow {
    let bp = ctx.bp;
    let ea = *bp.entry(a);
    let q = ctx.q;
    let cutoff = if q.cutoff {
        q.margin.next_up()
    } else {
        f64::INFINITY
    };
    approximate.clear();
    let mut search = Search {
        ctx,
        best: None,
        approximate,
    };
    let seed = seed.and_then(|id| bp.slot(id)).filter(|&s| {
        let group = search.ctx.group;
        s != a
            && bp.entry(s).live
            && (q.self_pairs || !group.contains(s))
            && !group.allowed(ea.id, bp.entry(s).id)
    });
    let mut bound = cutoff;
    if let Some(s) = seed {
        search.ctx.counters.candidates += 1;
        if let Some(upper) = search.visit(a, s, cutoff) {
            bound = upper;
        }
    }
    let search = RefCell::new(search);
    // The tree compares squared distances (see node_gap_squared).
    bp.bvh().find_best(
        square_up(bound),
        |node, _| node_gap_squared(&ea.mins, &ea.maxs, node),
        |leaf, best_squared| {
            let best_cost = root_up(best_squared);
            let mut search = search.borrow_mut();
            let eb = bp.entry(leaf);
            let group = search.ctx.group;
            if leaf == a
                || Some(leaf) == seed
                || !eb.live
                || (group.contains(leaf) && !q.self_pairs)
                || group.allowed(ea.id, eb.id)
                || sphere_gap(&ea, eb) >= best_cost
            {
                return None;
            }
            search.ctx.counters.candidates += 1;
            search.visit(a, leaf, best_cost).map(square_up)
        },
    );
    let mut search = search.into_inner();
    search.settle_ties(a);
    let (b, result) = match search.best {
        Some((slot, r)) => (bp.entry(slot).id, r),
        None => (
            0,
            ItemResult {
                distance: f64::INFINITY,
                lower: if q.cutoff { q.margin } else { f64::INFINITY },
                upper: f64::INFINITY,
                ..ItemResult::default()
            },
        ),
    };
    SceneRow {
        a: ea.id,
        b,
        step,
        reserved: 0,
        result,
        gradient: gjkd_proto::Gradient::NONE,
        s_lo: 0.0,
        s_hi: 0.0,
    }
}
