//! The brute-force penetration depth, owing nothing to GJK or to an
//! expanding polytope: the Minkowski difference `K = A - B` of two small
//! point sets is the hull of the differences `a_i - b_j`; its facets are
//! the planes through three differences with every difference on one side
//! (decided by exact orientation predicates, `robust`); the depth is the
//! least distance from the origin to a facet's plane, which is the least
//! support value `h_K(n)` over unit `n` when the origin is inside `K`.
//!
//! The cost is cubic in the number of differences times their number:
//! meant for sets of a few points each (at most 100 differences).

use crate::reference::{P, V};

/// The depth of the origin inside the hull of the differences of `p` and
/// `q` (world points; `q`'s radius and `p`'s not counted), and the unit
/// outward normal of the facet that realises it. `None` when the
/// differences are coplanar (`K` has no interior) or the origin is not
/// inside every facet (the sets are apart or touching: no depth).
pub fn minkowski_depth(p: &[P], q: &[P]) -> Option<(f64, V)> {
    let d: Vec<V> = p
        .iter()
        .flat_map(|a| q.iter().map(move |b| a - b))
        .collect();
    let coord = |v: &V| robust::Coord3D {
        x: v.x,
        y: v.y,
        z: v.z,
    };
    let n = d.len();
    let mut best: Option<(f64, V)> = None;
    let mut any_facet = false;
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                // Which side of the plane (i, j, k) each difference lies on.
                // orient3d(a, b, c, x) > 0 puts x below the plane, on the
                // side opposite its normal (b - a) × (c - a).
                let (mut below, mut above) = (false, false);
                for (l, x) in d.iter().enumerate() {
                    if l == i || l == j || l == k {
                        continue;
                    }
                    let s = robust::orient3d(coord(&d[i]), coord(&d[j]), coord(&d[k]), coord(x));
                    below |= s > 0.0;
                    above |= s < 0.0;
                    if above && below {
                        break;
                    }
                }
                if above == below {
                    // Both sides (not a facet), or none (all coplanar).
                    continue;
                }
                let normal = (d[j] - d[i]).cross(&(d[k] - d[i]));
                let len = normal.norm();
                if len == 0.0 {
                    continue;
                }
                any_facet = true;
                // Outward is away from the other differences.
                let outward = if below { normal / len } else { -normal / len };
                let h = outward.dot(&d[i]);
                if h <= 0.0 {
                    // The origin is on or outside this facet.
                    return None;
                }
                if best.is_none_or(|(b, _)| h < b) {
                    best = Some((h, outward));
                }
            }
        }
    }
    if any_facet { best } else { None }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(c: V, h: f64) -> Vec<P> {
        (0..8)
            .map(|i| {
                P::from(
                    c + V::new(
                        if i & 1 == 0 { -h } else { h },
                        if i & 2 == 0 { -h } else { h },
                        if i & 4 == 0 { -h } else { h },
                    ),
                )
            })
            .collect()
    }

    #[test]
    fn two_unit_cubes_overlapping_along_x() {
        let (depth, normal) =
            minkowski_depth(&cube(V::zeros(), 1.0), &cube(V::new(1.5, 0.2, 0.0), 1.0))
                .expect("overlapping");
        assert!((depth - 0.5).abs() < 1e-15, "{depth}");
        assert_eq!(normal, V::x());
    }

    #[test]
    fn apart_touching_and_flat_sets_have_no_depth() {
        let a = cube(V::zeros(), 1.0);
        assert_eq!(minkowski_depth(&a, &cube(V::new(3.0, 0.0, 0.0), 1.0)), None);
        assert_eq!(minkowski_depth(&a, &cube(V::new(2.0, 0.0, 0.0), 1.0)), None);
        let flat = [P::origin(), P::new(1.0, 0.0, 0.0), P::new(0.0, 1.0, 0.0)];
        assert_eq!(minkowski_depth(&flat, &[P::new(0.2, 0.2, 0.0)]), None);
    }
}
