//! Continuous paths ([`PathMode::Continuous`](gjkd_proto::PathMode::Continuous)):
//! is the whole motion between consecutive waypoints clear, and if not,
//! where does it first come within the margin?
//!
//! Per segment, the candidate pairs are those the sampled path would ask
//! (the group against the rest, its members against each other too with
//! the group's own pairs, or all pairs; allowed pairs left out)
//! with at least one object the path moves, found once for the whole
//! segment: the broadphase searched with each mover's bounding sphere at
//! `s = 0` grown by how far it can move along the segment. Each pair is
//! then searched from `s = 0` ([`search`]), nearest to contact first; a
//! contact found becomes the horizon of the pairs after it, which need
//! only be cleared up to it.

mod motion;
mod probe;
mod search;
#[cfg(test)]
mod tests;
mod waypoints;

use gjkd_proto::{ErrorCode, SceneRow};
use nalgebra::{Isometry3, Point3};

use super::broadphase::node_gap;
use super::entry::ROUND_OFF;
use super::rows::Rows;
use super::{Counters, Question};
use crate::engine::state::State;
use motion::{Mover, Segment};
use probe::probe_points;
use search::{Hit, Pair, Search, Side};
pub(crate) use waypoints::Waypoints;

impl State {
    /// Reads a continuous path's waypoints, storing nothing.
    ///
    /// # Errors
    /// As [`waypoints::plan`].
    pub(super) fn plan_continuous(
        &mut self,
        q: &Question,
        items: &[gjkd_proto::Item],
    ) -> Result<Waypoints, ErrorCode> {
        waypoints::plan(
            &self.store,
            &self.robots,
            &self.groups.broadphase,
            &mut self.groups.overlay,
            items,
            q.clamp,
        )
    }

    /// Answers every segment of `w`: a row for each segment with a
    /// contact. Returns the segments answered and the first with a contact.
    ///
    /// # Errors
    /// As [`Segment::new`].
    // Never inlined: profiles (callgrind's `--toggle-collect`) count the
    // continuous check's work under its name.
    #[inline(never)]
    pub(super) fn answer_continuous(
        &mut self,
        q: &Question,
        w: &Waypoints,
        rows: &mut Rows<'_>,
        counters: &mut Counters,
    ) -> Result<(u32, u32), ErrorCode> {
        let mut first_hit = u32::MAX;
        let segments = w.count - 1;
        for k in 0..segments {
            let bp = &self.groups.broadphase;
            let mut segment =
                Segment::new(&self.store, &self.robots, bp, w, k, q.linear_quaternion)?;
            let starts = (0..segment.movers.len())
                .map(|i| segment.pose(i, 0.0))
                .collect::<Result<Vec<_>, _>>()?;
            let probes = probe_count(bp, &segment.movers);
            let found_pairs = self.continuous_pairs(q, &segment, &starts);
            counters.candidates += found_pairs.len() as u64;
            // Nearest to contact first: its contact shortens the horizon
            // of every later pair. The pairs are large (warm starts), so
            // their keys are sorted, and pairs the spheres clear for the
            // whole segment are left out first.
            let mut order: Vec<(f64, usize)> = found_pairs
                .iter()
                .enumerate()
                .filter(|(_, p)| p.sphere_gap - p.slack - q.margin <= p.rate)
                .map(|(i, p)| ((p.sphere_gap - q.margin) / p.rate, i))
                .collect();
            counters.bounded += (found_pairs.len() - order.len()) as u64;
            order.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            let mut pairs: Vec<Pair> = order.iter().map(|&(_, i)| found_pairs[i]).collect();
            let mut options = q.options;
            options.margin = None;
            options.warm_start = true;
            let mut search = Search {
                segment: &mut segment,
                workspace: &mut self.workspace,
                options,
                margin: q.margin,
                bracket: q.bracket,
                runs: 0,
                horizon: 1.0,
            };
            let mut horizon = 1.0;
            let mut found: Option<(u32, u32, Hit)> = None;
            let any = q.bracket >= 1.0;
            if let Some(p) = search.probe(&mut pairs, &probe_points(probes, any)) {
                let slots = pairs[p.pair].slots;
                // `[0, s]` is a bracket when the caller allows its width:
                // nothing before 0 needs clearing.
                let lo = if p.s <= q.bracket { 0.0 } else { p.s };
                found = Some((
                    slots.0,
                    slots.1,
                    Hit {
                        lo,
                        hi: p.s,
                        result: p.result,
                    },
                ));
                horizon = if lo == 0.0 { 0.0 } else { p.s };
            }
            for pair in &mut pairs {
                if horizon == 0.0 {
                    break;
                }
                // Beyond the margin up to the horizon by the spheres alone.
                if pair.sphere_gap - pair.slack - q.margin > pair.rate * horizon {
                    counters.bounded += 1;
                    continue;
                }
                if let Some(hit) = search.first_contact(pair, horizon) {
                    let lo = found.map_or(hit.lo, |(_, _, f)| f.lo.min(hit.lo));
                    // As for a probe: `[0, hi]` when it is narrow enough.
                    let lo = if hit.hi <= q.bracket { 0.0 } else { lo };
                    horizon = if lo == 0.0 { 0.0 } else { hit.hi };
                    found = Some((pair.slots.0, pair.slots.1, Hit { lo, ..hit }));
                }
            }
            counters.gjk_runs += search.runs;
            if let Some((a, b, hit)) = found {
                rows.push(SceneRow {
                    a: bp.entry(a).id,
                    b: bp.entry(b).id,
                    step: k as u32,
                    reserved: 0,
                    result: hit.result,
                    gradient: gjkd_proto::Gradient::NONE,
                    s_lo: hit.lo,
                    s_hi: hit.hi,
                });
                first_hit = first_hit.min(k as u32);
            }
        }
        Ok((segments as u32, first_hit))
    }

