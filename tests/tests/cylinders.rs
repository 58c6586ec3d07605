//! Exact cylinders through a real server: registered alone, rounded, as a
//! compound's piece, from a URDF arm's links and from a scene file, each
//! answering the closed form of a ball's (or a box's) distance to a finite
//! cylinder; surviving a crash and a clean restart bit for bit; every bad
//! input refused with its code and nothing stored.

use std::f64::consts::FRAC_PI_2;
use std::path::PathBuf;
use std::time::Duration;

use gjkd_client::{Client, ClientError, ErrorCode, Geometry, ObjectId, PackagePath, Piece};
use gjkd_client::{QueryOptions, Status};
use gjkd_e2e::{Server, once_reached, unique_service};
use nalgebra::{Isometry3, Point3, Vector3};

const TIMEOUT: Duration = Duration::from_secs(5);

/// A cylinder in the world: centre, unit axis, half-height, radius (the
/// rounding included in `rounding`).
struct Can {
    centre: Point3<f64>,
    axis: Vector3<f64>,
    half_height: f64,
    radius: f64,
    rounding: f64,
}

impl Can {
    /// The exact distance from the cylinder to a ball of `r_ball` about
    /// `p`, outside it: along the axis beyond a cap and across it beyond
    /// the curved face, whichever apply, less both roundings.
    fn distance_to_ball(&self, p: Point3<f64>, r_ball: f64) -> f64 {
        let v = p - self.centre;
        let along = v.dot(&self.axis);
        let radial = (v - along * self.axis).norm();
        let dz = (along.abs() - self.half_height).max(0.0);
        let dr = (radial - self.radius).max(0.0);
        dz.hypot(dr) - self.rounding - r_ball
    }
}

fn rejected<T: std::fmt::Debug, E: Into<ClientError>>(r: Result<T, E>) -> ErrorCode {
    match r.map_err(Into::into) {
        Err(ClientError::Rejected(code)) => code,
        other => panic!("expected a rejection, got {other:?}"),
    }
}

/// Distance of `a` at `pa` to `b` at `pb`, checked against `want` to
/// 1e-12 (the bounds containing it); returns the distance's bits.
fn check(
    client: &mut Client,
    (a, pa): (ObjectId, &Isometry3<f64>),
    (b, pb): (ObjectId, &Isometry3<f64>),
    want: f64,
) -> u64 {
    let got = client
        .distance_at(a, pa, b, pb, &QueryOptions::default())
        .expect("answered");
    assert_eq!(got.status, Some(Status::Converged));
    assert!(
        (got.distance - want).abs() <= 1e-12,
        "{} vs {want}",
        got.distance
    );
    assert!(got.lower <= want + 1e-15 && want - 1e-15 <= got.upper);
    got.distance.to_bits()
}

/// The objects of the persistence test.
struct Objects {
    can: ObjectId,
    rounded: ObjectId,
    pair: ObjectId,
    ball: ObjectId,
    cube: ObjectId,
}

fn register(client: &mut Client) -> Objects {
    let can = client.register_cylinder(0.5, 1.0, 0.0).unwrap();
    let rounded = client
        .register_named(
            "rounded",
            &Geometry::Cylinder {
                radius: 0.5,
                half_height: 1.0,
                rounding: 0.1,
            },
            &Isometry3::identity(),
        )
        .unwrap();
    let pieces = [
        Piece {
            offset: Isometry3::translation(0.0, 0.0, 5.0),
            geometry: Geometry::Cylinder {
                radius: 0.5,
                half_height: 1.0,
                rounding: 0.0,
            },
        },
        Piece {
            offset: Isometry3::identity(),
            geometry: Geometry::Sphere { radius: 0.2 },
        },
    ];
    let pair = client
        .register_named("pair", &Geometry::Compound(&pieces), &Isometry3::identity())
        .unwrap();
    let ball = client.register_sphere(0.25).unwrap();
    let cube = client
        .register_cuboid(Vector3::new(0.5, 0.5, 0.5), 0.0)
        .unwrap();
    Objects {
        can,
        rounded,
        pair,
        ball,
        cube,
    }
}

