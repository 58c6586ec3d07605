//! Whatever a client's registration calls accept can be queried, and
//! whatever they refuse gets its documented error: a property test against
//! a real server, with values drawn on both sides of every documented limit
//! (2^999, about 5.4e300, for a shape's reach and radius; negative half
//! extents; no vertices; NaN and infinities).

use std::time::Duration;

use gjkd_client::{
    Client, ClientError, Geometry, ObjectId, QueryOptions, RegisterError, ShapeError,
};
use gjkd_e2e::Server;
use nalgebra::{Isometry3, Point3, Vector3};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRng, TestRunner};

/// The documented bound on a shape's reach and radius: 2^999.
const BOUND: f64 = 5.357543035931337e300;

/// Coordinates and radii: ordinary ones, ones far inside the bound (a few
/// of them summed stay inside), far beyond it, and not numbers at all.
fn value() -> impl Strategy<Value = f64> {
    prop_oneof![
        16 => -10.0..10.0f64,
        1 => -1e299..1e299f64,
        1 => prop_oneof![Just(1e301), Just(-1e301), Just(1e305), Just(f64::MAX)],
        1 => prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(f64::NEG_INFINITY)],
    ]
}

/// Radii: mostly valid ones, then large ones on both sides of the bound
/// (2e300 is within it even with the largest vertices drawn), else any
/// value.
fn radius() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => 0.0..2.0f64,
        1 => prop_oneof![Just(2e300), Just(1e301), Just(1e305), Just(f64::MAX)],
        1 => value(),
    ]
}

fn point() -> impl Strategy<Value = Point3<f64>> {
    (value(), value(), value()).prop_map(|(x, y, z)| Point3::new(x, y, z))
}

/// One of the client's registration calls with its arguments.
#[derive(Clone, Debug)]
enum Call {
    Sphere(f64),
    Capsule(Point3<f64>, Point3<f64>, f64),
    Cuboid(Vector3<f64>, f64),
    Polytope(Vec<Point3<f64>>, f64),
}

fn call() -> impl Strategy<Value = Call> {
    prop_oneof![
        radius().prop_map(Call::Sphere),
        (point(), point(), radius()).prop_map(|(a, b, r)| Call::Capsule(a, b, r)),
        (point(), radius()).prop_map(|(h, r)| Call::Cuboid(h.coords.abs(), r)),
        (point(), radius()).prop_map(|(h, r)| Call::Cuboid(h.coords, r)),
        (proptest::collection::vec(point(), 0..5), radius())
            .prop_map(|(v, r)| Call::Polytope(v, r)),
    ]
}

impl Call {
    /// The vertices the shape is made of, and its radius.
    fn parts(&self) -> (Vec<Point3<f64>>, f64) {
        match self {
            Call::Sphere(r) => (vec![Point3::origin()], *r),
            Call::Capsule(a, b, r) => (vec![*a, *b], *r),
            Call::Cuboid(h, r) => (vec![Point3::from(*h), Point3::from(-*h)], *r),
            Call::Polytope(v, r) => (v.clone(), *r),
        }
    }

    /// What the documentation says the call gives: `Ok(())` or the error.
    /// The values drawn keep clear of the bound (within 1e299 or beyond
    /// 1e301), so the reach is judged by the largest vertex alone.
    fn documented(&self) -> Result<(), RegisterError> {
        if let Call::Cuboid(h, _) = self
            && h.iter().any(|&c| c < 0.0)
        {
            return Err(RegisterError::InvalidShape(
                ShapeError::HalfExtentIsNegative,
            ));
        }
        let (vertices, radius) = self.parts();
        if vertices.is_empty() {
            return Err(RegisterError::EmptyVertices);
        }
        if !(radius.is_finite() && radius >= 0.0) {
            return Err(RegisterError::InvalidRadius);
        }
        if vertices
            .iter()
            .any(|v| !v.coords.iter().all(|c| c.is_finite()))
        {
            return Err(RegisterError::NonFiniteVertex);
        }
        if radius > BOUND {
            return Err(RegisterError::InvalidRadius);
        }
        let reach = vertices.iter().map(|v| v.coords.amax()).fold(0.0, f64::max);
        if reach > BOUND || reach + radius > BOUND {
            return Err(RegisterError::NonFiniteVertex);
        }
        Ok(())
    }

    fn register(&self, client: &mut Client) -> Result<ObjectId, RegisterError> {
        match self {
            Call::Sphere(r) => client.register_sphere(*r),
            Call::Capsule(a, b, r) => client.register_capsule(*a, *b, *r),
            Call::Cuboid(h, r) => client.register_cuboid(*h, *r),
            Call::Polytope(v, r) => client.register(&Geometry::Polytope {
                vertices: v,
                radius: *r,
            }),
        }
    }
}

#[test]
fn accepted_registrations_can_be_queried_and_refused_ones_say_why() {
    let server = Server::start("registration-limits", &["--no-persist"]);
    let client = std::cell::RefCell::new(server.client(Duration::from_secs(5)));
    let unit = client
        .borrow_mut()
        .register_cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)
        .expect("unit box");
    let config = Config {
        cases: 128,
        failure_persistence: None,
        ..Config::default()
    };
    // The same cases every run, so the count of accepted ones is stable.
    let rng = TestRng::deterministic_rng(config.rng_algorithm);
    let mut runner = TestRunner::new_with_rng(config, rng);
    let accepted = std::cell::Cell::new(0);
    runner
        .run(&call(), |c| {
            let want = c.documented();
            let mut client = client.borrow_mut();
            match c.register(&mut client) {
                Ok(id) => {
                    prop_assert!(want.is_ok(), "{c:?} accepted, documented {want:?}");
                    let id_pose = Isometry3::identity();
                    let answer =
                        client.distance_at(id, &id_pose, unit, &id_pose, &QueryOptions::cold());
                    prop_assert!(answer.is_ok(), "{c:?}: {answer:?}");
                    client.remove(id).expect("removed");
                    accepted.set(accepted.get() + 1);
                }
                Err(e) => {
                    // The umbrella error carries the same code.
                    let code = e.code();
                    prop_assert_eq!(ClientError::from(e.clone()).code(), code);
                    prop_assert_eq!(Err(e), want, "{:?}", c);
                }
            }
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{e}"));
    let accepted = accepted.get();
    eprintln!("{accepted} of 128 registrations accepted and queried");
    assert!(accepted > 40, "too few accepted to mean much: {accepted}");
}
