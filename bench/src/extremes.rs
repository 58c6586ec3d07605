//! The extremes family of `gjkd bench tradeoff`: what a user's scene can throw
//! at the algorithm besides the paper's well-scaled polytopes.
//!
//! - far offsets: boxes a millimetre or a metre apart, a thousand to a billion
//!   units from the origin;
//! - tiny and huge scales: objects of size 1e-6 and 1e6 with gaps in
//!   proportion, and the paper's polytopes scaled by the same factors;
//! - tiny gaps: unit objects 1e-9 to 1e-12 apart, and exact contact;
//! - degenerate sets: points, segments, flat polygons, duplicated and
//!   collinear vertices;
//! - rounded shapes: spheres and capsules against the paper's polytopes and
//!   each other at random poses (GJK runs on their cores, points and
//!   segments, and takes the radii off at the end).
//!
//! Almost every case is axis-aligned boxes (possibly flat), spheres or
//! segments placed by translations only, so its distance has a closed form in
//! the very `f64` inputs ([`gjkd_testkit::reference::aabb_distance`]); the scaled
//! polytopes are left to the brute force.

use gjk::{Convex, Shape};
use nalgebra::{Isometry3, Point3, Vector3};

/// One case before its reference is known.
#[derive(Clone, Debug)]
pub struct RawCase {
    /// Sub-family, for tables.
    pub family: &'static str,
    /// What it is.
    pub label: String,
    /// First shape.
    pub a: Shape,
    /// Its pose.
    pub pose_a: Isometry3<f64>,
    /// Second shape.
    pub b: Shape,
    /// Its pose.
    pub pose_b: Isometry3<f64>,
    /// The distance in closed form, when there is one.
    pub analytic: Option<f64>,
}

fn cuboid(h: [f64; 3]) -> Shape {
    Convex::cuboid(Vector3::from(h), 0.0)
        .expect("finite half extents")
        .into()
}

fn at(t: [f64; 3]) -> Isometry3<f64> {
    Isometry3::translation(t[0], t[1], t[2])
}

/// Boxes of half extents `ha`, `hb` at centres `ca`, `cb`, with the closed
/// form from the inputs as they are in `f64`.
fn boxes(
    family: &'static str,
    label: String,
    ha: [f64; 3],
    ca: [f64; 3],
    hb: [f64; 3],
    cb: [f64; 3],
) -> RawCase {
    let d = gjkd_testkit::reference::aabb_distance(
        &Vector3::from(ca),
        &Vector3::from(ha),
        &Vector3::from(cb),
        &Vector3::from(hb),
    );
    RawCase {
        family,
        label,
        a: cuboid(ha),
        pose_a: at(ca),
        b: cuboid(hb),
        pose_b: at(cb),
        analytic: Some(d),
    }
}

