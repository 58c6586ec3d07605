//! Probes along a segment before its certified search: the poses at a few
//! `s`, and at each every candidate pair whose bounding spheres come
//! within the margin there, evaluated. A pose found within the margin
//! settles the question at once when the caller's bracket allows `[0, s]`
//! (a caller who asks only whether the motion is clear), and otherwise
//! becomes every pair's horizon, so that no pair needs clearing beyond it.
//! Probes certify nothing: every pair is still searched up to the horizon.

use gjkd_proto::ItemResult;

use super::super::entry::ROUND_OFF;
use super::search::{Pair, Search};

/// A pose the probes found within the margin.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Probed {
    /// The pair's index in the probed slice.
    pub pair: usize,
    /// Where.
    pub s: f64,
    /// The pair's answer there.
    pub result: ItemResult,
}

/// The `s` of `count` probes or a few more (a power of two): the end first,
/// then halving the gaps (the order of OMPL's discrete motion check, which
/// meets a long contact soonest) when `any` (any contact will do), or in
/// increasing `s` (the earliest contact probed is the first found).
pub(crate) fn probe_points(count: u32, any: bool) -> Vec<f64> {
    let n = count.max(1).next_power_of_two();
    if !any {
        return (1..=n).map(|k| f64::from(k) / f64::from(n)).collect();
    }
    let mut points = vec![1.0];
    let mut level = 2;
    while level <= n {
        points.extend(
            (1..level)
                .step_by(2)
                .map(|k| f64::from(k) / f64::from(level)),
        );
        level *= 2;
    }
    points
}

impl Search<'_, '_> {
    /// The first pose within the margin among `points`, each pose's pairs
    /// in order.
    pub(crate) fn probe(&mut self, pairs: &mut [Pair], points: &[f64]) -> Option<Probed> {
        for &s in points {
            if self.segment.prepare(s).is_err() {
                continue;
            }
            for (i, pair) in pairs.iter_mut().enumerate() {
                let (Ok(pa), Ok(pb)) = (
                    self.side_pose(pair.sides.0, s),
                    self.side_pose(pair.sides.1, s),
                ) else {
                    continue;
                };
                let [(ca, ra), (cb, rb)] = pair.balls;
                let gap = ((pa * ca - pb * cb).norm() - ra - rb) * (1.0 - 4.0 * ROUND_OFF);
                if gap - pair.slack > self.margin {
                    continue;
                }
                let e = self.eval(pair, s);
                if e.gap <= 0.0 {
                    return Some(Probed {
                        pair: i,
                        s,
                        result: e.result,
                    });
                }
            }
        }
        None
    }
}