/// Every answer of the persistence test against its closed form; the
/// distances' bits, to compare across restarts.
fn answers(client: &mut Client, o: &Objects) -> Vec<u64> {
    let id = Isometry3::identity();
    let at = |x: f64, y: f64, z: f64| Isometry3::translation(x, y, z);
    let can = Can {
        centre: Point3::origin(),
        axis: Vector3::z(),
        half_height: 1.0,
        radius: 0.5,
        rounding: 0.0,
    };
    let mut bits = Vec::new();
    // Beside the face (|c_xy| - r - r_ball), beyond a cap (|z| - h - r_ball),
    // beyond the rim.
    for p in [
        Point3::new(1.2, -1.6, 0.3),
        Point3::new(0.1, 0.2, -3.0),
        Point3::new(3.0, 0.0, 2.0),
    ] {
        let want = can.distance_to_ball(p, 0.25);
        bits.push(check(
            client,
            (o.can, &id),
            (o.ball, &at(p.x, p.y, p.z)),
            want,
        ));
    }
    // Rounded, and laid along -y by a quarter turn about x.
    let turn = Isometry3::new(Vector3::new(10.0, 0.0, 0.0), Vector3::x() * FRAC_PI_2);
    let rounded = Can {
        centre: Point3::new(10.0, 0.0, 0.0),
        axis: turn.rotation * Vector3::z(),
        rounding: 0.1,
        ..can
    };
    for p in [
        Point3::new(10.0, 0.0, 2.0),
        Point3::new(10.0, 3.0, 0.0),
        Point3::new(12.0, -2.5, 1.0),
    ] {
        let want = rounded.distance_to_ball(p, 0.25);
        bits.push(check(
            client,
            (o.rounded, &turn),
            (o.ball, &at(p.x, p.y, p.z)),
            want,
        ));
    }
    // The compound's cylinder piece, 5 up.
    let piece = Can {
        centre: Point3::new(0.0, 0.0, 5.0),
        ..can
    };
    let p = Point3::new(0.0, 2.0, 5.0);
    let want = piece.distance_to_ball(p, 0.25);
    bits.push(check(
        client,
        (o.pair, &id),
        (o.ball, &at(p.x, p.y, p.z)),
        want,
    ));
    // A box beside the face, and above the cap.
    bits.push(check(
        client,
        (o.can, &id),
        (o.cube, &at(2.0, 0.0, 0.0)),
        1.0,
    ));
    bits.push(check(
        client,
        (o.can, &id),
        (o.cube, &at(0.3, 0.2, 3.0)),
        1.5,
    ));
    bits
}

#[test]
fn cylinders_answer_exactly_and_survive_a_crash_and_a_restart() {
    let mut server = Server::start("cyl-store", &[]);
    let mut client = server.client(TIMEOUT);
    let objects = register(&mut client);
    let before = answers(&mut client, &objects);

    server.kill9();
    server.restart();
    let stats = once_reached(|| client.stats());
    assert_eq!(stats.objects, 5, "every acknowledged object is back");
    assert_eq!(answers(&mut client, &objects), before, "bit for bit");

    server.terminate();
    server.restart();
    once_reached(|| client.stats());
    assert_eq!(answers(&mut client, &objects), before, "bit for bit");
    assert_eq!(client.lookup("rounded").unwrap(), objects.rounded);
}

