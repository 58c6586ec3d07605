//! The hunt: cases, their placements and warm starts, and the tally of
//! failures.

#[allow(unused_imports)]
use super::*;

/// How a case is started.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Start {
    Cold,
    /// The previous step's warm start along a motion.
    Motion,
    /// Another pair's warm start.
    Foreign,
    /// Random codes and indices.
    Random,
    /// Cold, with a margin near the distance: an early exit's bounds
    /// must hold the truth and decide the margin as its status says.
    Margin,
}

/// One query to check.
pub(crate) struct Case<'c> {
    pub(crate) a: &'c Body,
    pub(crate) pa: Isometry3<f64>,
    pub(crate) b: &'c Body,
    pub(crate) pb: Isometry3<f64>,
    pub(crate) hint: Hint,
    pub(crate) warm: Option<WarmStart>,
    pub(crate) margin: Option<f64>,
    pub(crate) label: String,
}

/// What went wrong with an answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Failure {
    Error,
    NotFinite,
    Distance,
    LowerAboveTruth,
    UpperBelowTruth,
    /// An early exit on the wrong side of its margin.
    WrongSide,
    /// A penetration bound above the overlap along some direction.
    Penetration,
    /// Nearest points off their shapes, or not the distance apart.
    Points,
    /// The two compiled forms of the query answered differently.
    CompiledForms,
}

impl Failure {
    /// Whether the class breaks what the issue judges (the distance, its
    /// bounds, a status), as against the penetration and points.
    pub(crate) fn is_judged(self) -> bool {
        !matches!(self, Failure::Penetration | Failure::Points)
    }
}

#[derive(Default)]
pub(crate) struct Tally {
    pub(crate) cases: u64,
    /// Foreign warm starts the query refused (indices out of range).
    pub(crate) refused: u64,
    pub(crate) failures: BTreeMap<Failure, u64>,
    pub(crate) undecided: u64,
    pub(crate) statuses: BTreeMap<String, u64>,
    pub(crate) widest: f64,
}

pub(crate) struct Hunt {
    pub(crate) tallies: BTreeMap<String, Tally>,
    pub(crate) printed: BTreeMap<(String, String), u32>,
    pub(crate) point_shape: Shape,
    pub(crate) options: Options,
    pub(crate) workspace: Workspace,
    pub(crate) asked: u64,
}

