//! A `gjkd serve` child process, as the demo and the measurements start it.

use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A `gjkd serve` child process, stopped with SIGTERM when dropped.
pub struct ServerProcess {
    child: Child,
    /// The service name it serves.
    pub service: String,
}

impl ServerProcess {
    /// Starts `gjkd serve --service SERVICE` plus `extra` arguments, using
    /// the current executable (which must be `gjkd`).
    ///
    /// # Errors
    /// When the process cannot be spawned.
    pub fn spawn(service: &str, extra: &[&str]) -> std::io::Result<Self> {
        let exe = std::env::current_exe()?;
        let child = Command::new(exe)
            .arg("serve")
            .arg("--service")
            .arg(service)
            .args(extra)
            .env(
                "RUST_LOG",
                std::env::var("GJKD_DEMO_LOG").unwrap_or_else(|_| "warn".into()),
            )
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .spawn()?;
        Ok(ServerProcess {
            child,
            service: service.to_owned(),
        })
    }

    /// The child's process id.
    pub fn id(&self) -> u32 {
        self.child.id()
    }

    /// Sends SIGTERM and waits up to five seconds for a clean exit, then
    /// kills. Returns whether it exited cleanly.
    pub fn stop(&mut self) -> bool {
        if let Ok(Some(status)) = self.child.try_wait() {
            return status.success();
        }
        if let Ok(pid) = libc::pid_t::try_from(self.child.id()) {
            // SAFETY: kill(2) with a pid we spawned and have not reaped yet.
            unsafe {
                libc::kill(pid, libc::SIGTERM);
            }
        }
        let deadline = Instant::now() + Duration::from_secs(5);
        while Instant::now() < deadline {
            if let Ok(Some(status)) = self.child.try_wait() {
                return status.success();
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
        false
    }
}

impl Drop for ServerProcess {
    fn drop(&mut self) {
        self.stop();
    }
}