/// The extremes family.
pub fn cases() -> Vec<RawCase> {
    let mut out = Vec::new();
    // Far offsets: the relative pose cancels the offset only if it is formed
    // before rotating; gaps of 1e-3 at 1e9 are 1e-12 relative.
    for offset in [1e3, 1e6, 1e9] {
        for gap in [1e-3, 1.0] {
            let ca = [offset, -0.5 * offset, 0.25 * offset];
            out.push(boxes(
                "far offset",
                format!("boxes at {offset:e}, gap {gap:e} along x"),
                [1.0, 1.0, 1.0],
                ca,
                [0.5, 0.5, 0.5],
                [ca[0] + 1.5 + gap, ca[1] + 0.2, ca[2] - 0.3],
            ));
            out.push(boxes(
                "far offset",
                format!("boxes at {offset:e}, gap {gap:e} diagonal"),
                [1.0, 1.0, 1.0],
                ca,
                [0.5, 0.5, 0.5],
                [ca[0] + 1.5 + gap, ca[1] + 1.5 + gap, ca[2] + 1.5 + gap],
            ));
        }
    }
    // Tiny and huge scales, gaps in proportion and far below it.
    for scale in [1e-6, 1e6] {
        for rel_gap in [1e-1, 1e-4, 1e-9] {
            let h = [scale, 0.5 * scale, 0.25 * scale];
            out.push(boxes(
                if scale < 1.0 {
                    "tiny scale"
                } else {
                    "huge scale"
                },
                format!("boxes of size {scale:e}, gap {rel_gap:e} of it"),
                h,
                [0.0; 3],
                h,
                [2.0 * scale * (1.0 + rel_gap), 0.3 * scale, 0.1 * scale],
            ));
        }
        let r = scale;
        let gap = 1e-3 * scale;
        out.push(RawCase {
            family: if scale < 1.0 {
                "tiny scale"
            } else {
                "huge scale"
            },
            label: format!("spheres of radius {scale:e}, gap 1e-3 of it"),
            a: Convex::sphere(r).expect("radius").into(),
            pose_a: Isometry3::identity(),
            b: Convex::sphere(r).expect("radius").into(),
            pose_b: at([2.0 * r + gap, 0.0, 0.0]),
            // Along an axis the centre distance is exact.
            analytic: Some((2.0 * r + gap) - 2.0 * r),
        });
    }
    // Tiny gaps on unit objects, and exact contact and overlap.
    for gap in [1e-6, 1e-9, 1e-12] {
        out.push(boxes(
            "tiny gap",
            format!("unit boxes, gap {gap:e}"),
            [1.0; 3],
            [0.0; 3],
            [1.0; 3],
            [2.0 + gap, 0.5, -0.25],
        ));
        out.push(RawCase {
            family: "tiny gap",
            label: format!("capsules side by side, gap {gap:e}"),
            a: Convex::capsule(Point3::new(0.0, 0.0, -1.0), Point3::new(0.0, 0.0, 1.0), 0.5)
                .expect("capsule")
                .into(),
            pose_a: Isometry3::identity(),
            b: Convex::capsule(Point3::new(0.0, 0.0, -1.0), Point3::new(0.0, 0.0, 1.0), 0.5)
                .expect("capsule")
                .into(),
            pose_b: at([1.0 + gap, 0.0, 0.5]),
            analytic: Some((1.0 + gap) - 1.0),
        });
    }
    out.push(boxes(
        "tiny gap",
        "unit boxes touching face to face".into(),
        [1.0; 3],
        [0.0; 3],
        [1.0; 3],
        [2.0, 0.5, 0.25],
    ));
    out.push(boxes(
        "tiny gap",
        "unit boxes touching edge to edge".into(),
        [1.0; 3],
        [0.0; 3],
        [1.0; 3],
        [2.0, 2.0, 0.25],
    ));
    out.push(boxes(
        "tiny gap",
        "unit boxes overlapping by 1e-9".into(),
        [1.0; 3],
        [0.0; 3],
        [1.0; 3],
        [2.0 - 1e-9, 0.5, 0.25],
    ));
    // Degenerate sets.
    let point: Shape = Convex::sphere(0.0).expect("point").into();
    out.push(RawCase {
        family: "degenerate",
        label: "point against a box".into(),
        a: point.clone(),
        pose_a: at([3.0, 0.5, -0.5]),
        b: cuboid([1.0; 3]),
        pose_b: Isometry3::identity(),
        analytic: Some(2.0),
    });
    out.push(RawCase {
        family: "degenerate",
        label: "point against a point".into(),
        a: point.clone(),
        pose_a: at([1.0, 2.0, 3.0]),
        b: point,
        pose_b: at([1.0, 2.0, 3.0 + 0.75]),
        analytic: Some(0.75),
    });
    let segment = |axis: usize| -> Shape {
        let mut e = [0.0; 3];
        e[axis] = 1.0;
        Convex::capsule(
            Point3::from(-Vector3::from(e)),
            Point3::from(Vector3::from(e)),
            0.0,
        )
        .expect("segment")
        .into()
    };
    out.push(RawCase {
        family: "degenerate",
        label: "skew segments".into(),
        a: segment(2),
        pose_a: Isometry3::identity(),
        b: segment(0),
        pose_b: at([0.0, 0.625, 0.5]),
        analytic: Some(0.625),
    });
    out.push(RawCase {
        family: "degenerate",
        label: "parallel segments".into(),
        a: segment(2),
        pose_a: Isometry3::identity(),
        b: segment(2),
        pose_b: at([0.375, 0.0, 0.5]),
        analytic: Some(0.375),
    });
    out.push(RawCase {
        family: "degenerate",
        label: "crossing segments".into(),
        a: segment(2),
        pose_a: Isometry3::identity(),
        b: segment(0),
        pose_b: Isometry3::identity(),
        analytic: Some(0.0),
    });
    // A box whose every vertex is given three times.
    let cube = Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0).expect("cube");
    let tripled: Vec<Point3<f64>> = cube.vertices().iter().flat_map(|v| [*v, *v, *v]).collect();
    out.push(RawCase {
        family: "degenerate",
        label: "box with every vertex three times".into(),
        a: Convex::new(tripled, 0.0).expect("box").into(),
        pose_a: Isometry3::identity(),
        b: cuboid([0.5; 3]),
        pose_b: at([2.0, 0.25, 1.75]),
        analytic: Some(((2.0f64 - 1.5).powi(2) + (1.75f64 - 1.5).powi(2)).sqrt()),
    });
    // Collinear points: a segment given by twelve points.
    let line: Vec<Point3<f64>> = (0..12)
        .map(|i| Point3::new(-1.0 + 2.0 * f64::from(i) / 11.0, 0.0, 0.0))
        .collect();
    out.push(RawCase {
        family: "degenerate",
        label: "twelve collinear points against a box".into(),
        a: Convex::new(line, 0.0).expect("line").into(),
        pose_a: Isometry3::identity(),
        b: cuboid([0.5; 3]),
        pose_b: at([0.0, 1.5, 0.0]),
        analytic: Some(1.0),
    });
    // Flat squares: parallel planes, and side by side in one plane.
    out.push(boxes(
        "degenerate",
        "flat squares in parallel planes".into(),
        [1.0, 1.0, 0.0],
        [0.0; 3],
        [1.0, 1.0, 0.0],
        [0.5, 0.25, 0.125],
    ));
    out.push(boxes(
        "degenerate",
        "flat squares side by side in one plane".into(),
        [1.0, 1.0, 0.0],
        [0.0; 3],
        [1.0, 1.0, 0.0],
        [2.25, 0.5, 0.0],
    ));
    rounded(&mut out);
    out
}

