//! Helpers for the end-to-end tests: start the real `gjkd` binary on a
//! unique service name, and stop it whatever happens to the test.

#![warn(missing_docs)]

use std::path::PathBuf;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

use gjkd_client::{Client, ClientError};
use iceoryx2::node::NodeView;
use iceoryx2::prelude::*;

/// The `gjkd` binary of this build profile: `$GJKD_BIN` if set, else
/// `target/<profile>/gjkd` next to the test executable's `deps/` folder,
/// built with `cargo build --workspace --bins` once per test process (cargo
/// does not build another package's binary for a test).
pub fn gjkd_binary() -> PathBuf {
    static BIN: OnceLock<PathBuf> = OnceLock::new();
    BIN.get_or_init(|| {
        if let Some(path) = std::env::var_os("GJKD_BIN") {
            return PathBuf::from(path);
        }
        let exe = std::env::current_exe().expect("test executable path");
        // target/<profile>/deps/<test> -> target/<profile>
        let profile_dir = exe
            .parent()
            .and_then(|deps| deps.parent())
            .expect("test executable lives in target/<profile>/deps")
            .to_path_buf();
        let bin = profile_dir.join("gjkd");
        let release = profile_dir.file_name().is_some_and(|n| n == "release");
        let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
        let mut build = Command::new(cargo);
        build
            // The whole workspace's binaries, so that features resolve as in
            // `cargo test --workspace` and its build is reused, not redone
            // for one package's feature set.
            .args(["build", "--quiet", "--workspace", "--bins"])
            .current_dir(env!("CARGO_MANIFEST_DIR"));
        if release {
            build.arg("--release");
        }
        // The target dir of this run, wherever it is configured to be.
        if let Some(target) = profile_dir.parent() {
            build.env("CARGO_TARGET_DIR", target);
        }
        let status = build.status().expect("run cargo build for gjkd");
        assert!(
            status.success(),
            "cargo build --workspace --bins failed: {status}"
        );
        assert!(bin.exists(), "{} missing after the build", bin.display());
        bin
    })
    .clone()
}

/// A service name no other test (of this or another process) uses.
pub fn unique_service(tag: &str) -> String {
    static COUNTER: AtomicU32 = AtomicU32::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.subsec_nanos())
        .unwrap_or(0);
    format!("gjkd-e2e-{tag}-{}-{n}-{nanos}", std::process::id())
}

/// A running `gjkd serve`, stopped (SIGTERM, then SIGKILL) when dropped, so
/// that a failing test leaves no server behind.
///
/// Unless its arguments say `--no-persist` or `--state-file`, it keeps its
/// objects in a state file in a fresh temporary directory (removed on drop),
/// never in the user's `~/.local/state`; [`Server::restart`] reuses it.
pub struct Server {
    child: Option<Child>,
    /// Its service name.
    pub service: String,
    args: Vec<String>,
    state_dir: Option<PathBuf>,
    /// Extra environment variables of the server process.
    env: Vec<(String, String)>,
}

impl Server {
    /// Starts `gjkd serve` on a fresh unique service with `args` (for example
    /// `["--wait", "spin"]`).
    pub fn start(tag: &str, args: &[&str]) -> Self {
        Self::start_on(&unique_service(tag), args)
    }

    /// As [`Server::start`], with extra environment variables (such as a
    /// fault-injection hook) until [`Server::clear_env`].
    pub fn start_with_env(tag: &str, args: &[&str], env: &[(&str, &str)]) -> Self {
        let env = env
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        Self::start_on_with_env(&unique_service(tag), args, env)
    }

    /// Drops the extra environment variables for the next
    /// [`Server::restart`].
    pub fn clear_env(&mut self) {
        self.env.clear();
    }

    /// Starts `gjkd serve --service SERVICE` with `args`.
    pub fn start_on(service: &str, args: &[&str]) -> Self {
        Self::start_on_with_env(service, args, Vec::new())
    }

