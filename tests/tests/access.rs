//! Access: what a server and its clients put on the file system is
//! owner-only, a client removes only what it registered (before and after a
//! server restart), and scene objects are read-only.

use std::collections::HashSet;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use gjkd_client::{ClientError, ErrorCode, Geometry, ObjectId, QueryOptions};
use gjkd_e2e::{LoadProcess, Server, once_reached, unique_service};
use nalgebra::Isometry3;

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            walk(&p, out);
        }
        out.push(p);
    }
}

/// iceoryx2's files: its shared memory in /dev/shm and its root directory.
fn iceoryx2_files() -> HashSet<PathBuf> {
    let mut all = Vec::new();
    walk(Path::new("/tmp/iceoryx2"), &mut all);
    if let Ok(entries) = std::fs::read_dir("/dev/shm") {
        all.extend(entries.flatten().map(|e| e.path()).filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("iox2_"))
        }));
    }
    all.into_iter().collect()
}

fn mode(p: &Path) -> Option<u32> {
    std::fs::symlink_metadata(p)
        .ok()
        .map(|m| m.permissions().mode())
}

#[test]
fn files_are_owner_only() {
    let before = iceoryx2_files();
    let server = Server::start("perm", &["--wait", "block"]);
    let mut client = server.client(Duration::from_secs(5));
    let id = client.register_sphere(1.0).expect("registered");
    client
        .distance(id, id, &QueryOptions::default())
        .expect("answer");
    let created: Vec<PathBuf> = iceoryx2_files().difference(&before).cloned().collect();
    assert!(
        created.iter().any(|p| p.starts_with("/dev/shm")),
        "no shared memory found: {created:?}"
    );
    let mut checked = 0;
    for p in &created {
        // iceoryx2's machine-wide node counter (`*.global_mgmt`, 16 bytes) is
        // world-accessible by its design (`enable_global_access(true)` in
        // iceoryx2's global_management_segment.rs) and outlives every
        // process: it is created once, by the first iceoryx2 node of the
        // machine, which on a fresh machine can be this test's server or one
        // started beside it. It holds no object, pose or query.
        if p.to_string_lossy().ends_with(".global_mgmt") {
            continue;
        }
        // Files of tests running beside this one may come and go meanwhile.
        let Some(m) = mode(p) else { continue };
        if p.is_dir() {
            // Directories: listable by the group at most (iceoryx2 makes
            // its node directories 0750), never writable by anyone else.
            assert_eq!(m & 0o022, 0, "{} is {:o}", p.display(), m & 0o777);
            assert_eq!(m & 0o007, 0, "{} is {:o}", p.display(), m & 0o777);
        } else {
            assert_eq!(m & 0o077, 0, "{} is {:o}", p.display(), m & 0o777);
        }
        checked += 1;
    }
    assert!(checked >= 5, "only {checked} files checked");

    let state = server.state_file().expect("state file");
    assert_eq!(mode(&state).expect("state file") & 0o777, 0o600);
    let journal = PathBuf::from(format!("{}.poses", state.display()));
    assert_eq!(mode(&journal).expect("journal") & 0o777, 0o600);
    eprintln!("{checked} iceoryx2 files and 2 state files checked");
}

/// The default state file lives under `$XDG_STATE_HOME/gjkd/`, created
/// 0700, the file 0600.
#[test]
fn the_default_state_directory_is_owner_only() {
    let home = std::env::temp_dir().join(unique_service("xdg"));
    let _ = std::fs::remove_dir_all(&home);
    let service = unique_service("xdg");
    let mut child = std::process::Command::new(gjkd_e2e::gjkd_binary())
        .args(["serve", "--service", &service, "--wait", "block"])
        .env("XDG_STATE_HOME", &home)
        .env("RUST_LOG", "warn")
        .stdout(std::process::Stdio::null())
        .spawn()
        .expect("spawn");
    let file = home.join("gjkd").join(format!("{service}.objects"));
    let deadline = Instant::now() + Duration::from_secs(10);
    while !file.exists() && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(20));
    }
    let file_mode = mode(&file);
    let dir_mode = mode(&home.join("gjkd"));
    // SAFETY: kill(2) on our own child.
    unsafe {
        libc::kill(child.id() as libc::pid_t, libc::SIGTERM);
    }
    let _ = child.wait();
    let _ = std::fs::remove_dir_all(&home);
    assert_eq!(
        file_mode.expect("state file written at start") & 0o777,
        0o600
    );
    assert_eq!(dir_mode.expect("directory") & 0o777, 0o700);
}

