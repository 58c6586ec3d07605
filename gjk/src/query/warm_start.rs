//! The simplex a query hands back for the next query of the same pair.

use crate::johnson::Simplex;
use crate::shape::Pieces;
use crate::support_map::SupportMap;

/// One piece pair's final simplex: its pieces and vertex index pairs (a
/// cylinder's entries are codes of its support points, see
/// [`Convex::cylinder`](crate::Convex::cylinder)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub(super) struct PieceSimplex {
    pub(super) pieces: [u32; 2],
    pub(super) len: u8,
    pub(super) pairs: [[u32; 2]; 4],
}

impl PieceSimplex {
    #[inline]
    pub(super) fn pairs(&self) -> &[[u32; 2]] {
        &self.pairs[..(self.len as usize).min(4)]
    }

    /// Whether every index names a piece and vertex that `a` and `b` have
    /// (an empty entry always fits). Branch-free over the pairs: one
    /// comparison each, folded into one flag.
    #[inline]
    pub(super) fn fits_shapes<A: Pieces, B: Pieces>(&self, a: &A, b: &B) -> bool {
        if self.len == 0 {
            return true;
        }
        let (Some(convex_a), Some(convex_b)) = (
            a.convex_piece(self.pieces[0] as usize),
            b.convex_piece(self.pieces[1] as usize),
        ) else {
            return false;
        };
        self.fits_counts(convex_a.index_count(), convex_b.index_count())
    }

    /// Whether every index pair is below `len_a` and `len_b` (an entry with
    /// no pairs always fits).
    #[inline]
    pub(super) fn fits_counts(&self, len_a: usize, len_b: usize) -> bool {
        let mut ok = self.len <= 4;
        for &[i, j] in self.pairs() {
            ok &= (i as usize) < len_a;
            ok &= (j as usize) < len_b;
        }
        ok
    }

    /// The index pairs of `mask`'s vertices in `simplex`.
    #[inline]
    pub(super) fn from_simplex(simplex: &Simplex, mask: u8, pieces: [u32; 2]) -> Self {
        let mut out = PieceSimplex {
            pieces,
            ..Default::default()
        };
        for (i, v) in simplex.vertices.iter().enumerate() {
            if mask & (1 << i) != 0 {
                out.pairs[out.len as usize] = [v.ia, v.ib];
                out.len += 1;
            }
        }
        out
    }
}

/// The final simplex of a query, as vertex index pairs (Section 8), plus the
/// pieces it belongs to. Keep it per object pair and hand it back with the next
/// query of the same pair: it changes the time, never the answer beyond `ε`.
///
/// For a compound it also keeps the runner-up piece pair's simplex, so that
/// along a motion both the nearest pair and the one most likely to take over
/// start warm (the paper warm-starts every convex pair of its Section 8 scene).
/// A runner-up that the nearest pair's normal proved farther without a run
/// has no simplex to keep; it starts cold on the query where it is run again.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct WarmStart {
    pub(super) first: PieceSimplex,
    pub(super) second: PieceSimplex,
}

impl WarmStart {
    /// A warm start from explicit `[vertex of A, vertex of B]` index pairs (at
    /// most 4; more return `None`) in the given pieces (`[0, 0]` for two convex
    /// shapes). Indices are checked against the shapes at query time. For a
    /// cylinder, an entry is a code of one of its points (any `u32` is one),
    /// best taken from an earlier answer's [`pairs`](Self::pairs).
    pub fn new(pieces: [u32; 2], pairs: &[[u32; 2]]) -> Option<Self> {
        if pairs.len() > 4 {
            return None;
        }
        let mut first = PieceSimplex {
            pieces,
            len: pairs.len() as u8,
            pairs: [[0; 2]; 4],
        };
        first.pairs[..pairs.len()].copy_from_slice(pairs);
        Some(WarmStart {
            first,
            second: PieceSimplex::default(),
        })
    }

    /// The `[vertex of A, vertex of B]` index pairs of the simplex (for a
    /// cylinder, the codes of its support points).
    pub fn pairs(&self) -> &[[u32; 2]] {
        self.first.pairs()
    }

    /// The `[piece of A, piece of B]` the simplex belongs to.
    pub fn pieces(&self) -> [u32; 2] {
        self.first.pieces
    }

    /// The same simplexes for the query with A and B swapped.
    pub(super) fn swapped(&self) -> WarmStart {
        let swap = |p: &PieceSimplex| PieceSimplex {
            pieces: [p.pieces[1], p.pieces[0]],
            len: p.len,
            pairs: p.pairs.map(|[i, j]| [j, i]),
        };
        WarmStart {
            first: swap(&self.first),
            second: swap(&self.second),
        }
    }

    /// The index pairs kept for the piece pair `pieces`, if any: the
    /// nearest pair's simplex, else the runner-up's. A plain loop over the
    /// two: as an iterator chain, the query's hot path kept the iterator's
    /// machinery once this file became a codegen unit of its own.
    #[inline(always)]
    pub(super) fn for_pieces(&self, pieces: [u32; 2]) -> Option<&[[u32; 2]]> {
        for kept in [&self.first, &self.second] {
            if kept.len > 0 && kept.pieces == pieces {
                return Some(kept.pairs());
            }
        }
        None
    }
}
