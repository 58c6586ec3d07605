//! The paper's Section 8 as a collision sweep, in-process (no IPC): is
//! any of the five obstacles within margin 0 of the moving object at each
//! of T = 1 000 steps? Once as cold per-pair queries, five a step, and once
//! as one scene path request (within, every step):
//!
//! ```text
//! cargo run --release -p gjkd-server --example scene_sweep
//! ```

use gjkd_proto::{
    Item, ItemResult, ObjectId, PathMode, QueryOptions, SceneKind, SceneRequest, SceneRow, WaitMode,
};
use gjkd_server::engine::state::{Limits, NewObject, Owner, State};

const STEPS: usize = 1000;
const PASSES: usize = 5;

/// This thread's CPU time in seconds.
fn cpu_seconds() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: a valid clock id and a pointer to a timespec we own.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

fn main() {
    let motion = gjkd_testkit::paper::section8();
    let mut state = State::new(Limits::default(), WaitMode::Spin, 1);
    let mover = state
        .insert(
            NewObject {
                shape: motion.moving().clone(),
                pose: motion.pose(0.0),
                name: None,
            },
            Owner::Client(1),
        )
        .unwrap();
    let obstacles: Vec<u64> = motion
        .obstacles()
        .iter()
        .map(|(shape, pose)| {
            let new = NewObject {
                shape: shape.clone(),
                pose: *pose,
                name: None,
            };
            state.insert(new, Owner::Scene).unwrap()
        })
        .collect();
    let id = ObjectId::from_raw;
    let poses: Vec<_> = (0..=STEPS)
        .map(|t| motion.pose(t as f64 / STEPS as f64))
        .collect();

    // Cold per-pair queries, five a step, each step one batch.
    let mut cold_hits = 0;
    let mut cold = f64::INFINITY;
    for _ in 0..PASSES {
        let mut out = [ItemResult::default(); 5];
        let start = cpu_seconds();
        cold_hits = 0;
        for pose in &poses {
            let items: [Item; 5] = std::array::from_fn(|i| {
                let mut item = Item::distance(id(mover), id(obstacles[i]), &QueryOptions::cold());
                item = item.with_pose_a(pose);
                item
            });
            state.handle(9, &items, &mut out);
            cold_hits += out.iter().filter(|r| r.distance <= 0.0).count();
        }
        cold = cold.min(cpu_seconds() - start);
    }

    // One path request.
    let path: Vec<Item> = poses
        .iter()
        .map(|pose| Item::set_pose(id(mover), pose).ending_step())
        .collect();
    let mut request = SceneRequest::new(SceneKind::Within, mover);
    request.path = PathMode::EveryStep as u32;
    let mut rows = vec![SceneRow::default(); 5 * poses.len()];
    let mut scene = f64::INFINITY;
    let mut reply = Default::default();
    for pass in 0..PASSES {
        let start = cpu_seconds();
        reply = state.scene(100 + pass as u128, &request, &path, &mut rows);
        scene = scene.min(cpu_seconds() - start);
    }
    println!(
        "Section 8 sweep, T = {STEPS}, in process, thread CPU time, fastest of {PASSES} passes"
    );
    println!(
        "cold per-pair queries: {:.1} us ({cold_hits} pairs at distance 0)",
        cold * 1e6
    );
    println!(
        "one path request:      {:.1} us ({} pairs within 0; {} GJK runs, {} bounded, {} candidates)",
        scene * 1e6,
        reply.total,
        reply.gjk_runs,
        reply.bounded,
        reply.candidates
    );
    println!("ratio: {:.1}x", cold / scene);
}
