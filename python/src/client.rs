//! `gjkd.Client`: the Rust client of a running server, on numpy arrays.

use std::time::Duration;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use gjkd_client::{ClientError, Gradient, Item, ItemResult};

use gjkd_client::{LimitMode, RobotHandle, SceneSummary};
use gjkd_proto::{Pose, SceneRequest, SceneRow};
use nalgebra::Isometry3;

use crate::api::{Backend, backend_methods};
use crate::backend::{Outcome, RobotText};
use crate::errors::{self, invalid};
use crate::runner::{Answerer, Buffers, OnThisThread};
use crate::shape::{Registration, isometry, wire_registration};

/// Batch size assumed before a server has said its own.
const DEFAULT_MAX_BATCH: usize = 1024;

/// A connection to a gjkd server (`python -m gjkd serve`, `gjkd serve`, or
/// `gjkd.Server`) on this host, over shared memory.
///
/// `Client(service="gjkd", timeout=1.0, connect_timeout=None,
/// remove_on_close=False)` connects to the server of `service`, waiting up
/// to `connect_timeout` seconds (default: `timeout`) for one to come up;
/// `timeout` bounds every later call. Use it as a context manager, or call
/// `close()`. Objects outlive the client that registered them (a server
/// with persistence keeps them across restarts); with
/// `remove_on_close=True` the objects and robots this client registers are
/// removed when it closes (best effort: a server gone then keeps them).
///
/// Register objects once (`register_sphere`, `register_box`, ...: each
/// returns an int id), store their poses (`set_pose`, `set_poses`), then
/// ask `distance(a, b)` for one pair or `distances(pairs)` for many in one
/// round trip. The server keeps each pair's last simplex for this client,
/// so a sequence of queries along a motion starts warm.
///
/// Failures of a whole call raise a `gjkd.Error`: `ServerGone` when no
/// server serves the name (the next call reconnects by itself once one
/// does), `Timeout`, `InvalidInput` (with `code`, `field` and `index`),
/// `NotFound`, `Refused`. The GIL is released during every round trip.
/// A `Client` belongs to the thread that created it: create one per thread.
#[pyclass(unsendable, module = "gjkd", name = "Client")]
pub struct Client {
    conn: Connection,
    buffers: Buffers,
    service: String,
    timeout: f64,
}

/// The Rust client, the answerer of batches.
struct Connection {
    /// `None` once closed.
    inner: Option<gjkd_client::Client>,
    /// The server's batch limit, as last heard.
    max_batch: usize,
}

impl Connection {
    /// Runs `call` on the client, then learns the server's batch limit as
    /// last heard (a reconnect may have changed it).
    fn run<R>(
        &mut self,
        call: impl FnOnce(&mut gjkd_client::Client) -> Result<R, ClientError>,
    ) -> Result<R, ClientError> {
        let Some(client) = self.inner.as_mut() else {
            return Err(ClientError::Protocol("the client is closed".into()));
        };
        let outcome = call(client);
        if let Some(info) = client.server_info() {
            self.max_batch = info.max_batch as usize;
        }
        outcome
    }
}

impl Answerer for Connection {
    fn max_batch(&self) -> usize {
        self.max_batch
    }

    fn answer(&mut self, items: &[Item], results: &mut [ItemResult]) -> Result<(), ClientError> {
        self.run(|client| {
            client
                .query_batch(items, results)
                .map_err(ClientError::from)
        })
    }

    fn answer_gradients(
        &mut self,
        items: &[Item],
        results: &mut [ItemResult],
        gradients: &mut [Gradient],
    ) -> Result<(), ClientError> {
        self.run(|client| {
            client
                .query_batch_gradients(items, results, gradients)
                .map(|_| ())
                .map_err(ClientError::from)
        })
    }

    fn refresh_limit(&mut self) -> bool {
        let known = self
            .inner
            .as_ref()
            .and_then(|c| c.server_info())
            .map(|i| i.max_batch as usize);
        match known {
            Some(m) if m != self.max_batch && m > 0 => {
                self.max_batch = m;
                true
            }
            _ => false,
        }
    }
}

fn closed(py: Python<'_>) -> PyErr {
    errors::Raise {
        kind: errors::Kind::Other,
        message: "the client is closed".into(),
        code: None,
        field: None,
        index: None,
    }
    .into_err(py)
}

fn seconds(py: Python<'_>, field: &str, s: f64) -> PyResult<Duration> {
    Duration::try_from_secs_f64(s)
        .ok()
        .filter(|d| !d.is_zero())
        .ok_or_else(|| {
            invalid(
                py,
                field,
                None,
                format!("{field} must be a positive number of seconds"),
            )
        })
}

