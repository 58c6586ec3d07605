//! Scene queries: a three-object "arm" among obstacles, asked about the
//! whole scene in one round trip each: every member's clearance, the pairs
//! within a margin, the nearest obstacles, and a candidate motion checked
//! step by step without moving anything.
//!
//! Start a server first (`cargo run --release -p gjkd -- serve`), then:
//!
//! ```sh
//! cargo run -p gjkd-client --example scene_clearance [SERVICE]
//! ```

use gjkd_client::{Client, ClientError, DEFAULT_SERVICE, ObjectId, SceneRow, Steps};
use nalgebra::{Isometry3, Vector3};

fn main() -> Result<(), ClientError> {
    let service = std::env::args().nth(1);
    let mut client = Client::connect(service.as_deref().unwrap_or(DEFAULT_SERVICE))?;

    // The arm: three balls of radius 0.2 along y, at x = 0.
    let arm: Vec<ObjectId> = (0..3)
        .map(|_| client.register_sphere(0.2))
        .collect::<Result<_, _>>()?;
    for (i, &link) in arm.iter().enumerate() {
        client.set_pose(link, &Isometry3::translation(0.0, i as f64, 0.0))?;
    }
    // A wall at x = 1 (its face at x = 0.9) and a post behind the arm.
    let wall = client.register_cuboid(Vector3::new(0.1, 3.0, 1.0), 0.0)?;
    client.set_pose(wall, &Isometry3::translation(1.0, 1.0, 0.0))?;
    let post = client.register_sphere(0.3)?;
    client.set_pose(post, &Isometry3::translation(-2.0, 0.0, 0.0))?;

    // Clearance: each link's nearest object outside the arm.
    let mut rows = [SceneRow::default(); 16];
    let summary = client.clearance(&arm).into_rows(&mut rows)?;
    for row in &rows[..summary.written] {
        println!(
            "link {:#x}: nearest {:#x} at {:.6} (in [{:.6}, {:.6}])",
            row.a, row.b, row.result.distance, row.result.lower, row.result.upper
        );
        // Every link is 0.9 - 0.2 = 0.7 from the wall's face.
        assert_eq!(row.b, wall.raw());
        assert!((row.result.distance - 0.7).abs() < 1e-9);
    }

    // Within: the pairs closer than 1.6 (the three links and the wall, and
    // the first link and the post, 2 - 0.5 = 1.5 apart).
    let summary = client.within(&arm, 1.6).into_rows(&mut rows)?;
    println!("{} pairs within 1.6", summary.total);
    assert_eq!(summary.total, 4);

    // Nearest: the two objects nearest to the first link, whatever group
    // they belong to: the next link (1 - 0.4 = 0.6 away), then the wall.
    let summary = client.nearest(arm[0], 2).into_rows(&mut rows)?;
    assert_eq!(summary.written, 2);
    assert_eq!((rows[0].b, rows[1].b), (arm[1].raw(), wall.raw()));

    // A path: the arm slides towards the wall in five steps of 0.15; the
    // first step within 0.2 of anything is step 4 (0.7 - 4 * 0.15 = 0.1).
    let poses: Vec<Isometry3<f64>> = (0..5)
        .flat_map(|s| (0..3).map(move |i| Isometry3::translation(0.15 * s as f64, i as f64, 0.0)))
        .collect();
    let steps = Steps::Poses {
        objects: &arm,
        poses: &poses,
    };
    let summary = client
        .within(&arm, 0.2)
        .until_hit(steps)
        .into_rows(&mut rows)?;
    println!("first step within 0.2: {:?}", summary.first_hit);
    assert_eq!(summary.first_hit, Some(4));
    // Nothing moved: the clearance is as before.
    let summary = client.path(&arm, steps).into_rows(&mut rows)?;
    assert_eq!(summary.steps, 5);
    let again = client.clearance(&arm).into_rows(&mut rows)?;
    assert!((rows[0].result.distance - 0.7).abs() < 1e-9 && again.written == 3);

    for id in arm.into_iter().chain([wall, post]) {
        client.remove(id)?;
    }
    Ok(())
}
