//! A hunt for wrong cylinder answers: millions of varied cases, each
//! checked against a certified reference bracket of its own.
//!
//! ```text
//! cargo run --release -p gjkd-bench --example cylinder_stress -- [cases] [seed]
//! ```
//!
//! Every case puts a cylinder (sharp or rounded, flat disks, needles,
//! zero radius or height, 1e-9 to 1e6 in size, up to 1e9 from the origin)
//! against a cylinder, a box, a sphere, a capsule or a point cloud's hull
//! (small, large enough for the other support searches, flat, with
//! repeated points), alone or as pieces of compounds, either way round,
//! in one of several placements: random; a contact built from the two
//! shapes' support faces at a chosen gap (touching, tiny gaps, overlaps;
//! cap on cap, side on side, rim on face or edge by the special
//! directions and relative rotations it draws: parallel, flipped,
//! perpendicular, nearly so, exact quarter turns); far apart; or on the
//! same centre. Each case is asked cold, from the previous pair's warm
//! start (when its indices fit), from random codes, sometimes with a
//! margin near its distance, and sometimes along a warm motion of sixteen
//! steps. A grid of round-number closed-form placements (parallel axes
//! side by side, coaxial caps, a cap on a box face, crossing axes, a ball
//! at the rim, at gaps from 1e-3 of the size to overlaps) closes the run.
//!
//! The reference is independent of the query: in the pair's relative
//! frame, alternating projections onto the shapes (closed forms, or a
//! polytope query for a hull, not the cylinder's code) give a pair of
//! points, one in each shape, hence an upper bound on the distance, and
//! the shapes' support functions in closed form give, for any unit
//! direction, a lower bound (the separation of their projections). The
//! truth lies in that bracket whatever the query answered; the answer's
//! own points and normal, and the construction's, only seed it. An answer
//! fails when its distance is out of the judged bound (relative 1e-6,
//! absolute 1e-9 of the larger shape's size) of the bracket, when its
//! bounds miss the bracket, when an early exit is on the wrong side of
//! its margin, or when the form compiled for any CPU answers differently
//! (one query in eight is asked both ways). A case whose bracket stays
//! too wide to judge is counted as undecided, not passed. Beside these,
//! the `other` column counts answers whose penetration bound exceeds the
//! overlap along some direction, or whose nearest points lie off their
//! shapes or not the distance apart (beyond the same bound plus the
//! round-off of their world coordinates): the issue does not judge them.

mod bodies;
mod hunt;
mod truth;

use bodies::*;
use gjk::{
    Compound, Convex, Options, Shape, Status, WarmStart, Workspace, distance, distance_in_baseline,
};
use hunt::*;
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};
use std::collections::BTreeMap;
use std::f64::consts::{FRAC_1_SQRT_2, PI};
use truth::*;

fn main() {
    let mut args = std::env::args().skip(1);
    let total: u64 = args
        .next()
        .map_or(1_000_000, |s| s.parse().expect("a count"));
    let seed: u64 = args
        .next()
        .map_or(0x5eed_c711_57e5_0001, |s| s.parse().expect("a seed"));
    let mut rng = Rng(seed | 1);
    let mut hunt = Hunt {
        tallies: BTreeMap::new(),
        printed: BTreeMap::new(),
        point_shape: Convex::sphere(0.0).expect("a point").into(),
        options: Options::default(),
        workspace: Workspace::new(),
        asked: 0,
    };
    let mut foreign: Option<WarmStart> = None;
    let mut done = 0u64;
    while done < total {
        let (a, b) = random_pair(&mut rng);
        let placement = match rng.below(10) {
            0..=3 => Placement::Random,
            4..=8 => Placement::Contact,
            9 if rng.chance(0.3) => Placement::Coincident,
            _ => Placement::Far,
        };
        let pa = world_pose(&mut rng);
        let (pb, hint, label) = place(&mut rng, &a, &pa, &b, placement);
        // The cylinder as the second shape a third of the time.
        let case = if rng.chance(1.0 / 3.0) {
            Case {
                a: &b,
                pa: pb,
                b: &a,
                pb: pa,
                hint: Hint {
                    points: hint.points.map(|(x, y)| (y, x)),
                    normal: hint.normal.map(|n| -n),
                },
                warm: None,
                margin: None,
                label: format!("{:<18} {label}", format!("{}-{}", b.kind(), a.kind())),
            }
        } else {
            Case {
                a: &a,
                pa,
                b: &b,
                pb,
                hint,
                warm: None,
                margin: None,
                label: format!("{:<18} {label}", format!("{}-{}", a.kind(), b.kind())),
            }
        };
        done += ask_every_way(&mut hunt, &mut rng, case, &mut foreign);
    }
    let grid = grid_cases(&mut hunt, &mut rng);
    summarise(&hunt, total + grid, seed);
}