    fn start_on_with_env(service: &str, args: &[&str], env: Vec<(String, String)>) -> Self {
        let mut args: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        let mut state_dir = None;
        if !args
            .iter()
            .any(|a| a == "--no-persist" || a == "--state-file")
        {
            // One directory per Server value: a second server started on the
            // same service must not share (or wipe) the first one's file.
            static DIRS: AtomicU32 = AtomicU32::new(0);
            let n = DIRS.fetch_add(1, Ordering::Relaxed);
            let dir = std::env::temp_dir().join(format!("{service}.{n}.state"));
            let _ = std::fs::remove_dir_all(&dir);
            args.push("--state-file".into());
            args.push(dir.join("objects").to_string_lossy().into_owned());
            state_dir = Some(dir);
        }
        let mut server = Server {
            child: None,
            service: service.to_owned(),
            args,
            state_dir,
            env,
        };
        server.spawn();
        server
    }

    /// The state file, when the helper chose it.
    pub fn state_file(&self) -> Option<PathBuf> {
        self.state_dir.as_ref().map(|d| d.join("objects"))
    }

    fn spawn(&mut self) {
        let child = Command::new(gjkd_binary())
            .arg("serve")
            .arg("--service")
            .arg(&self.service)
            .args(&self.args)
            .env(
                "RUST_LOG",
                std::env::var("GJKD_TEST_LOG").unwrap_or_else(|_| "warn".into()),
            )
            .envs(self.env.iter().map(|(k, v)| (k, v)))
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .spawn()
            .expect("spawn gjkd serve");
        self.child = Some(child);
    }

    /// Starts the same server again (same service and arguments) after it
    /// was stopped or killed.
    pub fn restart(&mut self) {
        assert!(self.child.is_none(), "restart of a running server");
        self.spawn();
    }

    /// A client with `timeout`, waiting up to ten seconds for the server to
    /// come up.
    pub fn client(&self, timeout: Duration) -> Client {
        match Client::builder(&self.service)
            .timeout(timeout)
            .connect_timeout(Duration::from_secs(10))
            .connect()
        {
            Ok(c) => c,
            Err(e) => panic!("cannot connect to {}: {e}", self.service),
        }
    }

    /// Process id.
    pub fn pid(&self) -> Option<u32> {
        self.child.as_ref().map(Child::id)
    }

