//! A full disk degrades the service, it does not stop it: on a small tmpfs
//! filled up, registrations and removals are refused with `StorageFull`
//! while queries and pose updates are served; a server killed there starts
//! again with every object; once there is room, changes are accepted
//! without a restart.
//!
//! Mounting a tmpfs needs root (as in CI here); where it cannot be mounted
//! the test says so and checks nothing.

use std::path::{Path, PathBuf};
use std::time::Duration;

use gjkd_client::{ClientError, ErrorCode, QueryOptions};
use gjkd_e2e::{Server, once_reached, unique_service};
use nalgebra::{Isometry3, Vector3};

/// A tmpfs of `size`, unmounted (and its directory removed) on drop.
struct Tmpfs(PathBuf);

impl Tmpfs {
    fn mount(size: &str) -> Option<Self> {
        let dir = std::env::temp_dir().join(unique_service("tmpfs"));
        std::fs::create_dir_all(&dir).ok()?;
        let status = std::process::Command::new("mount")
            .args([
                "-t",
                "tmpfs",
                "-o",
                &format!("size={size},mode=0700"),
                "tmpfs",
            ])
            .arg(&dir)
            .stderr(std::process::Stdio::null())
            .status()
            .ok()?;
        if status.success() {
            Some(Tmpfs(dir))
        } else {
            let _ = std::fs::remove_dir(&dir);
            None
        }
    }
}

impl Drop for Tmpfs {
    fn drop(&mut self) {
        let _ = std::process::Command::new("umount").arg(&self.0).status();
        let _ = std::fs::remove_dir(&self.0);
    }
}

/// Fills the file system of `dir` with `filler` until a write fails.
fn fill(dir: &Path, filler: &Path) {
    use std::io::Write;
    let mut f = std::fs::File::create(filler).expect("filler");
    let chunk = vec![0xA5u8; 4096];
    while f.write_all(&chunk).and_then(|()| f.sync_data()).is_ok() {}
    let free = free_bytes(dir);
    eprintln!("filled: {free} bytes left");
}

fn free_bytes(dir: &Path) -> u64 {
    let c = std::ffi::CString::new(dir.as_os_str().as_encoded_bytes()).expect("path");
    // SAFETY: statvfs(3) into a zeroed struct of our own.
    let mut st: libc::statvfs = unsafe { std::mem::zeroed() };
    if unsafe { libc::statvfs(c.as_ptr(), &mut st) } != 0 {
        return 0;
    }
    st.f_bavail as u64 * st.f_frsize as u64
}

/// A tmpfs of `size` with a block-mode server keeping its store there, or
/// `None` (said on stderr) where no tmpfs can be mounted. The server is
/// second in the pair so that, bound in this order, it stops before the
/// tmpfs is unmounted.
fn serve_on_tmpfs(size: &str, name: &str) -> Option<(Tmpfs, Server)> {
    let Some(tmpfs) = Tmpfs::mount(size) else {
        eprintln!("cannot mount a tmpfs (not root?): nothing checked");
        return None;
    };
    let store = tmpfs.0.join("objects");
    let server = Server::start(
        name,
        &[
            "--wait",
            "block",
            "--state-file",
            store.to_str().expect("utf-8"),
        ],
    );
    Some((tmpfs, server))
}

fn storage_full<T, E: Clone + Into<ClientError>>(r: &Result<T, E>) -> bool {
    matches!(r, Err(e) if e.clone().into() == ClientError::Rejected(ErrorCode::StorageFull))
}

