//! The object store: objects, their ids, names, owners and journal slots.
//! Everything a registration, a removal or a pose update changes goes
//! through here, and through its [`Durability`] when persistence is on, so
//! that what is acknowledged is what is on disk.

use std::collections::HashMap;

use gjk::Shape;
use gjkd_proto::ErrorCode;
use nalgebra::Isometry3;

use super::durability::{CommitError, Durability};
use super::records::{Snapshot, StoredObject, StoredOwner, StoredPose, StoredShape};
use super::tokens::{TokenKey, Tokens};
use super::warm_cache::FxBuild;

/// Who may remove an object.
///
/// A client is identified by the id of its iceoryx2 node: one per
/// `gjkd-client` `Client`, kept for the `Client`'s whole life, across its
/// reconnections and across server restarts (the id is stored in the state
/// store). A client *process* that restarts has a new node, so objects
/// registered by its previous life can no longer be removed by any client;
/// the operator can (`gjkd objects --remove-departed`, see
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
    /// Its slot in the pose journal (see [`crate::persist::journal`]).
    pub slot: u32,
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

/// Most objects of departed clients removed one committed transaction at a
/// time; beyond, [`ObjectStore::remove_departed`] removes them all in one.
pub const BULK_REMOVAL: usize = 16;

/// The objects and their persistence.
#[derive(Debug)]
pub struct ObjectStore {
    /// Upper 32 bits of every id of this store, so ids of another store
    /// are unknown rather than aliases.
    epoch: u64,
    next_index: u32,
    objects: HashMap<u64, Object, FxBuild>,
    names: HashMap<String, u64>,
    /// Where registrations and removals are committed before they are
    /// acknowledged, and poses recorded; `None` when persistence is off.
    durable: Option<Box<dyn Durability>>,
    /// Journal slots of removed objects, for reuse.
    free_slots: Vec<u32>,
    /// Lowest slot never used.
    next_slot: u32,
    /// Commits to the database and journal writes that failed.
    persist_errors: u64,
    /// Registration tokens of recent registrations, as in the database.
    tokens: Tokens,
    /// Objects added, moved or removed since the scene index last looked
    /// (see [`ObjectStore::take_changes`]); may repeat an id.
    changes: Vec<u64>,
    /// The change list overflowed (or the store was rebuilt): the scene
    /// index must look at every object.
    changes_lost: bool,
}

/// Most changes listed for the scene index before the list gives up and asks
/// for a full resync: bounds the memory of a server whose clients move
/// objects but never ask a scene question.
const MAX_LISTED_CHANGES: usize = 4096;

impl ObjectStore {
    /// An empty store. `epoch` goes into the upper 32 bits of every id (0 is
    /// replaced by 1, so that no id is 0).
    pub fn new(epoch: u32) -> Self {
        ObjectStore {
            epoch: u64::from(epoch.max(1)) << 32,
            next_index: 1,
            objects: HashMap::default(),
            names: HashMap::new(),
            durable: None,
            free_slots: Vec::new(),
            next_slot: 0,
            persist_errors: 0,
            tokens: Tokens::default(),
            changes: Vec::new(),
            changes_lost: true,
        }
    }

    /// Records that object `id` was added, moved or removed, for the scene
    /// index.
    #[inline]
    fn note_change(&mut self, id: u64) {
        if self.changes_lost {
            return;
        }
        if self.changes.len() >= MAX_LISTED_CHANGES.max(self.objects.len()) {
            self.changes.clear();
            self.changes_lost = true;
        } else {
            self.changes.push(id);
        }
    }

    /// Moves the ids of the objects added, moved or removed since the last
    /// call into `out` (cleared first); returns false when the list was lost
    /// and every object must be looked at instead.
    pub fn take_changes(&mut self, out: &mut Vec<u64>) -> bool {
        out.clear();
        std::mem::swap(out, &mut self.changes);
        let complete = !self.changes_lost;
        self.changes_lost = false;
        complete
    }