/// Registers `g`, named at `pose` (the identity without one), or unnamed
/// and then moved to `pose` if there is one.
fn register_at(
    c: &mut gjkd_client::Client,
    g: &gjkd_client::Geometry<'_>,
    name: Option<&str>,
    pose: Option<nalgebra::Isometry3<f64>>,
) -> Result<gjkd_client::ObjectId, ClientError> {
    let iso = pose.unwrap_or_else(nalgebra::Isometry3::identity);
    match name {
        Some(n) => Ok(c.register_named(n, g, &iso)?),
        None => {
            let id = c.register(g)?;
            if pose.is_some() {
                c.set_pose(id, &iso)?;
            }
            Ok(id)
        }
    }
}

impl Client {
    /// Runs `call` on the Rust client with the GIL released; the outer
    /// error is this class's own (a closed client), the inner one the
    /// call's, whichever operation's error it was (`RegisterError`,
    /// `QueryError`, ...), read as the umbrella [`ClientError`]: one fault,
    /// one Python exception and code (`errors::client`).
    fn call<R, E: Into<ClientError>>(
        &mut self,
        py: Python<'_>,
        call: impl FnOnce(&mut gjkd_client::Client) -> Result<R, E>,
    ) -> PyResult<Result<R, ClientError>> {
        let client = OnThisThread::new(self.inner_client(py)?);
        let call = OnThisThread::new(call);
        Ok(py
            .detach(move || {
                let (client, call) = (client.into_inner(), call.into_inner());
                OnThisThread::new(call(client).map_err(Into::into))
            })
            .into_inner())
    }

    fn inner_client(&mut self, py: Python<'_>) -> PyResult<&mut gjkd_client::Client> {
        self.conn.inner.as_mut().ok_or_else(|| closed(py))
    }

    /// Ends the connection; later calls raise.
    fn close(&mut self) {
        self.conn.inner = None;
    }
}

impl Backend for Client {
    fn parts(&mut self, py: Python<'_>) -> PyResult<(&mut dyn Answerer, &mut Buffers)> {
        if self.conn.inner.is_none() {
            return Err(closed(py));
        }
        Ok((&mut self.conn, &mut self.buffers))
    }

    fn register(
        &mut self,
        py: Python<'_>,
        what: &Registration<'_>,
        name: Option<&str>,
        pose: Option<Pose>,
    ) -> PyResult<u64> {
        // Built here only to refuse a name that is too long with the same
        // error `gjkd.Local` gives.
        wire_registration(py, what, name, pose.unwrap_or(Pose::IDENTITY))?;
        let iso = isometry(&pose.unwrap_or(Pose::IDENTITY));
        let result = match what {
            Registration::Convex(shape) => {
                let g = shape.geometry();
                self.call(py, |c| register_at(c, &g, name, pose.map(|_| iso)))?
            }
            Registration::Compound(pieces) => {
                let list = pieces.client_pieces();
                let g = gjkd_client::Geometry::Compound(&list);
                self.call(py, |c| register_at(c, &g, name, pose.map(|_| iso)))?
            }
        };
        result
            .map(|id| id.raw())
            .map_err(|e| errors::client(py, e, None))
    }

    fn remove(&mut self, py: Python<'_>, id: u64) -> PyResult<()> {
        self.call(py, |c| c.remove(gjkd_client::ObjectId::from_raw(id)))?
            .map_err(|e| errors::client(py, e, Some("id")))
    }

    fn lookup(&mut self, py: Python<'_>, name: &str) -> PyResult<u64> {
        self.call(py, |c| c.lookup(name))?
            .map(|id| id.raw())
            .map_err(|e| errors::client(py, e, Some("name")))
    }

    fn stored_poses(
        &mut self,
        py: Python<'_>,
        ids: &[u64],
    ) -> PyResult<Vec<Result<Pose, gjkd_client::ErrorCode>>> {
        let ids: Vec<gjkd_client::ObjectId> = ids
            .iter()
            .map(|&id| gjkd_client::ObjectId::from_raw(id))
            .collect();
        let got = self
            .call(py, |c| c.poses(&ids))?
            .map_err(|e| errors::client(py, e, Some("ids")))?;
        Ok(got
            .iter()
            .map(|r| r.as_ref().map(Pose::from_isometry).map_err(|c| *c))
            .collect())
    }

    fn register_robot(&mut self, py: Python<'_>, robot: &RobotText<'_>) -> Outcome<RobotHandle> {
        self.call(py, |c| {
            c.register_robot_text(
                robot.name,
                robot.urdf,
                robot.srdf,
                robot.mesh_base,
                robot.packages,
                robot.base,
            )
        })
    }

    fn open_robot(&mut self, py: Python<'_>, name: &str, urdf: &str) -> Outcome<RobotHandle> {
        self.call(py, |c| c.open_robot(name, urdf))
    }

