//! The server's state and its request handlers: pure functions of the state
//! and the bytes a client sent, with no iceoryx2 in sight, so that they can be
//! tested and fuzzed in-process.
//!
//! Nothing here trusts the request: every field is checked, every failure is
//! an [`ErrorCode`] in the result, and nothing panics on any input.

use std::collections::HashMap;

use gjk::{Compound, Convex, Shape};
use gjkd_proto::{
    AdminOp, AdminReply, AdminRequest, ErrorCode, Item, ItemKind, ItemResult, MAX_PIECES, Pose,
    ServerInfo, ServerStats, Vertex, WaitMode, item_flags, result_flags, shape_kind,
};
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion};

use crate::cache::{FxBuild, PairKey, WarmCache};
use crate::journal::Journal;
use crate::persist::{Change, Snapshot, Store, StoredObject, StoredOwner, StoredPose, StoredShape};

/// Limits the server enforces, also used to size the iceoryx2 services.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Most clients at once: iceoryx2 client ports per service, and each
    /// `gjkd-client` `Client` has one on the query and one on the admin
    /// service.
    pub max_clients: usize,
    /// Most iceoryx2 nodes (processes or `Client`s) attached to a service.
    pub max_nodes: usize,
    /// Most items in one query request.
    pub max_batch: usize,
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
            max_vertices: 100_000,
            max_pieces: MAX_PIECES,
            max_objects: 1 << 20,
            cache_capacity: 1 << 16,
        }
    }
}

/// Who may remove an object.
///
/// A client is identified by the id of its iceoryx2 node: one per
/// `gjkd-client` `Client`, kept for the `Client`'s whole life, across its
/// reconnections and across server restarts (the id is stored in the state
/// file). A client *process* that restarts has a new node, so objects
/// registered by its previous life can no longer be removed by anyone; they
/// stay until the state file and its log are removed (see
/// `docs/reliability.md`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Owner {
    /// Loaded from the scene file at start: read-only.
    Scene,
    /// Registered by the client whose iceoryx2 node has this id.
    Client(u128),
}

/// A registered object.
#[derive(Clone, Debug)]
pub struct Object {
    /// The geometry.
    pub shape: Shape,
    /// The stored pose, used by queries that do not give their own.
    pub pose: Isometry3<f64>,
    /// Who registered it.
    pub owner: Owner,
    /// Name for look-ups, if any.
    pub name: Option<String>,
    /// Its slot in the pose journal (see [`crate::journal`]).
    pub slot: u32,
}

/// Everything the server holds.
#[derive(Debug)]
pub struct State {
    limits: Limits,
    wait: WaitMode,
    pid: u64,
    /// Upper 32 bits of every id of this run, so ids of an earlier run are
    /// unknown rather than aliases.
    epoch: u64,
    next_index: u32,
    objects: HashMap<u64, Object, FxBuild>,
    names: HashMap<String, u64>,
    cache: WarmCache,
    stats: ServerStats,
    /// Where registrations and removals are written before they are
    /// acknowledged; `None` when persistence is off.
    store: Option<Store>,
    /// Latest poses, kept where a crash of this process cannot lose them
    /// (present when `store` is).
    journal: Option<Journal>,
    /// Journal slots of removed objects, for reuse.
    free_slots: Vec<u32>,
    /// Lowest slot never used.
    next_slot: u32,
    /// Writes of the state file or change log that failed.
    persist_errors: u64,
    /// Scratch memory of gjk queries, reused from one query to the next.
    workspace: gjk::Workspace,
    /// Query clients connected, as last seen by the serving loop.
    clients: u64,
    /// Robots: kinematics attached to link objects (see [`crate::robots`]).
    pub(crate) robots: crate::robots::Robots,
}

/// The shape part of a registration, in the server's terms.
#[derive(Clone, Debug)]
pub struct NewObject {
    /// The geometry.
    pub shape: Shape,
    /// Initial pose.
    pub pose: Isometry3<f64>,
    /// Optional unique name.
    pub name: Option<String>,
}

impl State {
    /// An empty store. `epoch` goes into the upper 32 bits of every id (0 is
    /// replaced by 1, so that no id is 0).
    pub fn new(limits: Limits, wait: WaitMode, epoch: u32) -> Self {
        State {
            limits,
            wait,
            pid: u64::from(std::process::id()),
            epoch: u64::from(epoch.max(1)) << 32,
            next_index: 1,
            objects: HashMap::default(),
            names: HashMap::new(),
            cache: WarmCache::new(limits.cache_capacity),
            stats: ServerStats::default(),
            store: None,
            journal: None,
            free_slots: Vec::new(),
            next_slot: 0,
            persist_errors: 0,
            clients: 0,
            robots: crate::robots::Robots::default(),
            workspace: gjk::Workspace::new(),
        }
    }

    /// A store holding the objects of `snapshot` with their exact ids, its
    /// id counter continuing where the snapshot's stopped (so no id is ever
    /// handed out twice).
    ///
    /// # Errors
    /// A description of the problem if the snapshot does not pass
    /// [`Snapshot::validate`] or holds more objects than `limits` allow;
    /// nothing is half-loaded.
    pub fn restore(limits: Limits, wait: WaitMode, snapshot: &Snapshot) -> Result<Self, String> {
        snapshot.validate()?;
        if snapshot.objects.len() > limits.max_objects {
            return Err(format!(
                "{} objects stored, the limit is {}",
                snapshot.objects.len(),
                limits.max_objects
            ));
        }
        let mut state = State::new(limits, wait, snapshot.epoch);
        state.next_index = snapshot.next_index;
        for o in &snapshot.objects {
            let object = Object {
                shape: o.shape.to_shape()?,
                pose: o.pose.to_isometry().ok_or("bad pose")?,
                owner: match o.owner {
                    StoredOwner::Scene => Owner::Scene,
                    StoredOwner::Client(c) => Owner::Client(c),
                },
                name: o.name.clone(),
                slot: o.slot,
            };
            if let Some(name) = &object.name {
                state.names.insert(name.clone(), o.id);
            }
            state.objects.insert(o.id, object);
        }
        let mut used: Vec<u32> = snapshot.objects.iter().map(|o| o.slot).collect();
        used.sort_unstable();
        state.next_slot = used.last().map_or(0, |&m| m + 1);
        state.free_slots = (0..state.next_slot)
            .rev()
            .filter(|s| used.binary_search(s).is_err())
            .collect();
        Ok(state)
    }

    /// Everything needed to rebuild this store: id counter and objects, in
    /// id order.
    pub fn snapshot(&self) -> Snapshot {
        let mut objects: Vec<StoredObject> = self
            .objects
            .keys()
            .filter_map(|&id| self.stored(id))
            .collect();
        objects.sort_unstable_by_key(|o| o.id);
        Snapshot {
            epoch: (self.epoch >> 32) as u32,
            next_index: self.next_index,
            objects,
        }
    }

    /// The stored form of object `id`.
    fn stored(&self, id: u64) -> Option<StoredObject> {
        let o = self.objects.get(&id)?;
        Some(StoredObject {
            id,
            owner: match o.owner {
                Owner::Scene => StoredOwner::Scene,
                Owner::Client(c) => StoredOwner::Client(c),
            },
            name: o.name.clone(),
            pose: StoredPose::from_isometry(&o.pose),
            shape: StoredShape::from_shape(&o.shape),
            slot: o.slot,
        })
    }

    /// Turns persistence on: from now on every registration and removal is
    /// written to `store` (its change log) before it is acknowledged, and
    /// every pose update goes to the pose journal next to it. Poses the
    /// journal holds for the objects already here (restored from the state
    /// file) replace theirs: they are the latest ones before a crash.
    ///
    /// # Errors
    /// When the journal cannot be opened; persistence stays off then.
    pub fn set_store(&mut self, store: Store) -> Result<(), crate::persist::StoreError> {
        let path = crate::journal::path_for(store.path());
        let mut journal =
            Journal::open(&path).map_err(|source| crate::persist::StoreError::Io {
                what: "cannot open the pose journal",
                path: path.clone(),
                source,
            })?;
        for (&id, o) in self.objects.iter_mut() {
            if let Some(pose) = journal.read(o.slot, id) {
                o.pose = pose;
            }
        }
        for (&id, o) in &self.objects {
            journal.write(o.slot, id, &o.pose).map_err(|source| {
                crate::persist::StoreError::Io {
                    what: "cannot write the pose journal",
                    path: path.clone(),
                    source,
                }
            })?;
        }
        self.journal = Some(journal);
        self.store = Some(store);
        Ok(())
    }