    /// A store holding the objects of `snapshot` with their exact ids, its
    /// id counter continuing where the snapshot's stopped (so no id is ever
    /// handed out twice).
    ///
    /// # Errors
    /// A description of the problem if the snapshot does not pass
    /// [`Snapshot::validate`] or holds more than `max_objects`; nothing is
    /// half-loaded.
    pub fn restore(snapshot: &Snapshot, max_objects: usize) -> Result<Self, String> {
        snapshot.validate()?;
        if snapshot.objects.len() > max_objects {
            return Err(format!(
                "{} objects stored, the limit is {max_objects}",
                snapshot.objects.len(),
            ));
        }
        let mut store = ObjectStore::new(snapshot.epoch);
        store.next_index = snapshot.next_index;
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
                store.names.insert(name.clone(), o.id);
            }
            store.objects.insert(o.id, object);
        }
        let mut used: Vec<u32> = snapshot.objects.iter().map(|o| o.slot).collect();
        used.sort_unstable();
        store.next_slot = used.last().map_or(0, |&m| m + 1);
        store.free_slots = (0..store.next_slot)
            .rev()
            .filter(|s| used.binary_search(s).is_err())
            .collect();
        Ok(store)
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

    /// Takes the poses `journaled` returns (the latest ones before a
    /// crash) for the objects here (restored from the database) in place of
    /// theirs; returns, in id order, the objects it has none for, which keep
    /// the pose stored with them.
    pub fn recover_poses(
        &mut self,
        journaled: impl Fn(u32, u64) -> Option<Isometry3<f64>>,
    ) -> Vec<u64> {
        let mut unverified = Vec::new();
        for (&id, o) in self.objects.iter_mut() {
            match journaled(o.slot, id) {
                Some(pose) => o.pose = pose,
                None => unverified.push(id),
            }
        }
        self.changes.clear();
        self.changes_lost = true;
        unverified.sort_unstable();
        unverified
    }

    /// Turns persistence on: from now on every registration and removal is
    /// committed to `durable` before it is acknowledged, and every pose
    /// update recorded there; every current pose is recorded now. `tokens`
    /// are the registration tokens it kept (those of objects no longer here
    /// are dropped).
    pub fn set_durability(&mut self, durable: Box<dyn Durability>, tokens: Vec<(TokenKey, u64)>) {
        let objects = &self.objects;
        self.tokens = Tokens::load(tokens, |id| objects.contains_key(&id));
        self.durable = Some(durable);
        let slots: Vec<(u32, u64)> = self.objects.iter().map(|(&id, o)| (o.slot, id)).collect();
        for (slot, id) in slots {
            self.journal_pose(slot, id);
        }
    }

    /// Whether persistence is on.
    pub fn is_durable(&self) -> bool {
        self.durable.is_some()
    }

    /// Writes `pose` of object `id` (in `slot`) to the journal, if any. A
    /// failure (the file cannot grow: disk full) costs only durability of
    /// this pose, not the update itself, so it is counted and logged.
    fn journal_pose(&mut self, slot: u32, id: u64) {
        let (Some(durable), Some(o)) = (self.durable.as_mut(), self.objects.get(&id)) else {
            return;
        };
        if let Err(e) = durable.write_pose(slot, id, &o.pose) {
            self.persist_errors += 1;
            tracing::error!("cannot write the pose journal: {e}");
        }
    }

    /// Makes the database hold exactly this store, current poses included
    /// (when persistence is on), writing only what differs: at start after
    /// the scene is installed, and at shutdown.
    ///
    /// On a full disk this is not an error: the server must start (and
    /// stop) there too. The poses stay in the journal, and the scene
    /// objects not yet stored get new ids at the next start; it is counted
    /// and logged.
    ///
    /// # Errors
    /// Any other commit error; the database is then as it was.
    pub fn persist(&mut self) -> Result<(), CommitError> {
        if self.durable.is_none() {
            return Ok(());
        }
        let snapshot = self.snapshot();
        let Some(durable) = &mut self.durable else {
            return Ok(());
        };
        match durable.sync(&snapshot) {
            Ok(()) => Ok(()),
            Err(CommitError::Full(e)) => {
                self.persist_errors += 1;
                tracing::warn!(
                    "{e}: cannot bring the store up to date, the current poses stay in the journal only"
                );
                Ok(())
            }
            Err(e) => {
                self.persist_errors += 1;
                Err(e)
            }
        }
    }

    /// Asks the kernel to put the pose journal on disk if poses changed.
    /// Only a machine crash needs this (the journal's pages outlive the
    /// process); called when idle and at shutdown.
    ///
    /// # Errors
    /// The `msync` error.
    pub fn flush(&mut self) -> std::io::Result<()> {
        match &mut self.durable {
            Some(d) => d.flush_poses(),
            None => Ok(()),
        }
    }

    /// Failed commits and journal writes so far.
    pub fn persist_errors(&self) -> u64 {
        self.persist_errors
    }

    /// The upper 32 bits of every id of this run (also those of robots,
    /// see [`crate::engine::robots`]).
    pub fn id_epoch(&self) -> u64 {
        self.epoch
    }

    /// The object with this id.
    pub fn object(&self, id: u64) -> Option<&Object> {
        self.objects.get(&id)
    }

    /// Every object, in no particular order.
    pub fn objects(&self) -> impl Iterator<Item = (u64, &Object)> {
        self.objects.iter().map(|(&id, o)| (id, o))
    }

    /// Number of objects.
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// Whether no object is stored.
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }

    /// The id of the object named `name`.
    pub fn lookup(&self, name: &str) -> Option<u64> {
        self.names.get(name).copied()
    }

    /// Moves object `id` to `pose`, recorded in the journal.
    ///
    /// # Errors
    /// [`ErrorCode::UnknownObject`].
    pub fn set_pose(&mut self, id: u64, pose: Isometry3<f64>) -> Result<(), ErrorCode> {
        let object = self.objects.get_mut(&id).ok_or(ErrorCode::UnknownObject)?;
        object.pose = pose;
        let slot = object.slot;
        self.journal_pose(slot, id);
        self.note_change(id);
        Ok(())
    }

    /// Installs a scene object: an object restored from the database with
    /// the same name, the same geometry and scene ownership keeps its id
    /// (and takes the scene's pose); otherwise a new object is inserted.
    /// Call [`ObjectStore::drop_scene_objects_except`] after the whole
    /// scene. The caller forgets the warm starts of a replaced object.
    ///
    /// # Errors
    /// As [`ObjectStore::insert`].
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
            self.note_change(id);
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
            self.unlink_object(id);
        }
        self.insert(new, Owner::Scene, usize::MAX)
    }

    /// Removes the scene objects restored from the database that the
    /// current scene no longer has; returns their ids.
    pub fn drop_scene_objects_except(&mut self, keep: &[u64]) -> Vec<u64> {
        let doomed: Vec<u64> = self
            .objects
            .iter()
            .filter(|(id, o)| o.owner == Owner::Scene && !keep.contains(id))
            .map(|(&id, _)| id)
            .collect();
        for &id in &doomed {
            self.unlink_object(id);
        }
        doomed
    }

    /// Takes object `id` out of the store (not out of the database); its
    /// slot is free again.
    fn unlink_object(&mut self, id: u64) -> Option<Object> {
        let object = self.objects.remove(&id)?;
        if let Some(name) = &object.name {
            self.names.remove(name);
        }
        self.free_slots.push(object.slot);
        self.note_change(id);
        Some(object)
    }

    /// Adds an object, returning its id, without committing it (see
    /// [`ObjectStore::register`] for that).
    ///
    /// # Errors
    /// [`ErrorCode::NameTaken`], [`ErrorCode::TooManyObjects`] when
    /// `max_objects` are stored or the id counter is spent.
    pub fn insert(
        &mut self,
        new: NewObject,
        owner: Owner,
        max_objects: usize,
    ) -> Result<u64, ErrorCode> {
        if self.objects.len() >= max_objects || self.next_index == u32::MAX {
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
        self.note_change(id);
        Ok(id)
    }

    /// Adds a client's object and commits it to the database (when
    /// persistence is on) before returning its id; if the commit fails, the
    /// object is not kept.
    ///
    /// A client's registration `token` (not 0, see [`crate::engine::tokens`]) is
    /// committed with the object; a registration whose token this owner
    /// used before, while that object is still stored, returns that
    /// object's id and stores nothing.
    ///
    /// # Errors
    /// As [`ObjectStore::insert`], and [`ErrorCode::StorageFull`] (no room
    /// on the disk) or [`ErrorCode::Internal`] when the commit fails;
    /// [`ErrorCode::Malformed`] for a token used before with another shape
    /// or name.
    pub fn register(
        &mut self,
        new: NewObject,
        owner: Owner,
        max_objects: usize,
        token: u64,
    ) -> Result<u64, ErrorCode> {
        let key = match owner {
            Owner::Client(c) if token != 0 => Some((c, token)),
            _ => None,
        };
        if let Some(id) = key.and_then(|k| self.tokens.find(k))
            && let Some(old) = self.objects.get(&id)
        {
            // A retry: the same object, or a client reusing a token.
            return if old.shape == new.shape && old.name == new.name {
                Ok(id)
            } else {
                Err(ErrorCode::Malformed)
            };
        }
        let id = self.insert(new, owner, max_objects)?;
        // Just inserted, so always there.
        let stored = self.stored(id).ok_or(ErrorCode::Internal)?;
        let next = self.next_index;
        let token_write = key.map(|k| (k, self.tokens.pushed_out_by_next(k.0)));
        match self.commit(|db| db.register(&stored, next, token_write)) {
            Ok(()) => {
                if let Some(k) = key {
                    self.tokens.remember(k, id);
                }
                Ok(id)
            }
            Err(e) => {
                self.unlink_object(id);
                Err(e)
            }
        }
    }

    /// Test and fault-injection view: the registration tokens remembered.
    pub fn tokens(&self) -> &Tokens {
        &self.tokens
    }

    /// Removes the objects of every client for which `alive` is false (its
    /// process ended: no client could remove them, since a restarted
    /// process gets a new identity). Scene objects stay; ids are never
    /// reused. A few are committed one by one, like a client's removals;
    /// more than [`BULK_REMOVAL`] at once in one transaction, since a
    /// crashed process's thousand objects would otherwise hold the request
    /// loop for a thousand synced commits. Returns the ids removed, in id
    /// order, and the error that stopped the pass if a commit failed (the
    /// objects it concerned are kept). The caller forgets their warm starts.
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
        if doomed.len() > BULK_REMOVAL && self.durable.is_some() {
            return self.remove_in_bulk(&doomed);
        }
        let mut removed = Vec::with_capacity(doomed.len());
        for (id, owner) in doomed {
            match self.remove(id, owner) {
                Ok(id) => removed.push(id),
                Err(e) => return (removed, Some(e)),
            }
        }
        (removed, None)
    }

    /// [`remove_departed`](Self::remove_departed)'s many: all dropped, then
    /// one transaction; if it cannot be committed, all put back (the
    /// database is as it was).
    fn remove_in_bulk(&mut self, doomed: &[(u64, u128)]) -> (Vec<u64>, Option<ErrorCode>) {
        let dropped: Vec<(u64, Object)> = doomed
            .iter()
            .filter_map(|&(id, _)| Some((id, self.unlink_object(id)?)))
            .collect();
        let ids: Vec<u64> = dropped.iter().map(|&(id, _)| id).collect();
        let keys: Vec<_> = ids
            .iter()
            .filter_map(|&id| self.tokens.key_of(id))
            .collect();
        if let Err(code) = self.commit(|db| db.remove(&ids, &keys)) {
            // In reverse: each object's slot is then on top of the stack.
            for (id, object) in dropped.into_iter().rev() {
                self.relink_object(id, object);
            }
            return (Vec::new(), Some(code));
        }
        for &id in &ids {
            self.tokens.forget_object(id);
        }
        (ids, None)
    }

    /// Undoes [`unlink_object`](Self::unlink_object), the last unlinked
    /// first.
    fn relink_object(&mut self, id: u64, object: Object) {
        if self.free_slots.last() == Some(&object.slot) {
            self.free_slots.pop();
        }
        if let Some(name) = &object.name {
            self.names.insert(name.clone(), id);
        }
        self.objects.insert(id, object);
        self.note_change(id);
    }

    /// Makes a registration or removal durable before it is acknowledged:
    /// `write` commits it to the database (when persistence is on). The
    /// error is what the client is told if that fails; the caller then
    /// undoes the change.
    fn commit(
        &mut self,
        write: impl FnOnce(&mut dyn Durability) -> Result<(), CommitError>,
    ) -> Result<(), ErrorCode> {
        let Some(durable) = &mut self.durable else {
            return Ok(());
        };
        write(durable.as_mut()).map_err(|e| {
            self.persist_errors += 1;
            tracing::error!("{e}; the change is undone");
            match e {
                CommitError::Full(_) => ErrorCode::StorageFull,
                CommitError::Failed(_) => ErrorCode::Internal,
            }
        })
    }

    /// Removes object `id` on behalf of `requester` and commits the removal
    /// (when persistence is on) before returning; the caller forgets its
    /// warm starts.
    ///
    /// # Errors
    /// [`ErrorCode::UnknownObject`], [`ErrorCode::ReadOnly`] for scene
    /// objects, [`ErrorCode::NotOwner`] for another client's object,
    /// [`ErrorCode::StorageFull`] or [`ErrorCode::Internal`] when the commit
    /// fails (nothing is removed).
    pub fn remove(&mut self, id: u64, requester: u128) -> Result<u64, ErrorCode> {
        self.check_removable(id, requester)?;
        let Some(object) = self.unlink_object(id) else {
            return Err(ErrorCode::UnknownObject);
        };
        let keys: Vec<_> = self.tokens.key_of(id).into_iter().collect();
        if let Err(e) = self.commit(|db| db.remove(&[id], &keys)) {
            self.relink_object(id, object);
            return Err(e);
        }
        self.tokens.forget_object(id);
        Ok(id)
    }

    /// Whether `requester` may remove object `id`.
    ///
    /// # Errors
    /// As [`ObjectStore::remove`], before anything changes.
    fn check_removable(&self, id: u64, requester: u128) -> Result<(), ErrorCode> {
        let object = self.objects.get(&id).ok_or(ErrorCode::UnknownObject)?;
        match object.owner {
            Owner::Scene => Err(ErrorCode::ReadOnly),
            Owner::Client(c) if c != requester => Err(ErrorCode::NotOwner),
            Owner::Client(_) => Ok(()),
        }
    }

    /// Removes every object of `ids` on behalf of `requester` in one
    /// commit, all or nothing (a robot's links: a robot is never left
    /// with a hole).
    ///
    /// # Errors
    /// As [`ObjectStore::remove`] for the first object that cannot be
    /// removed, or for the commit; nothing is removed then.
    pub fn remove_all(&mut self, ids: &[u64], requester: u128) -> Result<(), ErrorCode> {
        for &id in ids {
            self.check_removable(id, requester)?;
        }
        let doomed: Vec<(u64, u128)> = ids.iter().map(|&id| (id, requester)).collect();
        match self.remove_in_bulk(&doomed) {
            (_, Some(code)) => Err(code),
            (_, None) => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::engine::state::test_support::*;
    use crate::engine::state::{Limits, State};
    use gjkd_proto::{
        AdminChunk, AdminOp, AdminRequest, ErrorCode, Item, ObjectId, QueryOptions, Vertex,
        WaitMode, shape_kind,
    };
    use nalgebra::{Isometry3, Vector3};

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
            s.handle_admin(1, &req, AdminChunk::from_vertices(&v))
                .error_code(),
            ErrorCode::TooManyObjects
        );
        s.remove(a, 1).expect("owner");
        assert_eq!(
            s.handle_admin(1, &req, AdminChunk::from_vertices(&v))
                .error_code(),
            ErrorCode::Ok
        );
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
        let back = through_database("restored", &snap);
        assert_eq!(back, snap);
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
        let back = through_database("shrank", &snap);
        let mut r = State::restore(Limits::default(), WaitMode::Spin, &back).expect("restores");
        assert_eq!(r.len(), 10);
        // Freed slots are reused before new ones.
        let fresh = register_box(&mut r, 1);
        assert!(r.object(fresh).expect("there").slot < 2990);
    }
}
