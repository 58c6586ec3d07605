//! `gjkd.Local`: the same calls as `gjkd.Client`, answered in this process.

use pyo3::prelude::*;

use gjkd_client::{ClientError, Gradient, Item, ItemResult, LimitMode, RobotHandle, SceneSummary};
use gjkd_proto::{AdminOp, AdminRequest, Pose, SceneRequest, SceneRow};
use nalgebra::Isometry3;

use crate::api::{Backend, backend_methods};
use crate::backend::{Outcome, RobotText};
use crate::errors;
use crate::local_calls::{self, SceneScratch};
use crate::runner::{Answerer, Buffers, OnThisThread};
use crate::server_lib::{Limits, Store};
use crate::shape::{Registration, wire_registration};

/// Objects and robots held in this Python process, and the distances
/// between them, with no server: the same methods as `gjkd.Client` (but
/// the server's own: `service`, `timeout`, `connected`, `server_info`,
/// `stats`), the same arrays, the same errors. A robot script runs
/// unchanged with `gjkd.Local()` in place of `gjkd.Client()`:
/// `register_robot`, `open_robot`, `remove_robot`, `set_joints`, pose
/// read-back, and the scene questions (`clearance`, `within`, `nearest`,
/// `path`, `path_joints`, continuous paths, gradient and signed rows).
///
/// `Local(max_vertices=100000, cache_capacity=65536)`. The queries run the
/// server's own request handlers over the same `gjk` algorithm, so for the
/// same objects, poses, options and order of queries, `Local` answers bit
/// for bit what a server answers one `Client`. That includes warm starts:
/// like a server, `Local` keeps the last simplex of every ordered pair
/// queried with `warm_start=True` (up to `cache_capacity` pairs, the
/// least recently used dropped first), and the next warm query of the pair
/// starts from it. (A server keeps one such cache per client: a second
/// `Client` querying the same pairs starts cold where `Local` starts warm.)
/// `forget_warm_starts()` empties it (and the scene questions' warm starts
/// and motion bounds, kept apart as a server keeps them per client port).
/// A path of any length is answered whole, as a `Client` splits a long
/// path into requests the server takes and joins the answers.
///
/// The GIL is released while a batch, a robot registration or a scene
/// question is answered. A `Local` belongs to the
/// thread that created it.
#[pyclass(unsendable, module = "gjkd", name = "Local")]
pub struct Local {
    store: LocalStore,
    buffers: Buffers,
    scene: SceneScratch,
}

/// The store as the answerer of batches.
struct LocalStore {
    store: Store,
}

impl Answerer for LocalStore {
    fn max_batch(&self) -> usize {
        self.store.limits().max_batch
    }

    fn answer(&mut self, items: &[Item], results: &mut [ItemResult]) -> Result<(), ClientError> {
        self.store.handle(items, results);
        Ok(())
    }

    fn answer_gradients(
        &mut self,
        items: &[Item],
        results: &mut [ItemResult],
        gradients: &mut [Gradient],
    ) -> Result<(), ClientError> {
        self.store.handle_gradients(items, results, gradients);
        Ok(())
    }
}

impl Local {
    fn admin(
        &mut self,
        py: Python<'_>,
        request: &AdminRequest,
        vertices: &[gjkd_proto::Vertex],
        field: Option<&str>,
    ) -> PyResult<u64> {
        self.store
            .store
            .admin(request, gjkd_proto::AdminChunk::from_vertices(vertices))
            .map_err(|code| errors::refused(py, code, field, None))
    }

    fn close(&mut self) {}

    /// Runs `call` on the store with the GIL released (a robot's meshes
    /// load, a path is answered), as a `Client` waits for its server.
    fn detached<R>(
        &mut self,
        py: Python<'_>,
        call: impl FnOnce(&mut Store, &mut SceneScratch) -> R,
    ) -> R {
        let parts = OnThisThread::new((&mut self.store.store, &mut self.scene, call));
        py.detach(move || {
            let (store, scratch, call) = parts.into_inner();
            OnThisThread::new(call(store, scratch))
        })
        .into_inner()
    }
}