    /// Writes `pose` of object `id` (in `slot`) to the journal, if any. A
    /// failure (the file cannot grow: disk full) costs only durability of
    /// this pose, not the update itself, so it is counted and logged.
    fn journal_pose(&mut self, slot: u32, id: u64) {
        let (Some(journal), Some(o)) = (self.journal.as_mut(), self.objects.get(&id)) else {
            return;
        };
        if let Err(e) = journal.write(slot, id, &o.pose) {
            self.persist_errors += 1;
            tracing::error!("cannot write the pose journal: {e}");
        }
    }

    /// The state file, when persistence is on.
    pub fn store(&self) -> Option<&Store> {
        self.store.as_ref()
    }

    /// Writes the state file now (when persistence is on): a full snapshot,
    /// which also empties the change log (compaction).
    ///
    /// # Errors
    /// The write error; the previous file and log are then intact.
    pub fn persist(&mut self) -> Result<(), crate::persist::StoreError> {
        if self.store.is_none() {
            return Ok(());
        }
        let snapshot = self.snapshot();
        let Some(store) = &mut self.store else {
            return Ok(());
        };
        match store.write(&snapshot) {
            Ok(()) => Ok(()),
            Err(e) => {
                self.persist_errors += 1;
                Err(e)
            }
        }
    }

    /// Folds the change log into the state file if it holds any change:
    /// done at clean shutdown, so that the next start reads one file.
    ///
    /// # Errors
    /// As [`State::persist`]; the log still holds every change then.
    pub fn compact(&mut self) -> Result<(), crate::persist::StoreError> {
        if self.store.as_ref().is_some_and(Store::has_changes) {
            self.persist()
        } else {
            Ok(())
        }
    }

    /// Asks the kernel to put the pose journal on disk if poses changed.
    /// Only a machine crash needs this (the journal's pages outlive the
    /// process); called when idle and at shutdown.
    ///
    /// # Errors
    /// The `msync` error.
    pub fn flush(&mut self) -> std::io::Result<()> {
        match &mut self.journal {
            Some(j) => j.sync(),
            None => Ok(()),
        }
    }

    /// Records how many query clients are connected (for [`State::stats`]).
    pub fn set_clients(&mut self, clients: usize) {
        self.clients = clients as u64;
    }

    /// Installs a scene object: an object restored from the state file with
    /// the same name, the same geometry and scene ownership keeps its id
    /// (and takes the scene's pose); otherwise a new object is inserted.
    /// Call [`State::drop_scene_objects_except`] after the whole scene.
    ///
    /// # Errors
    /// As [`State::insert`].
    pub fn adopt_scene_object(&mut self, new: NewObject) -> Result<u64, ErrorCode> {
        if let Some(name) = &new.name
            && let Some(&id) = self.names.get(name)
            && let Some(old) = self.objects.get_mut(&id)
            && old.owner == Owner::Scene
            && old.shape == new.shape
        {
            old.pose = new.pose;
            let slot = old.slot;
            self.journal_pose(slot, id);
            return Ok(id);
        }
        if let Some(name) = &new.name
            && let Some(&id) = self.names.get(name)
            && self
                .objects
                .get(&id)
                .is_some_and(|o| o.owner == Owner::Scene)
        {
            // The scene file changed this object: the new one replaces it.
            self.drop_object(id);
        }
        self.insert(new, Owner::Scene)
    }

    /// Removes the scene objects restored from the state file that the
    /// current scene no longer has.
    pub fn drop_scene_objects_except(&mut self, keep: &[u64]) {
        let doomed: Vec<u64> = self
            .objects
            .iter()
            .filter(|(id, o)| o.owner == Owner::Scene && !keep.contains(id))
            .map(|(&id, _)| id)
            .collect();
        for id in doomed {
            self.drop_object(id);
        }
    }

    fn drop_object(&mut self, id: u64) -> Option<Object> {
        let object = self.unlink_object(id)?;
        self.cache.forget_object(id);
        Some(object)
    }

    /// [`drop_object`](Self::drop_object) but for the warm-start cache,
    /// whose entries naming `id` are left for the caller to drop (one pass
    /// over the cache for many objects instead of one each).
    fn unlink_object(&mut self, id: u64) -> Option<Object> {
        let object = self.objects.remove(&id)?;
        if let Some(name) = &object.name {
            self.names.remove(name);
        }
        self.free_slots.push(object.slot);
        Some(object)
    }

    /// The limits in force.
    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// The object with this id.
    pub fn object(&self, id: u64) -> Option<&Object> {
        self.objects.get(&id)
    }

