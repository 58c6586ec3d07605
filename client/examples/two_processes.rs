//! Two processes share one scene: this process registers a named object and
//! moves it; a second process (this program again, started with `watch`)
//! finds it by name and measures its distance to an object of its own.
//!
//! ```sh
//! cargo run -p gjkd-client --example two_processes [SERVICE]
//! ```

use std::process::Command;

use gjkd_client::{Client, ClientError, DEFAULT_SERVICE, Geometry, QueryOptions};
use nalgebra::{Isometry3, Vector3};

/// The name under which the first process shares its object.
const SHARED_NAME: &str = "example/door";

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let service = args.next().unwrap_or_else(|| DEFAULT_SERVICE.to_owned());
    if args.next().as_deref() == Some("watch") {
        return Ok(watch(&service)?);
    }

    let mut client = Client::connect(&service)?;
    // A slab 0.1 thick whose near face is at x = 4.9 once it is placed.
    let door = client.register_named(
        SHARED_NAME,
        &Geometry::Cuboid {
            half_extents: Vector3::new(0.05, 1.0, 1.0),
            radius: 0.0,
        },
        &Isometry3::translation(10.0, 0.0, 0.0),
    )?;
    client.set_pose(door, &Isometry3::translation(4.95, 0.0, 0.0))?;

    let status = Command::new(std::env::current_exe()?)
        .args([service.as_str(), "watch"])
        .status()?;
    client.remove(door)?;
    if !status.success() {
        return Err(format!("the watching process failed: {status}").into());
    }
    println!("owner: the watcher saw the door where it was put");
    Ok(())
}

/// The second process: it knows the shared object only by its name.
fn watch(service: &str) -> Result<(), ClientError> {
    let mut client = Client::connect(service)?;
    let door = client.lookup(SHARED_NAME)?;
    let ball = client.register_sphere(0.5)?;
    let answer = client.distance(ball, door, &QueryOptions::default())?;
    println!(
        "watcher: a ball at the origin is {:.12} from the door",
        answer.distance
    );
    client.remove(ball)?;
    // The door's near face at x = 4.9, the ball's surface at x = 0.5.
    assert!((answer.distance - 4.4).abs() < 1e-9);
    Ok(())
}
