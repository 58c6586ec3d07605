//! Move a robot past a row of obstacles and ask every distance in one round
//! trip per step: the pose update and the queries travel as one batch, the
//! results land in a buffer this process owns, and the server starts each
//! pair warm from its previous step.
//!
//! ```sh
//! cargo run -p gjkd-client --example batch_along_motion [SERVICE]
//! ```

use gjkd_client::{Client, ClientError, DEFAULT_SERVICE, Item, ItemResult, QueryOptions};
use nalgebra::{Isometry3, Vector3};

const STEPS: usize = 100;
const OBSTACLES: usize = 8;

fn main() -> Result<(), ClientError> {
    let service = std::env::args().nth(1);
    let mut client = Client::connect(service.as_deref().unwrap_or(DEFAULT_SERVICE))?;

    // A box of half height 1 gliding along x at y = 0; spheres of radius
    // 0.3 in a row at y = 2, so every clearance is 2 - 1 - 0.3 = 0.7 while
    // the box is beside a sphere.
    let robot = client.register_cuboid(Vector3::new(0.5, 1.0, 0.5), 0.0)?;
    let mut obstacles = Vec::with_capacity(OBSTACLES);
    for i in 0..OBSTACLES {
        let o = client.register_sphere(0.3)?;
        client.set_pose(o, &Isometry3::translation(i as f64, 2.0, 0.0))?;
        obstacles.push(o);
    }

    let options = QueryOptions::default();
    let mut items = Vec::with_capacity(OBSTACLES + 1);
    let mut results = vec![ItemResult::default(); OBSTACLES + 1];
    let mut closest = f64::INFINITY;
    for step in 0..STEPS {
        let x = (OBSTACLES - 1) as f64 * step as f64 / (STEPS - 1) as f64;
        items.clear();
        items.push(Item::set_pose(robot, &Isometry3::translation(x, 0.0, 0.0)));
        items.extend(
            obstacles
                .iter()
                .map(|&o| Item::distance(robot, o, &options)),
        );
        client.query_batch(&items, &mut results)?;

        let mut nearest = f64::INFINITY;
        for r in &results[1..] {
            let answer = r.answer().map_err(ClientError::Rejected)?;
            nearest = nearest.min(answer.distance);
        }
        closest = closest.min(nearest);
        if step % 20 == 0 {
            println!("step {step:3}: robot at x = {x:.3}, nearest obstacle {nearest:.9}");
        }
    }
    println!("closest approach over {STEPS} steps: {closest:.12}");
    assert!((closest - 0.7).abs() < 1e-9);

    client.remove(robot)?;
    for o in obstacles {
        client.remove(o)?;
    }
    Ok(())
}
