//! gjk beside parry3d-f64 on randomised extreme cases whose distance is known
//! by construction (the generator of `gjkd_testkit::sweep`, as in
//! `testkit/tests/random_extremes.rs`).
//!
//! ```text
//! cargo run --release -p gjkd-bench --example extremes_compare [CASES] [SEED]
//! ```
//!
//! Each case is checked against the issue's requirement: the distance within
//! 1e-6 of the truth, or 1e-9 of the size where that is larger; for gjk, also
//! the certified bounds around the truth. Both libraries get the same world
//! geometry: parry its typed primitive where one fits (ball, capsule, segment,
//! cuboid, triangle, rounded or not), else `SharedShape::convex_hull` of the
//! same points (rounded by `round_convex_hull`), and for collinear or
//! coplanar sets, whose hull parry declines, a capsule or two triangles.
//! Cases: CASES (default 20 000); one in 500 may draw a 100 000-point body.

use std::collections::BTreeMap;

use gjk::{Options, Status};
use gjkd_testkit::parry::parry_pose;
use gjkd_testkit::sweep::{self, Body, Case, Contact, Form, P, Rng, V};
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::shape::SharedShape;

fn vector(p: &P) -> Vector {
    Vector::new(p.x, p.y, p.z)
}

/// The parry shape a parry user would build for `b`.
fn parry_shape(b: &Body) -> SharedShape {
    let r = b.radius;
    let unshifted = b.shift == V::zeros();
    let hull = |pts: &[P]| -> Option<SharedShape> {
        let pts: Vec<Vector> = pts.iter().map(vector).collect();
        if r > 0.0 {
            SharedShape::round_convex_hull(&pts, r)
        } else {
            SharedShape::convex_hull(&pts)
        }
    };
    let v = &b.vertices;
    match b.form {
        Form::Ball if unshifted => SharedShape::ball(r),
        // A ball whose centre is off the body origin: a capsule of length 0.
        Form::Ball => SharedShape::capsule(vector(&v[0]), vector(&v[0]), r),
        Form::Capsule if r > 0.0 => SharedShape::capsule(vector(&v[0]), vector(&v[1]), r),
        Form::Capsule => SharedShape::segment(vector(&v[0]), vector(&v[1])),
        Form::Cuboid(h) if unshifted && r > 0.0 => SharedShape::round_cuboid(h.x, h.y, h.z, r),
        Form::Cuboid(h) if unshifted => SharedShape::cuboid(h.x, h.y, h.z),
        Form::Triangle if r > 0.0 => {
            SharedShape::round_triangle(vector(&v[0]), vector(&v[1]), vector(&v[2]), r)
        }
        Form::Triangle => SharedShape::triangle(vector(&v[0]), vector(&v[1]), vector(&v[2])),
        Form::Cuboid(_) | Form::Points => hull(v).unwrap_or_else(|| match b.outline.as_slice() {
            [a, c] if r > 0.0 => SharedShape::capsule(vector(a), vector(c), r),
            [a, c] => SharedShape::segment(vector(a), vector(c)),
            [c0, c1, c2, c3] => {
                let tri = |x: &P, y: &P, z: &P| {
                    if r > 0.0 {
                        SharedShape::round_triangle(vector(x), vector(y), vector(z), r)
                    } else {
                        SharedShape::triangle(vector(x), vector(y), vector(z))
                    }
                };
                SharedShape::compound(vec![
                    (Pose::IDENTITY, tri(c0, c1, c3)),
                    (Pose::IDENTITY, tri(c0, c3, c2)),
                ])
            }
            _ => panic!("parry declined the hull of {}", b.name),
        }),
    }
}

#[derive(Default)]
struct Tally {
    cases: usize,
    gjk_distance: usize,
    gjk_bounds: usize,
    gjk_uncertified: usize,
    parry_distance: usize,
    parry_unsupported: usize,
    /// Worst |error| / allowed.
    gjk_worst: f64,
    parry_worst: f64,
}

impl Tally {
    fn add(&mut self, o: &Tally) {
        self.cases += o.cases;
        self.gjk_distance += o.gjk_distance;
        self.gjk_bounds += o.gjk_bounds;
        self.gjk_uncertified += o.gjk_uncertified;
        self.parry_distance += o.parry_distance;
        self.parry_unsupported += o.parry_unsupported;
        self.gjk_worst = self.gjk_worst.max(o.gjk_worst);
        self.parry_worst = self.parry_worst.max(o.parry_worst);
    }

