//! The server's state: the façade over the parts the engine owns (the
//! object store, the warm-start cache, the robots, the group queries'
//! engine), with the limits and counters the request handlers
//! ([`super::handlers`]) work with. No iceoryx2 and no file in sight, so
//! that it can be tested and fuzzed in-process.

use gjkd_proto::{ErrorCode, MAX_PIECES, ServerInfo, ServerStats, WaitMode};

use nalgebra::Isometry3;

use super::durability::{CommitError, Durability};
use super::gradient::LinkPoses;
use super::group_queries::GroupQueries;
pub use super::objects::{BULK_REMOVAL, NewObject, Object, ObjectStore, Owner};
use super::records::Snapshot;
use super::robots::{NewRobot, Robots};
use super::tokens::TokenKey;
use super::warm_cache::WarmCache;

/// Limits the server enforces, also used to size the iceoryx2 services.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Most clients at once: iceoryx2 client ports per service, and each
    /// `gjkd-client` `Client` has one on the query and one on the admin
    /// service.
    pub max_clients: usize,
    /// Most iceoryx2 nodes (processes or `Client`s) attached to a service.
    pub max_nodes: usize,
    /// Most items in one query or scene request.
    pub max_batch: usize,
    /// Most rows in one scene answer. Separate from `max_batch` because
    /// one item of a path asks for a row per group member and step: a
    /// robot path's answer has many more rows than its request has items.
    pub max_rows: usize,
    /// Most vertices in one registration (all pieces together).
    pub max_vertices: usize,
    /// Most pieces in a compound, at most [`MAX_PIECES`].
    pub max_pieces: usize,
    /// Most objects held at once.
    pub max_objects: usize,
    /// Most warm-start cache entries.
    pub cache_capacity: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_clients: 128,
            max_nodes: 256,
            max_batch: 1024,
            max_rows: 4096,
            max_vertices: 100_000,
            max_pieces: MAX_PIECES,
            max_objects: 1 << 20,
            cache_capacity: 1 << 16,
        }
    }
}

/// Everything the server holds.
#[derive(Debug)]
pub struct State {
    pub(crate) limits: Limits,
    wait: WaitMode,
    pid: u64,
    pub(crate) store: ObjectStore,
    pub(crate) cache: WarmCache,
    pub(crate) stats: ServerStats,
    /// Scratch memory of gjk queries, reused from one query to the next.
    pub(crate) workspace: gjk::Workspace,
    /// Query clients connected, as last seen by the serving loop.
    clients: u64,
    /// Robots: kinematics attached to link objects (see [`crate::engine::robots`]).
    pub(crate) robots: Robots,
    /// The scene service's broadphase and buffers (see
    /// [`crate::engine::group_queries`]).
    pub(crate) groups: GroupQueries,
    /// Link poses of the query service's gradients (see
    /// [`crate::engine::gradient`]).
    pub(crate) gradient_poses: LinkPoses,
}

impl State {
    /// An empty store. `epoch` goes into the upper 32 bits of every id (0 is
    /// replaced by 1, so that no id is 0).
    pub fn new(limits: Limits, wait: WaitMode, epoch: u32) -> Self {
        Self::with_store(limits, wait, ObjectStore::new(epoch))
    }

    fn with_store(limits: Limits, wait: WaitMode, store: ObjectStore) -> Self {
        State {
            limits,
            wait,
            pid: u64::from(std::process::id()),
            store,
            cache: WarmCache::new(limits.cache_capacity),
            stats: ServerStats::default(),
            clients: 0,
            workspace: gjk::Workspace::new(),
            robots: Robots::default(),
            groups: GroupQueries::default(),
            gradient_poses: LinkPoses::default(),
        }
    }

    /// A state holding the objects of `snapshot` with their exact ids (see
    /// [`ObjectStore::restore`]).
    ///
    /// # Errors
    /// As [`ObjectStore::restore`], with `limits.max_objects`.
    pub fn restore(limits: Limits, wait: WaitMode, snapshot: &Snapshot) -> Result<Self, String> {
        let store = ObjectStore::restore(snapshot, limits.max_objects)?;
        Ok(Self::with_store(limits, wait, store))
    }

