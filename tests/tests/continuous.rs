//! The README's continuous-check example, run against a real server as
//! written, with only the service name changed.

use gjkd_e2e::Server;

#[test]
fn readme_continuous_example_runs() -> Result<(), gjkd_client::ClientError> {
    let server = Server::start("doc-continuous", &["--no-persist"]);
    let service = server.service.as_str();
    // --- from README.md, "Continuous checks: is the whole motion clear?" ---
    use gjkd_client::{Client, Contact, SceneRow, Steps};
    use nalgebra::{Isometry3, Vector3};

    let mut client = Client::connect(service)?;
    let ball = client.register_sphere(0.01)?;
    // A plate a tenth of a millimetre thick across the ball's way.
    let plate = client.register_cuboid(Vector3::new(0.5e-4, 1.0, 1.0), 0.0)?;
    let ends = [
        Isometry3::translation(-3.0, 0.0, 0.0),
        Isometry3::translation(3.3, 0.0, 0.0),
    ];
    let steps = Steps::Poses {
        objects: &[ball],
        poses: &ends,
    };
    let mut contacts = [Contact::default(); 1];
    let s = client
        .within(ball, 0.0)
        .continuous(steps, 1e-9)
        .into_contacts(&mut contacts)?;
    assert_eq!(s.total, 1);
    let c = contacts[0];
    assert_eq!((c.a, c.b), (ball, plate));
    // The ball's centre is at x = -3 + 6.3 s; it touches 0.01005 before x = 0.
    let exact = (3.0 - 0.01005) / 6.3;
    assert!(c.s_lo <= exact && exact <= c.s_hi && c.s_hi - c.s_lo <= 1e-9);
    // Sampled at ten steps, as OMPL would by default, the plate slips between.
    let sampled: Vec<Isometry3<f64>> = (0..=10)
        .map(|k| Isometry3::translation(-3.0 + 0.63 * k as f64, 0.0, 0.0))
        .collect();
    let steps = Steps::Poses {
        objects: &[ball],
        poses: &sampled,
    };
    let mut rows = [SceneRow::default(); 4];
    let s = client
        .within(ball, 0.0)
        .until_hit(steps)
        .into_rows(&mut rows)?;
    assert_eq!(s.first_hit, None);
    Ok(())
}
