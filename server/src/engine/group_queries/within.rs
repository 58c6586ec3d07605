//! Within: every pair, group against the rest (and, when asked, its
//! members against each other) or all against all, whose
//! distance is at most the margin. Candidates are the tree's leaves whose
//! box is within the margin of the object's; a pair is left out only when
//! its lower bound (box, sphere, motion bound or GJK's) exceeds the margin.

use gjkd_proto::SceneRow;

use super::broadphase::{node_gap, sphere_gap};
use super::pair::{Ask, Ctx, Outcome};
use super::rows::Rows;

/// Which objects a slot is paired with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Partners {
    /// Every later slot (all against all, each pair once).
    All,
    /// The objects outside the group.
    Rest,
    /// The group's members with a later slot (each pair once): the
    /// group's own pairs, a robot's self-collisions.
    Members,
}

/// Writes the rows of slot `a`'s pairs with its `partners` within the
/// margin at step `step`; allowed pairs are never reported. Returns how
/// many it found.
pub(crate) fn within_of(
    ctx: &mut Ctx<'_>,
    a: u32,
    partners: Partners,
    step: u32,
    rows: &mut Rows<'_>,
) -> u64 {
    let bp = ctx.bp;
    let ea = *bp.entry(a);
    let m = ctx.q.margin;
    let mut hits = 0;
    for leaf in bp
        .bvh()
        .leaves(|node| node_gap(&ea.mins, &ea.maxs, node) <= m)
    {
        let eb = bp.entry(leaf);
        let skip = match partners {
            Partners::All => leaf <= a,
            Partners::Rest => leaf == a || ctx.group.contains(leaf),
            Partners::Members => leaf <= a || !ctx.group.contains(leaf),
        };
        if skip || !eb.live || ctx.group.allowed(ea.id, eb.id) || sphere_gap(&ea, eb) > m {
            continue;
        }
        ctx.counters.candidates += 1;
        if let Outcome::Answer(result) = ctx.settle(a, leaf, Ask::Within(m))
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
        }
    }
    hits
}