    /// Number of objects.
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// Whether no object is registered.
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }

    /// Current statistics.
    pub fn stats(&self) -> ServerStats {
        let c = self.cache.stats();
        ServerStats {
            objects: self.objects.len() as u64,
            cache_entries: self.cache.len() as u64,
            cache_capacity: self.cache.capacity() as u64,
            cache_hits: c.hits,
            cache_misses: c.misses,
            cache_evictions: c.evictions,
            clients: self.clients,
            persist_errors: self.persist_errors,
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
            max_objects: self.limits.max_objects as u64,
            pid: self.pid,
        }
    }

    /// Adds an object, returning its id.
    ///
    /// # Errors
    /// [`ErrorCode::NameTaken`], [`ErrorCode::TooManyObjects`].
    pub fn insert(&mut self, new: NewObject, owner: Owner) -> Result<u64, ErrorCode> {
        if self.objects.len() >= self.limits.max_objects || self.next_index == u32::MAX {
            return Err(ErrorCode::TooManyObjects);
        }
        if let Some(name) = &new.name
            && self.names.contains_key(name)
        {
            return Err(ErrorCode::NameTaken);
        }
        let id = self.epoch | u64::from(self.next_index);
        self.next_index += 1;
        if let Some(name) = &new.name {
            self.names.insert(name.clone(), id);
        }
        let slot = self.free_slots.pop().unwrap_or_else(|| {
            let s = self.next_slot;
            self.next_slot += 1;
            s
        });
        self.objects.insert(
            id,
            Object {
                shape: new.shape,
                pose: new.pose,
                owner,
                name: new.name,
                slot,
            },
        );
        // The slot may hold a removed object's last pose: overwrite it now.
        self.journal_pose(slot, id);
        Ok(id)
    }

    /// Removes object `id` on behalf of `requester`, and writes the removal
    /// to disk (when persistence is on) before returning.
    ///
    /// # Errors
    /// [`ErrorCode::UnknownObject`], [`ErrorCode::ReadOnly`] for scene
    /// objects, [`ErrorCode::NotOwner`] for another client's object.
    pub fn remove(&mut self, id: u64, requester: u128) -> Result<(), ErrorCode> {
        self.remove_committed(id, requester).map(|_| ())
    }

    /// Removes the objects of every client for which `alive` is false (its
    /// process ended: no client could remove them, since a restarted
    /// process gets a new identity). Scene objects stay; ids are never
    /// reused. A few are committed one by one, like a client's removals;
    /// more than [`BULK_REMOVAL`] at once with one snapshot write, since a
    /// crashed process's thousand objects would otherwise hold the request
    /// loop for a thousand synced appends. Returns the ids removed, in id
    /// order, and the error that stopped the pass if a commit failed (the
    /// objects it concerned are kept).
    pub fn remove_departed(
        &mut self,
        alive: impl Fn(u128) -> bool,
    ) -> (Vec<u64>, Option<ErrorCode>) {
        let mut doomed: Vec<(u64, u128)> = self
            .objects
            .iter()
            .filter_map(|(&id, o)| match o.owner {
                Owner::Client(c) if !alive(c) => Some((id, c)),
                _ => None,
            })
            .collect();
        doomed.sort_unstable();
        if doomed.len() > BULK_REMOVAL && self.store.is_some() {
            return self.remove_in_bulk(&doomed);
        }
        let mut removed = Vec::with_capacity(doomed.len());
        for (id, owner) in doomed {
            match self.remove_committed(id, owner) {
                Ok(id) => removed.push(id),
                Err(e) => return (removed, Some(e)),
            }
        }
        (removed, None)
    }

    /// [`remove_departed`](Self::remove_departed)'s many: all dropped, then
    /// one snapshot; if it cannot be written, all put back (the previous
    /// file and log are intact). Their warm starts go in one pass over the
    /// cache once the snapshot is written, not in one pass per object.
    fn remove_in_bulk(&mut self, doomed: &[(u64, u128)]) -> (Vec<u64>, Option<ErrorCode>) {
        let dropped: Vec<(u64, Object)> = doomed
            .iter()
            .filter_map(|&(id, _)| Some((id, self.unlink_object(id)?)))
            .collect();
        if let Err(e) = self.persist() {
            tracing::error!("{e}; the removals are undone");
            // In reverse: each object's slot is then on top of the stack.
            for (id, object) in dropped.into_iter().rev() {
                if self.free_slots.last() == Some(&object.slot) {
                    self.free_slots.pop();
                }
                if let Some(name) = &object.name {
                    self.names.insert(name.clone(), id);
                }
                self.objects.insert(id, object);
            }
            return (Vec::new(), Some(ErrorCode::Internal));
        }
        let gone: std::collections::HashSet<u64> = dropped.iter().map(|&(id, _)| id).collect();
        self.cache
            .retain(|k| !gone.contains(&k.a) && !gone.contains(&k.b));
        (dropped.into_iter().map(|(id, _)| id).collect(), None)
    }

    /// The id of the object named `name`.
    pub fn lookup(&self, name: &str) -> Option<u64> {
        self.names.get(name).copied()
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
    }

    /// Answers one query request from `client` (its iceoryx2 client port id,
    /// which keys its warm-start cache): `results[i]` answers `items[i]`,
    /// items applied in order. `results` must be as long as `items`; extra
    /// results are left alone and a short buffer answers only what fits.
    pub fn handle(&mut self, client: u128, items: &[Item], results: &mut [ItemResult]) {
        self.stats.requests += 1;
        for (item, out) in items.iter().zip(results.iter_mut()) {
            *out = self.item(client, item);
            self.stats.items += 1;
            if out.error != 0 {
                self.stats.item_errors += 1;
            }
        }
    }

    /// Whole-request checks of a query batch of `len` items.
    pub fn check_batch(&self, len: usize) -> Result<(), ErrorCode> {
        if len == 0 {
            Err(ErrorCode::EmptyBatch)
        } else if len > self.limits.max_batch {
            Err(ErrorCode::BatchTooLarge)
        } else {
            Ok(())
        }
    }

    fn item(&mut self, client: u128, item: &Item) -> ItemResult {
        // Unknown flag bits and a non-zero reserved word are refused rather
        // than ignored, so that a later protocol version can give them a
        // meaning without old servers silently answering something else.
        if item.flags & !item_flags::ALL != 0 || item.reserved != 0 {
            return ItemResult::error(ErrorCode::Malformed);
        }
        match ItemKind::from_raw(item.kind) {
            Some(ItemKind::SetPose) => match self.set_pose(item) {
                Ok(()) => ItemResult::default(),
                Err(e) => ItemResult::error(e),
            },
            Some(ItemKind::Distance) => self
                .distance(client, item)
                .unwrap_or_else(ItemResult::error),
            Some(ItemKind::SetJoints) => match crate::robots::set_joints(self, item) {
                Ok(()) => ItemResult::default(),
                Err(e) => ItemResult::error(e),
            },
            None => ItemResult::error(ErrorCode::Malformed),
        }
    }

    fn set_pose(&mut self, item: &Item) -> Result<(), ErrorCode> {
        let pose = check_pose(&item.pose_a)?;
        self.store_pose(item.a, pose)
    }

    /// The upper 32 bits of every id of this run.
    pub(crate) fn id_epoch(&self) -> u64 {
        self.epoch
    }

    /// Stores a checked pose for object `id` (and journals it).
    pub(crate) fn store_pose(&mut self, id: u64, pose: Isometry3<f64>) -> Result<(), ErrorCode> {
        let object = self.objects.get_mut(&id).ok_or(ErrorCode::UnknownObject)?;
        object.pose = pose;
        if let Some(journal) = &mut self.journal
            && let Err(e) = journal.write(object.slot, id, &object.pose)
        {
            self.persist_errors += 1;
            tracing::error!("cannot write the pose journal: {e}");
        }
        Ok(())
    }

    fn distance(&mut self, client: u128, item: &Item) -> Result<ItemResult, ErrorCode> {
        let warm_on = item.flags & item_flags::WARM_START != 0;
        let options = gjk::Options {
            tolerance: item.tolerance,
            max_iterations: item.max_iterations,
            margin: (item.flags & item_flags::MARGIN != 0).then_some(item.margin),
            warm_start: warm_on,
            precision: if item.flags & item_flags::SINGLE_PRECISION != 0 {
                gjk::Precision::Single
            } else {
                gjk::Precision::Double
            },
        };
        if !(options.tolerance.is_finite() && options.tolerance >= 0.0)
            || options.max_iterations == 0
            || options.margin.is_some_and(|m| !m.is_finite())
        {
            return Err(ErrorCode::InvalidOptions);
        }
        let a = self.objects.get(&item.a).ok_or(ErrorCode::UnknownObject)?;
        let b = self.objects.get(&item.b).ok_or(ErrorCode::UnknownObject)?;
        let pose_a = if item.flags & item_flags::POSE_A != 0 {
            check_pose(&item.pose_a)?
        } else {
            a.pose
        };
        let pose_b = if item.flags & item_flags::POSE_B != 0 {
            check_pose(&item.pose_b)?
        } else {
            b.pose
        };
        let key = PairKey {
            client,
            a: item.a,
            b: item.b,
        };
        let warm = if warm_on { self.cache.get(&key) } else { None };
        let workspace = &mut self.workspace;
        let mut query = |warm: Option<&gjk::WarmStart>| {
            gjk::distance_in(
                workspace, &a.shape, &pose_a, &b.shape, &pose_b, &options, warm,
            )
        };
        let answer = match query(warm.as_ref()) {
            Ok(answer) => answer,
            // The cache is keyed by ids that are never reused, so this cannot
            // happen; if it does, the cold answer is still right.
            Err(gjk::Error::WarmStartOutOfRange) => query(None).map_err(map_gjk_error)?,
            Err(e) => return Err(map_gjk_error(e)),
        };
        if warm_on {
            self.cache.put(key, answer.warm_start);
        }
        let mut flags = 0;
        if warm.is_some() {
            flags |= result_flags::WARM_STARTED;
        }
        if answer.backup_used {
            flags |= result_flags::BACKUP_USED;
        }
        Ok(ItemResult {
            distance: answer.distance,
            lower: answer.lower,
            upper: answer.upper,
            penetration: answer.penetration,
            point_a: answer.point_a.coords.into(),
            point_b: answer.point_b.coords.into(),
            normal: answer.normal.into(),
            error: ErrorCode::Ok as u32,
            status: status_code(answer.status),
            iterations: answer.iterations,
            flags,
            pieces: answer.pieces,
        })
    }

    /// Answers one admin request from client `requester` (the id of its
    /// iceoryx2 node, see [`Owner`]), with the request's slice payload
    /// `vertices`. With persistence on, a registration or removal is written
    /// to the change log (or the state file, see [`crate::persist`]) before
    /// this returns; if the write fails the change is undone and the reply
    /// is [`ErrorCode::Internal`], so an acknowledged change is always on
    /// disk.
    pub fn handle_admin(
        &mut self,
        requester: u128,
        request: &AdminRequest,
        vertices: &[Vertex],
    ) -> AdminReply {
        let op = request.op;
        let mut reply = AdminReply {
            op,
            ..AdminReply::default()
        };
        let op_kind = AdminOp::from_raw(op);
        // Only a registration carries vertices: any other request with a
        // slice is malformed (and would otherwise be silently ignored).
        if !vertices.is_empty()
            && !matches!(op_kind, Some(AdminOp::Register | AdminOp::AttachRobot))
        {
            reply.error = ErrorCode::Malformed as u32;
            return reply;
        }
        let outcome = match op_kind {
            Some(AdminOp::Hello) => {
                reply.info = self.info();
                Ok(0)
            }
            Some(AdminOp::Stats) => {
                reply.stats = self.stats();
                Ok(0)
            }
            Some(AdminOp::Register) => decode_registration(&self.limits, request, vertices)
                .and_then(|new| self.insert(new, Owner::Client(requester)))
                .and_then(|id| {
                    // Just inserted, so always there.
                    let change = Change::Register(self.stored(id).ok_or(ErrorCode::Internal)?);
                    self.commit(change).map(|()| id).inspect_err(|_| {
                        self.drop_object(id);
                    })
                }),
            Some(AdminOp::Remove) => self.remove_committed(request.id, requester),
            Some(AdminOp::Lookup) => match (request.name(), request.shape) {
                (Some(name), 0) => self.lookup(name).ok_or(ErrorCode::UnknownName),
                (Some(name), gjkd_proto::lookup_kind::ROBOT) => {
                    self.robots.lookup(name).ok_or(ErrorCode::UnknownName)
                }
                _ => Err(ErrorCode::Malformed),
            },
            Some(AdminOp::AttachRobot) => {
                crate::robots::attach_request(self, requester, request, vertices)
            }
            None => Err(ErrorCode::Malformed),
        };
        match outcome {
            Ok(id) => reply.id = id,
            Err(e) => reply.error = e as u32,
        }
        reply
    }
}