/// A tiny deterministic generator (SplitMix64): the family must be the same
/// on every run for the reference cache to apply.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    fn direction(&mut self) -> Vector3<f64> {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f64::consts::TAU);
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vector3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

/// Spheres against each polytope of the paper's family, and capsules against
/// capsules, at random poses with gaps from 1e-3 to 3 (references by the
/// brute force: the radii come off the core distance exactly).
fn rounded(out: &mut Vec<RawCase>) {
    let mut rng = Rng(0x0005_eed5);
    for (i, poly) in gjkd_testkit::paper::family().into_iter().enumerate() {
        for k in 0..2 {
            let r = rng.range(0.2, 1.0);
            let dir = rng.direction();
            let reach = poly
                .vertices()
                .iter()
                .map(|v| v.coords.dot(&dir))
                .fold(f64::NEG_INFINITY, f64::max);
            let gap = 10f64.powf(rng.range(-3.0, 0.5));
            let rot =
                nalgebra::UnitQuaternion::from_scaled_axis(rng.direction() * rng.range(0.0, 3.0));
            out.push(RawCase {
                family: "rounded",
                label: format!("sphere against §7 polytope {} ({k})", i + 1),
                a: poly.clone().into(),
                pose_a: Isometry3::identity(),
                b: Convex::sphere(r).expect("radius").into(),
                // At least `gap` apart: the support point along `dir` is
                // the farthest the polytope reaches that way.
                pose_b: Isometry3::from_parts((dir * (reach + r + gap)).into(), rot),
                analytic: None,
            });
        }
    }
    for k in 0..12 {
        let capsule = |rng: &mut Rng| -> Shape {
            let half = rng.range(0.2, 2.0);
            Convex::capsule(
                Point3::new(0.0, 0.0, -half),
                Point3::new(0.0, 0.0, half),
                rng.range(0.05, 0.8),
            )
            .expect("capsule")
            .into()
        };
        let a = capsule(&mut rng);
        let b = capsule(&mut rng);
        let t = rng.direction() * rng.range(1.0, 5.0);
        out.push(RawCase {
            family: "rounded",
            label: format!("capsule against capsule ({k})"),
            a,
            pose_a: Isometry3::from_parts(
                nalgebra::Translation3::identity(),
                nalgebra::UnitQuaternion::from_scaled_axis(rng.direction() * rng.range(0.0, 3.0)),
            ),
            b,
            pose_b: Isometry3::from_parts(
                t.into(),
                nalgebra::UnitQuaternion::from_scaled_axis(rng.direction() * rng.range(0.0, 3.0)),
            ),
            analytic: None,
        });
    }
}