/// A random pair: a cylinder (alone, or a piece of a compound beside a
/// box) and another shape (alone, or a compound with a cylinder piece).
fn random_pair(rng: &mut Rng) -> (Body, Body) {
    let scale = rng.log(-9.0, 6.0);
    let cyl = random_cylinder(rng, scale);
    let other_scale = if rng.chance(0.8) {
        scale * rng.log(-1.0, 1.0)
    } else {
        rng.log(-9.0, 6.0)
    };
    let other = random_other(rng, other_scale);
    let a = if rng.chance(0.1) {
        let off = Isometry3::from_parts(
            Translation3::from(rng.direction() * scale * rng.range(0.0, 0.5)),
            special_rotation(rng),
        );
        let box_off = Isometry3::translation(2.0 * scale, 0.0, 0.0);
        let half = Vector3::new(0.3, 0.4, 0.5) * scale;
        let bx = Piece::new(Geom::Cuboid { half }, 0.0, rng);
        Body::compound(vec![(off, cyl), (box_off, bx)])
    } else {
        Body::convex(cyl)
    };
    let b = if rng.chance(0.05) {
        let off = Isometry3::from_parts(
            Translation3::from(rng.direction() * other_scale * rng.range(0.0, 2.0)),
            rng.rotation(),
        );
        let second = random_cylinder(rng, other_scale);
        Body::compound(vec![(Isometry3::identity(), other), (off, second)])
    } else {
        Body::convex(other)
    };
    (a, b)
}

/// Asks `case` cold, from `foreign` (the previous pair's warm start, if
/// it fits), from random codes, sometimes with a margin near its
/// distance and sometimes along a warm motion; leaves this pair's warm
/// start in `foreign`. Returns the number of queries checked.
fn ask_every_way(
    hunt: &mut Hunt,
    rng: &mut Rng,
    mut case: Case<'_>,
    foreign: &mut Option<WarmStart>,
) -> u64 {
    let mut asked = 1;
    let cold = hunt.check(&case, Start::Cold);
    if let Some(w) = foreign.take() {
        case.warm = Some(w);
        hunt.check(&case, Start::Foreign);
        asked += 1;
    }
    case.warm = Some(random_warm(rng, case.a, case.b));
    hunt.check(&case, Start::Random);
    asked += 1;
    case.warm = None;
    if let Some(c) = &cold
        && rng.chance(0.25)
    {
        let near = if rng.chance(0.5) {
            c.distance * (1.0 + rng.range(-1e-3, 1e-3))
        } else {
            c.distance * rng.range(0.0, 2.0)
        };
        case.margin = Some(near);
        hunt.check(&case, Start::Margin);
        case.margin = None;
        asked += 1;
    }
    *foreign = cold.map(|c| c.warm_start);
    if rng.chance(0.125) {
        asked += warm_motion(hunt, rng, &case, cold.map(|c| c.warm_start));
    }
    asked
}

/// Sixteen small steps of B (a drift and a turn) from `case`'s pose, each
/// started from the previous step's answer.
fn warm_motion(hunt: &mut Hunt, rng: &mut Rng, case: &Case<'_>, warm: Option<WarmStart>) -> u64 {
    let size = case.a.size() + case.b.size();
    let drift = rng.direction() * size * rng.log(-6.0, -1.0);
    let turn = UnitQuaternion::from_scaled_axis(rng.direction() * rng.log(-6.0, -1.0));
    let mut warm = warm;
    let mut pose_b = case.pb;
    for _ in 0..16 {
        pose_b = Isometry3::from_parts(
            Translation3::from(pose_b.translation.vector + drift),
            turn * pose_b.rotation,
        );
        let step = Case {
            a: case.a,
            pa: case.pa,
            b: case.b,
            pb: pose_b,
            hint: Hint::default(),
            warm,
            margin: None,
            label: case.label.clone(),
        };
        warm = hunt.check(&step, Start::Motion).map(|c| c.warm_start);
    }
    16
}