fn rejected<T: std::fmt::Debug, E: Into<ClientError>>(r: Result<T, E>) -> ErrorCode {
    match r.map_err(Into::into) {
        Err(ClientError::Rejected(code)) => code,
        other => panic!("expected a rejection, got {other:?}"),
    }
}

#[test]
fn owners_stay_owners_across_a_server_restart() {
    let mut server = Server::start("owners-restart", &[]);
    let mut alice = server.client(Duration::from_secs(10));
    let mut bob = server.client(Duration::from_secs(10));
    let hers = alice.register_sphere(1.0).expect("hers");
    let his = bob.register_sphere(1.0).expect("his");
    assert_eq!(rejected(bob.remove(hers)), ErrorCode::NotOwner);

    server.kill9();
    server.restart();
    // Both notice and reconnect with the same identity.
    for c in [&mut alice, &mut bob] {
        once_reached(|| c.stats());
    }
    assert_eq!(rejected(bob.remove(hers)), ErrorCode::NotOwner);
    assert_eq!(rejected(alice.remove(his)), ErrorCode::NotOwner);
    // A client that never registered anything owns nothing either.
    let mut carol = server.client(Duration::from_secs(10));
    assert_eq!(rejected(carol.remove(hers)), ErrorCode::NotOwner);
    // Anyone may query and move anyone's objects; only removal is owned.
    carol
        .set_pose(hers, &Isometry3::translation(5.0, 0.0, 0.0))
        .expect("move");
    let d = carol
        .distance(hers, his, &QueryOptions::default())
        .expect("query")
        .distance;
    assert!((d - 3.0).abs() < 1e-12, "{d}");
    alice.remove(hers).expect("owner removes");
    bob.remove(his).expect("owner removes");
    assert_eq!(carol.stats().expect("stats").objects, 0);
}

/// `gjkd objects` on the state file of a stopped server.
fn objects_tool(state_file: &Path, remove: bool) -> (bool, String) {
    let mut cmd = std::process::Command::new(gjkd_e2e::gjkd_binary());
    cmd.arg("objects").arg("--state-file").arg(state_file);
    if remove {
        cmd.arg("--remove-departed");
    }
    let out = cmd.output().expect("run gjkd objects");
    let text =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    (out.status.success(), text)
}

/// A client removes only what it registered, so the objects of a process
/// that is gone (here: a dropped `Client`, whose node ends as at a process
/// exit) stay for clients. `gjkd objects --remove-departed` is the
/// operator's way out: it refuses while the server holds the file, and with
/// the server stopped removes exactly those objects; after a restart the
/// rest is served under the same ids.
#[test]
fn the_operator_removes_objects_of_departed_clients() {
    let mut server = Server::start("departed", &[]);
    let state_file = server.state_file().expect("the helper's state file");
    let mut bob = server.client(Duration::from_secs(10));
    let his = bob.register_sphere(1.0).expect("his");
    let (hers, named) = {
        let mut alice = server.client(Duration::from_secs(10));
        let hers = alice.register_sphere(0.5).expect("hers");
        let named = alice
            .register_named(
                "alice-arm",
                &Geometry::Sphere { radius: 0.25 },
                &Isometry3::identity(),
            )
            .expect("named");
        (hers, named)
    };
    // Alice is gone; no client may remove her objects.
    assert_eq!(rejected(bob.remove(hers)), ErrorCode::NotOwner);
    // The tool refuses while the server runs, and changes nothing.
    let (ok, text) = objects_tool(&state_file, true);
    assert!(!ok, "{text}");
    assert!(text.contains("stopped first"), "{text}");
    assert_eq!(bob.stats().expect("stats").objects, 3);

    server.terminate();
    let (ok, text) = objects_tool(&state_file, false);
    assert!(ok, "{text}");
    assert_eq!(text.matches("gone").count(), 2, "{text}");
    assert_eq!(text.matches("running").count(), 1, "{text}");
    assert!(text.contains("alice-arm"), "{text}");
    let (ok, text) = objects_tool(&state_file, true);
    assert!(ok, "{text}");
    assert!(text.contains("removed 2 object(s)"), "{text}");
    assert!(text.contains(&format!("{:#x}", hers.raw())), "{text}");
    assert!(text.contains(&format!("{:#x}", named.raw())), "{text}");
    // A second pass finds nothing more.
    let (ok, text) = objects_tool(&state_file, true);
    assert!(ok && text.contains("nothing removed"), "{text}");

    server.restart();
    let stats = once_reached(|| bob.stats());
    assert_eq!(stats.objects, 1);
    assert_eq!(rejected(bob.lookup("alice-arm")), ErrorCode::UnknownName);
    assert_eq!(
        rejected(bob.distance(hers, his, &QueryOptions::default())),
        ErrorCode::UnknownObject
    );
    bob.remove(his).expect("his own, as before");
}

