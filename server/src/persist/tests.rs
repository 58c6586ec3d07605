//! Persistence as the engine meets it: commits and their failures, the
//! pose journal and registration tokens across a restart.

use super::attach;
use super::database::{Database, WriteFaults};
use super::journal;
use crate::engine::state::test_support::*;
use crate::engine::state::{BULK_REMOVAL, Limits, State};
use gjkd_proto::{
    AdminChunk, AdminOp, AdminRequest, ErrorCode, Item, ObjectId, QueryOptions, Vertex, WaitMode,
    shape_kind,
};
use nalgebra::Isometry3;

/// A state persisted in `<scratch dir>/objects`, and the handle that makes
/// its database's writes fail.
fn stored_with_faults(tag: &str) -> (std::path::PathBuf, std::path::PathBuf, State, WriteFaults) {
    let dir = scratch(tag);
    let path = dir.join("objects");
    let mut s = state();
    let (db, opened) = Database::open(&path, 3).expect("store");
    assert!(opened.fresh);
    let faults = db.write_faults();
    attach(&mut s, db).expect("journal");
    (dir, path, s, faults)
}

/// More than [`BULK_REMOVAL`] objects of a departed client go in one
/// transaction: a restart sees none of them. If it cannot be committed,
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
    assert_eq!(ids_of(&reload(&path)), vec![kept]);

    // Again, on a disk that is full: nothing is removed.
    let _ = std::fs::remove_dir_all(&dir);
    let (dir, path, mut s, faults) = stored_with_faults("bulk-removal-full");
    let first = register_box(&mut s, 1);
    let doomed: Vec<u64> = (0..BULK_REMOVAL + 1)
        .map(|_| register_box(&mut s, 3))
        .collect();
    let named = register_named(&mut s, 3, "leg");
    one(&mut s, 10, pair(doomed[0], named));
    let before = s.len();
    let want = s.snapshot();
    faults.simulate_full_disk(true);
    let (removed, failed) = s.remove_departed(|c| c == 1);
    assert_eq!((removed, failed), (vec![], Some(ErrorCode::StorageFull)));
    assert_eq!(s.len(), before);
    assert!(doomed.iter().all(|&id| s.object(id).is_some()));
    assert_eq!(s.lookup("leg"), Some(named));
    assert!(
        one(&mut s, 10, pair(doomed[0], named))
            .answer()
            .expect("ok")
            .warm_started
    );
    // Their slots are still theirs: a new object gets a fresh one, once
    // there is room again.
    faults.simulate_full_disk(false);
    let fresh = register_box(&mut s, 1);
    let slots: std::collections::HashSet<u32> = s.store().objects().map(|(_, o)| o.slot).collect();
    assert_eq!(slots.len(), s.len(), "{fresh}: no slot shared");
    drop(s);
    let back = reload(&path);
    assert_eq!(back.objects.len(), want.objects.len() + 1);
    assert!(ids_of(&back).contains(&first) && ids_of(&back).contains(&fresh));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A commit that fails on a full disk (a real `ENOSPC` from the storage
/// layer) undoes the change in memory and says `StorageFull`, while
/// queries and pose updates go on; once the disk has room again,
/// changes are accepted without a restart. Any other write failure
/// says `Internal`.
#[test]
fn a_full_disk_refuses_changes_until_there_is_room_again() {
    let (dir, path, mut s, faults) = stored_with_faults("full-disk");
    let kept = register_box(&mut s, 1);
    let other = register_box(&mut s, 1);
    faults.simulate_full_disk(true);
    let mut req = AdminRequest::new(AdminOp::Register);
    req.shape = shape_kind::CONVEX;
    req.piece_count = 1;
    req.pieces[0].vertex_count = 1;
    assert!(req.set_name("ghost"));
    let reply = s.handle_admin(1, &req, AdminChunk::from_vertices(&[Vertex::default()]));
    assert_eq!(reply.error_code(), ErrorCode::StorageFull);
    assert_eq!(s.len(), 2, "the unwritten object is not kept");
    assert_eq!(s.lookup("ghost"), None);
    assert_eq!(s.remove(kept, 1), Err(ErrorCode::StorageFull));
    assert!(s.object(kept).is_some(), "the unwritten removal is undone");
    assert_eq!(s.stats().persist_errors, 2);
    // Queries and pose updates go on meanwhile.
    let (ik, io) = (ObjectId::from_raw(kept), ObjectId::from_raw(other));
    let moved = Isometry3::translation(5.0, 0.0, 0.0);
    assert_eq!(
        one(&mut s, 9, Item::set_pose(ik, &moved)).error_code(),
        ErrorCode::Ok
    );
    let d = one(&mut s, 9, Item::distance(ik, io, &QueryOptions::cold()));
    assert_eq!(d.answer().expect("served").distance, 3.0);
    // Another failure of the storage is the server's own.
    faults.fail_writes(libc::EIO);
    assert_eq!(
        s.handle_admin(1, &req, AdminChunk::from_vertices(&[Vertex::default()]))
            .error_code(),
        ErrorCode::Internal
    );
    faults.fail_writes(0);
    assert_eq!(s.remove(kept, 1), Ok(()));
    let last = register_box(&mut s, 1);
    drop(s);
    assert_eq!(
        ids_of(&reload(&path)),
        [other, last],
        "neither the ghost nor the removed object"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A pose journal damaged while the server was stopped: the objects
/// whose slot no longer verifies are returned (and logged) and keep the
/// pose stored in the database (here: their registration pose), the
/// others their journaled pose; the journal is copied aside as found.
#[test]
fn poses_the_journal_cannot_verify_are_reported_and_fall_back() {
    let (dir, path, mut s) = stored("journal-damage");
    let ids: Vec<u64> = (0..3).map(|_| register_box(&mut s, 1)).collect();
    let moved = Isometry3::translation(7.0, 0.0, 0.0);
    for &id in &ids {
        let r = one(&mut s, 9, Item::set_pose(ObjectId::from_raw(id), &moved));
        assert_eq!(r.error_code(), ErrorCode::Ok);
    }
    let slot = s.object(ids[1]).expect("there").slot as usize;
    drop(s);
    let journal = crate::persist::journal::path_for(&path);
    let reopen = || {
        let (db, opened) = Database::open(&path, 9).expect("reopen");
        let mut r =
            State::restore(Limits::default(), WaitMode::Spin, &opened.snapshot).expect("ok");
        let unverified = attach(&mut r, db).expect("journal");
        (r, unverified)
    };
    let kept = |bytes: &[u8]| {
        std::fs::read_dir(&dir)
            .expect("list")
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().contains("poses.corrupt-"))
            .any(|e| std::fs::read(e.path()).expect("read") == bytes)
    };
    // A byte of object 1's slot (after the 16-byte header).
    let mut bytes = std::fs::read(&journal).expect("journal");
    bytes[16 + slot * crate::persist::journal::SLOT + 20] ^= 0x40;
    std::fs::write(&journal, &bytes).expect("spoil");
    let (r, unverified) = reopen();
    assert_eq!(unverified, [ids[1]]);
    assert_eq!(r.object(ids[0]).expect("there").pose, moved);
    assert_eq!(r.object(ids[1]).expect("there").pose, Isometry3::identity());
    assert_eq!(r.object(ids[2]).expect("there").pose, moved);
    assert!(kept(&bytes), "the damaged journal is kept as found");
    drop(r);
    // Cut short to its header: no pose verifies.
    let mut bytes = std::fs::read(&journal).expect("journal");
    bytes.truncate(16);
    std::fs::write(&journal, &bytes).expect("cut");
    let (r, unverified) = reopen();
    assert_eq!(unverified, ids);
    assert!(
        ids.iter()
            .all(|&id| r.object(id).expect("there").pose == Isometry3::identity())
    );
    assert!(kept(&bytes));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A registration retried with its token gets the object stored the
/// first time, also after a restart (the token is committed with the
/// object); another client's same token, or the token after the object
/// is removed, registers anew; the token with another shape is refused.
#[test]
fn a_retried_registration_gets_the_stored_object_across_a_restart() {
    let (dir, path, mut s) = stored("tokens");
    let mut req = AdminRequest::new(AdminOp::Register);
    req.shape = shape_kind::CONVEX;
    req.piece_count = 1;
    req.pieces[0].vertex_count = 1;
    req.pieces[0].rounding = 0.5;
    req.token = 0xfeed;
    let v = [Vertex::default()];
    let first = s.handle_admin(1, &req, AdminChunk::from_vertices(&v));
    assert_eq!(first.error_code(), ErrorCode::Ok);
    assert_eq!(
        s.handle_admin(1, &req, AdminChunk::from_vertices(&v)).id,
        first.id,
        "same token"
    );
    assert_eq!(s.len(), 1);
    drop(s);
    // As a server killed after the commit finds it.
    let (db, opened) = Database::open(&path, 9).expect("reopen");
    let mut r = State::restore(Limits::default(), WaitMode::Spin, &opened.snapshot).expect("valid");
    attach(&mut r, db).expect("journal");
    let again = r.handle_admin(1, &req, AdminChunk::from_vertices(&v));
    assert_eq!((again.error_code(), again.id), (ErrorCode::Ok, first.id));
    assert_eq!(r.len(), 1, "one object, not two");
    // Another owner's token is its own.
    let other = r.handle_admin(2, &req, AdminChunk::from_vertices(&v));
    assert_ne!(other.id, first.id);
    // The same token for another shape is a client bug.
    let mut changed = req;
    changed.pieces[0].rounding = 0.75;
    assert_eq!(
        r.handle_admin(1, &changed, AdminChunk::from_vertices(&v))
            .error_code(),
        ErrorCode::Malformed
    );
    // Token 0 is no token: two objects.
    let mut plain = req;
    plain.token = 0;
    let (p1, p2) = (
        r.handle_admin(1, &plain, AdminChunk::from_vertices(&v)),
        r.handle_admin(1, &plain, AdminChunk::from_vertices(&v)),
    );
    assert_ne!(p1.id, p2.id);
    // Removed: the token is forgotten with the object, on disk too.
    r.remove(first.id, 1).expect("owner");
    assert_eq!(r.store().tokens().find((1, 0xfeed)), None);
    drop(r);
    let (mut db, _) = Database::open(&path, 9).expect("reopen");
    let tokens = db.tokens().expect("tokens");
    assert_eq!(tokens, vec![((2, 0xfeed), other.id)]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A removal and a registration taking over the removed object's name
/// and journal slot: a restart gets exactly that, and the counter goes
/// on past both ids.
#[test]
fn a_removal_then_a_registration_reloads() {
    let (dir, path, mut s) = stored("remove-register");
    let other = register_box(&mut s, 2);
    let a = register_named(&mut s, 1, "n");
    let slot = s.object(a).expect("there").slot;
    s.remove(a, 1).expect("owner");
    let b = register_named(&mut s, 1, "n");
    assert_eq!(s.object(b).expect("there").slot, slot, "slot reused");
    let want = s.snapshot();
    drop(s);
    let snapshot = reload(&path);
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

/// A store file cut to zero bytes while its pose journal names objects is
/// not a new store: it is set aside with its journal, and the objects the
/// journal names are reported lost (they were opened as a new, empty store
/// with nothing said above INFO).
#[test]
fn an_empty_store_file_whose_journal_names_objects_is_set_aside() {
    let (dir, path, mut s) = stored("empty-store");
    let ids: Vec<u64> = (0..3).map(|_| register_box(&mut s, 1)).collect();
    drop(s);
    std::fs::File::create(&path).expect("truncate to zero bytes");
    let (db, opened) = Database::open(&path, 9).expect("reopen");
    assert_eq!(opened.lost, ids);
    assert!(opened.fresh && opened.snapshot.objects.is_empty());
    let [store, poses] = opened.set_aside.as_slice() else {
        panic!("the store and its journal set aside: {opened:?}");
    };
    assert_eq!(std::fs::metadata(store).expect("kept").len(), 0);
    assert_eq!(journal::ids_in(poses), ids, "the journal kept as it was");
    assert!(journal::ids_in(&journal::path_for(&path)).is_empty());
    drop(db);
    // The new store is a store: the next start finds it whole.
    assert!(reload(&path).objects.is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A store that cannot be read reports the ids its journal names too (its
/// own pages name none here), and its journal goes aside with it.
#[test]
fn an_unreadable_store_reports_the_objects_its_journal_names() {
    let (dir, path, mut s) = stored("garbage-store");
    let ids: Vec<u64> = (0..2).map(|_| register_box(&mut s, 1)).collect();
    drop(s);
    std::fs::write(&path, b"not a database at all").expect("overwrite");
    let (_, opened) = Database::open(&path, 9).expect("reopen");
    assert_eq!(opened.lost, ids);
    assert_eq!(opened.set_aside.len(), 2, "{opened:?}");
    assert_eq!(
        std::fs::read(&opened.set_aside[0]).expect("kept"),
        b"not a database at all"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// An empty store with no journal, or a journal naming nothing, is a new
/// store as before: nothing is set aside.
#[test]
fn an_empty_store_without_journaled_objects_is_new() {
    let dir = scratch("empty-no-journal");
    let path = dir.join("objects");
    std::fs::File::create(&path).expect("empty file");
    let (db, opened) = Database::open(&path, 9).expect("open");
    assert!(opened.fresh && opened.set_aside.is_empty() && opened.lost.is_empty());
    drop(db);
    let _ = std::fs::remove_dir_all(&dir);
}