    fn remove_robot(&mut self, py: Python<'_>, name: &str) -> Outcome<()> {
        self.call(py, |c| c.remove_robot(name))
    }

    fn set_joints(
        &mut self,
        py: Python<'_>,
        robot: &mut RobotHandle,
        positions: &[f64],
        base: Option<&Isometry3<f64>>,
        mode: LimitMode,
    ) -> Outcome<()> {
        self.call(py, |c| c.set_joints_with(robot, positions, base, mode))
    }

    fn scene(
        &mut self,
        py: Python<'_>,
        request: &SceneRequest,
        count: usize,
        item: &mut dyn FnMut(usize) -> Item,
        read: &mut dyn FnMut(&[SceneRow]),
    ) -> Outcome<SceneSummary> {
        self.call(py, |c| c.scene_with(request, count, item, read))
    }
}

backend_methods!(Client, {
    #[new]
    #[pyo3(signature = (service = "gjkd", timeout = 1.0, connect_timeout = None, remove_on_close = false))]
    fn new(
        py: Python<'_>,
        service: &str,
        timeout: f64,
        connect_timeout: Option<f64>,
        remove_on_close: bool,
    ) -> PyResult<Self> {
        let t = seconds(py, "timeout", timeout)?;
        let ct = connect_timeout
            .map(|s| seconds(py, "connect_timeout", s))
            .transpose()?;
        let mut builder = gjkd_client::Client::builder(service)
            .timeout(t)
            .remove_on_close(remove_on_close);
        if let Some(ct) = ct {
            builder = builder.connect_timeout(ct);
        }
        let connected = py
            .detach(move || OnThisThread::new(builder.connect()))
            .into_inner();
        let inner = connected.map_err(|e| errors::client(py, e, None))?;
        let max_batch = inner
            .server_info()
            .map_or(DEFAULT_MAX_BATCH, |i| i.max_batch as usize);
        Ok(Client {
            conn: Connection {
                inner: Some(inner),
                max_batch,
            },
            buffers: Buffers::default(),
            service: service.to_owned(),
            timeout,
        })
    }

    /// The service name.
    #[getter]
    fn service(&self) -> &str {
        &self.service
    }

    /// The timeout of every call, in seconds.
    #[getter]
    fn timeout(&self) -> f64 {
        self.timeout
    }

    /// Whether the client holds a connection (it may still find out at the
    /// next call that the server is gone).
    #[getter]
    fn connected(&self) -> bool {
        self.conn.inner.as_ref().is_some_and(|c| c.is_connected())
    }

    /// What the server said about itself at the last (re)connection, as a
    /// dict (`protocol`, `wait`, `max_batch`, `max_rows`, `max_vertices`,
    /// `max_pieces`, `max_clients`, `max_objects`, `pid`); `None` while
    /// disconnected.
    fn server_info<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(info) = self.conn.inner.as_ref().and_then(|c| c.server_info()) else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("protocol", info.protocol)?;
        d.set_item("wait", info.wait)?;
        d.set_item("max_batch", info.max_batch)?;
        d.set_item("max_rows", info.max_rows)?;
        d.set_item("max_vertices", info.max_vertices)?;
        d.set_item("max_pieces", info.max_pieces)?;
        d.set_item("max_clients", info.max_clients)?;
        d.set_item("max_objects", info.max_objects)?;
        d.set_item("pid", info.pid)?;
        Ok(Some(d))
    }

    /// The server's counters as a dict: `objects`, `requests`, `items`,
    /// `item_errors`, `cache_entries`, `cache_capacity`, `cache_hits`,
    /// `cache_misses`, `cache_evictions`, `clients`, `persist_errors`.
    fn stats<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self
            .call(py, |c| c.stats())?
            .map_err(|e| errors::client(py, e, None))?;
        let d = PyDict::new(py);
        d.set_item("objects", s.objects)?;
        d.set_item("requests", s.requests)?;
        d.set_item("items", s.items)?;
        d.set_item("item_errors", s.item_errors)?;
        d.set_item("cache_entries", s.cache_entries)?;
        d.set_item("cache_capacity", s.cache_capacity)?;
        d.set_item("cache_hits", s.cache_hits)?;
        d.set_item("cache_misses", s.cache_misses)?;
        d.set_item("cache_evictions", s.cache_evictions)?;
        d.set_item("clients", s.clients)?;
        d.set_item("persist_errors", s.persist_errors)?;
        Ok(d)
    }

    /// Closes the connection; later calls raise `gjkd.Error`.
    #[pyo3(name = "close")]
    fn py_close(&mut self) {
        self.close();
    }

    fn __repr__(&self) -> String {
        format!(
            "gjkd.Client(service={:?}, timeout={})",
            self.service, self.timeout
        )
    }
});

crate::robot_api::robot_methods!(Client);
crate::scene_api::scene_methods!(Client);