/// A fresh directory holding a scene file of one box named "wall": the
/// directory (for removal) and the file.
fn wall_scene(tag: &str) -> (PathBuf, PathBuf) {
    let dir = std::env::temp_dir().join(unique_service(tag));
    std::fs::create_dir_all(&dir).expect("dir");
    let path = dir.join("scene.toml");
    std::fs::write(
        &path,
        "[[object]]\nname = \"wall\"\ntype = \"box\"\nhalf_extents = [1.0, 1.0, 1.0]\n",
    )
    .expect("scene");
    (dir, path)
}

/// The ids a `gjkd-load` process says it registered.
fn registered(load: &LoadProcess) -> Vec<ObjectId> {
    load.seen
        .iter()
        .filter_map(|l| l.strip_prefix("REG ")?.split(' ').next()?.parse().ok())
        .map(ObjectId::from_raw)
        .collect()
}

/// A client process killed (`kill -9`) leaves its objects behind. A plain
/// server keeps serving them past its housekeeping (5 s at most); one started
/// with `--remove-departed` on the same state file removes them within its
/// housekeeping, keeping the scene object and a running client's, and the
/// removal is on disk: after a restart only the survivors come back.
#[test]
fn serve_remove_departed_removes_the_objects_of_killed_clients() {
    let (dir, scene) = wall_scene("reap-scene");
    let scene = scene.to_str().expect("utf-8");
    let mut plain = Server::start("reap", &["--scene", scene]);
    let state_file = plain.state_file().expect("the helper's state file");
    let state = state_file.to_str().expect("utf-8");
    let mut bob = plain.client(Duration::from_secs(10));
    let his = bob.register_sphere(1.0).expect("his");
    let mut victim = LoadProcess::spawn(&plain.service, "victim", 5, None);
    assert!(
        victim.wait_for("READY", Duration::from_secs(30)).is_some(),
        "{:?}",
        victim.seen
    );
    let theirs = registered(&victim);
    assert!(theirs.len() > 3, "{:?}", victim.seen);
    victim.kill9();
    let all = 2 + theirs.len() as u64;
    // Past the forced housekeeping: a plain server still has them all.
    std::thread::sleep(Duration::from_secs(6));
    assert_eq!(bob.stats().expect("stats").objects, all);
    let wall = bob.lookup("wall").expect("wall");
    bob.distance(theirs[0], his, &QueryOptions::default())
        .expect("still served");
    plain.terminate();

    let reaper = Server::start_on(
        &plain.service,
        &["--scene", scene, "--state-file", state, "--remove-departed"],
    );
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        let objects = once_reached(|| bob.stats()).objects;
        if objects == 2 {
            break;
        }
        assert!(objects == all, "{objects} objects");
        assert!(Instant::now() < deadline, "still {objects} objects");
        std::thread::sleep(Duration::from_millis(200));
    }
    for &id in &theirs {
        assert_eq!(
            rejected(bob.distance(id, his, &QueryOptions::default())),
            ErrorCode::UnknownObject
        );
    }
    let d = bob
        .distance(wall, his, &QueryOptions::default())
        .expect("scene and running client's objects stay");
    assert!(d.distance.is_finite());
    drop(reaper);

    let mut again = Server::start_on(&plain.service, &["--scene", scene, "--state-file", state]);
    assert_eq!(once_reached(|| bob.stats()).objects, 2);
    bob.remove(his).expect("his own, as before");
    again.terminate();
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn scene_objects_stay_read_only_and_keep_their_ids_across_a_restart() {
    let (dir, path) = wall_scene("scene-ro");
    let mut server = Server::start("scene-ro", &["--scene", path.to_str().expect("utf-8")]);
    let mut client = server.client(Duration::from_secs(10));
    let wall = client.lookup("wall").expect("wall");
    assert_eq!(rejected(client.remove(wall)), ErrorCode::ReadOnly);
    assert_eq!(
        rejected(client.register_named(
            "wall",
            &Geometry::Sphere { radius: 1.0 },
            &Isometry3::identity()
        )),
        ErrorCode::NameTaken
    );
    server.kill9();
    server.restart();
    let mut client = server.client(Duration::from_secs(10));
    assert_eq!(client.lookup("wall").expect("wall"), wall, "same id");
    assert_eq!(rejected(client.remove(wall)), ErrorCode::ReadOnly);
    assert_eq!(client.stats().expect("stats").objects, 1);
    let _ = std::fs::remove_dir_all(&dir);
}
