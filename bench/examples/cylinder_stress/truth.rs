//! The independent answer: a bracket on the true distance from the
//! bodies' own geometry, and the verdict on a gjk answer against it.

#[allow(unused_imports)]
use super::*;

/// A reference bracket `[lo, hi]` of the true distance, and the
/// magnitude of the coordinates it was computed from (for its round-off).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Bracket {
    pub(crate) lo: f64,
    pub(crate) hi: f64,
    pub(crate) mag: f64,
}

/// The lower bound of direction `n` (A's frame, towards B), B at `rel`.
pub(crate) fn separation(a: &Piece, b: &Piece, rel: &Isometry3<f64>, n: &Vector3<f64>) -> f64 {
    let len = n.norm();
    if !(len > 0.0 && len.is_finite()) {
        return 0.0;
    }
    let n = n / len;
    let nb = rel.rotation.inverse_transform_vector(&-n);
    n.dot(&rel.translation.vector) - a.support(&n) - b.support(&nb)
}

/// The bracket of one piece pair, B at `rel` in A's frame, seeded by
/// points (A's frame) to start the projections from and directions to try.
pub(crate) fn pair_bracket(
    a: &Piece,
    b: &Piece,
    rel: &Isometry3<f64>,
    starts: &[Vector3<f64>],
    dirs: &[Vector3<f64>],
    iterations: usize,
    point_shape: &Shape,
) -> Bracket {
    let into_b = |p: &Vector3<f64>| {
        let local = rel
            .rotation
            .inverse_transform_vector(&(p - rel.translation.vector));
        rel.rotation * b.project(&local, point_shape) + rel.translation.vector
    };
    // The support points of the best direction so far start the
    // projections too: on a curved contact they are the nearest points.
    // When the first round leaves the case undecided, the direction of
    // the nearest points found seeds further rounds.
    let mut starts = starts.to_vec();
    let mut dirs = dirs.to_vec();
    let rounds = if iterations > 64 { 4 } else { 1 };
    let mut hi = f64::INFINITY;
    let mut tried = 0;
    for _ in 0..rounds {
        let best_given = dirs
            .iter()
            .filter(|n| n.norm() > 0.0)
            .max_by(|m, n| separation(a, b, rel, m).total_cmp(&separation(a, b, rel, n)));
        if let Some(n) = best_given {
            let n = n.normalize();
            starts.push(a.support_point(&n));
            let nb = rel.rotation.inverse_transform_vector(&-n);
            starts.push(
                rel.transform_point(&Point3::from(b.support_point(&nb)))
                    .coords,
            );
        }
        let mut best_dir = Vector3::zeros();
        for s in &starts[tried..] {
            let mut qa = a.project(s, point_shape);
            let mut prev = f64::INFINITY;
            for _ in 0..iterations {
                let qb = into_b(&qa);
                let d = (qb - qa).norm();
                if d < hi {
                    hi = d;
                    best_dir = qb - qa;
                }
                if d == 0.0 || d >= prev * (1.0 - 1e-13) {
                    break;
                }
                prev = d;
                qa = a.project(&qb, point_shape);
            }
        }
        tried = starts.len();
        dirs.push(best_dir);
    }
    let lo = dirs
        .iter()
        .map(|n| separation(a, b, rel, n))
        .fold(0.0, f64::max);
    Bracket {
        lo: lo.max(0.0),
        hi,
        mag: rel.translation.vector.norm() + a.size() + b.size(),
    }
}

/// What the reference knows of a case beyond the shapes and poses: the
/// construction's points and direction (world frame), if any.
#[derive(Clone, Copy, Default)]
pub(crate) struct Hint {
    pub(crate) points: Option<(Point3<f64>, Point3<f64>)>,
    pub(crate) normal: Option<Vector3<f64>>,
}

