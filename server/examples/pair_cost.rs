//! The pair query's cost in the engine, in process, for instruction counts
//! under `valgrind --tool=callgrind`: a fixed corpus of pairs apart
//! (boxes, polytopes of 12 to 64 vertices, capsules, spheres, cylinders
//! and two-piece compounds at random poses), answered `REPEATS` times by
//! `State::handle` as the query service does.
//!
//! `cargo build --release -p gjkd-server --example pair_cost`, then
//! `valgrind --tool=callgrind target/release/examples/pair_cost off 200`
//! (or `on`: the same items with `item_flags::SIGNED_DISTANCE`, bit 7).

use gjk::{Compound, Convex, Shape};
use gjkd_proto::{Item, ItemResult, ObjectId, QueryOptions, WaitMode};
use gjkd_server::engine::objects::{NewObject, Owner};
use gjkd_server::engine::state::{Limits, State};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// A small deterministic generator (xorshift64*): the same corpus every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    fn vector(&mut self) -> Vector3<f64> {
        Vector3::new(self.next(), self.next(), self.next())
    }
}

fn shape(kind: usize, rng: &mut Rng) -> Shape {
    match kind % 6 {
        0 => Convex::cuboid(rng.vector().abs() + Vector3::repeat(0.2), 0.0)
            .unwrap()
            .into(),
        1 => {
            let n = 12 + (rng.next().abs() * 52.0) as usize;
            let points: Vec<Point3<f64>> = (0..n).map(|_| Point3::from(rng.vector())).collect();
            Convex::new(points, 0.0).unwrap().into()
        }
        2 => Convex::capsule(Point3::from(rng.vector()), Point3::from(rng.vector()), 0.2)
            .unwrap()
            .into(),
        3 => Convex::sphere(0.3 + rng.next().abs()).unwrap().into(),
        4 => Convex::cylinder(0.3 + 0.5 * rng.next().abs(), 0.5 + rng.next().abs(), 0.0)
            .unwrap()
            .into(),
        _ => Compound::new(vec![
            (
                Isometry3::translation(-0.5, 0.0, 0.0),
                Convex::sphere(0.3).unwrap(),
            ),
            (
                Isometry3::translation(0.5, 0.0, 0.0),
                Convex::cuboid(Vector3::new(0.3, 0.3, 0.3), 0.05).unwrap(),
            ),
        ])
        .unwrap()
        .into(),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let on = args.get(1).is_some_and(|a| a == "on");
    let repeats: usize = args.get(2).and_then(|r| r.parse().ok()).unwrap_or(100);
    let mut state = State::new(Limits::default(), WaitMode::Block, 1);
    let mut rng = Rng(0x5eed_0ab0_0001);
    let mut items = Vec::new();
    for k in 0..96 {
        let place = |rng: &mut Rng, centre: Vector3<f64>| {
            Isometry3::from_parts(
                Translation3::from(centre),
                UnitQuaternion::from_scaled_axis(rng.vector() * 3.0),
            )
        };
        let a = shape(k, &mut rng);
        let b = shape(k / 6 + k, &mut rng);
        // Apart: centres 5 to 7 apart, every shape within 2.1 of its centre.
        let dir = rng.vector().normalize();
        let pose_a = place(&mut rng, Vector3::zeros());
        let reach = 5.0 + 2.0 * rng.next().abs();
        let pose_b = place(&mut rng, dir * reach);
        let owner = Owner::Client(1);
        let ia = state
            .insert(
                NewObject {
                    shape: a,
                    pose: pose_a,
                    name: None,
                },
                owner,
            )
            .expect("registered");
        let ib = state
            .insert(
                NewObject {
                    shape: b,
                    pose: pose_b,
                    name: None,
                },
                owner,
            )
            .expect("registered");
        let mut item = Item::distance(
            ObjectId::from_raw(ia),
            ObjectId::from_raw(ib),
            &QueryOptions::default(),
        );
        if on {
            // item_flags::SIGNED_DISTANCE, by value so that the same file
            // builds against a tree without it (for the A/B).
            item.flags |= 1 << 7;
        }
        items.push(item);
    }
    let mut results = vec![ItemResult::default(); items.len()];
    let mut sum = 0.0;
    for _ in 0..repeats {
        state.handle(1, &items, &mut results);
        sum += results.iter().map(|r| r.distance).sum::<f64>();
    }
    let errors = results.iter().filter(|r| r.error != 0).count();
    println!(
        "pairs {} repeats {repeats} errors {errors} sum {sum:.9}",
        items.len()
    );
}