impl Backend for Local {
    fn parts(&mut self, _py: Python<'_>) -> PyResult<(&mut dyn Answerer, &mut Buffers)> {
        Ok((&mut self.store, &mut self.buffers))
    }

    fn register(
        &mut self,
        py: Python<'_>,
        what: &Registration<'_>,
        name: Option<&str>,
        pose: Option<Pose>,
    ) -> PyResult<u64> {
        let (request, vertices) =
            wire_registration(py, what, name, pose.unwrap_or(Pose::IDENTITY))?;
        self.admin(py, &request, &vertices, None)
    }

    fn remove(&mut self, py: Python<'_>, id: u64) -> PyResult<()> {
        let mut request = AdminRequest::new(AdminOp::Remove);
        request.object = id;
        self.admin(py, &request, &[], Some("id")).map(|_| ())
    }

    fn lookup(&mut self, py: Python<'_>, name: &str) -> PyResult<u64> {
        let mut request = AdminRequest::new(AdminOp::Lookup);
        if !request.set_name(name) {
            return Err(errors::invalid(py, "name", None, "name too long".into()));
        }
        self.admin(py, &request, &[], Some("name"))
    }

    fn stored_poses(
        &mut self,
        _py: Python<'_>,
        ids: &[u64],
    ) -> PyResult<Vec<Result<Pose, gjkd_proto::ErrorCode>>> {
        let mut out = vec![gjkd_proto::StoredPose::default(); ids.len()];
        self.store.store.poses(ids, &mut out);
        Ok(out.iter().map(gjkd_proto::StoredPose::pose).collect())
    }

    fn register_robot(&mut self, py: Python<'_>, robot: &RobotText<'_>) -> Outcome<RobotHandle> {
        Ok(self.detached(py, |store, _| local_calls::register_robot(store, robot)))
    }

    fn open_robot(&mut self, py: Python<'_>, name: &str, urdf: &str) -> Outcome<RobotHandle> {
        Ok(self.detached(py, |store, _| local_calls::open_robot(store, name, urdf)))
    }

    fn remove_robot(&mut self, py: Python<'_>, name: &str) -> Outcome<()> {
        Ok(self.detached(py, |store, _| local_calls::remove_robot(store, name)))
    }

    fn set_joints(
        &mut self,
        py: Python<'_>,
        robot: &mut RobotHandle,
        positions: &[f64],
        base: Option<&Isometry3<f64>>,
        mode: LimitMode,
    ) -> Outcome<()> {
        Ok(self.detached(py, |store, scratch| {
            local_calls::set_joints(store, scratch, robot, positions, base, mode)
        }))
    }

    fn scene(
        &mut self,
        py: Python<'_>,
        request: &SceneRequest,
        count: usize,
        item: &mut dyn FnMut(usize) -> Item,
        read: &mut dyn FnMut(&[SceneRow]),
    ) -> Outcome<SceneSummary> {
        Ok(self.detached(py, |store, scratch| {
            local_calls::scene(store, scratch, request, count, item, read)
        }))
    }
}

backend_methods!(Local, {
    #[new]
    #[pyo3(signature = (max_vertices = 100_000, cache_capacity = 65_536))]
    fn new(max_vertices: usize, cache_capacity: usize) -> Self {
        let limits = Limits {
            max_vertices,
            cache_capacity,
            ..Limits::default()
        };
        Local {
            store: LocalStore {
                store: Store::new(limits),
            },
            buffers: Buffers::default(),
            scene: SceneScratch::default(),
        }
    }

    /// Number of objects held.
    fn __len__(&self) -> usize {
        self.store.store.len()
    }

    /// Forgets every pair's last simplex: the next query of each starts
    /// cold.
    fn forget_warm_starts(&mut self) {
        self.store.store.forget_warm_starts();
    }

    /// Does nothing (a `Local` holds no connection); there for symmetry
    /// with `Client.close`.
    #[pyo3(name = "close")]
    fn py_close(&mut self) {
        self.close();
    }

    fn __repr__(&self) -> String {
        format!("gjkd.Local(<{} objects>)", self.store.store.len())
    }
});

crate::robot_api::robot_methods!(Local);
crate::scene_api::scene_methods!(Local);