#[test]
fn bad_cylinders_are_refused_and_change_nothing() {
    let server = Server::start("cyl-bad", &["--no-persist"]);
    let mut client = server.client(TIMEOUT);
    let kept = client.register_cylinder(0.5, 1.0, 0.0).unwrap();
    let objects = client.stats().unwrap().objects;
    let nan = f64::NAN;
    for (r, h, rounding) in [
        (-0.5, 1.0, 0.0),
        (0.5, -1.0, 0.0),
        (nan, 1.0, 0.0),
        (0.5, nan, 0.0),
        (0.5, f64::INFINITY, 0.0),
        (0.5, 1.0, -0.1),
        (0.5, 1.0, nan),
        (4e300, 4e300, 0.0),
    ] {
        assert_eq!(
            rejected(client.register_cylinder(r, h, rounding)),
            ErrorCode::InvalidRadius,
            "{r} {h} {rounding}"
        );
    }
    let bad_piece = [
        Piece {
            offset: Isometry3::identity(),
            geometry: Geometry::Sphere { radius: 1.0 },
        },
        Piece {
            offset: Isometry3::identity(),
            geometry: Geometry::Cylinder {
                radius: nan,
                half_height: 1.0,
                rounding: 0.0,
            },
        },
    ];
    assert_eq!(
        rejected(client.register(&Geometry::Compound(&bad_piece))),
        ErrorCode::InvalidRadius
    );
    let far = [Piece {
        offset: Isometry3::translation(6e300, 0.0, 0.0),
        geometry: Geometry::Cylinder {
            radius: 1.0,
            half_height: 1.0,
            rounding: 0.0,
        },
    }];
    assert_eq!(
        rejected(client.register(&Geometry::Compound(&far))),
        ErrorCode::NonFinitePose
    );
    assert_eq!(client.stats().unwrap().objects, objects);
    // The one registered before still answers.
    let ball = client.register_sphere(0.0).unwrap();
    let d = client
        .distance_at(
            kept,
            &Isometry3::identity(),
            ball,
            &Isometry3::translation(0.0, 0.0, 4.0),
            &QueryOptions::default(),
        )
        .unwrap();
    assert!((d.distance - 3.0).abs() <= 1e-12);
}

/// A post (cylinder along z) and an arm turning about the post's axis: the
/// arm link is a compound of a hub box and a cylinder laid along the link's
/// x axis by its origin's pitch.
const ARM: &str = r#"<robot name="crane">
  <link name="post"><collision><origin xyz="0 0 0.2"/>
    <geometry><cylinder radius="0.1" length="0.4"/></geometry></collision></link>
  <link name="boom">
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
    <collision><origin xyz="0.3 0 0" rpy="0 1.5707963267948966 0"/>
      <geometry><cylinder radius="0.05" length="0.6"/></geometry></collision>
  </link>
  <joint name="slew" type="revolute"><parent link="post"/><child link="boom"/>
    <origin xyz="0 0 0.4"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"#;

fn folder(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(unique_service(tag));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("crane.urdf"), ARM).unwrap();
    dir
}

/// The boom's cylinder at slew angle `theta` (base at the identity).
fn boom(theta: f64) -> Can {
    let axis = Vector3::new(theta.cos(), theta.sin(), 0.0);
    Can {
        centre: Point3::new(0.0, 0.0, 0.4) + 0.3 * axis,
        axis,
        half_height: 0.3,
        radius: 0.05,
        rounding: 0.0,
    }
}

/// A ball of 0.1 at `(0, 1, 0.4)` is nearer the boom's cylinder than its
/// hub (at least `1 - 0.05·√2 - 0.1` away) at these angles.
const ANGLES: [f64; 5] = [0.9, 1.2, FRAC_PI_2, 2.0, 2.2];

