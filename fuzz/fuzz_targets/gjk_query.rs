//! Arbitrary vertex sets, radii, poses, options and warm starts, extreme
//! magnitudes included: `gjk::distance` never panics, and every answer has
//! `lower <= distance <= upper` with no NaN anywhere; bad input is a typed
//! error.

#![no_main]

use gjk::{Compound, Convex, Options, Precision, Shape, WarmStart};
use libfuzzer_sys::fuzz_target;
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion};

/// Reads the fuzzer's bytes as numbers, zeros once they run out.
struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn u8(&mut self) -> u8 {
        match self.0.split_first() {
            Some((&b, rest)) => {
                self.0 = rest;
                b
            }
            None => 0,
        }
    }

    fn u32(&mut self) -> u32 {
        u32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }

    fn u64(&mut self) -> u64 {
        u64::from(self.u32()) | (u64::from(self.u32()) << 32)
    }

    /// A number: mostly tame, sometimes huge, tiny or raw bits (NaN and
    /// infinities included), chosen by a tag byte.
    fn f64(&mut self) -> f64 {
        let tag = self.u8();
        match tag % 8 {
            0 => f64::from_bits(self.u64()),
            1 => f64::from(self.u8() as i8) / 16.0,
            2 => f64::from(self.u32() as i32) * 1e-6,
            3 => f64::from(self.u8() as i8) * 10f64.powi(i32::from(self.u8() % 160)),
            4 => f64::from(self.u8() as i8) * 10f64.powi(-i32::from(self.u8() % 160)),
            5 => f64::from(self.u8() as i8) * 1e300,
            _ => f64::from(self.u8() as i8) / 8.0,
        }
    }

    fn convex(&mut self) -> Option<Convex> {
        let n = 1 + usize::from(self.u8() % 24);
        let mut points: Vec<Point3<f64>> = (0..n)
            .map(|_| Point3::new(self.f64(), self.f64(), self.f64()))
            .collect();
        if self.u8() % 8 == 0 {
            // Large enough for the block search: scaled copies of the drawn
            // points, so that extremes and exact ties repeat across blocks.
            let steps = [1.0, 0.5, 0.25, 1.0 - 1e-9, 0.999];
            points = (0..512 + n)
                .map(|k| points[k % n] * steps[(k / n) % steps.len()])
                .collect();
        }
        let radius = if self.u8() % 2 == 0 { 0.0 } else { self.f64() };
        Convex::new(points, radius).ok()
    }

    fn pose(&mut self) -> Isometry3<f64> {
        let t = Translation3::new(self.f64(), self.f64(), self.f64());
        let q = Quaternion::new(self.f64(), self.f64(), self.f64(), self.f64());
        // Only unit quaternions reach the query (the server checks them);
        // a NaN, zero or underflowing one becomes the identity.
        let r = UnitQuaternion::try_new(q, 0.0)
            .filter(|r| (r.coords.norm() - 1.0).abs() < 1e-6)
            .unwrap_or_else(UnitQuaternion::identity);
        Isometry3::from_parts(t, r)
    }

    fn shape(&mut self) -> Option<Shape> {
        if self.u8() % 4 == 0 {
            let n = 1 + usize::from(self.u8() % 4);
            let pieces = (0..n)
                .map(|_| Some((self.pose(), self.convex()?)))
                .collect::<Option<Vec<_>>>()?;
            Some(Compound::new(pieces).ok()?.into())
        } else {
            Some(self.convex()?.into())
        }
    }
}

fn check(a: &gjk::Answer) {
    let all = [a.distance, a.lower, a.upper, a.penetration];
    assert!(all.iter().all(|x| !x.is_nan()), "NaN in {a:?}");
    assert!(
        a.point_a.iter().chain(a.point_b.iter()).chain(a.normal.iter()).all(|x| !x.is_nan()),
        "NaN point in {a:?}"
    );
    assert!(a.lower <= a.distance && a.distance <= a.upper, "bounds out of order: {a:?}");
    assert!(a.lower >= 0.0 && a.penetration >= 0.0, "negative bound: {a:?}");
}

/// The lower bound can never exceed the distance between any vertex of A
/// and any vertex of B (less the radii), up to round-off of their size.
fn check_lower_against_vertices(
    a: &Shape,
    pa: &Isometry3<f64>,
    b: &Shape,
    pb: &Isometry3<f64>,
    ans: &gjk::Answer,
) {
    let (Shape::Convex(ca), Shape::Convex(cb)) = (a, b) else {
        return;
    };
    let wa: Vec<Point3<f64>> = ca.vertices().iter().map(|p| pa * p).collect();
    let wb: Vec<Point3<f64>> = cb.vertices().iter().map(|p| pb * p).collect();
    let mut scale: f64 = 0.0;
    let mut nearest = f64::INFINITY;
    for x in &wa {
        for y in &wb {
            // Scaled, so that the squares of 1e-200 gaps do not underflow
            // (gjk answers those exactly since its run is scaled).
            let d = x - y;
            let m = d.amax();
            let len = if m > 0.0 && m.is_finite() { m * (d / m).norm() } else { d.norm() };
            nearest = nearest.min(len);
            scale = scale.max(x.coords.amax()).max(y.coords.amax());
        }
    }
    let bound = nearest - ca.radius() - cb.radius();
    if !bound.is_finite() || !scale.is_finite() {
        return;
    }
    let slack = 1e-9 * (scale + nearest + ca.radius() + cb.radius());
    assert!(ans.lower <= bound.max(0.0) + slack, "lower {} above vertex bound {bound}: {ans:?}", ans.lower);
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let (Some(sa), Some(sb)) = (b.shape(), b.shape()) else {
        return;
    };
    let (pa, pb) = (b.pose(), b.pose());
    let debug = std::env::var_os("GJK_FUZZ_DEBUG").is_some();
    let options = Options {
        tolerance: if b.u8() % 2 == 0 { Options::default().tolerance } else { b.f64() },
        max_iterations: 1 + b.u32() % 200,
        margin: if b.u8() % 3 == 0 { Some(b.f64()) } else { None },
        warm_start: true,
        precision: if b.u8() % 2 == 0 { Precision::Double } else { Precision::Single },
        penetration_expansions: u32::from(b.u8() % 3) * 8,
    };
    if debug {
        eprintln!("a = {sa:?}\nb = {sb:?}\npose_a = {pa:?}\npose_b = {pb:?}\noptions = {options:?}");
    }
    let Ok(first) = gjk::distance(&sa, &pa, &sb, &pb, &options, None) else {
        return;
    };
    check(&first);
    check_lower_against_vertices(&sa, &pa, &sb, &pb, &first);
    // Warm from its own simplex at new poses, then from a made-up one.
    let (qa, qb) = (b.pose(), b.pose());
    if debug {
        eprintln!("first = {first:?}\nwarm at pose_a = {qa:?}\npose_b = {qb:?}");
    }
    if let Ok(again) = gjk::distance(&sa, &qa, &sb, &qb, &options, Some(&first.warm_start)) {
        check(&again);
        check_lower_against_vertices(&sa, &qa, &sb, &qb, &again);
    }
    let pairs: Vec<[u32; 2]> = (0..1 + b.u8() % 4).map(|_| [b.u32() % 32, b.u32() % 32]).collect();
    let w = WarmStart::new([b.u32() % 4, b.u32() % 4], &pairs);
    if debug {
        eprintln!("made-up warm start {w:?}");
    }
    if let Some(w) = w
        && let Ok(made_up) = gjk::distance(&sa, &pa, &sb, &pb, &options, Some(&w))
    {
        check(&made_up);
    }
});