    /// Sends `signal` and waits for the process to end (SIGKILL after five
    /// seconds). Returns its exit status.
    pub fn signal_and_wait(&mut self, signal: i32) -> Option<ExitStatus> {
        let mut child = self.child.take()?;
        if let Ok(Some(status)) = child.try_wait() {
            return Some(status);
        }
        if let Ok(pid) = libc::pid_t::try_from(child.id()) {
            // SAFETY: kill(2) on a child we spawned and have not reaped.
            unsafe {
                libc::kill(pid, signal);
            }
        }
        let deadline = Instant::now() + Duration::from_secs(5);
        while Instant::now() < deadline {
            if let Ok(Some(status)) = child.try_wait() {
                return Some(status);
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        let _ = child.kill();
        child.wait().ok()
    }

    /// SIGKILL: the server gets no chance to clean up.
    pub fn kill9(&mut self) {
        self.signal_and_wait(libc::SIGKILL);
    }

    /// SIGTERM and wait: a clean shutdown.
    pub fn terminate(&mut self) -> Option<ExitStatus> {
        self.signal_and_wait(libc::SIGTERM)
    }

    /// Waits up to five seconds for the server to exit by itself.
    pub fn wait_exit(&mut self) -> Option<ExitStatus> {
        let mut child = self.child.take()?;
        let deadline = Instant::now() + Duration::from_secs(5);
        while Instant::now() < deadline {
            if let Ok(Some(status)) = child.try_wait() {
                return Some(status);
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        self.child = Some(child);
        None
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        self.terminate();
        if let Some(dir) = &self.state_dir {
            let _ = std::fs::remove_dir_all(dir);
        }
    }
}

/// Connects to `service`, waiting up to `timeout` (also the client's call
/// timeout). Panics with the error if no server comes up.
pub fn connect(service: &str, timeout: Duration) -> Client {
    match Client::builder(service).timeout(timeout).connect() {
        Ok(c) => c,
        Err(e) => panic!("cannot connect to {service}: {e}"),
    }
}

/// Whether any of the three services of `service` still exists in shared
/// memory.
pub fn services_exist(service: &str) -> bool {
    let config = Config::global_config();
    let names = [
        (
            gjkd_proto::query_service_name(service),
            MessagingPattern::RequestResponse,
        ),
        (
            gjkd_proto::admin_service_name(service),
            MessagingPattern::RequestResponse,
        ),
        (
            gjkd_proto::wake_service_name(service),
            MessagingPattern::Event,
        ),
    ];
    names.iter().any(|(name, pattern)| {
        let name = ServiceName::new(name).expect("valid service name");
        ipc::Service::does_exist(&name, config, *pattern).unwrap_or(true)
    })
}

/// Whether an iceoryx2 node of process `pid`, alive or dead (its resources
/// not yet cleaned up), is still registered on this host.
pub fn node_of_pid_exists(pid: u32) -> bool {
    let mut found = false;
    let _ = Node::<ipc::Service>::list(Config::global_config(), |state| {
        let id = match &state {
            NodeState::Alive(v) => Some(*v.id()),
            NodeState::Dead(v) => Some(*v.id()),
            NodeState::Inaccessible(id) | NodeState::Undefined(id) => Some(*id),
        };
        if let Some(id) = id
            && id
                .pid::<ipc::Service>()
                .is_ok_and(|p| i64::from(p.value()) == i64::from(pid))
        {
            found = true;
            return CallbackProgression::Stop;
        }
        CallbackProgression::Continue
    });
    found
}

/// Resident set size of process `pid` in KiB, from `/proc/<pid>/status`.
pub fn rss_kib(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
}

/// The `gjkd-load` client process of this package (see its source).
pub fn load_binary() -> PathBuf {
    let bin = gjkd_binary().with_file_name("gjkd-load");
    if !bin.exists() {
        let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
        let mut build = Command::new(cargo);
        build
            .args(["build", "--quiet", "--workspace", "--bins"])
            .current_dir(env!("CARGO_MANIFEST_DIR"));
        if bin
            .parent()
            .and_then(|d| d.file_name())
            .is_some_and(|n| n == "release")
        {
            build.arg("--release");
        }
        let status = build.status().expect("run cargo build for gjkd-load");
        assert!(
            status.success(),
            "cargo build --workspace --bins failed: {status}"
        );
    }
    bin
}

/// A running `gjkd-load` process whose stdout lines are collected by a
/// thread; killed (SIGKILL) when dropped.
pub struct LoadProcess {
    child: Child,
    lines: std::sync::mpsc::Receiver<String>,
    /// Every line read so far.
    pub seen: Vec<String>,
}

impl LoadProcess {
    /// Starts `gjkd-load SERVICE MODE SEED [COUNT]`.
    pub fn spawn(service: &str, mode: &str, seed: u64, count: Option<u64>) -> Self {
        let mut cmd = Command::new(load_binary());
        cmd.arg(service).arg(mode).arg(seed.to_string());
        if let Some(c) = count {
            cmd.arg(c.to_string());
        }
        let mut child = cmd
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .spawn()
            .expect("spawn gjkd-load");
        let stdout = child.stdout.take().expect("piped");
        let (tx, lines) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            use std::io::BufRead;
            for line in std::io::BufReader::new(stdout).lines() {
                let Ok(line) = line else { break };
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        LoadProcess {
            child,
            lines,
            seen: Vec::new(),
        }
    }

    /// Process id.
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// Waits up to `within` for a line starting with `prefix`; returns it.
    pub fn wait_for(&mut self, prefix: &str, within: Duration) -> Option<String> {
        let deadline = Instant::now() + within;
        if let Some(l) = self.seen.iter().find(|l| l.starts_with(prefix)) {
            return Some(l.clone());
        }
        loop {
            let left = deadline.checked_duration_since(Instant::now())?;
            match self.lines.recv_timeout(left) {
                Ok(line) => {
                    self.seen.push(line.clone());
                    if line.starts_with(prefix) {
                        return Some(line);
                    }
                }
                Err(_) => return None,
            }
        }
    }

    /// Waits up to `within` for the process to exit; its status and every
    /// line it printed.
    pub fn finish(&mut self, within: Duration) -> Option<(ExitStatus, Vec<String>)> {
        let deadline = Instant::now() + within;
        let status = loop {
            if let Ok(Some(status)) = self.child.try_wait() {
                break status;
            }
            if Instant::now() >= deadline {
                return None;
            }
            std::thread::sleep(Duration::from_millis(5));
        };
        // The reader thread ends at end of file.
        while let Ok(line) = self.lines.recv_timeout(Duration::from_secs(2)) {
            self.seen.push(line);
        }
        Some((status, self.seen.clone()))
    }

    /// SIGKILL and reap.
    pub fn kill9(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Drop for LoadProcess {
    fn drop(&mut self) {
        self.kill9();
    }
}

/// Whether `e`, any operation's error, says the server is gone.
pub fn is_gone<E: Clone + Into<ClientError>>(e: &E) -> bool {
    matches!(e.clone().into(), ClientError::ServerGone(_))
}

/// `call` retried while it reports the server gone, up to thirty seconds: a
/// client reaching a restarted server, at most after some `ServerGone`.
///
/// # Panics
/// On any other error, or when the server is still gone after thirty seconds.
pub fn once_reached<T, E>(mut call: impl FnMut() -> Result<T, E>) -> T
where
    E: Clone + Into<ClientError> + std::fmt::Display,
{
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        match call() {
            Ok(v) => return v,
            Err(e) if is_gone(&e) && Instant::now() < deadline => {
                std::thread::sleep(Duration::from_millis(20));
            }
            Err(e) => panic!("restarted server not reached: {e}"),
        }
    }
}

/// A small deterministic generator (xorshift64*), so tests see the same
/// poses on every run.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a non-zero seed.
    pub fn new(seed: u64) -> Self {
        Rng(seed.max(1))
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }

    /// A pose with translation in the cube of half side `extent` and a
    /// random rotation.
    pub fn pose(&mut self, extent: f64) -> nalgebra::Isometry3<f64> {
        let t = nalgebra::Vector3::new(
            self.range(-extent, extent),
            self.range(-extent, extent),
            self.range(-extent, extent),
        );
        let axis = nalgebra::Vector3::new(
            self.range(-3.0, 3.0),
            self.range(-3.0, 3.0),
            self.range(-3.0, 3.0),
        );
        nalgebra::Isometry3::new(t, axis)
    }
}

/// The wire status of a gjk status.
pub fn status_of(s: gjk::Status) -> gjkd_client::Status {
    use gjkd_client::Status as W;
    match s {
        gjk::Status::Converged => W::Converged,
        gjk::Status::Farther => W::Farther,
        gjk::Status::Closer => W::Closer,
        gjk::Status::IterationCap => W::IterationCap,
        gjk::Status::ToleranceNotMet => W::ToleranceNotMet,
    }
}

/// Asserts that a served answer is the in-process one, bit for bit.
pub fn assert_same(got: &gjkd_client::Answer, want: &gjk::Answer, context: &str) {
    let bits = |x: f64| x.to_bits();
    let pairs = [
        ("distance", got.distance, want.distance),
        ("lower", got.lower, want.lower),
        ("upper", got.upper, want.upper),
        ("penetration", got.penetration, want.penetration),
        ("point_a.x", got.point_a.x, want.point_a.x),
        ("point_a.y", got.point_a.y, want.point_a.y),
        ("point_a.z", got.point_a.z, want.point_a.z),
        ("point_b.x", got.point_b.x, want.point_b.x),
        ("point_b.y", got.point_b.y, want.point_b.y),
        ("point_b.z", got.point_b.z, want.point_b.z),
        ("normal.x", got.normal.x, want.normal.x),
        ("normal.y", got.normal.y, want.normal.y),
        ("normal.z", got.normal.z, want.normal.z),
    ];
    for (field, g, w) in pairs {
        assert_eq!(bits(g), bits(w), "{context}: {field} {g:e} != {w:e}");
    }
    assert_eq!(got.iterations, want.iterations, "{context}: iterations");
    assert_eq!(got.pieces, want.pieces, "{context}: pieces");
    assert_eq!(
        got.status,
        Some(status_of(want.status)),
        "{context}: status"
    );
    assert_eq!(got.backup_used, want.backup_used, "{context}: backup_used");
}

/// gjk options equal to a client's query options.
pub fn gjk_options(o: &gjkd_client::QueryOptions) -> gjk::Options {
    gjk::Options {
        tolerance: o.tolerance,
        max_iterations: o.max_iterations,
        margin: o.margin,
        warm_start: o.warm_start,
        precision: match o.precision {
            gjkd_client::Precision::Double => gjk::Precision::Double,
            gjkd_client::Precision::Single => gjk::Precision::Single,
        },
        penetration_expansions: 0,
    }
}

/// A test shape, registrable with the server and buildable in-process from
/// the same numbers.
#[derive(Clone, Debug)]
pub enum Solid {
    /// A ball.
    Sphere(f64),
    /// A segment and a radius.
    Capsule(nalgebra::Point3<f64>, nalgebra::Point3<f64>, f64),
    /// Half extents and a rounding radius.
    Cuboid(nalgebra::Vector3<f64>, f64),
    /// Vertices and a rounding radius.
    Polytope(Vec<nalgebra::Point3<f64>>, f64),
    /// Convex pieces with offsets.
    Compound(Vec<(nalgebra::Isometry3<f64>, Solid)>),
}

impl Solid {
    /// One of each kind: a sphere, a capsule, a rounded box, a random
    /// polytope of 30 vertices and a compound of three pieces.
    pub fn zoo() -> Vec<Solid> {
        use nalgebra::{Isometry3, Point3, Vector3};
        let mut rng = Rng::new(77);
        let cloud: Vec<Point3<f64>> = (0..30)
            .map(|_| {
                Point3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-0.5, 0.5),
                    rng.range(-1.5, 1.5),
                )
            })
            .collect();
        vec![
            Solid::Sphere(0.7),
            Solid::Capsule(Point3::new(0.0, 0.0, -1.0), Point3::new(0.0, 0.0, 1.0), 0.3),
            Solid::Cuboid(Vector3::new(0.8, 0.5, 0.3), 0.05),
            Solid::Polytope(cloud.clone(), 0.0),
            Solid::Compound(vec![
                (
                    Isometry3::translation(-1.2, 0.0, 0.0),
                    Solid::Cuboid(Vector3::new(0.4, 0.4, 0.4), 0.0),
                ),
                (
                    Isometry3::identity(),
                    Solid::Polytope(cloud[..8].to_vec(), 0.1),
                ),
                (
                    Isometry3::new(Vector3::new(1.2, 0.0, 0.0), Vector3::new(0.0, 0.4, 0.0)),
                    Solid::Sphere(0.5),
                ),
            ]),
        ]
    }

    fn convex(&self) -> gjk::Convex {
        match self {
            Solid::Sphere(r) => gjk::Convex::sphere(*r),
            Solid::Capsule(a, b, r) => gjk::Convex::capsule(*a, *b, *r),
            Solid::Cuboid(h, r) => gjk::Convex::cuboid(*h, *r),
            Solid::Polytope(v, r) => gjk::Convex::new(v.clone(), *r),
            Solid::Compound(_) => panic!("nested compound"),
        }
        .expect("valid test shape")
    }

    /// The in-process shape.
    pub fn shape(&self) -> gjk::Shape {
        match self {
            Solid::Compound(pieces) => {
                gjk::Compound::new(pieces.iter().map(|(o, s)| (*o, s.convex())).collect())
                    .expect("valid compound")
                    .into()
            }
            convex => convex.convex().into(),
        }
    }

    fn geometry(&self) -> gjkd_client::Geometry<'_> {
        use gjkd_client::Geometry;
        match self {
            Solid::Sphere(radius) => Geometry::Sphere { radius: *radius },
            Solid::Capsule(a, b, radius) => Geometry::Capsule {
                a: *a,
                b: *b,
                radius: *radius,
            },
            Solid::Cuboid(h, radius) => Geometry::Cuboid {
                half_extents: *h,
                radius: *radius,
            },
            Solid::Polytope(v, radius) => Geometry::Polytope {
                vertices: v,
                radius: *radius,
            },
            Solid::Compound(_) => panic!("use register"),
        }
    }

    /// Registers it through the client's typed calls.
    pub fn register(
        &self,
        client: &mut Client,
    ) -> Result<gjkd_client::ObjectId, gjkd_client::RegisterError> {
        match self {
            Solid::Sphere(r) => client.register_sphere(*r),
            Solid::Capsule(a, b, r) => client.register_capsule(*a, *b, *r),
            Solid::Cuboid(h, r) => client.register_cuboid(*h, *r),
            Solid::Polytope(v, r) => client.register_polytope(v, *r),
            Solid::Compound(pieces) => {
                let pieces: Vec<gjkd_client::Piece<'_>> = pieces
                    .iter()
                    .map(|(offset, s)| gjkd_client::Piece {
                        offset: *offset,
                        geometry: s.geometry(),
                    })
                    .collect();
                client.register_compound(&pieces)
            }
        }
    }
}