/// The bracket of the case's pair (the least over piece pairs), seeded
/// by the answer's points and normal and by the case's hint.
pub(crate) fn bracket(
    case: &Case<'_>,
    answer: Option<&gjk::Answer>,
    iterations: usize,
    point_shape: &Shape,
) -> Bracket {
    let (a, pa, b, pb, hint) = (case.a, &case.pa, case.b, &case.pb, &case.hint);
    let rel = pa.inv_mul(pb);
    let mut out = Bracket {
        lo: f64::INFINITY,
        hi: f64::INFINITY,
        mag: 0.0,
    };
    for (oa, piece_a) in &a.pieces {
        for (ob, piece_b) in &b.pieces {
            let r = oa.inv_mul(&(rel * ob));
            // World points into piece A's frame.
            let local = |p: &Point3<f64>| {
                let q = pa
                    .rotation
                    .inverse_transform_vector(&(p.coords - pa.translation.vector));
                oa.rotation
                    .inverse_transform_vector(&(q - oa.translation.vector))
            };
            let local_dir = |n: &Vector3<f64>| {
                oa.rotation
                    .inverse_transform_vector(&pa.rotation.inverse_transform_vector(n))
            };
            let mut starts = vec![r.translation.vector, Vector3::zeros()];
            let mut dirs = vec![r.translation.vector];
            if let Some(ans) = answer {
                starts.push(local(&ans.point_a));
                starts.push(local(&ans.point_b));
                dirs.push(local_dir(&ans.normal));
            }
            if let Some((qa, qb)) = hint.points {
                starts.push(local(&qa));
                starts.push(local(&qb));
            }
            if let Some(n) = hint.normal {
                dirs.push(local_dir(&n));
            }
            let br = pair_bracket(
                piece_a,
                piece_b,
                &r,
                &starts,
                &dirs,
                iterations,
                point_shape,
            );
            out.lo = out.lo.min(br.lo);
            out.hi = out.hi.min(br.hi);
            out.mag = out.mag.max(br.mag);
        }
    }
    out
}

/// The most the pair can penetrate: for each piece pair, the least
/// overlap of the two shapes' projections over a set of directions (any
/// direction's overlap separates them, so the depth is at most it); the
/// largest over piece pairs, as a compound's bound is.
pub(crate) fn deepest_possible(case: &Case<'_>, answer: &gjk::Answer) -> f64 {
    let rel = case.pa.inv_mul(&case.pb);
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut sample: Vec<Vector3<f64>> = (0..64).map(|_| rng.direction()).collect();
    for x in [-1.0, 0.0, 1.0] {
        for y in [-1.0, 0.0, 1.0] {
            for z in [-1.0, 0.0, 1.0] {
                if x != 0.0 || y != 0.0 || z != 0.0 {
                    sample.push(Vector3::new(x, y, z).normalize());
                }
            }
        }
    }
    let mut most = 0.0f64;
    for (oa, a) in &case.a.pieces {
        for (ob, b) in &case.b.pieces {
            let r = oa.inv_mul(&(rel * ob));
            let to_a = |n: &Vector3<f64>| {
                oa.rotation
                    .inverse_transform_vector(&case.pa.rotation.inverse_transform_vector(n))
            };
            let mut dirs: Vec<Vector3<f64>> = Vec::with_capacity(3 * sample.len() + 2);
            for n in &sample {
                dirs.push(*n);
                dirs.push(r.rotation * n);
            }
            dirs.push(to_a(&answer.normal));
            dirs.push(r.translation.vector);
            let least = dirs
                .iter()
                .filter(|n| n.norm() > 0.0)
                .map(|n| -separation(a, b, &r, n))
                .fold(f64::INFINITY, f64::min);
            most = most.max(least);
        }
    }
    most
}

/// What the reference says of an answer.
pub(crate) enum Verdict {
    Pass,
    /// The bracket stayed too wide to tell.
    Undecided,
    Fail(Failure, String),
}

/// The verdict on `answer` against the reference bracket, widened by more
/// projections until it decides; with the bracket and the judged bound.
pub(crate) fn judge(
    case: &Case<'_>,
    answer: &gjk::Answer,
    size: f64,
    point_shape: &Shape,
) -> (Verdict, Bracket, f64) {
    let mut iterations = 64;
    loop {
        let br = bracket(case, Some(answer), iterations, point_shape);
        let bound = 1e-6 * br.lo + 1e-9 * size;
        let fuzz = 64.0 * f64::EPSILON * br.mag;
        let d = answer.distance;
        let margin = case.margin.unwrap_or(f64::NAN);
        let fail = |f| (Verdict::Fail(f, String::new()), br, bound);
        if answer.lower > br.hi + fuzz {
            return fail(Failure::LowerAboveTruth);
        }
        if answer.upper < br.lo - fuzz {
            return fail(Failure::UpperBelowTruth);
        }
        // An early exit decides the margin, not the distance.
        match answer.status {
            Status::Farther if br.hi <= margin - fuzz => return fail(Failure::WrongSide),
            Status::Closer if br.lo > margin + fuzz => return fail(Failure::WrongSide),
            Status::Farther | Status::Closer => return (Verdict::Pass, br, bound),
            _ => {}
        }
        if d > br.hi + bound + fuzz || d < br.lo - bound - fuzz {
            return fail(Failure::Distance);
        }
        if d <= br.lo + bound + fuzz && d >= br.hi - bound - fuzz {
            return (Verdict::Pass, br, bound);
        }
        if iterations >= 20_000 {
            return (Verdict::Undecided, br, bound);
        }
        iterations *= 16;
    }
}