    /// The object store.
    pub fn store(&self) -> &ObjectStore {
        &self.store
    }

    /// Everything needed to rebuild the store (see [`ObjectStore::snapshot`]).
    pub fn snapshot(&self) -> Snapshot {
        self.store.snapshot()
    }

    /// Takes journaled poses in place of the restored ones (see
    /// [`ObjectStore::recover_poses`]).
    pub fn recover_poses(
        &mut self,
        journaled: impl Fn(u32, u64) -> Option<Isometry3<f64>>,
    ) -> Vec<u64> {
        self.store.recover_poses(journaled)
    }

    /// Turns persistence on (see [`ObjectStore::set_durability`]).
    pub fn set_durability(&mut self, durable: Box<dyn Durability>, tokens: Vec<(TokenKey, u64)>) {
        self.store.set_durability(durable, tokens);
    }

    /// Whether persistence is on.
    pub fn is_durable(&self) -> bool {
        self.store.is_durable()
    }

    /// Writes the store into the database (see [`ObjectStore::persist`]).
    ///
    /// # Errors
    /// As [`ObjectStore::persist`].
    pub fn persist(&mut self) -> Result<(), CommitError> {
        self.store.persist()
    }

    /// Puts the pose journal on disk (see [`ObjectStore::flush`]).
    ///
    /// # Errors
    /// The `msync` error.
    pub fn flush(&mut self) -> std::io::Result<()> {
        self.store.flush()
    }

    /// Records how many query clients are connected (for [`State::stats`]).
    pub fn set_clients(&mut self, clients: usize) {
        self.clients = clients as u64;
    }

    /// Installs a scene object (see [`ObjectStore::adopt_scene_object`]).
    ///
    /// # Errors
    /// As [`ObjectStore::insert`].
    pub fn adopt_scene_object(&mut self, new: NewObject) -> Result<u64, ErrorCode> {
        let replaced = new.name.as_deref().and_then(|n| self.store.lookup(n));
        let id = self.store.adopt_scene_object(new)?;
        if let Some(old) = replaced.filter(|&old| old != id) {
            self.cache.forget_object(old);
        }
        Ok(id)
    }

    /// Removes the scene objects the current scene no longer has.
    pub fn drop_scene_objects_except(&mut self, keep: &[u64]) {
        for id in self.store.drop_scene_objects_except(keep) {
            self.cache.forget_object(id);
        }
    }

    /// Attaches a robot to its link objects (see [`Robots::attach`]).
    ///
    /// # Errors
    /// As [`Robots::attach`].
    pub fn attach_robot(&mut self, new: NewRobot<'_>) -> Result<u64, ErrorCode> {
        self.robots.attach(&mut self.store, new)
    }

    /// The limits in force.
    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// The object with this id.
    pub fn object(&self, id: u64) -> Option<&Object> {
        self.store.object(id)
    }

    /// Number of objects.
    pub fn len(&self) -> usize {
        self.store.len()
    }

    /// Whether no object is registered.
    pub fn is_empty(&self) -> bool {
        self.store.is_empty()
    }

    /// Current statistics.
    pub fn stats(&self) -> ServerStats {
        let c = self.cache.stats();
        ServerStats {
            objects: self.store.len() as u64,
            cache_entries: self.cache.len() as u64,
            cache_capacity: self.cache.capacity() as u64,
            cache_hits: c.hits,
            cache_misses: c.misses,
            cache_evictions: c.evictions,
            clients: self.clients,
            persist_errors: self.store.persist_errors(),
            ..self.stats
        }
    }

