//! What a signed-distance query is asked to do: [`DepthOptions`].

use crate::{Error, Options};

/// How hard the penetration depth works, and the distance query under it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthOptions {
    /// The distance query run first (its `margin` is ignored: the signed
    /// distance needs the converged answer).
    pub distance: Options,
    /// Relative tolerance of the expansion: it stops when the face of its
    /// polytope nearest the origin is within `tolerance × depth` (or the
    /// round-off of the pair's size) of `A - B`'s support plane along its
    /// normal. The interval in the answer says what was reached. Finite
    /// and `>= 0`; the default is `1e-9`.
    pub tolerance: f64,
    /// The most points the expanding polytope may have, at least 4; the
    /// default is 256. A polytope pair converges long before (a few
    /// points); a round difference whose least support value is reached
    /// along a whole ring of directions (coaxial cylinders) would need
    /// thousands for its lower bound to meet a small tolerance, at a cost
    /// that grows with their square, while the value, the least support
    /// value seen, is exact there already. The answer's interval holds
    /// wherever it stops.
    pub max_points: u32,
}

impl Default for DepthOptions {
    fn default() -> Self {
        DepthOptions {
            distance: Options::default(),
            tolerance: 1e-9,
            max_points: 256,
        }
    }
}

impl DepthOptions {
    pub(super) fn validate(&self) -> Result<(), Error> {
        if !(self.tolerance >= 0.0 && self.tolerance <= f64::MAX) {
            return Err(Error::InvalidOption(
                "depth tolerance must be finite and >= 0",
            ));
        }
        if self.max_points < 4 {
            return Err(Error::InvalidOption("max_points must be at least 4"));
        }
        Ok(())
    }

    /// The distance query's options for a depth: validated, and run to
    /// convergence (no margin), since a margin's early exit leaves the
    /// pair's overlap undecided.
    pub(super) fn converged_distance(&self) -> Result<Options, Error> {
        self.validate()?;
        Ok(Options {
            margin: None,
            ..self.distance
        })
    }
}
