//! Unions of drawn bodies: many pieces, and one piece that must answer
//! as the piece alone.

use super::*;

/// Unions of up to five pieces on each side, the case's bodies among copies
/// of themselves that are no nearer (some exactly as near: ties), asked cold,
/// warm, in f32 (held as [`check_single`] holds one pair), with an iteration
/// cap of 1 to 3 (bounds only) and with a margin at
/// the truth or 1e-9 or 1e-3 of the size either side of it: the distance,
/// bounds and status as for one pair, or an early exit that decides the
/// margin as the truth does; the pieces the answer names realise the distance
/// (their own distance is the truth); a penetration bound never above the
/// unions' depth (0 apart; the near pieces' exact depth when only their
/// shells overlap, since the copies sit behind the support planes) and, on
/// runs to the end, equal to it; and nearest points `distance` apart.
#[test]
fn unions_of_many_pieces_keep_the_truth() {
    let cases = env("SWEEP_CASES", 3000) as usize / 3;
    let mut rng = Rng::new(env("SWEEP_SEED", 1) ^ 0x0c0b1e5);
    let mut failed = Vec::new();
    let o = Options::default();
    for k in 0..cases {
        let case = draw(&mut rng, false);
        // Towards B in A's body frame, and towards A in B's.
        let ua = case.pa.rotation.inverse() * case.normal;
        let ub = case.pb.rotation.inverse() * -case.normal;
        let (a, pieces_a) = copies(&mut rng, &case.a, &ua, case.size);
        let (b, pieces_b) = copies(&mut rng, &case.b, &ub, case.size);
        let nudge = nalgebra::Translation3::from(rng.direction() * (0.01 * case.size));
        let m = (case.truth + rng.pick(&[-1e-3, -1e-9, 0.0, 1e-9, 1e-3]) * case.size).max(0.0);
        let margin = Options {
            margin: Some(m),
            ..o
        };
        let single = Options {
            precision: gjk::Precision::Single,
            ..o
        };
        // Every piece pair stopped after one to three iterations: the union's
        // bounds then rest on unfinished pairs. (Not drawn: the seeds' cases
        // stay those they were before this was asked.)
        let capped = Options {
            max_iterations: 1 + (k % 3) as u32,
            ..o
        };
        let asked = distance(&a, &case.pa, &b, &(nudge * case.pb), &o, None).and_then(|prev| {
            Ok([
                ("cold", distance(&a, &case.pa, &b, &case.pb, &o, None)?),
                (
                    "warm",
                    distance(&a, &case.pa, &b, &case.pb, &o, Some(&prev.warm_start))?,
                ),
                (
                    "margin",
                    distance(&a, &case.pa, &b, &case.pb, &margin, None)?,
                ),
                (
                    "single",
                    distance(&a, &case.pa, &b, &case.pb, &single, None)?,
                ),
                ("cap", distance(&a, &case.pa, &b, &case.pb, &capped, None)?),
            ])
        });
        let answers = match asked {
            Ok(x) => x,
            Err(e) => {
                failed.push(format!("{}: error {e:?}", case.describe()));
                continue;
            }
        };
        let allowed = (1e-6 * case.truth).max(1e-9 * case.size) + case.truth_slack;
        for (how, ans) in answers {
            // f32 is held to its own allowance; its bounds hold all the same.
            let why = if how == "single" {
                check_single(&case, &ans)
            } else if how == "cap" {
                bounds_error(&case, ans.lower, ans.upper)
                    .into_iter()
                    .chain(
                        (!(ans.lower <= ans.distance && ans.distance <= ans.upper))
                            .then(|| "distance outside its bounds".to_string()),
                    )
                    .collect()
            } else {
                let mut why: Vec<String> = bounds_error(&case, ans.lower, ans.upper)
                    .into_iter()
                    .collect();
                if how == "margin" {
                    // An early exit must decide as the truth does; a run to the
                    // end must meet the requirement.
                    let t = case.truth;
                    match ans.status {
                        Status::Farther if !(ans.lower > m && t + case.truth_slack > m) => {
                            why.push(format!("Farther than margin {m:e}"));
                        }
                        Status::Closer if !(ans.upper <= m && t - case.truth_slack <= m) => {
                            why.push(format!("Closer than margin {m:e}"));
                        }
                        Status::Farther | Status::Closer => {}
                        _ => why.extend(distance_error(&case, ans.distance)),
                    }
                } else {
                    why.extend(distance_error(&case, ans.distance));
                    why.extend(status_error(&case, &ans));
                }
                // An early exit stops before the depth is worked out (its bound
                // may be far below): checked on runs to the end only.
                if let Some(depth) = case.depth
                    && how != "margin"
                    && (ans.penetration.is_nan() || ans.penetration < depth - allowed)
                {
                    why.push(format!("penetration {:e} below {depth:e}", ans.penetration));
                }
                // The named pieces alone, each at its offset: a union of one. An
                // early exit names the pair that decided it, not the nearest.
                let [i, j] = ans.pieces.map(|k| k as usize);
                let alone = |p: &(nalgebra::Isometry3<f64>, gjk::Convex)| -> gjk::Shape {
                    gjk::Compound::new(vec![p.clone()]).unwrap().into()
                };
                match distance(
                    &alone(&pieces_a[i]),
                    &case.pa,
                    &alone(&pieces_b[j]),
                    &case.pb,
                    &o,
                    None,
                ) {
                    Ok(pair) if how != "margin" && pair.lower > case.truth + allowed => {
                        why.push(format!(
                            "pieces {:?} are {:e} apart, not the nearest",
                            ans.pieces, pair.lower
                        ))
                    }
                    Ok(_) => {}
                    Err(e) => why.push(format!("pieces {:?}: error {e:?}", ans.pieces)),
                }
                // World points at 1e9 from the origin carry 1e-7 of round-off.
                let span = (ans.point_b - ans.point_a).norm();
                if case.truth > 0.0 && case.offset == 0.0 && (span - ans.distance).abs() > allowed {
                    why.push(format!("nearest points {span:e} apart"));
                }
                why
            };
            let mut why = why;
            // Every copy stays behind its body's support plane, so moving B
            // along the normal by the near pair's depth separates the unions
            // too: their depth is the case's (0 when the cores are apart),
            // and no run, however it ended, may report more.
            let union_depth = match case.contact {
                Contact::Separated
                | Contact::Aligned
                | Contact::NearlyParallelEdges
                | Contact::Twins => Some(0.0),
                Contact::ShellsOverlap => case.depth,
                _ => None,
            };
            if let Some(d) = union_depth {
                let allowed = (1e-6 * d).max(1e-9 * case.size) + case.truth_slack;
                if ans.penetration.is_nan() || ans.penetration > d + allowed {
                    why.push(format!(
                        "penetration {:e} above the depth {d:e}",
                        ans.penetration
                    ));
                }
            }
            if !why.is_empty() {
                failed.push(format!(
                    "{} ({how}, {}×{} pieces): got {:e} [{:e}, {:e}] pen {:e} {:?} pieces {:?}: {}",
                    case.describe(),
                    pieces_a.len(),
                    pieces_b.len(),
                    ans.distance,
                    ans.lower,
                    ans.upper,
                    ans.penetration,
                    ans.status,
                    ans.pieces,
                    why.join("; ")
                ));
            }
        }
    }
    none_failed(&failed);
}

