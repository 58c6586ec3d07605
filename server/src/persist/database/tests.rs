use super::*;
use crate::engine::records::{StoredConvex, StoredOwner, StoredPose, StoredShape};
use crate::persist::legacy::Change;
use crate::persist::legacy::tests::{encode_log, encode_snapshot};
use gjk::Convex;
use nalgebra::{Isometry3, Vector3};

const EPOCH: u32 = 0xABCD_0123;

fn id(index: u32) -> u64 {
    (u64::from(EPOCH) << 32) | u64::from(index)
}

/// Object `index`, a box whose x half-extent tells it apart.
fn object(index: u32, slot: u32, name: Option<&str>) -> StoredObject {
    StoredObject {
        id: id(index),
        owner: StoredOwner::Client(u128::MAX - u128::from(index)),
        name: name.map(Into::into),
        pose: StoredPose::from_isometry(&Isometry3::new(
            Vector3::new(f64::from(index), -2.0, 3.5),
            Vector3::new(0.1, 0.2, -0.3),
        )),
        shape: StoredShape::from_shape(
            &Convex::cuboid(Vector3::new(0.5 + f64::from(index) * 1e-3, 0.4, 0.3), 0.25)
                .expect("box")
                .into(),
        ),
        slot,
    }
}

fn sample() -> Snapshot {
    let mut dumbbell = object(7, 3, None);
    dumbbell.owner = StoredOwner::Scene;
    dumbbell.shape = StoredShape::Compound(vec![
        (
            StoredPose::from_isometry(&Isometry3::translation(-1.0, 0.0, 0.0)),
            StoredConvex {
                radius: 0.3,
                vertices: vec![[0.0; 3]],
            },
        ),
        (
            StoredPose::from_isometry(&Isometry3::identity()),
            StoredConvex {
                radius: 0.0,
                vertices: vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1e-300, 0.0, 1e150]],
            },
        ),
    ]);
    Snapshot {
        epoch: EPOCH,
        next_index: 9,
        objects: vec![object(1, 0, Some("cube")), dumbbell],
    }
}

/// A scratch directory of the test's own.
fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("gjkd-db-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    dir
}

