//! Judging one gjk answer against the brute-force [`reference`](mod@crate::reference):
//! the shapes' pieces in world coordinates, the reference distance of a posed
//! pair of shapes, and everything a property test asserts about an answer.

use gjk::{Convex, Shape};
use nalgebra::Isometry3;

use crate::reference::{
    P, V, extent, hull_distance, penetration_depth, point_to_hull, point_to_rounded,
    rounded_distance,
};

/// A convex piece in world coordinates: posed vertices and radius.
#[derive(Clone, Debug)]
pub struct WorldPiece {
    /// The posed vertices.
    pub points: Vec<P>,
    /// The rounding radius.
    pub radius: f64,
}

/// A convex shape's vertices at `pose`, with its radius.
pub fn world_convex(c: &Convex, pose: &Isometry3<f64>) -> WorldPiece {
    WorldPiece {
        points: c.vertices().iter().map(|v| pose * v).collect(),
        radius: c.radius(),
    }
}

/// The pieces of a shape in world coordinates.
pub fn world_pieces(s: &Shape, pose: &Isometry3<f64>) -> Vec<WorldPiece> {
    match s {
        Shape::Convex(c) => vec![world_convex(c, pose)],
        Shape::Compound(c) => c
            .pieces()
            .iter()
            .map(|(offset, piece)| world_convex(piece, &(pose * offset)))
            .collect(),
    }
}

/// Reference distance between two posed shapes: min over piece pairs (2.3),
/// (2.8), and the piece pair(s) that realise it (the per-pair distances).
pub fn shape_distance(a: &Shape, pa: &Isometry3<f64>, b: &Shape, pb: &Isometry3<f64>) -> RefShape {
    let wa = world_pieces(a, pa);
    let wb = world_pieces(b, pb);
    let mut per_pair = Vec::new();
    let mut best = f64::INFINITY;
    for (i, x) in wa.iter().enumerate() {
        for (j, y) in wb.iter().enumerate() {
            let d = rounded_distance(&x.points, x.radius, &y.points, y.radius);
            per_pair.push(([i as u32, j as u32], d));
            best = best.min(d);
        }
    }
    let all: Vec<&[P]> = wa
        .iter()
        .chain(wb.iter())
        .map(|w| w.points.as_slice())
        .collect();
    let radii = wa
        .iter()
        .chain(wb.iter())
        .map(|w| w.radius)
        .fold(0.0, f64::max);
    // The world points are sums of a translation and a rotated body point:
    // their round-off follows those terms' sizes, which can exceed the sums'
    // (a pose that brings a body point far from its origin near the world
    // origin), so the scale covers them too.
    let terms = |s: &Shape, pose: &Isometry3<f64>| {
        let body = world_pieces(s, &Isometry3::identity());
        let body: Vec<&[P]> = body.iter().map(|w| w.points.as_slice()).collect();
        pose.translation.vector.amax() + extent(&body)
    };
    let scale = extent(&all).max(terms(a, pa)).max(terms(b, pb)) + radii;
    RefShape {
        distance: best,
        per_pair,
        pieces_a: wa,
        pieces_b: wb,
        scale,
    }
}

/// The reference answer for a posed pair of shapes.
#[derive(Clone, Debug)]
pub struct RefShape {
    /// The distance between the shapes: the least over their piece pairs.
    pub distance: f64,
    /// Each piece pair's distance, by piece indices `[in a, in b]`.
    pub per_pair: Vec<([u32; 2], f64)>,
    /// The pieces of the first shape, posed.
    pub pieces_a: Vec<WorldPiece>,
    /// The pieces of the second shape, posed.
    pub pieces_b: Vec<WorldPiece>,
    /// Largest world coordinate magnitude plus the largest radius.
    pub scale: f64,
}

impl RefShape {
    /// Distance from a world point to the union of the first shape's
    /// rounded pieces.
    pub fn to_a(&self, x: &P) -> f64 {
        self.pieces_a
            .iter()
            .map(|w| point_to_rounded(x, &w.points, w.radius))
            .fold(f64::INFINITY, f64::min)
    }

    /// Distance from a world point to the union of the second shape's
    /// rounded pieces.
    pub fn to_b(&self, x: &P) -> f64 {
        self.pieces_b
            .iter()
            .map(|w| point_to_rounded(x, &w.points, w.radius))
            .fold(f64::INFINITY, f64::min)
    }
}

/// Absolute tolerances of a check: on the distance, and on the bounds
/// (round-off of the brute force itself).
#[derive(Clone, Copy, Debug)]
pub struct Tolerance {
    /// On the distance, the nearest points and the surface relations.
    pub distance: f64,
    /// On the certified bounds' holding the reference.
    pub bounds: f64,
}