    /// What the server tells clients at hello.
    pub fn info(&self) -> ServerInfo {
        let clamp = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
        ServerInfo {
            protocol: gjkd_proto::PROTOCOL_VERSION,
            wait: self.wait as u32,
            max_batch: clamp(self.limits.max_batch),
            max_vertices: clamp(self.limits.max_vertices),
            max_pieces: clamp(self.limits.max_pieces.min(MAX_PIECES)),
            max_clients: clamp(self.limits.max_clients),
            max_rows: self.limits.max_rows as u64,
            max_objects: self.limits.max_objects as u64,
            pid: self.pid,
        }
    }

    /// Adds an object without committing it, returning its id.
    ///
    /// # Errors
    /// [`ErrorCode::NameTaken`], [`ErrorCode::TooManyObjects`].
    pub fn insert(&mut self, new: NewObject, owner: Owner) -> Result<u64, ErrorCode> {
        self.store.insert(new, owner, self.limits.max_objects)
    }

    /// Removes object `id` on behalf of `requester`, and commits the
    /// removal (when persistence is on) before returning.
    ///
    /// # Errors
    /// As [`ObjectStore::remove`].
    pub fn remove(&mut self, id: u64, requester: u128) -> Result<(), ErrorCode> {
        self.store.remove(id, requester)?;
        self.cache.forget_object(id);
        Ok(())
    }

    /// Removes the robot named `name` as a whole on behalf of `requester`:
    /// its link objects (in one commit, all or nothing), their warm
    /// starts, then its kinematics. Returns the robot's id.
    ///
    /// # Errors
    /// [`ErrorCode::UnknownName`] (no such robot), [`ErrorCode::ReadOnly`]
    /// (a scene robot), [`ErrorCode::NotOwner`] (another client's robot or
    /// link), and those of [`ObjectStore::remove_all`]; nothing changes
    /// then.
    pub fn remove_robot(&mut self, name: &str, requester: u128) -> Result<u64, ErrorCode> {
        let id = self.robots.lookup(name).ok_or(ErrorCode::UnknownName)?;
        let robot = self.robots.get(id).ok_or(ErrorCode::UnknownName)?;
        match robot.owner {
            Owner::Scene => return Err(ErrorCode::ReadOnly),
            Owner::Client(c) if c != requester => return Err(ErrorCode::NotOwner),
            Owner::Client(_) => {}
        }
        // Links removed since (one by one, by their owner) are gone already.
        let links: Vec<u64> = robot
            .links
            .iter()
            .flatten()
            .copied()
            .filter(|&l| self.store.object(l).is_some())
            .collect();
        self.store.remove_all(&links, requester)?;
        for &l in &links {
            self.cache.forget_object(l);
        }
        self.robots.take(id);
        Ok(id)
    }

    /// Removes the objects of every client for which `alive` is false, and
    /// their warm starts (see [`ObjectStore::remove_departed`]).
    pub fn remove_departed(
        &mut self,
        alive: impl Fn(u128) -> bool,
    ) -> (Vec<u64>, Option<ErrorCode>) {
        let (removed, failed) = self.store.remove_departed(&alive);
        // One pass over the cache for all of them, not one per object.
        let gone: std::collections::HashSet<u64> = removed.iter().copied().collect();
        if !gone.is_empty() {
            self.cache
                .retain(|k| !gone.contains(&k.a) && !gone.contains(&k.b));
        }
        // Only once every object of theirs is gone: a failed commit leaves
        // objects a robot still moves, retried at the next housekeeping.
        if failed.is_none() {
            self.robots.drop_departed(&alive);
        }
        (removed, failed)
    }

    /// The id of the object named `name`.
    pub fn lookup(&self, name: &str) -> Option<u64> {
        self.store.lookup(name)
    }

    /// Forgets the warm starts of a client that has gone away.
    pub fn forget_client(&mut self, client: u128) {
        self.cache.forget_client(client);
    }

    /// Forgets the warm starts of every client for which `alive` is false
    /// (clients that disconnected or died), so their entries do not wait for
    /// eviction.
    pub fn retain_clients(&mut self, alive: impl Fn(u128) -> bool) {
        self.cache.retain(|k| alive(k.client));
        self.groups.retain_clients(alive);
    }
}

