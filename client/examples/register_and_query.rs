//! Register two objects, place one, ask how far apart they are.
//!
//! Start a server first (`cargo run --release -p gjkd -- serve`), then:
//!
//! ```sh
//! cargo run -p gjkd-client --example register_and_query [SERVICE]
//! ```

use gjkd_client::{Client, ClientError, DEFAULT_SERVICE, QueryOptions};
use nalgebra::{Isometry3, Vector3};

fn main() -> Result<(), ClientError> {
    let service = std::env::args().nth(1);
    let mut client = Client::connect(service.as_deref().unwrap_or(DEFAULT_SERVICE))?;

    let ball = client.register_sphere(0.5)?;
    let crate_ = client.register_cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)?;
    client.set_pose(ball, &Isometry3::translation(3.0, 0.0, 0.0))?;

    let answer = client.distance(crate_, ball, &QueryOptions::default())?;
    println!(
        "distance {:.12} in [{:.12}, {:.12}], nearest points {} and {}",
        answer.distance, answer.lower, answer.upper, answer.point_a, answer.point_b
    );
    // The box's face is at x = 1 and the ball's surface at x = 2.5.
    assert!((answer.distance - 1.5).abs() < 1e-9);

    client.remove(ball)?;
    client.remove(crate_)?;
    Ok(())
}
