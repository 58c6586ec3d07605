//! Nearest k: the k objects nearest to one object, nearest first.
//!
//! The same branch and bound as clearance, against the k-th best upper
//! bound once k candidates are known. Motion bounds only rule candidates
//! out here: an accepted width never stands for a GJK answer, since an
//! approximate interval could put the k in the wrong order.

use std::cell::RefCell;

use gjkd_proto::{ItemResult, SceneRow};

use super::broadphase::{node_gap, sphere_gap};
use super::pair::{Ask, Ctx, Outcome};
use super::rows::Rows;

/// Writes the rows of the `k` objects nearest to slot `a` at step `step`,
/// using `found` as scratch.
pub(crate) fn nearest_of(
    ctx: &mut Ctx<'_>,
    a: u32,
    k: usize,
    step: u32,
    found: &mut Vec<(u32, ItemResult)>,
    rows: &mut Rows<'_>,
) {
    let bp = ctx.bp;
    let ea = *bp.entry(a);
    let q = ctx.q;
    let cutoff = if q.cutoff {
        q.margin.next_up()
    } else {
        f64::INFINITY
    };
    found.clear();
    let state = RefCell::new((ctx, found));
    bp.bvh().find_best(
        cutoff,
        |node, _| node_gap(&ea.mins, &ea.maxs, node),
        |leaf, kth| {
            let mut guard = state.borrow_mut();
            let (ctx, found) = &mut *guard;
            let eb = bp.entry(leaf);
            if leaf == a
                || !eb.live
                || ctx.group.allowed(ea.id, eb.id)
                || sphere_gap(&ea, eb) >= kth
            {
                return None;
            }
            ctx.counters.candidates += 1;
            let Outcome::Answer(r) = ctx.settle(a, leaf, Ask::BelowExactly(kth)) else {
                return None;
            };
            if r.error != 0 {
                return None;
            }
            let at = found.partition_point(|(_, f)| f.upper <= r.upper);
            if at >= k {
                return None;
            }
            found.insert(at, (leaf, r));
            found.truncate(k);
            let new_kth = if found.len() == k {
                found[k - 1].1.upper
            } else {
                f64::INFINITY
            };
            (new_kth < kth).then_some(new_kth)
        },
    );
    let (_, found) = state.into_inner();
    found.sort_by(|x, y| x.1.distance.total_cmp(&y.1.distance));
    for &(slot, result) in found.iter() {
        rows.push(SceneRow {
            a: ea.id,
            b: bp.entry(slot).id,
            step,
            reserved: 0,
            result,
            gradient: gjkd_proto::Gradient::NONE,
            s_lo: 0.0,
            s_hi: 0.0,
        });
    }
}