fn names_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn objects_ids_and_counter_survive_reopening_bit_for_bit() {
    use std::os::unix::fs::PermissionsExt;
    let dir = scratch("round-trip");
    let path = dir.join("sub").join("x.objects");
    let (mut db, opened) = Database::open(&path, 5).expect("create");
    assert!(opened.fresh);
    assert_eq!((opened.snapshot.epoch, opened.snapshot.next_index), (5, 1));
    db.sync(&sample()).expect("sync");
    // A registration holding a cylinder takes the newer stored form.
    let mut extra = object(9, 1, Some("extra"));
    let can = Convex::cylinder(0.5, 2.0, 0.125).expect("cylinder");
    let pieces = vec![
        (Isometry3::translation(0.0, 0.0, 1.0), can),
        (Isometry3::identity(), Convex::sphere(0.5).expect("ball")),
    ];
    let extra_shape: gjk::Shape = gjk::Compound::new(pieces).expect("valid").into();
    extra.shape = StoredShape::from_shape(&extra_shape);
    db.register(&extra, 10, None).expect("register");
    db.remove(&[id(1)], &[]).expect("remove");
    drop(db);
    let (_, opened) = Database::open(&path, 6).expect("reopen");
    let mut want = sample();
    want.objects.remove(0);
    want.objects.push(extra);
    want.next_index = 10;
    assert!(!opened.fresh);
    assert_eq!(
        opened.snapshot, want,
        "the epoch of the store, not the new one"
    );
    let shape = want.objects[1].shape.to_shape().expect("valid");
    assert_eq!(StoredShape::from_shape(&shape), want.objects[1].shape);
    let reloaded = opened.snapshot.objects[1].shape.to_shape().expect("valid");
    assert_eq!(reloaded, extra_shape, "the cylinder piece comes back exact");
    let mode = |p: &Path| std::fs::metadata(p).expect("exists").permissions().mode() & 0o777;
    assert_eq!(mode(&path), 0o600);
    assert_eq!(mode(path.parent().expect("dir")), 0o700);
    assert_eq!(names_in(path.parent().expect("dir")), ["x.objects"]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// redb's own lock keeps a second opener out, within one process too
/// (the lock belongs to the open file, not to the process), and goes
/// with the first one.
#[test]
fn a_second_opener_is_refused_while_the_first_holds_the_store() {
    let dir = scratch("lock");
    let path = dir.join("x.objects");
    let (mut db, _) = Database::open(&path, 5).expect("create");
    db.sync(&sample()).expect("sync");
    let err = Database::open(&path, 6).expect_err("in use");
    assert!(matches!(err, StoreError::InUse(_)), "{err}");
    assert!(err.to_string().contains("stop it first"), "{err}");
    db.register(&object(9, 1, None), 10, None)
        .expect("the first still writes");
    drop(db);
    let (_, opened) = Database::open(&path, 6).expect("free again");
    assert_eq!(opened.snapshot.objects.len(), 3);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Damage anywhere in the file: a file either loads exactly what was
/// stored (the byte was not in use) or is set aside byte for byte and
/// the store starts empty; never anything in between.
#[test]
fn a_damaged_file_is_set_aside_whole_or_loads_whole() {
    let dir = scratch("damage");
    let path = dir.join("x.objects");
    let (mut db, _) = Database::open(&path, 5).expect("create");
    db.sync(&sample()).expect("sync");
    for i in 10..14 {
        db.register(&object(i, i, None), i + 1, None)
            .expect("register");
    }
    drop(db);
    let good = std::fs::read(&path).expect("file");
    let (_, opened) = Database::open(&path, 6).expect("intact");
    let want = opened.snapshot;
    // What a damaged file's ERROR line names as lost.
    let all: Vec<u64> = want.objects.iter().map(|o| o.id).collect();
    assert_eq!(readable_ids(good.clone()), Some(all));
    assert_eq!(readable_ids(b"garbage".to_vec()), None);
    let mut cases: Vec<(String, Vec<u8>)> = Vec::new();
    for cut in [1, 7, 4096, good.len() / 2, good.len() - 100] {
        cases.push((format!("cut to {cut}"), good[..cut].to_vec()));
    }
    // Flips spread over every page of the file.
    for at in (0..good.len()).step_by(127) {
        let mut b = good.clone();
        b[at] ^= 0x10;
        cases.push((format!("flip at {at}"), b));
    }
    // Every bit of redb's flag byte (which commit slot is the newest,
    // whether it was two-phase, whether repair is due).
    for bit in 0..8 {
        let mut b = good.clone();
        b[9] ^= 1 << bit;
        cases.push((format!("flag bit {bit}"), b));
    }
    let mut b = good.clone();
    b[..9].copy_from_slice(b"garbage!!");
    cases.push(("magic".into(), b));
    let (mut refused, mut loaded) = (0, 0);
    for (what, bytes) in &cases {
        std::fs::write(&path, bytes).expect("spoil");
        let (db, opened) = Database::open(&path, 6).expect(what);
        drop(db);
        if opened.set_aside.is_empty() {
            assert_eq!(opened.snapshot, want, "{what}: loaded, so whole");
            loaded += 1;
        } else {
            assert!(opened.fresh && opened.snapshot.objects.is_empty(), "{what}");
            assert_eq!(opened.set_aside.len(), 1, "{what}");
            let aside = &opened.set_aside[0];
            assert!(aside.to_string_lossy().contains(".corrupt-"), "{what}");
            assert!(
                &std::fs::read(aside).expect("kept") == bytes,
                "{what}: as found"
            );
            std::fs::remove_file(aside).expect("clean");
            refused += 1;
        }
    }
    eprintln!(
        "{} damaged files: {refused} set aside, {loaded} loaded whole",
        cases.len()
    );
    assert!(refused >= 5, "every cut and the magic at least");
    let _ = std::fs::remove_dir_all(&dir);
}

/// What `kill -9` leaves: the file as it is while the server has it
/// open (redb marks it as needing repair until a clean close). It
/// loads every committed change.
#[test]
fn a_file_left_by_a_killed_server_loads_every_commit() {
    let dir = scratch("killed");
    let path = dir.join("x.objects");
    let (mut db, _) = Database::open(&path, 5).expect("create");
    db.sync(&sample()).expect("sync");
    let mut want = sample();
    for i in 10..40 {
        let o = object(i, i, None);
        db.register(&o, i + 1, None).expect("register");
        want.objects.push(o);
        want.next_index = i + 1;
    }
    db.remove(&[id(1)], &[]).expect("remove");
    want.objects.remove(0);
    let at_kill = std::fs::read(&path).expect("read while open");
    drop(db);
    std::fs::write(&path, &at_kill).expect("as at the kill");
    let (mut db, opened) = Database::open(&path, 6).expect("reopen");
    assert!(opened.set_aside.is_empty(), "{opened:?}");
    assert_eq!(opened.snapshot, want);
    // And it is writable again.
    db.register(&object(50, 50, None), 51, None)
        .expect("register");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A commit that fails as on a full disk stores nothing of the change;
/// once there is room, the next change reopens the database and is
/// stored.
#[test]
fn a_full_disk_refuses_changes_until_there_is_room() {
    let dir = scratch("full");
    let path = dir.join("x.objects");
    let (mut db, _) = Database::open(&path, 5).expect("create");
    db.sync(&sample()).expect("sync");
    db.simulate_full_disk(true);
    let err = db
        .register(&object(9, 1, None), 10, None)
        .expect_err("full");
    assert!(matches!(err, StoreError::Full(_)), "{err}");
    assert!(db.remove(&[id(1)], &[]).is_err());
    db.simulate_full_disk(false);
    db.register(&object(10, 1, None), 11, None)
        .expect("room again");
    drop(db);
    let (_, opened) = Database::open(&path, 6).expect("reopen");
    let ids: Vec<u64> = opened.snapshot.objects.iter().map(|o| o.id).collect();
    assert_eq!(ids, [id(1), id(7), id(10)]);
    assert_eq!(opened.snapshot.next_index, 11);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Changes to the sample (ids 1 and 7, counter 9) as the old server
/// logged them: a registration, the removal of a snapshot object, a
/// registration reusing its slot and name, one registered and removed
/// within the log.
fn changes() -> Vec<Change> {
    vec![
        Change::Register(object(9, 1, Some("a"))),
        Change::Remove(id(1)),
        Change::Register(object(10, 0, Some("cube"))),
        Change::Register(object(11, 2, Some("b"))),
        Change::Remove(id(11)),
    ]
}

/// The old state file and log are migrated on first open: the objects
/// are the snapshot's with the log replayed (its torn last record
/// dropped), the old files are kept byte for byte, and the next open
/// reads the database alone.
#[test]
fn an_old_state_file_and_log_are_migrated_and_kept() {
    let dir = scratch("migrate");
    let path = dir.join("x.objects");
    let old = encode_snapshot(&sample());
    let (mut log, _) = encode_log(EPOCH, &changes());
    let whole_log = log.clone();
    let (torn, _) = encode_log(EPOCH, &[Change::Register(object(12, 3, None))]);
    log.extend_from_slice(&torn[16..torn.len() - 5]);
    std::fs::write(&path, &old).expect("old file");
    std::fs::write(legacy::log_path_for(&path), &log).expect("old log");
    let (db, opened) = Database::open(&path, 6).expect("migrates");
    drop(db);
    let ids: Vec<u64> = opened.snapshot.objects.iter().map(|o| o.id).collect();
    assert_eq!(ids, [id(7), id(9), id(10)]);
    assert_eq!(opened.snapshot.next_index, 12, "past the removed id 11");
    assert_eq!(opened.snapshot.epoch, EPOCH);
    assert!(!opened.fresh);
    assert_eq!(opened.set_aside.len(), 2, "{:?}", opened.set_aside);
    let kept: Vec<Vec<u8>> = opened
        .set_aside
        .iter()
        .map(|p| std::fs::read(p).expect("kept"))
        .collect();
    assert!(kept == [old, log], "both kept as they were");
    let (_, again) = Database::open(&path, 7).expect("reopen");
    assert_eq!(again.snapshot, opened.snapshot);
    assert!(again.set_aside.is_empty());

    // A damaged old file is set aside, as a damaged database would be.
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let mut bad = encode_snapshot(&sample());
    bad[30] ^= 1;
    std::fs::write(&path, &bad).expect("old file");
    std::fs::write(legacy::log_path_for(&path), &whole_log).expect("old log");
    let (_, opened) = Database::open(&path, 6).expect("opens empty");
    assert!(opened.fresh && opened.snapshot.objects.is_empty());
    assert_eq!(opened.set_aside.len(), 2);
    assert!(std::fs::read(&opened.set_aside[0]).expect("kept") == bad);
    assert!(std::fs::read(&opened.set_aside[1]).expect("kept") == whole_log);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every single-bit flip in a middle record of an old log stops the
/// replay there: the records before it are kept, none after.
#[test]
fn a_flip_in_an_old_log_keeps_the_records_before_it() {
    let (bytes, starts) = encode_log(EPOCH, &changes());
    for i in starts[2]..starts[3] {
        for bit in 0..8 {
            let mut b = bytes.clone();
            b[i] ^= 1 << bit;
            let mut s = sample();
            let replay = legacy::replay_log(&mut s, &b);
            assert!(replay.error.is_some(), "flip of bit {bit} of byte {i}");
            assert_eq!(replay.applied, 2, "flip of bit {bit} of byte {i}");
            let ids: Vec<u64> = s.objects.iter().map(|o| o.id).collect();
            assert_eq!(ids, [id(7), id(9)], "flip of bit {bit} of byte {i}");
        }
    }
    eprintln!("{} flips in a middle record", (starts[3] - starts[2]) * 8);
}