    fn row(&self, label: &str) {
        println!(
            "{label:<24} {:>7} | {:>6} {:>6} {:>6} {:>9.3e} | {:>6} {:>5} {:>9.3e}",
            self.cases,
            self.gjk_distance,
            self.gjk_bounds,
            self.gjk_uncertified,
            self.gjk_worst,
            self.parry_distance,
            self.parry_unsupported,
            self.parry_worst,
        );
    }
}

fn allowed(case: &Case) -> f64 {
    (1e-6 * case.truth).max(1e-9 * case.size) + case.truth_slack
}

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().map_or(20_000, |s| s.parse().expect("CASES"));
    let seed: u64 = args.next().map_or(1, |s| s.parse().expect("SEED"));
    let mut rng = Rng::new(seed);
    let options = Options::default();
    let mut by_contact: BTreeMap<Contact, Tally> = BTreeMap::new();
    let mut by_gap: BTreeMap<String, Tally> = BTreeMap::new();
    let mut by_scale: BTreeMap<String, Tally> = BTreeMap::new();
    let mut by_offset: BTreeMap<String, Tally> = BTreeMap::new();
    let mut examples: Vec<String> = Vec::new();
    for i in 0..n {
        let case = draw_case(&mut rng, i);
        let mut t = Tally {
            cases: 1,
            ..Tally::default()
        };
        let ans = gjk::distance(
            &case.a.shape(),
            &case.pa,
            &case.b.shape(),
            &case.pb,
            &options,
            None,
        )
        .expect("valid input");
        let err = (ans.distance - case.truth).abs() / allowed(&case);
        t.gjk_worst = err;
        if sweep::distance_error(&case, ans.distance).is_some() {
            t.gjk_distance = 1;
            if examples.len() < 5 {
                examples.push(format!(
                    "gjk: {}: got {:e} [{:e}, {:e}]",
                    case.describe(),
                    ans.distance,
                    ans.lower,
                    ans.upper
                ));
            }
        }
        if sweep::bounds_error(&case, ans.lower, ans.upper).is_some() {
            t.gjk_bounds = 1;
        }
        if ans.status != Status::Converged {
            t.gjk_uncertified = 1;
        }
        let (sa, sb) = (parry_shape(&case.a), parry_shape(&case.b));
        let (pa, pb) = (parry_pose(&case.pa), parry_pose(&case.pb));
        match parry3d_f64::query::distance(&pa, &*sa, &pb, &*sb) {
            Ok(d) => {
                let d = d.distance;
                t.parry_worst = (d - case.truth).abs() / allowed(&case);
                t.parry_distance = usize::from(sweep::distance_error(&case, d).is_some());
            }
            Err(_) => t.parry_unsupported = 1,
        }
        by_contact.entry(case.contact).or_default().add(&t);
        by_gap
            .entry(format!("gap {:e}", case.gap))
            .or_default()
            .add(&t);
        by_scale
            .entry(format!("scale {:e}", decade(case.scale)))
            .or_default()
            .add(&t);
        by_offset
            .entry(format!("offset {:e}", case.offset))
            .or_default()
            .add(&t);
    }
    println!("{n} cases, seed {seed}; gjk Options::default(), parry3d-f64 0.31 query::distance");
    println!(
        "failures: distance outside max(1e-6·truth, 1e-9·size); bounds missing the truth; not Converged (gjk's own status)"
    );
    println!(
        "{:<24} {:>7} | {:>6} {:>6} {:>6} {:>9} | {:>6} {:>5} {:>9}",
        "", "cases", "gjk", "bounds", "status", "worst", "parry", "unsup", "worst"
    );
    let mut total = Tally::default();
    for (k, t) in &by_contact {
        t.row(&format!("{k:?}"));
        total.add(t);
    }
    total.row("all");
    for group in [&by_gap, &by_scale, &by_offset] {
        println!();
        for (k, t) in group {
            t.row(k);
        }
    }
    if !examples.is_empty() {
        println!("\nFirst gjk failures:");
        for e in &examples {
            println!("{e}");
        }
    }
}

fn draw_case(rng: &mut Rng, i: usize) -> Case {
    sweep::draw(rng, i % 500 == 499)
}

/// The power of ten nearest below `x`.
fn decade(x: f64) -> f64 {
    10f64.powi(x.log10().round() as i32)
}