/// A grid of closed-form placements with round numbers, the kind a
/// hand-written test set holds: sizes 1e-9 to 1e6, at the origin and far
/// from it, under exact quarter and half turns, at gaps from touching to
/// overlapping: parallel axes side by side (caps overlapping in z),
/// coaxial caps, a cap on a box face, crossing axes side on side, a ball
/// at the rim. Each is asked cold, then warm from the previous gap's
/// answer. Returns the number of cases.
fn grid_cases(hunt: &mut Hunt, rng: &mut Rng) -> u64 {
    let s2 = FRAC_1_SQRT_2;
    let exact = |w, x, y, z| UnitQuaternion::new_unchecked(Quaternion::new(w, x, y, z));
    let turns = [
        UnitQuaternion::identity(),
        exact(s2, s2, 0.0, 0.0),
        exact(s2, 0.0, s2, 0.0),
        exact(0.0, 1.0, 0.0, 0.0),
        exact(0.5, 0.5, 0.5, 0.5),
    ];
    let mut count = 0;
    for scale in [1e-9, 1e-6, 1e-3, 1.0, 1e3, 1e6] {
        for base in [0.0, 1e3, 1e6, 1e9] {
            for rounded in [0.0, 0.1] {
                let set = GridSet::new(scale, rounded * scale, rng);
                for turn in turns {
                    let pa = Isometry3::from_parts(Translation3::new(base, -base, base), turn);
                    for placement in set.placements() {
                        count += grid_gaps(hunt, &set, &pa, &placement);
                    }
                }
            }
        }
    }
    count
}

/// The shapes of the grid at one scale and rounding.
struct GridSet {
    scale: f64,
    rho: f64,
    a: Body,
    other: Body,
    cuboid: Body,
    ball: Body,
}

/// One placement of the grid: its label, B, B's offset in A's frame at
/// gap 0, B's rotation relative to A, and the gap's direction.
struct GridPlacement<'g> {
    label: &'static str,
    b: &'g Body,
    offset: Vector3<f64>,
    rotation: UnitQuaternion<f64>,
    out: Vector3<f64>,
}

impl GridSet {
    fn new(scale: f64, rho: f64, rng: &mut Rng) -> GridSet {
        let cylinder = |r: f64, h: f64, rng: &mut Rng| {
            Body::convex(Piece::new(Geom::Cylinder { r, h }, rho, rng))
        };
        let half = Vector3::new(0.4, 0.3, 0.6) * scale;
        let centre = Geom::Segment {
            a: Vector3::zeros(),
            b: Vector3::zeros(),
        };
        GridSet {
            scale,
            rho,
            a: cylinder(0.5 * scale, scale, rng),
            other: cylinder(0.3 * scale, 0.7 * scale, rng),
            cuboid: Body::convex(Piece::new(Geom::Cuboid { half }, rho, rng)),
            ball: Body::convex(Piece::new(centre, 0.2 * scale, rng)),
        }
    }

    fn placements(&self) -> Vec<GridPlacement<'_>> {
        let s2 = FRAC_1_SQRT_2;
        let exact = |w, x, y, z| UnitQuaternion::new_unchecked(Quaternion::new(w, x, y, z));
        let flip = exact(0.0, 1.0, 0.0, 0.0);
        let quarter_z = exact(s2, 0.0, 0.0, s2);
        let across = exact(s2, s2, 0.0, 0.0);
        let none = UnitQuaternion::identity();
        let (s, radii) = (self.scale, 2.0 * self.rho);
        let at = |label, b, offset: Vector3<f64>, rotation, out: Vector3<f64>| GridPlacement {
            label,
            b,
            offset,
            rotation,
            out: out.normalize(),
        };
        let (x, z) = (Vector3::x(), Vector3::z());
        let rim = Vector3::new(s2, 0.0, s2);
        vec![
            at("side", &self.other, x * (0.8 * s + radii), flip, x),
            at(
                "side-z",
                &self.other,
                x * (0.8 * s + radii) + z * (1.6 * s),
                quarter_z,
                x,
            ),
            at("caps", &self.other, z * (1.7 * s + radii), quarter_z, z),
            at(
                "caps-off",
                &self.other,
                x * (0.6 * s) - z * (1.7 * s + radii),
                flip,
                -z,
            ),
            at(
                "box-face",
                &self.cuboid,
                Vector3::new(0.2 * s, 0.1 * s, 1.6 * s + radii),
                none,
                z,
            ),
            at("crossing", &self.other, x * (0.8 * s + radii), across, x),
            at(
                "rim-ball",
                &self.ball,
                Vector3::new(0.5 * s, 0.0, s) + rim * (0.2 * s + self.rho),
                none,
                rim,
            ),
        ]
    }
}