/// The shape's parameters as Rust would write them.
pub(crate) fn describe(body: &Body) -> String {
    body.pieces
        .iter()
        .map(|(o, p)| {
            let g = match &p.geom {
                Geom::Cylinder { r, h } => format!("Convex::cylinder({r:?}, {h:?}, {:?})", p.rho),
                Geom::Cuboid { half } => format!(
                    "Convex::cuboid(Vector3::new({:?}, {:?}, {:?}), {:?})",
                    half.x, half.y, half.z, p.rho
                ),
                Geom::Segment { a, b } if a == b => format!("Convex::sphere({:?})", p.rho),
                Geom::Segment { a, b } => format!(
                    "Convex::capsule({:?}, {:?}, {:?})",
                    a.as_slice(),
                    b.as_slice(),
                    p.rho
                ),
                Geom::Hull { verts } => format!(
                    "Convex::new({:?}, {:?})",
                    verts
                        .iter()
                        .map(|v| v.as_slice().to_vec())
                        .collect::<Vec<_>>(),
                    p.rho
                ),
            };
            if body.pieces.len() == 1 {
                g
            } else {
                format!("({}, {g})", pose(o))
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

pub(crate) fn pose(p: &Isometry3<f64>) -> String {
    let t = p.translation.vector;
    let q = p.rotation.quaternion();
    format!(
        "pose(t = [{:?}, {:?}, {:?}], q(w,x,y,z) = [{:?}, {:?}, {:?}, {:?}])",
        t.x, t.y, t.z, q.w, q.i, q.j, q.k
    )
}

impl Hunt {
    /// Query `case`, check it against the reference and tally it; the
    /// answer, for a motion's next warm start.
    pub(crate) fn check(&mut self, case: &Case<'_>, start: Start) -> Option<gjk::Answer> {
        let key = format!("{:<8} {}", format!("{start:?}"), case.label);
        let options = Options {
            margin: case.margin,
            ..self.options
        };
        let (a, b, warm) = (&case.a.shape, &case.b.shape, case.warm.as_ref());
        let result = distance(a, &case.pa, b, &case.pb, &options, warm);
        // The form compiled for any CPU must answer the same, bit for bit
        // (on a CPU with AVX2 and FMA `distance` runs the other form).
        self.asked += 1;
        if self.asked.is_multiple_of(8) {
            let baseline = distance_in_baseline(
                &mut self.workspace,
                a,
                &case.pa,
                b,
                &case.pb,
                &options,
                warm,
            );
            if baseline != result {
                let text = format!("baseline {baseline:?}\n  vs {result:?}");
                *self
                    .tallies
                    .entry(key.clone())
                    .or_default()
                    .failures
                    .entry(Failure::CompiledForms)
                    .or_default() += 1;
                self.report(case, "FAIL CompiledForms", &text, &key);
            }
        }
        let size = case.a.size().max(case.b.size());
        let tally = self.tallies.entry(key.clone()).or_default();
        tally.cases += 1;
        let answer = match result {
            Ok(ans) => ans,
            Err(gjk::Error::WarmStartOutOfRange) if start == Start::Foreign => {
                // Another pair's indices need not fit these shapes: the
                // query refuses it, as documented, and nothing is checked.
                tally.cases -= 1;
                tally.refused += 1;
                return None;
            }
            Err(e) => {
                *tally.failures.entry(Failure::Error).or_default() += 1;
                self.report(case, "FAIL Error", &format!("error {e:?}"), &key);
                return None;
            }
        };
        *tally
            .statuses
            .entry(format!("{:?}", answer.status))
            .or_default() += 1;
        let finite = [answer.distance, answer.lower, answer.upper]
            .iter()
            .all(|x| x.is_finite());
        if !finite || answer.lower > answer.upper {
            *tally.failures.entry(Failure::NotFinite).or_default() += 1;
            self.report(case, "FAIL NotFinite", &format!("{answer:?}"), &key);
            return Some(answer);
        }
        let (verdict, br, bound) = judge(case, &answer, size, &self.point_shape);
        let verdict = match verdict {
            Verdict::Pass => self
                .side_checks(case, &answer, size, &br)
                .map_or(Verdict::Pass, |(f, t)| Verdict::Fail(f, t)),
            v => v,
        };
        let tally = self.tallies.get_mut(&key).expect("counted above");
        let err = (answer.distance - br.lo.max(br.hi.min(answer.distance))).abs();
        if !matches!(answer.status, Status::Farther | Status::Closer) {
            tally.widest = tally.widest.max(err / bound);
        }
        let summary = format!(
            "got {:?} [{:?}, {:?}] {:?} it {} vs bracket [{:?}, {:?}] (bound {bound:e}, off by {:.3e} bounds)",
            answer.distance,
            answer.lower,
            answer.upper,
            answer.status,
            answer.iterations,
            br.lo,
            br.hi,
            err / bound
        );
        match verdict {
            Verdict::Pass => {}
            Verdict::Undecided => {
                tally.undecided += 1;
                self.report(case, "UNDECIDED", &summary, &key);
            }
            Verdict::Fail(f, text) => {
                *tally.failures.entry(f).or_default() += 1;
                self.report(
                    case,
                    &format!("FAIL {f:?}"),
                    &format!("{text}{summary}"),
                    &key,
                );
            }
        }
        Some(answer)
    }

    /// The answer's penetration and nearest points, checked when its
    /// distance passed: `Some` with what is wrong with them.
    pub(crate) fn side_checks(
        &self,
        case: &Case<'_>,
        answer: &gjk::Answer,
        size: f64,
        br: &Bracket,
    ) -> Option<(Failure, String)> {
        let fuzz = 64.0 * f64::EPSILON * br.mag;
        if answer.penetration > 0.0 {
            let most = deepest_possible(case, answer);
            if answer.penetration > most + fuzz + 1e-12 * size {
                let text = format!("penetration {:?} > {most:?}; ", answer.penetration);
                return Some((Failure::Penetration, text));
            }
        }
        // The points: on their shapes and the distance apart, to the
        // judged bound plus the round-off of their world coordinates.
        let world =
            64.0 * f64::EPSILON * (answer.point_a.coords.norm() + answer.point_b.coords.norm());
        let tol = 1e-6 * answer.distance + 1e-9 * size + world + fuzz;
        let gap = (answer.point_b - answer.point_a).norm();
        if answer.distance > 0.0 && (gap - answer.distance).abs() > tol {
            let text = format!("points {gap:?} apart (tolerance {tol:e}); ");
            return Some((Failure::Points, text));
        }
        let off = |body: &Body, pose: &Isometry3<f64>, p: &Point3<f64>| {
            body.pieces
                .iter()
                .map(|(o, piece)| {
                    let local = (pose * o).inverse_transform_point(p).coords;
                    (piece.project(&local, &self.point_shape) - local).norm()
                })
                .fold(f64::INFINITY, f64::min)
        };
        let (off_a, off_b) = (
            off(case.a, &case.pa, &answer.point_a),
            off(case.b, &case.pb, &answer.point_b),
        );
        if off_a > tol || off_b > tol {
            let text = format!(
                "points {off_a:?} and {off_b:?} off their shapes (tolerance {tol:e}); normal {:?}, penetration {:?}, pieces {:?}; ",
                answer.normal.as_slice(),
                answer.penetration,
                answer.pieces
            );
            return Some((Failure::Points, text));
        }
        None
    }

    /// Prints the first few of each class and key, with a repro.
    pub(crate) fn report(&mut self, case: &Case<'_>, what: &str, text: &str, key: &str) {
        let n = self
            .printed
            .entry((what.to_string(), key.to_string()))
            .or_default();
        *n += 1;
        if *n > 3 {
            return;
        }
        println!(
            "{what} {key}: {text}\n  A = {} at {}\n  B = {} at {}\n  warm = {:?}, margin = {:?}",
            describe(case.a),
            pose(&case.pa),
            describe(case.b),
            pose(&case.pb),
            case.warm.as_ref().map(|w| (w.pieces(), w.pairs().to_vec())),
            case.margin
        );
    }
}

/// Where a case is placed.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Placement {
    Random,
    /// Support faces at a gap (0, tiny, ordinary or negative).
    Contact,
    Far,
    /// The same centre, or nearly.
    Coincident,
}

/// A world pose for A: at or far from the origin, special or random.
pub(crate) fn world_pose(rng: &mut Rng) -> Isometry3<f64> {
    let t = if rng.chance(0.3) {
        Vector3::zeros()
    } else {
        let reach = if rng.chance(0.8) { 6.0 } else { 9.0 };
        rng.direction() * rng.log(0.0, reach)
    };
    let rot = if rng.chance(0.5) {
        special_rotation(rng)
    } else {
        rng.rotation()
    };
    Isometry3::from_parts(Translation3::from(t), rot)
}

/// A contact direction in A's frame: its cap, its side, a tilt off
/// either, B's face, or random.
pub(crate) fn contact_direction(
    rng: &mut Rng,
    b: &Piece,
    rot_b: &UnitQuaternion<f64>,
) -> (Vector3<f64>, &'static str) {
    let around = rng.range(-PI, PI);
    let side = Vector3::new(around.cos(), around.sin(), 0.0);
    let cap = Vector3::new(0.0, 0.0, if rng.chance(0.5) { 1.0 } else { -1.0 });
    match rng.below(7) {
        0 => (cap, "cap"),
        1 => (side, "side"),
        2 => ((cap + side * rng.log(-12.0, -1.0)).normalize(), "near-cap"),
        3 => ((side + cap * rng.log(-12.0, -1.0)).normalize(), "near-side"),
        4 if !matches!(b.geom, Geom::Cylinder { .. }) && rng.chance(0.5) => {
            // B's edge: -n has one zero component in B's frame.
            let t = rng.range(-PI, PI);
            let (c, s) = (t.cos(), t.sin());
            let local = match rng.below(3) {
                0 => Vector3::new(c, s, 0.0),
                1 => Vector3::new(c, 0.0, s),
                _ => Vector3::new(0.0, c, s),
            };
            (-rot_b.transform_vector(&local), "b-edge")
        }
        4 => {
            // B's face, cap or side: -n is one of B's special directions.
            let local = match b.geom {
                Geom::Cylinder { .. } if rng.chance(0.5) => side,
                _ => {
                    let axis = match rng.below(3) {
                        0 => Vector3::x(),
                        1 => Vector3::y(),
                        _ => Vector3::z(),
                    };
                    axis * if rng.chance(0.5) { 1.0 } else { -1.0 }
                }
            };
            (-(rot_b.transform_vector(&local)), "b-face")
        }
        5 if rng.chance(0.3) => {
            // About a quarter off the axis (the sine), where the query
            // turns from its rim steps to its cap's closed form.
            let sin = 0.25 * (1.0 + rng.range(-1e-3, 1e-3));
            let cos = (1.0 - sin * sin).sqrt();
            ((side * sin + cap * cos).normalize(), "quarter-tilt")
        }
        _ => (rng.direction(), "random-dir"),
    }
}

/// A gap for a contact, relative to `scale`: touching, tiny, ordinary or
/// overlapping.
pub(crate) fn contact_gap(rng: &mut Rng, scale: f64) -> (f64, &'static str) {
    match rng.below(5) {
        0 | 1 => (0.0, "touch"),
        2 => (scale * rng.log(-12.0, -3.0), "tiny-gap"),
        3 => (scale * rng.range(0.01, 2.0), "gap"),
        _ => (
            -scale
                * if rng.chance(0.5) {
                    rng.log(-12.0, -3.0)
                } else {
                    rng.range(0.0, 0.5)
                },
            "overlap",
        ),
    }
}

/// Builds B's pose about A for `placement`, with the hint the reference
/// may use and a label for the tally.
pub(crate) fn place(
    rng: &mut Rng,
    a: &Body,
    pa: &Isometry3<f64>,
    b: &Body,
    placement: Placement,
) -> (Isometry3<f64>, Hint, String) {
    let (rot, rot_label) = relative_rotation(rng);
    let scale = a.size().max(b.size());
    match placement {
        Placement::Random => {
            let t = rng.direction() * (a.size() + b.size()) * rng.range(0.2, 2.0);
            let rel = Isometry3::from_parts(Translation3::from(t), rot);
            (pa * rel, Hint::default(), format!("random {rot_label}"))
        }
        Placement::Far => {
            let t = rng.direction() * scale * rng.log(1.0, 6.0);
            let rel = Isometry3::from_parts(Translation3::from(t), rot);
            (pa * rel, Hint::default(), format!("far {rot_label}"))
        }
        Placement::Coincident => {
            let t = if rng.chance(0.5) {
                Vector3::zeros()
            } else {
                rng.direction() * scale * rng.log(-12.0, 0.0)
            };
            let rel = Isometry3::from_parts(Translation3::from(t), rot);
            (pa * rel, Hint::default(), format!("coincident {rot_label}"))
        }
        Placement::Contact => {
            // Piece 0 of each: the cylinder of A, B's first piece.
            let (oa, piece_a) = &a.pieces[0];
            let (ob, piece_b) = &b.pieces[0];
            // Directions in piece A's frame; B's piece rotation relative
            // to piece A is `rot`.
            let (n, dir_label) = contact_direction(rng, piece_b, &rot);
            let (gap, gap_label) = contact_gap(rng, scale);
            let qa = piece_a.face_point(&n, rng) + n * piece_a.rho;
            let nb = rot.inverse_transform_vector(&-n);
            let qb_local = piece_b.face_point(&nb, rng) + nb * piece_b.rho;
            // Piece B placed so that its point lands on A's plus gap·n.
            let t = qa + n * gap - rot * qb_local;
            let rel_pieces = Isometry3::from_parts(Translation3::from(t), rot);
            // Body B's pose: pa · oa · rel_pieces · ob⁻¹.
            let pb = pa * (oa * rel_pieces * ob.inverse());
            let world_a = pa * (oa * Point3::from(qa));
            let hint = Hint {
                points: Some((world_a, world_a + pa.rotation * (oa.rotation * (n * gap)))),
                normal: Some(pa.rotation * (oa.rotation * n)),
            };
            (
                pb,
                hint,
                format!("contact {gap_label} {dir_label} {rot_label}"),
            )
        }
    }
}

/// A random garbage warm start for the pair: one to four index pairs,
/// each valid for the pieces it names.
pub(crate) fn random_warm(rng: &mut Rng, a: &Body, b: &Body) -> WarmStart {
    let pieces = [
        rng.below(a.pieces.len() as u64) as u32,
        rng.below(b.pieces.len() as u64) as u32,
    ];
    let (la, lb) = (
        a.index_limit(pieces[0] as usize),
        b.index_limit(pieces[1] as usize),
    );
    let n = 1 + rng.below(4) as usize;
    let pick = |rng: &mut Rng, limit: u32| {
        if limit == u32::MAX {
            match rng.below(4) {
                0 => 0,
                1 => 1u32 << 31,
                _ => rng.bits() as u32,
            }
        } else {
            rng.below(u64::from(limit) + 1) as u32
        }
    };
    let pairs: Vec<[u32; 2]> = (0..n).map(|_| [pick(rng, la), pick(rng, lb)]).collect();
    WarmStart::new(pieces, &pairs).expect("at most four pairs")
}