#[test]
fn a_urdf_arm_with_cylinder_links_answers_exactly() {
    let dir = folder("cyl-urdf");
    let server = Server::start("cyl-urdf", &["--no-persist"]);
    let mut client = server.client(TIMEOUT);
    let mut crane = client
        .register_robot(
            "crane",
            &dir.join("crane.urdf"),
            None,
            &PackagePath::default(),
            &Isometry3::identity(),
        )
        .unwrap();
    let ball = client.register_sphere(0.1).unwrap();
    let at = Point3::new(0.0, 1.0, 0.4);
    client
        .set_pose(ball, &Isometry3::translation(at.x, at.y, at.z))
        .unwrap();
    let (post, arm) = (crane.link("post").unwrap(), crane.link("boom").unwrap());
    let options = QueryOptions::default();
    for theta in ANGLES {
        client.set_joints(&mut crane, &[theta], None).unwrap();
        let want = boom(theta).distance_to_ball(at, 0.1);
        assert!(want < 1.0 - 0.05 * 2f64.sqrt() - 0.1, "the boom is nearest");
        let got = client.distance(arm, ball, &options).unwrap();
        assert!(
            (got.distance - want).abs() <= 1e-12,
            "{theta}: {} vs {want}",
            got.distance
        );
        assert!(got.lower <= want + 1e-15 && want - 1e-15 <= got.upper);
        // The post: the ball is level with its top cap, 1 from its axis.
        let d = client.distance(post, ball, &options).unwrap().distance;
        assert!((d - (1.0 - 0.1 - 0.1)).abs() <= 1e-12, "{d}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn scene_file_cylinders_and_cylinder_links_are_exact() {
    let dir = folder("cyl-scene");
    let scene = r#"
[[object]]
name = "can"
type = "cylinder"
radius = 0.5
length = 2.0
rounding = 0.05
pose = { translation = [5.0, 0.0, 0.0] }

[[object]]
name = "rack"
type = "compound"
[[object.pieces]]
type = "cylinder"
radius = 0.1
half_height = 1.0
offset = { translation = [-5.0, 1.0, 0.0] }
[[object.pieces]]
type = "cylinder"
radius = 0.1
half_height = 1.0
offset = { translation = [-5.0, -1.0, 0.0] }

[[robot]]
name = "crane"
urdf = "crane.urdf"
joints = { slew = 1.5707963267948966 }
"#;
    let scene_path = dir.join("scene.toml");
    std::fs::write(&scene_path, scene).unwrap();
    let server = Server::start(
        "cyl-scene",
        &["--no-persist", "--scene", scene_path.to_str().unwrap()],
    );
    let mut client = server.client(TIMEOUT);
    let can = client.lookup("can").unwrap();
    let rack = client.lookup("rack").unwrap();
    let ball = client.register_sphere(0.25).unwrap();
    let cases = [
        (
            can,
            Point3::new(5.0, 2.0, 0.5),
            Point3::new(5.0, 0.0, 0.0),
            0.5,
        ),
        (
            can,
            Point3::new(5.2, 0.0, -3.0),
            Point3::new(5.0, 0.0, 0.0),
            0.5,
        ),
        (
            rack,
            Point3::new(-5.0, 0.0, 0.0),
            Point3::new(-5.0, 1.0, 0.0),
            0.1,
        ),
        (
            rack,
            Point3::new(-5.0, -1.0, 4.0),
            Point3::new(-5.0, -1.0, 0.0),
            0.1,
        ),
    ];
    for (id, p, centre, radius) in cases {
        let rounding = if id == can { 0.05 } else { 0.0 };
        let want = Can {
            centre,
            axis: Vector3::z(),
            half_height: 1.0,
            radius,
            rounding,
        }
        .distance_to_ball(p, 0.25);
        let pose = if id == can {
            Isometry3::translation(5.0, 0.0, 0.0)
        } else {
            Isometry3::identity()
        };
        check(
            &mut client,
            (id, &pose),
            (ball, &Isometry3::translation(p.x, p.y, p.z)),
            want,
        );
    }
    // The scene's crane, slewed a quarter turn: the boom points along +y.
    let mut crane = client.open_robot("crane", ARM).unwrap();
    let boom_link = crane.link("boom").unwrap();
    let at = Point3::new(0.0, 1.0, 0.4);
    client
        .set_pose(ball, &Isometry3::translation(at.x, at.y, at.z))
        .unwrap();
    let d = client
        .distance(boom_link, ball, &QueryOptions::default())
        .unwrap()
        .distance;
    assert!((d - (1.0 - 0.6 - 0.25)).abs() <= 1e-12, "{d}");
    client.set_joints(&mut crane, &[2.0], None).unwrap();
    let d = client
        .distance(boom_link, ball, &QueryOptions::default())
        .unwrap()
        .distance;
    let want = boom(2.0).distance_to_ball(at, 0.25);
    assert!((d - want).abs() <= 1e-12, "{d} vs {want}");
    std::fs::remove_dir_all(dir).unwrap();
}