#[test]
fn a_full_disk_refuses_changes_serves_the_rest_and_recovers_without_restart() {
    let Some((tmpfs, mut server)) = serve_on_tmpfs("2m", "full-disk") else {
        return;
    };
    let mut client = server.client(Duration::from_secs(5));
    let a = client.register_sphere(0.5).expect("a");
    let b = client
        .register_cuboid(Vector3::new(0.5, 0.5, 0.5), 0.0)
        .expect("b");
    let filler = tmpfs.0.join("filler");
    fill(&tmpfs.0, &filler);

    // Registrations fail with StorageFull (the first few may still find a
    // free page of the store), and the object count does not move.
    let mut refused = false;
    for _ in 0..200 {
        let r = client.register_sphere(0.25);
        if storage_full(&r) {
            refused = true;
            break;
        }
        r.expect("either registered or StorageFull");
    }
    assert!(refused, "no StorageFull on a full disk");
    let objects = client.stats().expect("stats").objects;
    assert!(storage_full(&client.register_sphere(0.25)));
    assert!(storage_full(&client.remove(a)));
    assert_eq!(client.stats().expect("stats").objects, objects);
    // Queries and pose updates are served.
    client
        .set_pose(b, &Isometry3::translation(3.0, 0.0, 0.0))
        .expect("pose update on a full disk");
    let d = client.distance(a, b, &QueryOptions::cold()).expect("query");
    assert!((d.distance - 2.0).abs() < 1e-12, "{d:?}");

    // Killed and started again on the full disk: everything is back.
    server.kill9();
    server.restart();
    let stats = once_reached(|| client.stats());
    assert_eq!(stats.objects, objects, "every object back on a full disk");
    let d = client.distance(a, b, &QueryOptions::cold()).expect("query");
    assert!((d.distance - 2.0).abs() < 1e-12, "pose back too: {d:?}");
    assert!(storage_full(&client.register_sphere(0.25)));

    // Room again: accepted without a restart.
    std::fs::remove_file(&filler).expect("free the disk");
    let c = client
        .register_sphere(0.75)
        .expect("registered once there is room");
    client.remove(a).expect("removed once there is room");
    assert_eq!(client.stats().expect("stats").objects, objects);
    server.kill9();
    server.restart();
    let stats = once_reached(|| client.stats());
    assert_eq!(stats.objects, objects);
    client
        .remove(c)
        .expect("c was stored, a was removed for good");
    assert!(
        client.distance(a, b, &QueryOptions::cold()).is_err(),
        "a stays removed"
    );
    drop(client);
    server.terminate();
}

/// A server started on a disk too small for a new store starts and serves;
/// it refuses registrations with `StorageFull` until there is room, then
/// accepts them without a restart. (It exited, unable to open its pose
/// journal.)
#[test]
fn a_server_starts_on_a_disk_too_small_for_a_new_store() {
    let Some((tmpfs, mut server)) = serve_on_tmpfs("64k", "small-disk") else {
        return;
    };
    let mut client = server.client(Duration::from_secs(5));
    assert_eq!(client.stats().expect("served").objects, 0);
    let mut refused = false;
    for _ in 0..200 {
        let r = client.register_sphere(0.25);
        if storage_full(&r) {
            refused = true;
            break;
        }
        r.expect("either registered or StorageFull");
    }
    assert!(refused, "no StorageFull on a 64 KiB disk");
    let objects = client.stats().expect("stats").objects;

    // Room again (the file system grown in place): accepted at once.
    let status = std::process::Command::new("mount")
        .args(["-o", "remount,size=4m"])
        .arg(&tmpfs.0)
        .status()
        .expect("remount");
    assert!(status.success());
    let a = client
        .register_sphere(0.5)
        .expect("registered once there is room");
    let b = client
        .register_cuboid(Vector3::new(0.5, 0.5, 0.5), 0.0)
        .expect("registered");
    client
        .set_pose(b, &Isometry3::translation(3.0, 0.0, 0.0))
        .expect("pose");
    let d = client.distance(a, b, &QueryOptions::cold()).expect("query");
    assert!((d.distance - 2.0).abs() < 1e-12, "{d:?}");
    assert_eq!(client.stats().expect("stats").objects, objects + 2);
    server.kill9();
    server.restart();
    let stats = once_reached(|| client.stats());
    assert_eq!(stats.objects, objects + 2, "kept across a crash");
    drop(client);
    server.terminate();
}
