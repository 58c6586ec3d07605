//! Clearance: for each member of the group, the nearest object outside it.
//!
//! Branch and bound over the tree (parry's `find_best`: nearer child
//! first), each candidate's lower bound (box, then bounding sphere, then
//! motion bound) against the best certified upper bound so far: a
//! candidate is skipped only when it cannot be nearer than the best.

use std::cell::RefCell;

use gjkd_proto::{ItemResult, SceneRow};

use super::broadphase::{node_gap, sphere_gap};
use super::pair::{Ask, Ctx, Outcome};

/// The best candidate so far: its slot and answer.
type Best = Option<(u32, ItemResult)>;

/// The clearance row of member slot `a` at path step `step`.
pub(crate) fn clearance_of(ctx: &mut Ctx<'_>, a: u32, step: u32) -> SceneRow {
    let bp = ctx.bp;
    let ea = *bp.entry(a);
    let q = ctx.q;
    let cutoff = if q.cutoff {
        q.margin.next_up()
    } else {
        f64::INFINITY
    };
    let state: RefCell<(&mut Ctx<'_>, Best)> = RefCell::new((ctx, None));
    bp.bvh().find_best(
        cutoff,
        |node, _| node_gap(&ea.mins, &ea.maxs, node),
        |leaf, best_cost| {
            let mut guard = state.borrow_mut();
            let (ctx, best) = &mut *guard;
            let eb = bp.entry(leaf);
            if leaf == a
                || !eb.live
                || ctx.group.contains(leaf)
                || ctx.group.allowed(ea.id, eb.id)
                || sphere_gap(&ea, eb) >= best_cost
            {
                return None;
            }
            ctx.counters.candidates += 1;
            let Outcome::Answer(r) = ctx.settle(a, leaf, Ask::Below(best_cost)) else {
                return None;
            };
            if r.error != 0 {
                return None;
            }
            if best.as_ref().is_none_or(|(_, b)| r.upper < b.upper) {
                *best = Some((leaf, r));
            }
            (r.upper < best_cost).then_some(r.upper)
        },
    );
    let (_, best) = state.into_inner();
    let (b, result) = match best {
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
    }
}