/// One grid placement at gaps from a thousandth of the scale to an
/// overlap of a tenth, each cold and warm from the previous gap's answer.
fn grid_gaps(hunt: &mut Hunt, set: &GridSet, pa: &Isometry3<f64>, p: &GridPlacement<'_>) -> u64 {
    let (a, scale) = (&set.a, set.scale);
    let mut warm = None;
    let mut count = 0;
    for gap in [1e-3, 1e-6, 1e-9, 1e-12, 0.0, -1e-9, -1e-6, -0.1] {
        let rel = Isometry3::from_parts(
            Translation3::from(p.offset + p.out * (gap * scale)),
            p.rotation,
        );
        let mut case = Case {
            a,
            pa: *pa,
            b: p.b,
            pb: pa * rel,
            hint: Hint::default(),
            warm: None,
            margin: None,
            label: format!("grid-{}", p.label),
        };
        hunt.check(&case, Start::Cold);
        case.warm = warm;
        warm = hunt.check(&case, Start::Motion).map(|c| c.warm_start);
        count += 2;
    }
    count
}

/// The tallies, grouped by start and kinds, and the failures by class.
fn summarise(hunt: &Hunt, total: u64, seed: u64) {
    #[derive(Default)]
    struct Group {
        cases: u64,
        judged: u64,
        other: u64,
        undecided: u64,
        worst: f64,
    }
    let mut groups: BTreeMap<String, Group> = BTreeMap::new();
    let mut statuses: BTreeMap<String, u64> = BTreeMap::new();
    let mut classes: BTreeMap<Failure, u64> = BTreeMap::new();
    let mut refused = 0;
    // Contacts by gap and by direction (the key's fourth and fifth words).
    let mut contacts: BTreeMap<String, u64> = BTreeMap::new();
    for (key, t) in &hunt.tallies {
        refused += t.refused;
        let words: Vec<&str> = key.split_whitespace().collect();
        if words.get(2) == Some(&"contact") {
            for w in &words[3..5] {
                *contacts.entry((*w).to_string()).or_default() += t.cases;
            }
        }
        // Start, kinds and placement (the first three words).
        let group: String = key.split_whitespace().take(3).collect::<Vec<_>>().join(" ");
        let g = groups.entry(group).or_default();
        g.cases += t.cases;
        for (f, n) in &t.failures {
            if f.is_judged() {
                g.judged += n;
            } else {
                g.other += n;
            }
            *classes.entry(*f).or_default() += n;
        }
        g.undecided += t.undecided;
        g.worst = g.worst.max(t.widest);
        for (s, n) in &t.statuses {
            *statuses.entry(s.clone()).or_default() += n;
        }
    }
    println!("\nseed {seed}, {total} cases asked\n");
    println!(
        "{:<48} {:>9} {:>6} {:>6} {:>9} {:>10}",
        "start, kinds, placement", "cases", "fail", "other", "undecided", "worst/bnd"
    );
    for (name, g) in &groups {
        println!(
            "{name:<48} {:>9} {:>6} {:>6} {:>9} {:>10.2e}",
            g.cases, g.judged, g.other, g.undecided, g.worst
        );
    }
    println!("\nforeign warm starts refused as out of range (not counted): {refused}");
    println!("contacts by gap and direction: {contacts:?}");
    println!("statuses: {statuses:?}");
    println!("failures by class: {classes:?}");
}