/// A union of one piece at its compound's origin answers as the piece does,
/// to the last bit of every field (status, points and warm start too), on
/// either side and on both, under every option: the union's path adds
/// nothing to a pair's answer. Before 1d6e0e8 a piece far from its frame
/// (vertices 1e6 from it) lost the centroids' offset to f64 cancellation in a
/// union, where the convex shape kept it in double-double; before the union's
/// margin decision followed its pairs', a union whose pairs had converged
/// said `Farther` where the piece alone said `Converged`.
#[test]
fn a_one_piece_union_answers_as_its_piece() {
    let cases = env("SWEEP_CASES", 3000) as usize;
    let mut rng = Rng::new(env("SWEEP_SEED", 1) ^ 0x0e1ece);
    let mut failed = Vec::new();
    for i in 0..cases {
        let case = draw(&mut rng, i % 500 == 499);
        let (a, b) = (case.a.shape(), case.b.shape());
        let union = |body: &sweep::Body| -> gjk::Shape {
            let piece = gjk::Convex::new(body.vertices.clone(), body.radius).unwrap();
            gjk::Compound::new(vec![(nalgebra::Isometry3::identity(), piece)])
                .unwrap()
                .into()
        };
        let (ua, ub) = (union(&case.a), union(&case.b));
        let d = Options::default();
        let options = [
            d,
            Options {
                tolerance: 1e-6,
                ..d
            },
            Options {
                max_iterations: 2,
                ..d
            },
            Options {
                margin: Some(0.5 * case.truth),
                ..d
            },
            Options {
                margin: Some(case.truth + 1e-3 * case.size),
                ..d
            },
        ];
        let o = &options[i % options.len()];
        let alone = distance(&a, &case.pa, &b, &case.pb, o, None);
        for (how, x, y) in [("A", &ua, &b), ("B", &a, &ub), ("both", &ua, &ub)] {
            let asked = distance(x, &case.pa, y, &case.pb, o, None);
            if format!("{asked:?}") != format!("{alone:?}") {
                failed.push(format!(
                    "{} ({how} a union, {o:?}):\n  piece {alone:?}\n  union {asked:?}",
                    case.describe()
                ));
            }
        }
    }
    assert!(
        failed.is_empty(),
        "{} of {} answers differ:\n{}",
        failed.len(),
        3 * cases,
        failed.join("\n")
    );
}
