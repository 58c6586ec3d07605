//! The expansion: from GJK's final simplex to a polytope inside `K`
//! whose nearest face is a face of `K` to the tolerance, with the certified
//! interval on the penetration depth of the cores.
//!
//! The depth is `d⁺ = min over unit n of h_K(n)` (the distance from the
//! origin to `K`'s boundary; negative, the distance to `K`, when the origin
//! is outside), so every support value along a unit direction is an upper
//! bound on it, and the polytope's certified inner radius a lower one. The
//! polytope may start with the origin outside it or on its boundary (GJK
//! ended on a point, a segment or a triangle through the origin, or the
//! shapes only touch): its face nearest the origin is then one the origin
//! is outside of or on, the support point along that face's normal is past
//! it whenever the origin is inside `K`, and the expansion moves on.

use nalgebra::Vector3;

use super::frame::{PairFrame, Vertex};
use super::polytope::{Face, Polytope};
use super::ties::tied;
use crate::support_map::SupportMap;

/// What the expansion found, in the frame (scaled).
pub(super) struct DepthFound {
    /// Certified lower bound on the cores' depth (0 when nothing is proved).
    pub(super) lower: f64,
    /// Certified upper bound: the least support value seen, with its
    /// round-off.
    pub(super) upper: f64,
    /// The estimate, between the two.
    pub(super) depth: f64,
    /// The unit direction of the least support value (from A towards B).
    pub(super) normal: Vector3<f64>,
    /// A's point on the nearest face, when a polytope was built: B's is
    /// `depth · normal` behind it.
    pub(super) witness_a: Option<Vector3<f64>>,
    /// Support points added to the polytope.
    pub(super) expansions: u32,
    /// Whether the nearest face met the tolerance.
    pub(super) converged: bool,
    /// Whether another direction, far from `normal`, reaches the least
    /// support value within the interval too (see [`super::ties`]).
    pub(super) tied: bool,
}

/// The least support value seen (as computed, and certified), and along
/// which direction.
struct Upper {
    computed: f64,
    value: f64,
    normal: Vector3<f64>,
}

impl Upper {
    /// The support point along `dir`, its support value (per unit of
    /// `dir`) kept as an upper bound when it is the least; the value is
    /// returned uncertified.
    fn probe<A: SupportMap, B: SupportMap>(
        &mut self,
        frame: &PairFrame<'_, A, B>,
        dir: &Vector3<f64>,
    ) -> Option<(Vertex, f64)> {
        let len = dir.norm();
        if !(len > 0.0 && len.is_finite()) {
            return None;
        }
        let unit = dir / len;
        let w = frame.support(&unit);
        let h = unit.dot(&w.y);
        // The point errs by `delta` at most, the product and the unit
        // vector's length by a few ε of `|w|`.
        let certified = h + frame.delta + 8.0 * f64::EPSILON * w.y.norm();
        if certified < self.value {
            self.computed = h;
            self.value = certified;
            self.normal = unit;
        }
        Some((w, h))
    }
}

/// The expansion of the pair in `frame` from `start` (GJK's final
/// simplex, 0 to 4 points), stopping when the nearest face's support gap
/// is within `tolerance` of the depth, or at `max_points` points.
pub(super) fn expand<A: SupportMap, B: SupportMap>(
    frame: &PairFrame<'_, A, B>,
    start: &[Vertex],
    tolerance: f64,
    max_points: usize,
) -> DepthFound {
    let mut upper = Upper {
        computed: f64::INFINITY,
        value: f64::INFINITY,
        normal: Vector3::zeros(),
    };
    let Some(mut polytope) = initial_tetrahedron(frame, start, &mut upper) else {
        return DepthFound {
            lower: 0.0,
            upper: upper.value,
            depth: upper.computed.max(0.0).min(upper.value),
            normal: upper.normal,
            witness_a: None,
            expansions: 0,
            converged: true,
            // `K` is flat through the origin: its two normals (or, on a
            // segment or a point, every direction across it) tie at 0.
            tied: true,
        };
    };
    // Below this a gap is round-off, whatever the tolerance.
    let floor = 16.0 * frame.delta;
    let mut expansions = 0;
    let mut converged = false;
    let mut last: Option<Face> = None;
    while let Some(face) = polytope.nearest() {
        last = Some(face);
        let Some((w, h)) = upper.probe(frame, &face.normal) else {
            break;
        };
        let gap = h - face.distance;
        if gap <= tolerance * h.abs().max(face.distance.abs()) + floor {
            converged = true;
            break;
        }
        if polytope.points.len() >= max_points || !polytope.add(w, &face) {
            break;
        }
        expansions += 1;
    }
    let lower = polytope.certified_depth(frame.delta);
    let witness_a = last.map(|face| polytope.witness_a(&face));
    // The interval's upper end, with the tolerance's room: a direction
    // whose support value is within it is as good as the one found.
    let bound = upper.value + tolerance * upper.value.abs() + floor;
    let tied = last.is_some_and(|face| tied(frame, &mut polytope, &face, bound, max_points));
    DepthFound {
        lower,
        upper: upper.value,
        // The least support value: exact where the face is one of `K`'s,
        // and where `K` is round it errs by the square of the normal's
        // error, where the face's distance errs by the square of its size.
        depth: upper.computed.max(lower).min(upper.value),
        normal: upper.normal,
        witness_a,
        expansions,
        converged,
        tied,
    }
}

