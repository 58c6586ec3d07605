//! The subsets of the four slots, as tables built at compile time: each
//! subset's members, the order in which subsets are tried, and the
//! macros that run a body once per subset with its mask as a constant.

use nalgebra::Vector3;

/// Slot bit masks of each subset's members, precomputed for speed.
pub(super) const fn members(mask: usize) -> ([u8; 4], u8) {
    let mut out = [0u8; 4];
    let mut n = 0;
    let mut i = 0;
    while i < 4 {
        if mask & (1 << i) != 0 {
            out[n] = i as u8;
            n += 1;
        }
        i += 1;
    }
    (out, n as u8)
}

/// A triangle is thin when `Δ(Y_s)` is below this times its longest squared
/// edge squared (its smallest angle below about 1e-3 rad): (5.6) then loses
/// more than 1e-10 of its cofactors to round-off.
pub(super) const THIN: f64 = 1e-6;

/// The slot a triangle's mask leaves out. A triangle's cofactors use three
/// of its row's four entries; the fourth marks it thin (1) or not (0).
#[inline(always)]
pub(super) const fn missing(mask: usize) -> usize {
    (!mask & 15).trailing_zeros() as usize & 3
}

/// `a × b`, each component `p·q - r·s` with one rounding (Kahan's fused
/// difference of products): exact to a unit in the last place of the
/// component, however much the two products cancel.
#[inline(always)]
pub(super) fn fused_cross(a: &Vector3<f64>, b: &Vector3<f64>) -> Vector3<f64> {
    let dop = |p: f64, q: f64, r: f64, t: f64| {
        let w = r * t;
        let err = (-r).mul_add(t, w);
        p.mul_add(q, -w) + err
    };
    Vector3::new(
        dop(a.y, b.z, a.z, b.y),
        dop(a.z, b.x, a.x, b.z),
        dop(a.x, b.y, a.y, b.x),
    )
}

/// Every non-empty subset, smallest first, so that a subset's cofactors are
/// computed after those of the subsets they recurse on.
pub(super) const BY_SIZE: [u8; 15] = [1, 2, 4, 8, 3, 5, 6, 9, 10, 12, 7, 11, 13, 14, 15];

/// For each new slot `n` and set `all` holding it: the subsets of `all` that
/// hold `n`, smallest first, so each cofactor's smaller subsets are ready.
pub(super) const WITH_NEW: [[([u8; 8], u8); 16]; 4] = {
    let mut t = [[([0u8; 8], 0u8); 16]; 4];
    let mut n = 0;
    while n < 4 {
        let mut all = 0;
        while all < 16 {
            let mut k = 0;
            while k < 15 {
                let m = BY_SIZE[k] as usize;
                if m & (1 << n) != 0 && m & !all == 0 {
                    let (list, len) = &mut t[n][all];
                    list[*len as usize] = m as u8;
                    *len += 1;
                }
                k += 1;
            }
            all += 1;
        }
        n += 1;
    }
    t
};

pub(super) const MEMBERS: [([u8; 4], u8); 16] = {
    let mut t = [([0u8; 4], 0u8); 16];
    let mut m = 0;
    while m < 16 {
        t[m] = members(m);
        m += 1;
    }
    t
};

/// Runs `$body` with `$m` bound to `$mask` as a constant, one arm per
/// non-empty subset: inside an arm every table lookup on `$m` is a constant,
/// so the loops over its members unroll into straight-line code.
macro_rules! by_mask {
    ($mask:expr, $m:ident => $body:expr) => {
        match $mask & 15 {
            1 => {
                const $m: usize = 1;
                $body
            }
            2 => {
                const $m: usize = 2;
                $body
            }
            3 => {
                const $m: usize = 3;
                $body
            }
            4 => {
                const $m: usize = 4;
                $body
            }
            5 => {
                const $m: usize = 5;
                $body
            }
            6 => {
                const $m: usize = 6;
                $body
            }
            7 => {
                const $m: usize = 7;
                $body
            }
            8 => {
                const $m: usize = 8;
                $body
            }
            9 => {
                const $m: usize = 9;
                $body
            }
            10 => {
                const $m: usize = 10;
                $body
            }
            11 => {
                const $m: usize = 11;
                $body
            }
            12 => {
                const $m: usize = 12;
                $body
            }
            13 => {
                const $m: usize = 13;
                $body
            }
            14 => {
                const $m: usize = 14;
                $body
            }
            _ => {
                const $m: usize = 15;
                $body
            }
        }
    };
}

/// Runs `$body` with `$n` and `$all` bound as constants to the newest slot
/// and the set holding it: the 32 shapes a simplex can have after a push.
/// `$other` handles anything else (only reachable through a logic error).
macro_rules! by_shape {
    ($slot:expr, $set:expr, $n:ident, $all:ident => $body:expr, $other:expr) => {
        by_shape!(@arms ($slot, $set), $n, $all, $body, $other;
            0: 1 3 5 7 9 11 13 15;
            1: 2 3 6 7 10 11 14 15;
            2: 4 5 6 7 12 13 14 15;
            3: 8 9 10 11 12 13 14 15)
    };
    (@arms $key:expr, $n:ident, $all:ident, $body:expr, $other:expr;
        $($nv:literal: $($av:literal)*);*) => {
        match $key {
            $($(($nv, $av) => {
                const $n: usize = $nv;
                const $all: usize = $av;
                $body
            })*)*
            _ => $other,
        }
    };
}

/// For each newest slot `n` and set `all` holding it, the candidates of the
/// subalgorithm after the "first face" of Section 6: the subsets holding `n`,
/// smallest first (but a full tetrahedron first of all), then the rest
/// (rejected last iteration; tried again for round-off's sake only).
pub(super) const ORDER: [[([u8; 15], u8); 16]; 4] = {
    let mut t = [[([0u8; 15], 0u8); 16]; 4];
    let mut n = 0;
    while n < 4 {
        let mut all = 0;
        while all < 16 {
            let (list, len) = &mut t[n][all];
            // A full tetrahedron is tried right after the first face: when the
            // origin is inside (the objects intersect) it is the answer, and
            // when not, its first negative cofactor rejects it at once.
            if all == 15 {
                list[0] = 15;
                *len = 1;
            }
            let (with, with_len) = WITH_NEW[n][all];
            let mut k = 0;
            while k < with_len as usize {
                if !(all == 15 && with[k] == 15) {
                    list[*len as usize] = with[k];
                    *len += 1;
                }
                k += 1;
            }
            let mut m = 1;
            while m < 16 {
                if m & (1 << n) == 0 && m & !all == 0 {
                    list[*len as usize] = m as u8;
                    *len += 1;
                }
                m += 1;
            }
            all += 1;
        }
        n += 1;
    }
    t
};

/// For each set `all`, its non-empty subsets, largest first: the candidates
/// for a fresh `V0`, where the whole set is the likeliest answer.
pub(super) const DOWN: [([u8; 15], u8); 16] = {
    let mut t = [([0u8; 15], 0u8); 16];
    let mut all = 0;
    while all < 16 {
        let (list, len) = &mut t[all];
        let mut k = 15;
        while k > 0 {
            k -= 1;
            let m = BY_SIZE[k] as usize;
            if m & !all == 0 {
                list[*len as usize] = m as u8;
                *len += 1;
            }
        }
        all += 1;
    }
    t
};