/// Helpers shared by the tests of the state, the store and the handlers.
#[cfg(test)]
pub(crate) mod test_support {
    use super::*;
    use crate::persist::attach;
    use crate::persist::database::Database;
    use gjk::Convex;
    use gjkd_proto::{AdminChunk, AdminOp, AdminRequest, Item, ItemResult, Vertex, shape_kind};
    use nalgebra::{Isometry3, Vector3};

    pub(crate) fn state() -> State {
        State::new(Limits::default(), WaitMode::Spin, 3)
    }

    pub(crate) fn register_box(s: &mut State, owner: u128) -> u64 {
        let mut req = AdminRequest::new(AdminOp::Register);
        req.shape = shape_kind::CONVEX;
        req.piece_count = 1;
        req.pieces[0].vertex_count = 8;
        let verts: Vec<Vertex> = Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)
            .expect("box")
            .vertices()
            .iter()
            .map(|&p| p.into())
            .collect();
        let reply = s.handle_admin(owner, &req, AdminChunk::from_vertices(&verts));
        assert_eq!(reply.error_code(), ErrorCode::Ok);
        reply.id
    }

    pub(crate) fn one(s: &mut State, client: u128, item: Item) -> ItemResult {
        let mut out = [ItemResult::error(ErrorCode::Internal)];
        s.handle(client, &[item], &mut out);
        out[0]
    }

    /// A scene object: a unit ball named `name`.
    pub(crate) fn insert_scene_ball(s: &mut State, name: &str) -> u64 {
        s.insert(
            NewObject {
                shape: Convex::sphere(1.0).expect("sphere").into(),
                pose: Isometry3::identity(),
                name: Some(name.into()),
            },
            Owner::Scene,
        )
        .expect("room")
    }

    pub(crate) fn register_named(s: &mut State, owner: u128, name: &str) -> u64 {
        let mut req = AdminRequest::new(AdminOp::Register);
        req.shape = shape_kind::CONVEX;
        req.piece_count = 1;
        req.pieces[0].vertex_count = 1;
        req.pieces[0].rounding = 0.5;
        assert!(req.set_name(name));
        let reply = s.handle_admin(owner, &req, AdminChunk::from_vertices(&[Vertex::default()]));
        assert_eq!(reply.error_code(), ErrorCode::Ok);
        reply.id
    }

    /// A scratch directory of the test's own.
    pub(crate) fn scratch(tag: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("gjkd-state-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("dir");
        dir
    }

    /// `snapshot` written to a database, and read back as a restarted
    /// server would.
    pub(crate) fn through_database(tag: &str, snapshot: &Snapshot) -> Snapshot {
        let dir = scratch(tag);
        let path = dir.join("objects");
        let (mut db, _) = Database::open(&path, 1).expect("create");
        db.sync(snapshot).expect("sync");
        drop(db);
        let back = reload(&path);
        let _ = std::fs::remove_dir_all(&dir);
        back
    }

    /// A state persisted in `<scratch dir>/objects`: the directory, the
    /// database file and the state.
    pub(crate) fn stored(tag: &str) -> (std::path::PathBuf, std::path::PathBuf, State) {
        let dir = scratch(tag);
        let path = dir.join("objects");
        let mut s = state();
        let (db, opened) = Database::open(&path, 3).expect("store");
        assert!(opened.fresh);
        attach(&mut s, db).expect("journal");
        (dir, path, s)
    }

    /// The store as a restarted server would load it.
    pub(crate) fn reload(path: &std::path::Path) -> Snapshot {
        let (_, opened) = Database::open(path, 99).expect("reopen");
        assert!(!opened.fresh && opened.set_aside.is_empty(), "{opened:?}");
        opened.snapshot
    }

    pub(crate) fn ids_of(snapshot: &Snapshot) -> Vec<u64> {
        snapshot.objects.iter().map(|o| o.id).collect()
    }
}