/// A tetrahedron of points of `K` from GJK's simplex, completed by support
/// points along directions out of its affine hull (each probed as an upper
/// bound); `None` when `K` is flat to round-off in some direction, whose
/// support values then bound the depth by that round-off.
fn initial_tetrahedron<A: SupportMap, B: SupportMap>(
    frame: &PairFrame<'_, A, B>,
    start: &[Vertex],
    upper: &mut Upper,
) -> Option<Polytope> {
    let tiny = 16.0 * frame.delta;
    let mut points: Vec<Vertex> = Vec::with_capacity(4);
    for p in start {
        if points.len() < 4 && independent(&points, &p.y) > tiny {
            points.push(*p);
        }
    }
    if points.is_empty() {
        points.push(upper.probe(frame, &Vector3::x())?.0);
    }
    while points.len() < 4 {
        let directions = out_of_hull(&points);
        let mut best: Option<(f64, Vertex)> = None;
        for d in directions.iter().flatten() {
            for dir in [*d, -d] {
                if let Some((w, _)) = upper.probe(frame, &dir) {
                    let away = independent(&points, &w.y);
                    if away > best.map_or(tiny, |b| b.0) {
                        best = Some((away, w));
                    }
                }
            }
        }
        points.push(best?.1);
    }
    Polytope::tetrahedron([points[0], points[1], points[2], points[3]])
}

/// How far `y` is from the affine hull of `points` (1 to 3 of them; from
/// nothing, its norm): the norm of its part out of the hull.
fn independent(points: &[Vertex], y: &Vector3<f64>) -> f64 {
    match points {
        [] => f64::INFINITY,
        [p] => (y - p.y).norm(),
        [p, q] => {
            let e = q.y - p.y;
            let r = y - p.y;
            let len2 = e.norm_squared();
            if len2 > 0.0 {
                (r - e * (r.dot(&e) / len2)).norm()
            } else {
                r.norm()
            }
        }
        [p, q, s] => {
            let n = (q.y - p.y).cross(&(s.y - p.y));
            let len = n.norm();
            if len > 0.0 {
                (n.dot(&(y - p.y)) / len).abs()
            } else {
                0.0
            }
        }
        _ => 0.0,
    }
}

/// Directions out of the affine hull of `points` (1 to 3): the axes from a
/// point, two normals of a segment, the normal of a triangle.
fn out_of_hull(points: &[Vertex]) -> [Option<Vector3<f64>>; 3] {
    match points {
        [_] => [Some(Vector3::x()), Some(Vector3::y()), Some(Vector3::z())],
        [p, q] => {
            let e = q.y - p.y;
            let axis = if e.x.abs() <= e.y.abs() && e.x.abs() <= e.z.abs() {
                Vector3::x()
            } else if e.y.abs() <= e.z.abs() {
                Vector3::y()
            } else {
                Vector3::z()
            };
            let d1 = e.cross(&axis);
            let d2 = e.cross(&d1);
            [Some(d1), Some(d2), None]
        }
        [p, q, s] => [Some((q.y - p.y).cross(&(s.y - p.y))), None, None],
        _ => [None, None, None],
    }
}