/// Everything a property test asserts about one answer, against the brute
/// force. `tol` is absolute (callers scale it by the size of the scene).
/// Returns a description of the first violated property.
pub fn verify(
    a: &Shape,
    pa: &Isometry3<f64>,
    b: &Shape,
    pb: &Isometry3<f64>,
    ans: &gjk::Answer,
    reference: &RefShape,
    tolerance: Tolerance,
) -> Result<(), String> {
    let Tolerance {
        distance: tol,
        bounds: bound_eps,
    } = tolerance;
    let truth = reference.distance;
    let ctx = || format!("truth {truth}\nanswer {ans:?}\nA = {a:?} at {pa:?}\nB = {b:?} at {pb:?}");
    if !(ans.lower <= truth + bound_eps && truth <= ans.upper + bound_eps) {
        return Err(format!(
            "bounds [{}, {}] miss the truth\n{}",
            ans.lower,
            ans.upper,
            ctx()
        ));
    }
    if !(ans.lower <= ans.distance && ans.distance <= ans.upper) {
        return Err(format!("distance outside its own bounds\n{}", ctx()));
    }
    // Round-off may stop the Backup Procedure short of ε·D (a thin simplex
    // at contact): then the status must say so, and the certified interval
    // must still be within the accuracy asked of a converged answer.
    let round_off_floor = ans.status == gjk::Status::ToleranceNotMet
        && ans.backup_used
        && ans.upper - ans.lower <= tol;
    if ans.status != gjk::Status::Converged && !round_off_floor {
        return Err(format!("status {:?}\n{}", ans.status, ctx()));
    }
    if (ans.distance - truth).abs() > tol {
        return Err(format!(
            "distance error {:e} > tol {tol:e}\n{}",
            ans.distance - truth,
            ctx()
        ));
    }
    // The pieces named realise the distance.
    let named = reference
        .per_pair
        .iter()
        .find(|(pp, _)| *pp == ans.pieces)
        .map(|(_, d)| *d);
    match named {
        Some(d) if (d - truth).abs() <= tol => {}
        _ => {
            return Err(format!(
                "pieces {:?} do not realise the distance ({named:?})\n{}",
                ans.pieces,
                ctx()
            ));
        }
    }
    let (ia, ib) = (ans.pieces[0] as usize, ans.pieces[1] as usize);
    let (wa, wb) = (&reference.pieces_a[ia], &reference.pieces_b[ib]);
    // Nearest points lie on (or, when overlapping, in) their rounded pieces.
    let da = point_to_rounded(&ans.point_a, &wa.points, wa.radius);
    let db = point_to_rounded(&ans.point_b, &wb.points, wb.radius);
    if da > tol || db > tol {
        return Err(format!("point off its shape: {da:e}, {db:e}\n{}", ctx()));
    }
    let separated = ans.normal != V::zeros();
    let core = hull_distance(&wa.points, &wb.points);
    // The surface checks need a well-conditioned normal: cores apart by more
    // than round-off amplified by the scene size.
    if separated && core.distance > 1e-8 * reference.scale {
        if (ans.normal.norm() - 1.0).abs() > 1e-12 {
            return Err(format!("normal not unit\n{}", ctx()));
        }
        // On the surface: at distance r from the core.
        let ca = point_to_hull(&ans.point_a, &wa.points);
        let cb = point_to_hull(&ans.point_b, &wb.points);
        if (ca - wa.radius).abs() > tol || (cb - wb.radius).abs() > tol {
            return Err(format!(
                "point not on the surface: {ca} vs r {}, {cb} vs r {}\n{}",
                wa.radius,
                wb.radius,
                ctx()
            ));
        }
        if ans.distance > 0.0 {
            let err = (ans.point_b - ans.point_a - ans.normal * ans.distance).norm();
            if err > tol {
                return Err(format!(
                    "point_b - point_a != distance·normal by {err:e}\n{}",
                    ctx()
                ));
            }
        } else if reference.per_pair.len() == 1 {
            // Shells overlap: b - a = -penetration·normal (for a union the
            // penetration aggregates pairs and the relation is per pair).
            let err = (ans.point_b - ans.point_a + ans.normal * ans.penetration).norm();
            if err > tol {
                return Err(format!(
                    "point_b - point_a != -penetration·normal by {err:e}\n{}",
                    ctx()
                ));
            }
        }
    }
    Ok(())
}

/// The penetration field against the brute force: 0 when separated; exactly
/// `rA + rB - d(cores)` when only the shells overlap; between `rA + rB` and
/// the true depth when the cores touch or intersect. For a union (which
/// aggregates piece pairs) only the sign is checked.
pub fn verify_penetration(ans: &gjk::Answer, reference: &RefShape, tol: f64) -> Result<(), String> {
    let truth = reference.distance;
    let ctx = || {
        format!(
            "truth {truth}\nanswer {ans:?}\nA = {:?}\nB = {:?}",
            reference.pieces_a, reference.pieces_b
        )
    };
    let (ia, ib) = (ans.pieces[0] as usize, ans.pieces[1] as usize);
    let (wa, wb) = (&reference.pieces_a[ia], &reference.pieces_b[ib]);
    let core = hull_distance(&wa.points, &wb.points);
    let radii = wa.radius + wb.radius;
    let single = reference.per_pair.len() == 1;
    if truth > tol {
        if ans.penetration != 0.0 {
            return Err(format!(
                "separated but penetration {}\n{}",
                ans.penetration,
                ctx()
            ));
        }
    } else if !single {
        // A union's penetration aggregates piece pairs: only its sign is checked.
        if ans.penetration.is_nan() || ans.penetration < 0.0 {
            return Err(format!("penetration {}\n{}", ans.penetration, ctx()));
        }
    } else if core.distance > tol {
        // Only the shells overlap: exact.
        let want = radii - core.distance;
        if (ans.penetration - want).abs() > tol {
            return Err(format!(
                "shell penetration {} != {want}\n{}",
                ans.penetration,
                ctx()
            ));
        }
    } else if truth == 0.0 {
        // Cores touch or intersect: radii <= penetration <= true depth. Cores
        // apart by at most `tol` may also be answered as apart, with the
        // shells' exact overlap: `radii - core.distance`, within `tol`.
        let depth = penetration_depth(&wa.points, &wb.points) + radii;
        let least = radii - core.distance;
        if ans.penetration < least - tol || ans.penetration > depth + tol {
            return Err(format!(
                "penetration {} not in [{least}, {depth}]\n{}",
                ans.penetration,
                ctx()
            ));
        }
    }
    Ok(())
}