impl State {
    /// Makes a registration or removal durable before it is acknowledged:
    /// appended to the change log, or, when the log is due for compaction
    /// (or there is none), written as a full snapshot, which holds the
    /// change as well. The error is what the client is told if neither
    /// works; the caller then undoes the change.
    fn commit(&mut self, change: Change) -> Result<(), ErrorCode> {
        let Some(store) = &self.store else {
            return Ok(());
        };
        if store.wants_compaction() {
            match self.persist() {
                Ok(()) => return Ok(()),
                // The snapshot is still the old one and the log intact, so
                // the change can still go to the log: a compaction that
                // fails (a full disk has room for a record, not a copy of
                // the store) does not cost the client its request.
                Err(e) if self.store.as_ref().is_some_and(Store::can_append) => {
                    tracing::error!("{e}; compaction postponed, the change is appended");
                }
                Err(e) => {
                    tracing::error!("{e}; the change is undone");
                    return Err(ErrorCode::Internal);
                }
            }
        }
        let Some(store) = &mut self.store else {
            return Ok(());
        };
        store.append(&change).map_err(|e| {
            self.persist_errors += 1;
            tracing::error!("{e}; the change is undone");
            ErrorCode::Internal
        })
    }

    fn remove_committed(&mut self, id: u64, requester: u128) -> Result<u64, ErrorCode> {
        let object = self.objects.get(&id).ok_or(ErrorCode::UnknownObject)?;
        match object.owner {
            Owner::Scene => return Err(ErrorCode::ReadOnly),
            Owner::Client(c) if c != requester => return Err(ErrorCode::NotOwner),
            Owner::Client(_) => {}
        }
        let Some(object) = self.drop_object(id) else {
            return Err(ErrorCode::UnknownObject);
        };
        if let Err(e) = self.commit(Change::Remove(id)) {
            if self.free_slots.last() == Some(&object.slot) {
                self.free_slots.pop();
            }
            if let Some(name) = &object.name {
                self.names.insert(name.clone(), id);
            }
            self.objects.insert(id, object);
            return Err(e);
        }
        Ok(id)
    }
}

/// Most objects of departed clients removed one committed record at a time;
/// beyond, [`State::remove_departed`] writes one snapshot instead.
pub const BULK_REMOVAL: usize = 16;

/// The wire value of a gjk status.
pub fn status_code(s: gjk::Status) -> u32 {
    use gjkd_proto::Status as W;
    match s {
        gjk::Status::Converged => W::Converged as u32,
        gjk::Status::Farther => W::Farther as u32,
        gjk::Status::Closer => W::Closer as u32,
        gjk::Status::IterationCap => W::IterationCap as u32,
        gjk::Status::ToleranceNotMet => W::ToleranceNotMet as u32,
    }
}

/// The wire code of a gjk error.
pub fn map_gjk_error(e: gjk::Error) -> ErrorCode {
    match e {
        gjk::Error::EmptyVertices => ErrorCode::EmptyVertices,
        gjk::Error::TooManyVertices(_) => ErrorCode::TooManyVertices,
        gjk::Error::NonFiniteVertex(_) => ErrorCode::NonFiniteVertex,
        gjk::Error::InvalidRadius(_) => ErrorCode::InvalidRadius,
        gjk::Error::EmptyCompound => ErrorCode::EmptyCompound,
        gjk::Error::NonFinitePose => ErrorCode::NonFinitePose,
        gjk::Error::InvalidOption(_) => ErrorCode::InvalidOptions,
        gjk::Error::WarmStartOutOfRange => ErrorCode::Internal,
    }
}

/// Quaternions whose squared norm is this close to 1 are taken as they are:
/// that is what nalgebra's own normalisation yields, and re-normalising them
/// would change the last bits of every answer relative to an in-process call.
const UNIT_ROUNDING: f64 = 8.0 * f64::EPSILON;

/// How far off unit length a quaternion may be and still be accepted (after
/// normalising).
pub const UNIT_TOLERANCE: f64 = 1e-6;

/// The isometry of a wire pose: finite, and a rotation quaternion within
/// [`UNIT_TOLERANCE`] of unit length (normalised unless it already is, to
/// round-off).
///
/// # Errors
/// [`ErrorCode::NonFinitePose`], [`ErrorCode::BadQuaternion`].
pub fn check_pose(p: &Pose) -> Result<Isometry3<f64>, ErrorCode> {
    if !p
        .translation
        .iter()
        .chain(&p.rotation)
        .all(|c| c.is_finite())
    {
        return Err(ErrorCode::NonFinitePose);
    }
    let [i, j, k, w] = p.rotation;
    let q = Quaternion::new(w, i, j, k);
    let n2 = q.norm_squared();
    let rotation = if (n2 - 1.0).abs() <= UNIT_ROUNDING {
        UnitQuaternion::new_unchecked(q)
    } else if (n2.sqrt() - 1.0).abs() <= UNIT_TOLERANCE {
        UnitQuaternion::new_normalize(q)
    } else {
        return Err(ErrorCode::BadQuaternion);
    };
    let [x, y, z] = p.translation;
    Ok(Isometry3::from_parts(Translation3::new(x, y, z), rotation))
}

/// Checks a registration and builds its shape.
///
/// # Errors
/// The specific [`ErrorCode`] of the first problem found.
pub fn decode_registration(
    limits: &Limits,
    request: &AdminRequest,
    vertices: &[Vertex],
) -> Result<NewObject, ErrorCode> {
    if vertices.len() > limits.max_vertices {
        return Err(ErrorCode::TooManyVertices);
    }
    let name = match request.name_len {
        0 => None,
        _ => Some(request.name().ok_or(ErrorCode::Malformed)?.to_owned()),
    };
    let pose = check_pose(&request.pose)?;
    let count = request.piece_count as usize;
    let shape = match request.shape {
        shape_kind::CONVEX => {
            if count != 1 {
                return Err(ErrorCode::Malformed);
            }
            let piece = &request.pieces[0];
            if piece.reserved != 0 {
                return Err(ErrorCode::Malformed);
            }
            if piece.vertex_count as usize != vertices.len() {
                return Err(if vertices.is_empty() {
                    ErrorCode::EmptyVertices
                } else {
                    ErrorCode::Malformed
                });
            }
            Shape::Convex(convex(vertices, piece.radius)?)
        }
        shape_kind::COMPOUND => {
            if count == 0 {
                return Err(ErrorCode::EmptyCompound);
            }
            if count > MAX_PIECES || count > limits.max_pieces {
                return Err(ErrorCode::TooManyPieces);
            }
            let table = &request.pieces[..count];
            if table.iter().any(|p| p.reserved != 0) {
                return Err(ErrorCode::Malformed);
            }
            let total: u64 = table.iter().map(|p| u64::from(p.vertex_count)).sum();
            if total != vertices.len() as u64 {
                return Err(ErrorCode::Malformed);
            }
            let mut pieces = Vec::with_capacity(count);
            let mut start = 0usize;
            for p in table {
                let end = start + p.vertex_count as usize;
                let offset = check_pose(&p.offset)?;
                pieces.push((offset, convex(&vertices[start..end], p.radius)?));
                start = end;
            }
            Shape::Compound(Compound::new(pieces).map_err(map_gjk_error)?)
        }
        _ => return Err(ErrorCode::Malformed),
    };
    Ok(NewObject { shape, pose, name })
}

fn convex(vertices: &[Vertex], radius: f64) -> Result<Convex, ErrorCode> {
    if vertices.is_empty() {
        return Err(ErrorCode::EmptyVertices);
    }
    if !(radius.is_finite() && radius >= 0.0) {
        return Err(ErrorCode::InvalidRadius);
    }
    let points: Vec<Point3<f64>> = vertices.iter().map(|&v| v.into()).collect();
    Convex::new(points, radius).map_err(map_gjk_error)
}

#[cfg(test)]
mod tests {
    use super::*;
    use gjkd_proto::{ObjectId, PieceDesc, QueryOptions};
    use nalgebra::Vector3;

    fn state() -> State {
        State::new(Limits::default(), WaitMode::Spin, 3)
    }

