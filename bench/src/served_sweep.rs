//! The paper's Section 8 sweep through a served `gjkd serve`: the scene
//! registered through the client library, and each sweep sent as few
//! batches as the server's batch limit allows, or as one path request
//! (`gjkd demo` and `gjkd bench sweep` time both).

use std::time::{Duration, Instant};

use gjk::Shape;
use gjkd_client::{
    Client, ClientError, Geometry, Item, ItemResult, ObjectId, Piece, QueryOptions, Status,
};
use gjkd_paper::{Motion, OBSTACLES};
use gjkd_proto::{PathMode, SceneKind, SceneReply, SceneRequest, SceneRow};
use nalgebra::Isometry3;

use crate::{BenchError, scene_call};

/// The paper's Table 1: time without warm start over time with it, for
/// T = 10, 100, 1000.
pub const PAPER_RATIOS: [(usize, f64); 3] = [(10, 1.7), (100, 2.9), (1000, 3.1)];

/// What can stop the demo.
#[derive(Debug, thiserror::Error)]
pub enum DemoError {
    /// The server process could not be started.
    #[error("cannot start the server: {0}")]
    Spawn(std::io::Error),
    /// A client call failed.
    #[error("client: {0}")]
    Client(#[from] ClientError),
    /// Connecting to the server failed.
    #[error("connect: {0}")]
    Connect(#[from] gjkd_client::ConnectError),
    /// An answer failed or disagreed with the in-process computation.
    #[error("{0}")]
    Check(String),
}

crate::from_client_operations!(DemoError);

/// The scene as registered with the server.
pub(crate) struct Registered {
    pub(crate) moving: ObjectId,
    pub(crate) obstacles: [ObjectId; OBSTACLES],
}

pub(crate) fn register(client: &mut Client, motion: &Motion) -> Result<Registered, DemoError> {
    let Shape::Compound(moving) = motion.moving() else {
        return Err(DemoError::Check(
            "the moving object is not a compound".into(),
        ));
    };
    let pieces: Vec<Piece<'_>> = moving
        .pieces()
        .iter()
        .map(|(offset, convex)| Piece {
            offset: *offset,
            geometry: Geometry::Polytope {
                vertices: convex.vertices(),
                radius: convex.radius(),
            },
        })
        .collect();
    let moving = client.register_named("KA", &Geometry::Compound(&pieces), &motion.pose(0.0))?;
    let mut obstacles = [ObjectId::from_raw(0); OBSTACLES];
    for (i, (shape, pose)) in motion.obstacles().iter().enumerate() {
        let Shape::Convex(c) = shape else {
            return Err(DemoError::Check(format!(
                "obstacle {} is not convex",
                i + 1
            )));
        };
        let geometry = Geometry::Polytope {
            vertices: c.vertices(),
            radius: c.radius(),
        };
        obstacles[i] = client.register_named(&format!("K{}", i + 1), &geometry, pose)?;
    }
    Ok(Registered { moving, obstacles })
}

/// One sweep through the server: distances per step, total iterations.
// Some fields are read by `gjkd bench sweep` only (feature `measure`).
#[cfg_attr(not(feature = "measure"), allow(dead_code))]
pub(crate) struct ServedSweep {
    pub(crate) distances: Vec<[f64; OBSTACLES]>,
    /// Per step, the obstacles proved within the query's margin (or at
    /// distance 0 without one), as bits.
    pub(crate) hits: Vec<u8>,
    pub(crate) iterations: u64,
    pub(crate) elapsed: Duration,
}

/// Reusable buffers, so that timing measures the server and not `Vec` growth.
pub(crate) struct Buffers {
    pub(crate) items: Vec<Item>,
    pub(crate) results: Vec<ItemResult>,
}

pub(crate) fn sweep(
    client: &mut Client,
    motion: &Motion,
    scene: &Registered,
    steps: usize,
    options: &QueryOptions,
    max_batch: usize,
    buffers: &mut Buffers,
) -> Result<ServedSweep, DemoError> {
    let steps = steps.max(1);
    let per_batch = (max_batch / OBSTACLES).max(1);
    // Poses are computed before the clock starts: the paper times the
    // distance computations, not the path.
    let poses: Vec<Isometry3<f64>> = (0..=steps)
        .map(|t| motion.pose(t as f64 / steps as f64))
        .collect();
    let mut distances = Vec::with_capacity(steps + 1);
    let mut hits = Vec::with_capacity(steps + 1);
    let mut iterations = 0u64;
    let mut elapsed = Duration::ZERO;
    for chunk in poses.chunks(per_batch) {
        buffers.items.clear();
        for pose in chunk {
            for &o in &scene.obstacles {
                buffers
                    .items
                    .push(Item::distance(scene.moving, o, options).with_pose_a(pose));
            }
        }
        let n = buffers.items.len();
        buffers.results.resize(n, ItemResult::default());
        let start = Instant::now();
        client.query_batch(&buffers.items, &mut buffers.results[..n])?;
        elapsed += start.elapsed();
        for step in buffers.results[..n].chunks(OBSTACLES) {
            let mut d = [0.0; OBSTACLES];
            let mut hit = 0u8;
            for (i, (slot, r)) in d.iter_mut().zip(step).enumerate() {
                let a = r
                    .answer()
                    .map_err(|e| DemoError::Check(format!("query failed: {e}")))?;
                *slot = a.distance;
                iterations += u64::from(a.iterations);
                let within = match a.status {
                    Some(Status::Closer) => true,
                    Some(Status::Farther) => false,
                    _ => a.distance <= options.margin.unwrap_or(0.0),
                };
                hit |= u8::from(within) << i;
            }
            distances.push(d);
            hits.push(hit);
        }
    }
    Ok(ServedSweep {
        distances,
        hits,
        iterations,
        elapsed,
    })
}

/// Arguments of the servers the sweep runs through: a batch limit that
/// holds a whole T = 1 000 path in one request.
pub const SERVER_ARGS: [&str; 5] = ["--wait", "spin", "--no-persist", "--max-batch", "8192"];

/// One path request's outcome.
// Some fields are read by `gjkd bench sweep` only (feature `measure`).
#[cfg_attr(not(feature = "measure"), allow(dead_code))]
pub(crate) struct PathSweep {
    /// Per step, the obstacles within the margin, as bits.
    pub(crate) hits: Vec<u8>,
    /// [`PathMode::FirstHit`]: the step that hit first.
    pub(crate) first_hit: Option<usize>,
    /// Round trip of the request.
    pub(crate) elapsed: Duration,
    /// Pair queries that ran GJK, and pairs answered from motion bounds.
    pub(crate) work: (u64, u64),
}

/// Reusable buffers of the path requests.
pub(crate) struct PathBuffers {
    items: Vec<Item>,
    rows: Vec<SceneRow>,
}

impl PathBuffers {
    /// Room for paths of up to `steps` steps.
    pub(crate) fn new(steps: usize) -> Self {
        PathBuffers {
            items: Vec::with_capacity(steps + 1),
            rows: vec![SceneRow::default(); (steps + 1) * OBSTACLES],
        }
    }
}

/// The sweep of `steps` steps as one path request in `mode`: the moving
/// object's pose per step, flagged to end it; the obstacles within margin 0.
///
/// # Errors
/// The client's, a scene error, or a truncated answer.
pub(crate) fn path_sweep(
    client: &mut Client,
    motion: &Motion,
    scene: &Registered,
    steps: usize,
    mode: PathMode,
    buf: &mut PathBuffers,
) -> Result<PathSweep, BenchError> {
    let mut call =
        |r: &SceneRequest, i: &[Item], rows: &mut [SceneRow]| scene_call::query(client, r, i, rows);
    path_sweep_with(&mut call, motion, scene, steps, mode, buf)
}

/// How a scene request is sent: through a client, or to the engine in
/// process.
pub(crate) type SceneCall<'a> =
    dyn FnMut(&SceneRequest, &[Item], &mut [SceneRow]) -> Result<SceneReply, BenchError> + 'a;

/// [`path_sweep`] with the request sent by `call`.
pub(crate) fn path_sweep_with(
    call: &mut SceneCall<'_>,
    motion: &Motion,
    scene: &Registered,
    steps: usize,
    mode: PathMode,
    buf: &mut PathBuffers,
) -> Result<PathSweep, BenchError> {
    let steps = steps.max(1);
    // Poses are computed before the clock starts, as in the demo.
    let poses: Vec<Isometry3<f64>> = (0..=steps)
        .map(|t| motion.pose(t as f64 / steps as f64))
        .collect();
    buf.items.clear();
    for pose in &poses {
        buf.items
            .push(Item::set_pose(scene.moving, pose).ending_step());
    }
    buf.rows
        .resize((steps + 1) * OBSTACLES, SceneRow::default());
    let mut request = SceneRequest::new(SceneKind::Within, scene.moving.raw());
    request.path = mode as u32;
    request.margin = 0.0;
    request.max_rows = buf.rows.len() as u32;
    let start = Instant::now();
    let reply = call(&request, &buf.items, &mut buf.rows)?;
    let elapsed = start.elapsed();
    if reply.total > u64::from(request.max_rows) {
        return Err(BenchError::Other("a path answer was truncated".into()));
    }
    let mut hits = vec![0u8; steps + 1];
    for row in &buf.rows[..reply.total as usize] {
        let obstacle = scene.obstacles.iter().position(|o| o.raw() == row.b);
        if let (Some(i), Some(h)) = (obstacle, hits.get_mut(row.step as usize)) {
            *h |= 1 << i;
        }
    }
    Ok(PathSweep {
        hits,
        first_hit: (reply.first_hit != u32::MAX).then_some(reply.first_hit as usize),
        elapsed,
        work: (reply.gjk_runs, reply.bounded),
    })
}
