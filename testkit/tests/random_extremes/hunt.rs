//! The randomised sweep itself and the generator's own checks.

use super::*;

#[test]
fn random_extreme_cases_meet_the_requirement() {
    let cases = env("SWEEP_CASES", 3000) as usize;
    let mut rng = Rng::new(env("SWEEP_SEED", 1));
    // One in 500 cases (SWEEP_BIG_EVERY) may draw a 100 000-point body.
    let every = env("SWEEP_BIG_EVERY", 500).max(1) as usize;
    let (n, failed) = failures((0..cases).map(|i| draw(&mut rng, i % every == every - 1)));
    assert!(
        failed.is_empty(),
        "{} of {n} cases failed:\n{}",
        failed.len(),
        failed.join("\n")
    );
}

/// The generator itself: every contact kind and every gap is drawn, and the
/// truths it claims hold against a brute-force check on small bodies (the
/// nearest vertex pair can only be farther than the truth, and the slab
/// along the drawn normal can only be nearer).
#[test]
fn the_generator_covers_its_kinds_and_its_truths_are_consistent() {
    let mut rng = Rng::new(99);
    let mut seen = std::collections::BTreeMap::new();
    let mut names = std::collections::BTreeMap::new();
    for _ in 0..2000 {
        let case = draw(&mut rng, false);
        *seen.entry(case.contact).or_insert(0) += 1;
        *names.entry(case.a.name).or_insert(0) += 1;
        *names.entry(case.b.name).or_insert(0) += 1;
        // World vertices of both cores.
        let world = |b: &sweep::Body, pose: &nalgebra::Isometry3<f64>| -> Vec<sweep::P> {
            b.vertices.iter().map(|x| pose * x).collect()
        };
        let (wa, wb) = (world(&case.a, &case.pa), world(&case.b, &case.pb));
        let nearest_pair = wa
            .iter()
            .flat_map(|x| wb.iter().map(move |y| (y - x).norm()))
            .fold(f64::INFINITY, f64::min);
        let radii = case.a.radius + case.b.radius;
        // Rounding of far poses (1e9 · ε) allowed for on this check only.
        let tol = 1e-6 * case.truth + 1e-9 * case.size + 4.0 * f64::EPSILON * case.offset;
        assert!(
            (nearest_pair - radii).max(0.0) >= case.truth - tol,
            "{}: a vertex pair is nearer ({:e}) than the truth",
            case.describe(),
            nearest_pair - radii
        );
        // The slab itself: A's cores end where the drawn normal says, and
        // B's begin the truth (plus the radii) beyond.
        if matches!(
            case.contact,
            Contact::Separated | Contact::Aligned | Contact::NearlyParallelEdges | Contact::Twins
        ) {
            let n = case.normal;
            let top_a = wa.iter().map(|x| n.dot(&x.coords)).fold(f64::MIN, f64::max);
            let low_b = wb.iter().map(|x| n.dot(&x.coords)).fold(f64::MAX, f64::min);
            let slab = low_b - top_a - radii;
            assert!(
                (slab - case.truth).abs() <= tol,
                "{}: the slab is {slab:e} wide",
                case.describe()
            );
        }
    }
    for kind in [
        Contact::Separated,
        Contact::Aligned,
        Contact::NearlyParallelEdges,
        Contact::ShellsOverlap,
        Contact::ShallowOverlap,
        Contact::DeepOverlap,
        Contact::Identical,
        Contact::Twins,
    ] {
        assert!(
            seen.get(&kind).copied().unwrap_or(0) > 20,
            "{kind:?} drawn {seen:?}"
        );
    }
    for name in [
        "box",
        "sphere",
        "segment",
        "capsule",
        "triangle",
        "polytope",
        "duplicates",
        "collinear",
        "coplanar",
        "point",
        "prism",
    ] {
        assert!(
            names.get(name).copied().unwrap_or(0) > 50,
            "{name} drawn {names:?}"
        );
    }
}

/// The certified bounds hold whatever the options: tolerance 0 or loose,
/// iteration caps of 1 and 2, a margin on either side of the truth (far, or
/// 1e-9 of the size away) or at it. With tolerance 0 the distance must also
/// meet the requirement, and an early exit on a margin must decide it as the
/// truth does.
#[test]
fn bounds_hold_under_every_option() {
    let cases = env("SWEEP_CASES", 3000) as usize;
    let mut rng = Rng::new(env("SWEEP_SEED", 1) ^ 0x5eed);
    let mut failed = Vec::new();
    for i in 0..cases {
        let case = draw(&mut rng, i % 500 == 499);
        let (a, b) = (case.a.shape(), case.b.shape());
        let d = Options::default();
        let variants = [
            (
                "tolerance 0",
                Options {
                    tolerance: 0.0,
                    ..d
                },
            ),
            (
                "tolerance 1e-6",
                Options {
                    tolerance: 1e-6,
                    ..d
                },
            ),
            (
                "cap 1",
                Options {
                    max_iterations: 1,
                    ..d
                },
            ),
            (
                "cap 2",
                Options {
                    max_iterations: 2,
                    ..d
                },
            ),
            (
                "margin below",
                Options {
                    margin: Some(0.5 * case.truth),
                    ..d
                },
            ),
            (
                "margin above",
                Options {
                    margin: Some(case.truth + 1e-3 * case.size),
                    ..d
                },
            ),
            (
                "margin at",
                Options {
                    margin: Some(case.truth),
                    ..d
                },
            ),
            (
                "margin a hair below",
                Options {
                    margin: Some((case.truth - 1e-9 * case.size).max(0.0)),
                    ..d
                },
            ),
            (
                "margin a hair above",
                Options {
                    margin: Some(case.truth + 1e-9 * case.size),
                    ..d
                },
            ),
        ];
        for (name, o) in variants {
            let ans = match distance(&a, &case.pa, &b, &case.pb, &o, None) {
                Ok(x) => x,
                Err(e) => {
                    failed.push(format!("{name}: {}: error {e:?}", case.describe()));
                    continue;
                }
            };
            let mut why: Vec<String> = bounds_error(&case, ans.lower, ans.upper)
                .into_iter()
                .collect();
            if name == "tolerance 0" {
                why.extend(distance_error(&case, ans.distance));
            }
            // An early exit is a decision about the truth: "farther than m"
            // must hold of the truth, and so must "at most m".
            if let Some(m) = o.margin {
                let t = case.truth;
                let wrong = match ans.status {
                    Status::Farther => !(ans.lower > m && t + case.truth_slack > m),
                    Status::Closer => !(ans.upper <= m && t - case.truth_slack <= m),
                    _ => false,
                };
                if wrong {
                    why.push(format!("{:?} about margin {m:e}", ans.status));
                }
            }
            if !(ans.lower <= ans.distance && ans.distance <= ans.upper) {
                why.push("distance outside its bounds".into());
            }
            // Whatever ended the run, the depth bound is a lower bound.
            if let Some(depth) = case.depth {
                let allowed = (1e-6 * depth).max(1e-9 * case.size) + case.truth_slack;
                if ans.penetration.is_nan() || ans.penetration > depth + allowed {
                    why.push(format!("penetration {:e} above {depth:e}", ans.penetration));
                }
            }
            if !why.is_empty() {
                failed.push(format!(
                    "{name}: {}: got {:e} [{:e}, {:e}] {:?}: {}",
                    case.describe(),
                    ans.distance,
                    ans.lower,
                    ans.upper,
                    ans.status,
                    why.join("; ")
                ));
            }
        }
    }
    none_failed(&failed);
}