    fn register_box(s: &mut State, owner: u128) -> u64 {
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
        let reply = s.handle_admin(owner, &req, &verts);
        assert_eq!(reply.error_code(), ErrorCode::Ok);
        reply.id
    }

    fn one(s: &mut State, client: u128, item: Item) -> ItemResult {
        let mut out = [ItemResult::error(ErrorCode::Internal)];
        s.handle(client, &[item], &mut out);
        out[0]
    }

    #[test]
    fn answers_match_gjk_bit_for_bit() {
        let mut s = state();
        let a = register_box(&mut s, 1);
        let b = register_box(&mut s, 1);
        let pb = Isometry3::new(Vector3::new(3.0, 0.5, 0.2), Vector3::new(0.1, 0.2, 0.3));
        let (a, b) = (ObjectId::from_raw(a), ObjectId::from_raw(b));
        let r = one(&mut s, 9, Item::set_pose(b, &pb));
        assert_eq!(r.error_code(), ErrorCode::Ok);
        let r = one(&mut s, 9, Item::distance(a, b, &QueryOptions::cold()));
        let shape: Shape = Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)
            .expect("box")
            .into();
        let opts = gjk::Options {
            warm_start: false,
            ..Default::default()
        };
        let want =
            gjk::distance(&shape, &Isometry3::identity(), &shape, &pb, &opts, None).expect("valid");
        let got = r.answer().expect("ok");
        assert_eq!(got.distance.to_bits(), want.distance.to_bits());
        assert_eq!(got.point_a, want.point_a);
        assert_eq!(got.normal, want.normal);
        assert_eq!(got.iterations, want.iterations);
    }

    #[test]
    fn warm_start_is_per_client_and_counted() {
        let mut s = state();
        let a = ObjectId::from_raw(register_box(&mut s, 1));
        let b = ObjectId::from_raw(register_box(&mut s, 1));
        let pa = Isometry3::translation(-2.0, 0.0, 0.0);
        let item = Item::distance(a, b, &QueryOptions::default()).with_pose_a(&pa);
        assert!(!one(&mut s, 1, item).answer().expect("ok").warm_started);
        assert!(one(&mut s, 1, item).answer().expect("ok").warm_started);
        assert!(!one(&mut s, 2, item).answer().expect("ok").warm_started);
        let st = s.stats();
        assert_eq!(
            (st.cache_hits, st.cache_misses, st.cache_entries),
            (1, 2, 2)
        );
    }

    #[test]
    fn departed_clients_lose_their_warm_starts() {
        let mut s = state();
        let a = ObjectId::from_raw(register_box(&mut s, 1));
        let b = ObjectId::from_raw(register_box(&mut s, 1));
        let item = Item::distance(a, b, &QueryOptions::default())
            .with_pose_b(&Isometry3::translation(3.0, 0.0, 0.0));
        for client in [10, 11, 12] {
            one(&mut s, client, item);
        }
        assert_eq!(s.stats().cache_entries, 3);
        s.retain_clients(|c| c == 11);
        assert_eq!(s.stats().cache_entries, 1);
        assert!(one(&mut s, 11, item).answer().expect("ok").warm_started);
        assert!(!one(&mut s, 10, item).answer().expect("ok").warm_started);
    }

    #[test]
    fn bad_items_get_their_codes() {
        let mut s = state();
        let a = ObjectId::from_raw(register_box(&mut s, 1));
        let ghost = ObjectId::from_raw(12345);
        let o = QueryOptions::default();
        let nan = Isometry3::translation(f64::NAN, 0.0, 0.0);
        let mut bad_q = Item::set_pose(a, &Isometry3::identity());
        bad_q.pose_a.rotation = [0.0, 0.0, 0.0, 2.0];
        let mut close_q = bad_q;
        close_q.pose_a.rotation = [0.0, 0.0, 0.0, 1.0 + 1e-7];
        let mut kind = Item::distance(a, a, &o);
        kind.kind = 77;
        let mut flags = Item::distance(a, a, &o);
        flags.flags |= 1 << 20;
        let cases = [
            (Item::distance(a, ghost, &o), ErrorCode::UnknownObject),
            (
                Item::set_pose(ghost, &Isometry3::identity()),
                ErrorCode::UnknownObject,
            ),
            (Item::set_pose(a, &nan), ErrorCode::NonFinitePose),
            (
                Item::distance(a, a, &o).with_pose_b(&nan),
                ErrorCode::NonFinitePose,
            ),
            (bad_q, ErrorCode::BadQuaternion),
            (close_q, ErrorCode::Ok),
            (
                Item::distance(
                    a,
                    a,
                    &QueryOptions {
                        max_iterations: 0,
                        ..o
                    },
                ),
                ErrorCode::InvalidOptions,
            ),
            (
                Item::distance(
                    a,
                    a,
                    &QueryOptions {
                        tolerance: -1.0,
                        ..o
                    },
                ),
                ErrorCode::InvalidOptions,
            ),
            (kind, ErrorCode::Malformed),
            (flags, ErrorCode::Malformed),
        ];
        for (item, code) in cases {
            assert_eq!(one(&mut s, 1, item).error_code(), code, "{item:?}");
        }
        assert_eq!(s.check_batch(0), Err(ErrorCode::EmptyBatch));
        assert_eq!(s.check_batch(1025), Err(ErrorCode::BatchTooLarge));
        assert_eq!(s.check_batch(1024), Ok(()));
    }

    #[test]
    fn registration_errors_are_specific() {
        let mut s = state();
        let mut req = AdminRequest::new(AdminOp::Register);
        req.shape = shape_kind::CONVEX;
        req.piece_count = 1;
        let v = Vertex {
            x: 1.0,
            y: 2.0,
            z: 3.0,
        };
        let code = |s: &mut State, req: &AdminRequest, verts: &[Vertex]| {
            s.handle_admin(1, req, verts).error_code()
        };
        assert_eq!(code(&mut s, &req, &[]), ErrorCode::EmptyVertices);
        req.pieces[0].vertex_count = 1;
        req.pieces[0].radius = -1.0;
        assert_eq!(code(&mut s, &req, &[v]), ErrorCode::InvalidRadius);
        req.pieces[0].radius = 0.5;
        let nan = Vertex { x: f64::NAN, ..v };
        assert_eq!(code(&mut s, &req, &[nan]), ErrorCode::NonFiniteVertex);
        assert_eq!(code(&mut s, &req, &[v, v]), ErrorCode::Malformed);
        let many = vec![v; 100_001];
        assert_eq!(code(&mut s, &req, &many), ErrorCode::TooManyVertices);
        req.shape = shape_kind::COMPOUND;
        req.piece_count = 0;
        assert_eq!(code(&mut s, &req, &[v]), ErrorCode::EmptyCompound);
        req.piece_count = 65;
        assert_eq!(code(&mut s, &req, &[v]), ErrorCode::TooManyPieces);
        req.piece_count = 2;
        req.pieces[1] = PieceDesc {
            vertex_count: 1,
            ..req.pieces[0]
        };
        req.pieces[1].offset.translation[0] = f64::INFINITY;
        assert_eq!(code(&mut s, &req, &[v, v]), ErrorCode::NonFinitePose);
        req.pieces[1].offset.translation[0] = 2.0;
        assert!(req.set_name("dumbbell"));
        let reply = s.handle_admin(1, &req, &[v, v]);
        assert_eq!(reply.error_code(), ErrorCode::Ok);
        assert_eq!(code(&mut s, &req, &[v, v]), ErrorCode::NameTaken);
        req.shape = 9;
        assert_eq!(code(&mut s, &req, &[v, v]), ErrorCode::Malformed);

        let mut lookup = AdminRequest::new(AdminOp::Lookup);
        assert!(lookup.set_name("dumbbell"));
        assert_eq!(s.handle_admin(5, &lookup, &[]).id, reply.id);
        let mut remove = AdminRequest::new(AdminOp::Remove);
        remove.id = reply.id;
        assert_eq!(code(&mut s, &remove, &[]), ErrorCode::Ok);
        assert_eq!(
            s.handle_admin(5, &lookup, &[]).error_code(),
            ErrorCode::UnknownName
        );
        assert_eq!(code(&mut s, &remove, &[]), ErrorCode::UnknownObject);
    }

    /// The strictness added for the reliability work: reserved words,
    /// unknown flags on any item kind, vertices on a non-registration, ids
    /// at the edges of the range.
    #[test]
    fn reserved_fields_stray_slices_and_edge_ids_are_refused() {
        let mut s = state();
        let a = ObjectId::from_raw(register_box(&mut s, 1));
        let mut reserved = Item::distance(a, a, &QueryOptions::default());
        reserved.reserved = 1;
        let mut pose_flags = Item::set_pose(a, &Isometry3::identity());
        pose_flags.flags = 1 << 9;
        let mut pose_reserved = Item::set_pose(a, &Isometry3::identity());
        pose_reserved.reserved = 7;
        for item in [reserved, pose_flags, pose_reserved] {
            assert_eq!(one(&mut s, 1, item).error_code(), ErrorCode::Malformed);
        }
        let epoch_of_a = a.raw() & !0xFFFF_FFFF;
        for raw in [
            0,
            u64::MAX,
            epoch_of_a,
            epoch_of_a | 0xFFFF_FFFF,
            a.raw() ^ (1 << 40),
        ] {
            let ghost = ObjectId::from_raw(raw);
            let item = Item::distance(a, ghost, &QueryOptions::default());
            assert_eq!(one(&mut s, 1, item).error_code(), ErrorCode::UnknownObject);
            let mut rm = AdminRequest::new(AdminOp::Remove);
            rm.id = raw;
            assert_eq!(
                s.handle_admin(1, &rm, &[]).error_code(),
                ErrorCode::UnknownObject
            );
        }
        let v = [Vertex::default()];
        for op in [
            AdminOp::Hello,
            AdminOp::Stats,
            AdminOp::Remove,
            AdminOp::Lookup,
        ] {
            let mut req = AdminRequest::new(op);
            req.id = a.raw();
            assert_eq!(
                s.handle_admin(1, &req, &v).error_code(),
                ErrorCode::Malformed,
                "{op:?}"
            );
        }
        assert!(
            s.object(a.raw()).is_some(),
            "the stray remove removed nothing"
        );
        let mut reg = AdminRequest::new(AdminOp::Register);
        reg.shape = shape_kind::CONVEX;
        reg.piece_count = 1;
        reg.pieces[0].vertex_count = 1;
        reg.pieces[0].reserved = 3;
        assert_eq!(
            s.handle_admin(1, &reg, &v).error_code(),
            ErrorCode::Malformed
        );
        reg.shape = shape_kind::COMPOUND;
        assert_eq!(
            s.handle_admin(1, &reg, &v).error_code(),
            ErrorCode::Malformed
        );
        reg.pieces[0].reserved = 0;
        assert_eq!(s.handle_admin(1, &reg, &v).error_code(), ErrorCode::Ok);
        // Quaternions: zero and NaN; registration poses as well as items.
        reg.pose.rotation = [0.0; 4];
        assert_eq!(
            s.handle_admin(1, &reg, &v).error_code(),
            ErrorCode::BadQuaternion
        );
        reg.pose.rotation = [f64::NAN, 0.0, 0.0, 1.0];
        assert_eq!(
            s.handle_admin(1, &reg, &v).error_code(),
            ErrorCode::NonFinitePose
        );
        reg.pose = Pose::IDENTITY;
        reg.pieces[0].offset.rotation = [0.0, 0.0, 0.0, 1.5];
        assert_eq!(
            s.handle_admin(1, &reg, &v).error_code(),
            ErrorCode::BadQuaternion
        );
        reg.pieces[0].offset.rotation = [0.0, 0.0, 0.0, 1.0];
        // Names: too long a length, bad UTF-8.
        reg.name_len = 65;
        assert_eq!(
            s.handle_admin(1, &reg, &v).error_code(),
            ErrorCode::Malformed
        );
        reg.name_len = 1;
        reg.name[0] = 0xC3;
        assert_eq!(
            s.handle_admin(1, &reg, &v).error_code(),
            ErrorCode::Malformed
        );
        // Options: infinite tolerance, infinite margin.
        for o in [
            QueryOptions {
                tolerance: f64::INFINITY,
                ..QueryOptions::default()
            },
            QueryOptions {
                margin: Some(f64::NEG_INFINITY),
                ..QueryOptions::default()
            },
        ] {
            let item = Item::distance(a, a, &o);
            assert_eq!(one(&mut s, 1, item).error_code(), ErrorCode::InvalidOptions);
        }
    }

    #[test]
    fn a_full_server_refuses_and_recovers_room_on_removal() {
        let limits = Limits {
            max_objects: 2,
            ..Limits::default()
        };
        let mut s = State::new(limits, WaitMode::Spin, 5);
        let a = register_box(&mut s, 1);
        register_box(&mut s, 1);
        let mut req = AdminRequest::new(AdminOp::Register);
        req.shape = shape_kind::CONVEX;
        req.piece_count = 1;
        req.pieces[0].vertex_count = 1;
        let v = [Vertex::default()];
        assert_eq!(
            s.handle_admin(1, &req, &v).error_code(),
            ErrorCode::TooManyObjects
        );
        s.remove(a, 1).expect("owner");
        assert_eq!(s.handle_admin(1, &req, &v).error_code(), ErrorCode::Ok);
    }

    /// A scene object: a unit ball named `name`.
    fn insert_scene_ball(s: &mut State, name: &str) -> u64 {
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

    #[test]
    fn only_the_owner_removes_and_scene_objects_stay() {
        let mut s = state();
        let id = register_box(&mut s, 1);
        assert_eq!(s.remove(id, 2), Err(ErrorCode::NotOwner));
        let scene = insert_scene_ball(&mut s, "fixed");
        assert_eq!(s.remove(scene, 1), Err(ErrorCode::ReadOnly));
        assert_eq!(s.remove(id, 1), Ok(()));
        assert!(s.object(id).is_none());
    }

    #[test]
    fn the_objects_of_departed_clients_are_removed_and_no_others() {
        let mut s = state();
        let kept = register_box(&mut s, 1);
        let gone = [register_box(&mut s, 2), register_named(&mut s, 2, "arm")];
        let scene = insert_scene_ball(&mut s, "fixed");
        let (removed, failed) = s.remove_departed(|c| c == 1);
        assert_eq!(failed, None);
        assert_eq!(removed, gone.to_vec());
        assert!(gone.iter().all(|&id| s.object(id).is_none()));
        assert!(s.object(kept).is_some() && s.object(scene).is_some());
        assert_eq!(s.lookup("arm"), None);
        assert_eq!(s.lookup("fixed"), Some(scene));
        // Nothing more to remove, and the name is free again under a new id.
        assert_eq!(s.remove_departed(|c| c == 1), (vec![], None));
        let again = register_named(&mut s, 1, "arm");
        assert!(!gone.contains(&again));
        // Everybody gone: only the scene object is left.
        let (removed, _) = s.remove_departed(|_| false);
        assert_eq!(removed.len(), 2);
        assert_eq!(s.len(), 1);
    }

    #[test]
    fn ids_carry_the_epoch_and_are_not_reused() {
        let mut s = state();
        let a = register_box(&mut s, 1);
        assert_eq!(a >> 32, 3);
        s.remove(a, 1).expect("owner");
        let b = register_box(&mut s, 1);
        assert_ne!(a, b);
    }

    #[test]
    fn a_restored_store_keeps_ids_owners_answers_and_counter() {
        let mut s = state();
        let a = register_box(&mut s, 41);
        let b = register_box(&mut s, 42);
        let gone = register_box(&mut s, 41);
        s.remove(gone, 41).expect("owner");
        let pb = Isometry3::new(Vector3::new(3.0, 0.5, 0.2), Vector3::new(0.1, 0.2, 0.3));
        let (ia, ib) = (ObjectId::from_raw(a), ObjectId::from_raw(b));
        one(&mut s, 1, Item::set_pose(ib, &pb));
        let before = one(&mut s, 1, Item::distance(ia, ib, &QueryOptions::cold()));

        let snap = s.snapshot();
        let bytes = snap.encode().expect("encodes");
        let back = crate::persist::Snapshot::decode(&bytes).expect("decodes");
        let mut r = State::restore(Limits::default(), WaitMode::Spin, &back).expect("valid");
        assert_eq!(r.len(), 2);
        let after = one(&mut r, 1, Item::distance(ia, ib, &QueryOptions::cold()));
        assert_eq!(
            after, before,
            "same ids, same poses, same answer bit for bit"
        );
        assert_eq!(r.remove(a, 42), Err(ErrorCode::NotOwner));
        let c = register_box(&mut r, 41);
        assert!(c > gone, "the counter continues past removed ids");
        assert_eq!(r.remove(a, 41), Ok(()));
        let too_few = Limits {
            max_objects: 1,
            ..Limits::default()
        };
        assert!(State::restore(too_few, WaitMode::Spin, &back).is_err());
    }

    /// Many objects registered and most removed: the survivors may sit in
    /// high journal slots, and the file must still load.
    #[test]
    fn a_store_that_shrank_restores() {
        let mut s = state();
        let ids: Vec<u64> = (0..3000).map(|_| register_box(&mut s, 1)).collect();
        for &id in &ids[..2990] {
            s.remove(id, 1).expect("owner");
        }
        let snap = s.snapshot();
        assert!(snap.objects.iter().any(|o| o.slot > 2000));
        let bytes = snap.encode().expect("encodes");
        let back = crate::persist::Snapshot::decode(&bytes).expect("a valid file");
        let mut r = State::restore(Limits::default(), WaitMode::Spin, &back).expect("restores");
        assert_eq!(r.len(), 10);
        // Freed slots are reused before new ones.
        let fresh = register_box(&mut r, 1);
        assert!(r.object(fresh).expect("there").slot < 2990);
    }

    /// The input `fuzz/` found (`gjk/tests/fuzz_regressions.rs`), through
    /// the server: a warm query across poses with 1e108 and 1e100
    /// coordinates. It used to panic inside gjk (answered `Internal` by the
    /// serving loop's catch_unwind); now it is answered with ordered bounds.
    #[test]
    fn the_fuzz_found_warm_start_is_answered() {
        let mut s = state();
        let mut req = AdminRequest::new(AdminOp::Register);
        req.shape = shape_kind::CONVEX;
        req.piece_count = 1;
        req.pieces[0].vertex_count = 4;
        req.pieces[0].radius = 6.4000000000000006e100;
        let v = |x: f64, y: f64, z: f64| Vertex { x, y, z };
        let a = s.handle_admin(
            1,
            &req,
            &[
                v(9.9e100, 9.900000000000002e108, 9.9e100),
                v(9.9e100, 9.9e100, 9.9e100),
                v(9.9e100, 9.9e100, 9.9e100),
                v(6.1875, 9.9e100, 9.9e100),
            ],
        );
        req.pieces[0].radius = 0.0;
        let b = s.handle_admin(
            1,
            &req,
            &[
                v(9.9e100, 9.9e100, -6.25),
                v(-6.25, -6.25, -6.25),
                v(-6.25, -6.25, -6.25),
                v(-6.25, -6.25, -6.25),
            ],
        );
        let (a, b) = (ObjectId::from_raw(a.id), ObjectId::from_raw(b.id));
        let pose = |w: f64, i: f64, j: f64, k: f64| {
            Isometry3::from_parts(
                Translation3::new(-6.25, -6.25, -6.25),
                UnitQuaternion::new_unchecked(Quaternion::new(w, i, j, k)),
            )
        };
        let o = QueryOptions {
            tolerance: 2.220446049250313e-14,
            max_iterations: 55,
            ..QueryOptions::default()
        };
        let p = pose(-0.5, -0.5, -0.5, -0.5);
        let turned = pose(
            -0.51231551957856,
            -0.51231551957856,
            -0.51231551957856,
            0.46108396762070397,
        );
        // The truths, independent of GJK: at the shared pose the triangle
        // lies in the plane z = 9.9e100 and the segment in z = -6.25, their
        // projections meeting at a common (x, y), so the distance is
        // 9.9e100 + 6.25 - 6.4e100 = 3.5e100. For the turned pose it is the
        // minimum over vertex-triangle and edge-edge distances evaluated in
        // 60-digit arithmetic (mpmath). This test pinned 7e100..8e100 for
        // both until the run was scaled: the first answer was then spoilt by
        // overflowing cofactors. (The f64 brute force of `bench::reference`
        // is off by 1e-5 here, in world coordinates of 1e108.)
        let truths = [3.5e100, 7.582268067529549e100];
        for ((pa, pb), truth) in [(p, p), (p, turned)].into_iter().zip(truths) {
            let item = Item::distance(a, b, &o).with_pose_a(&pa).with_pose_b(&pb);
            let got = one(&mut s, 9, item).answer().expect("answered");
            assert!(
                got.lower <= got.distance && got.distance <= got.upper,
                "{got:?}"
            );
            assert!(
                got.lower <= truth * (1.0 + 1e-12) && truth <= got.upper * (1.0 + 1e-12),
                "truth {truth:e}: {got:?}"
            );
            assert!(
                (got.distance - truth).abs() <= 1e-6 * truth,
                "truth {truth:e}: {got:?}"
            );
        }
    }

    /// A scratch directory of the test's own.
    fn scratch(tag: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("gjkd-state-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("dir");
        dir
    }

    /// A state persisted in `<scratch dir>/objects`: the directory, the
    /// state file and the state.
    fn stored(tag: &str) -> (std::path::PathBuf, std::path::PathBuf, State) {
        let dir = scratch(tag);
        let path = dir.join("objects");
        let mut s = state();
        s.set_store(Store::open(&path).expect("store"))
            .expect("journal");
        (dir, path, s)
    }

    /// The store as a restarted server would load it.
    fn reload(path: &std::path::Path) -> (Snapshot, crate::persist::Replay) {
        let mut store = Store::open(path).expect("store");
        match store.load_or_quarantine().expect("load") {
            crate::persist::Loaded::Snapshot { snapshot, log } => (snapshot, log),
            other => panic!("{other:?}"),
        }
    }

    fn register_named(s: &mut State, owner: u128, name: &str) -> u64 {
        let mut req = AdminRequest::new(AdminOp::Register);
        req.shape = shape_kind::CONVEX;
        req.piece_count = 1;
        req.pieces[0].vertex_count = 1;
        req.pieces[0].radius = 0.5;
        assert!(req.set_name(name));
        let reply = s.handle_admin(owner, &req, &[Vertex::default()]);
        assert_eq!(reply.error_code(), ErrorCode::Ok);
        reply.id
    }

    /// More than [`BULK_REMOVAL`] objects of a departed client go with one
    /// snapshot write: a restart sees none of them. If that write fails,
    /// every one of them is put back, named ones still found by name.
    #[test]
    fn a_departed_clients_many_objects_go_in_one_write_or_not_at_all() {
        let (dir, path, mut s) = stored("bulk-removal");
        let kept = register_box(&mut s, 1);
        let mut gone: Vec<u64> = (0..BULK_REMOVAL + 4)
            .map(|_| register_box(&mut s, 2))
            .collect();
        gone.push(register_named(&mut s, 2, "arm"));
        // Warm starts: one naming a doomed object, one not.
        let pair = |a: u64, b: u64| {
            Item::distance(
                ObjectId::from_raw(a),
                ObjectId::from_raw(b),
                &QueryOptions::default(),
            )
            .with_pose_b(&Isometry3::translation(3.0, 0.0, 0.0))
        };
        one(&mut s, 10, pair(kept, gone[0]));
        one(&mut s, 10, pair(kept, kept));
        assert_eq!(s.stats().cache_entries, 2);
        let (removed, failed) = s.remove_departed(|c| c == 1);
        assert_eq!((removed, failed), (gone, None));
        assert_eq!(
            s.stats().cache_entries,
            1,
            "the doomed pair's entry is gone"
        );
        assert!(
            one(&mut s, 10, pair(kept, kept))
                .answer()
                .expect("ok")
                .warm_started
        );
        drop(s);
        let (snapshot, log) = reload(&path);
        let ids: Vec<u64> = snapshot.objects.iter().map(|o| o.id).collect();
        assert_eq!(ids, vec![kept]);
        assert_eq!(log.applied, 0, "one snapshot, no records: {log:?}");

        // Again, with the state file's path blocked: nothing is removed.
        let path = dir.join("again");
        let mut s = state();
        s.set_store(Store::open(&path).expect("store"))
            .expect("journal");
        register_box(&mut s, 1);
        let doomed: Vec<u64> = (0..BULK_REMOVAL + 1)
            .map(|_| register_box(&mut s, 3))
            .collect();
        let named = register_named(&mut s, 3, "leg");
        one(&mut s, 10, pair(doomed[0], named));
        let before = s.len();
        std::fs::remove_file(&path).expect("rm");
        std::fs::create_dir(&path).expect("block the path");
        let (removed, failed) = s.remove_departed(|c| c == 1);
        assert_eq!((removed, failed), (vec![], Some(ErrorCode::Internal)));
        assert_eq!(s.len(), before);
        assert!(doomed.iter().all(|&id| s.object(id).is_some()));
        assert_eq!(s.lookup("leg"), Some(named));
        assert!(
            one(&mut s, 10, pair(doomed[0], named))
                .answer()
                .expect("ok")
                .warm_started
        );
        // Their slots are still theirs: a new object gets a fresh one.
        let fresh = register_box(&mut s, 1);
        let slots: std::collections::HashSet<u32> = s.objects.values().map(|o| o.slot).collect();
        assert_eq!(slots.len(), s.len(), "{fresh}: no slot shared");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A snapshot that drops objects registered since the last one, whose
    /// change log cannot then be emptied: the old log, whose records would
    /// bring them back at the next start, is removed instead.
    #[test]
    fn a_log_that_cannot_be_emptied_does_not_bring_removed_objects_back() {
        let (dir, path, mut s) = stored("stale-log");
        let kept = register_box(&mut s, 1);
        // Appended to the log after the first snapshot.
        let gone: Vec<u64> = (0..BULK_REMOVAL + 1)
            .map(|_| register_box(&mut s, 2))
            .collect();
        assert!(s.store().expect("store").has_changes());
        s.store.as_mut().expect("store").fail_log_resets();
        let (removed, failed) = s.remove_departed(|c| c == 1);
        assert_eq!((removed, failed), (gone, None));
        drop(s);
        let (snapshot, log) = reload(&path);
        let ids: Vec<u64> = snapshot.objects.iter().map(|o| o.id).collect();
        assert_eq!(ids, vec![kept], "{log:?}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_failed_write_undoes_the_change_and_says_internal() {
        let dir = scratch("failed-write");
        let path = dir.join("objects");
        let mut s = state();
        s.set_store(Store::open(&path).expect("store"))
            .expect("journal");
        // No log yet: the first change is written as a snapshot.
        let kept = register_box(&mut s, 1);
        assert!(path.exists());
        let store = s.store().expect("store");
        assert!(store.can_append() && !store.has_changes());
        // The disk fills up under the log (a real ENOSPC), and a directory
        // where the state file should be makes every rename onto it fail.
        store.fill_disk_under_log();
        std::fs::remove_file(&path).expect("rm");
        std::fs::create_dir(&path).expect("block the path");
        let mut req = AdminRequest::new(AdminOp::Register);
        req.shape = shape_kind::CONVEX;
        req.piece_count = 1;
        req.pieces[0].vertex_count = 1;
        assert!(req.set_name("ghost"));
        let reply = s.handle_admin(1, &req, &[Vertex::default()]);
        assert_eq!(reply.error_code(), ErrorCode::Internal);
        assert_eq!(s.len(), 1, "the unwritten object is not kept");
        assert_eq!(s.lookup("ghost"), None);
        assert!(!s.store().expect("store").can_append(), "log closed");
        // No log to append to, no snapshot can be written.
        assert_eq!(s.remove(kept, 1), Err(ErrorCode::Internal));
        assert!(s.object(kept).is_some(), "the unwritten removal is undone");
        assert_eq!(s.stats().persist_errors, 2);
        std::fs::remove_dir(&path).expect("unblock");
        // Written as a snapshot, which starts a fresh log...
        assert_eq!(s.remove(kept, 1), Ok(()));
        assert!(s.store().expect("store").can_append());
        // ...that the next change goes to.
        let last = register_box(&mut s, 1);
        assert!(s.store().expect("store").has_changes());
        drop(s);
        let (snapshot, log) = reload(&path);
        assert_eq!((log.applied, log.error), (1, None));
        let ids: Vec<u64> = snapshot.objects.iter().map(|o| o.id).collect();
        assert_eq!(ids, [last], "neither the ghost nor the removed object");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Registrations go to the log until it outgrows the snapshot (or
    /// 64 KiB), which is then rewritten and the log emptied: the log never
    /// gets much longer than the snapshot, so each registration writes a
    /// bounded amount on average. A compaction that fails leaves the change
    /// in the log instead.
    #[test]
    fn the_log_is_compacted_when_it_outgrows_the_snapshot() {
        use crate::persist::{COMPACT_MIN, LOG_HEADER_LEN};
        let dir = scratch("compaction");
        let path = dir.join("objects");
        let mut s = state();
        s.set_store(Store::open(&path).expect("store"))
            .expect("journal");
        let (mut compactions, mut last_len, mut appended) = (0, 0, 0u64);
        for _ in 0..700 {
            register_box(&mut s, 1);
            let store = s.store().expect("store");
            let len = store.log_len();
            if len < last_len {
                compactions += 1;
                assert_eq!(len, LOG_HEADER_LEN as u64, "emptied");
            } else {
                appended += len - last_len;
            }
            let snapshot = std::fs::metadata(&path).expect("state file").len();
            assert!(
                len <= snapshot.max(COMPACT_MIN) + 512,
                "a log of {len} bytes beside a snapshot of {snapshot}"
            );
            last_len = len;
        }
        // A box's record is about 300 bytes: the first compaction comes
        // after about 220 registrations, the next when the log outgrows the
        // snapshot, so a handful in 700, and all other changes appended.
        assert!((2..=5).contains(&compactions), "{compactions} compactions");
        assert!(appended > 2 * COMPACT_MIN, "{appended} bytes appended");
        let want = s.snapshot();

        // Fill the log up to its threshold, then block the state file.
        while !s.store().expect("store").wants_compaction() {
            register_box(&mut s, 1);
        }
        std::fs::rename(&path, dir.join("aside")).expect("move");
        std::fs::create_dir(&path).expect("block the path");
        let before = s.store().expect("store").log_len();
        let late = register_box(&mut s, 1);
        assert!(s.store().expect("store").log_len() > before, "appended");
        assert_eq!(s.stats().persist_errors, 1, "the failed compaction");
        std::fs::remove_dir(&path).expect("unblock");
        std::fs::rename(dir.join("aside"), &path).expect("back");
        register_box(&mut s, 1);
        assert_eq!(
            s.store().expect("store").log_len(),
            LOG_HEADER_LEN as u64,
            "compacted at the next change"
        );
        let all = s.snapshot();
        assert!(all.objects.iter().any(|o| o.id == late));
        assert!(all.objects.len() > want.objects.len());
        drop(s);
        let (snapshot, log) = reload(&path);
        assert_eq!(snapshot, all);
        assert_eq!(log.applied + log.skipped, 0);
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A removal and a registration taking over the removed object's name
    /// and journal slot, both only in the log: a restart gets exactly
    /// that, and the counter goes on past both ids.
    #[test]
    fn a_removal_then_a_registration_replays_from_the_log() {
        let dir = scratch("remove-register");
        let path = dir.join("objects");
        let mut s = state();
        s.set_store(Store::open(&path).expect("store"))
            .expect("journal");
        s.persist().expect("first snapshot");
        let other = register_box(&mut s, 2);
        let a = register_named(&mut s, 1, "n");
        let slot = s.object(a).expect("there").slot;
        s.remove(a, 1).expect("owner");
        let b = register_named(&mut s, 1, "n");
        assert_eq!(s.object(b).expect("there").slot, slot, "slot reused");
        let want = s.snapshot();
        drop(s);
        assert_eq!(
            Snapshot::decode(&std::fs::read(&path).expect("state file"))
                .expect("valid")
                .objects
                .len(),
            0,
            "everything is in the log"
        );
        let (snapshot, log) = reload(&path);
        assert_eq!((log.applied, log.skipped, log.error), (4, 0, None));
        assert_eq!(snapshot, want);
        let mut r = State::restore(Limits::default(), WaitMode::Spin, &snapshot).expect("valid");
        assert_eq!(r.lookup("n"), Some(b));
        assert!(r.object(a).is_none());
        assert!(r.object(other).is_some());
        assert_eq!(r.object(b).expect("there").slot, slot);
        let c = register_box(&mut r, 1);
        assert!(c > b && c > a, "ids are not reused");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Arbitrary bytes reinterpreted as items never panic the handler.
    #[test]
    fn garbage_items_do_not_panic() {
        let mut s = state();
        let a = register_box(&mut s, 1);
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        for _ in 0..2000 {
            let mut item = Item::distance(
                ObjectId::from_raw(a),
                ObjectId::from_raw(a),
                &QueryOptions::default(),
            );
            item.kind = (next() % 4) as u32;
            // Every known bit and the first unknown one.
            item.flags = (next() % 64) as u32;
            item.tolerance = f64::from_bits(next());
            item.margin = f64::from_bits(next());
            item.max_iterations = (next() % 300) as u32;
            item.pose_a.translation[0] = f64::from_bits(next());
            item.pose_b.rotation[1] = f64::from_bits(next());
            let _ = one(&mut s, 3, item);
        }
    }
}