    /// The pairs of segment `segment` that the question asks, the group's
    /// object first; `starts` are its movers' poses at `s = 0`.
    fn continuous_pairs(
        &self,
        q: &Question,
        segment: &Segment<'_>,
        starts: &[Isometry3<f64>],
    ) -> Vec<Pair> {
        let bp = &self.groups.broadphase;
        let group = &self.groups.group;
        let movers = &segment.movers;
        let mover_of = |slot: u32| movers.iter().position(|m| m.slot == slot);
        // Whether the question asks the pair, and in which order.
        let asks = |a: u32, b: u32| -> Option<(u32, u32)> {
            let (ea, eb) = (bp.entry(a), bp.entry(b));
            if a == b || !ea.live || !eb.live || group.allowed(ea.id, eb.id) {
                return None;
            }
            match (group.contains(a), group.contains(b)) {
                _ if q.all_pairs => Some((a, b)),
                (true, true) if q.self_pairs => Some((a, b)),
                (true, false) => Some((a, b)),
                (false, true) => Some((b, a)),
                _ => None,
            }
        };
        // Each mover's sphere at `s = 0`: centre, radius, rate, slack.
        let spheres: Vec<(Point3<f64>, f64)> = movers
            .iter()
            .zip(starts)
            .map(|(m, pose)| {
                let e = bp.entry(m.slot);
                (pose * e.centre, e.extent)
            })
            .collect();
        let mut pairs = Vec::new();
        let make = |(a, b): (u32, u32)| {
            let ball = |slot: u32| {
                let e = bp.entry(slot);
                (e.centre, e.extent)
            };
            let side = |slot: u32| match mover_of(slot) {
                Some(i) => (Side::Moving(i), spheres[i], movers[i]),
                None => {
                    let e = bp.entry(slot);
                    let still = Mover::still(
                        slot,
                        ROUND_OFF * (e.pose.translation.vector.abs().sum() + e.reach)
                            + f64::MIN_POSITIVE,
                    );
                    (Side::Still(e.pose), (e.world_centre, e.extent), still)
                }
            };
            let (sa, (ca, ra), ma) = side(a);
            let (sb, (cb, rb), mb) = side(b);
            let gap = ((ca - cb).norm() - ra - rb) * (1.0 - 4.0 * ROUND_OFF);
            let bounds = (
                (ma.rate + mb.rate) * (1.0 + ROUND_OFF),
                mb.drift - ma.drift,
                ma.spin + mb.spin,
            );
            Pair::new(
                (a, b),
                (sa, sb),
                bounds,
                ma.slack + mb.slack,
                gap,
                [ball(a), ball(b)],
            )
        };
        for (i, m) in movers.iter().enumerate() {
            // Pairs of two movers, once, if either moves.
            for other in &movers[i + 1..] {
                if (m.rate > 0.0 || other.rate > 0.0)
                    && let Some(ab) = asks(m.slot, other.slot)
                {
                    pairs.push(make(ab));
                }
            }
            if m.rate == 0.0 {
                continue;
            }
            // Objects that stay, within reach of the mover's sweep.
            let (centre, radius) = spheres[i];
            let grow = (radius + m.rate + m.slack) * (1.0 + 4.0 * ROUND_OFF);
            let mins = [centre.x - grow, centre.y - grow, centre.z - grow];
            let maxs = [centre.x + grow, centre.y + grow, centre.z + grow];
            let limit = q.margin * (1.0 + 4.0 * f64::EPSILON);
            for leaf in bp
                .bvh()
                .leaves(|node| node_gap(&mins, &maxs, node) <= limit)
            {
                if mover_of(leaf).is_none()
                    && let Some(ab) = asks(m.slot, leaf)
                {
                    pairs.push(make(ab));
                }
            }
        }
        pairs
    }
}

/// Most probes a segment takes: too many and a clear segment pays for
/// them, too few and a short contact slips between them.
const MOST_PROBES: f64 = 16.0;

/// How many probes a segment takes: enough that no mover's point moves
/// much more than its object's diameter between two.
fn probe_count(bp: &super::broadphase::Broadphase, movers: &[Mover]) -> u32 {
    let moving = movers.iter().filter(|m| m.rate > 0.0);
    let fastest = moving.clone().map(|m| m.rate).fold(0.0, f64::max);
    let smallest = moving
        .map(|m| bp.entry(m.slot).extent)
        .fold(f64::INFINITY, f64::min);
    let count = (fastest / (2.0 * smallest)).ceil();
    if count.is_nan() {
        1
    } else {
        count.clamp(1.0, MOST_PROBES) as u32
    }
}
