//! SRDF: the link pairs a robot's collision checks skip.
//!
//! Only `<disable_collisions link1="..." link2="..."/>` is read (with any
//! `reason`); groups, states and the rest of the format are ignored.

use crate::kinematics::Kinematics;
use crate::xml_prefixes::rename_unbound_prefixes;

/// What can be wrong with an SRDF.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SrdfError {
    /// Not XML.
    #[error("malformed SRDF: {0}")]
    Malformed(String),
    /// A `disable_collisions` element without both links.
    #[error("a disable_collisions element lacks link1 or link2")]
    MissingLink,
    /// A pair names a link the robot does not have.
    #[error("disable_collisions names link `{0}`, which the robot does not have")]
    UnknownLink(String),
}

/// The robot's allowed pairs (pairs of link indices, each `(low, high)`,
/// sorted, without duplicates): the SRDF's `disable_collisions` pairs, plus,
/// if `adjacent`, every pair of links joined by a joint.
///
/// # Errors
/// An [`SrdfError`].
pub fn disabled_pairs(
    srdf: Option<&str>,
    kinematics: &Kinematics,
    adjacent: bool,
) -> Result<Vec<(usize, usize)>, SrdfError> {
    let links = kinematics.link_names();
    let index = |name: &str| {
        links
            .iter()
            .position(|l| l == name)
            .ok_or_else(|| SrdfError::UnknownLink(name.to_owned()))
    };
    let mut pairs = Vec::new();
    if adjacent {
        pairs.extend(kinematics.adjacent_links());
    }
    if let Some(text) = srdf {
        // Prefixes used undeclared, as ROS's parser allows, renamed.
        let text = rename_unbound_prefixes(text);
        let doc =
            roxmltree::Document::parse(&text).map_err(|e| SrdfError::Malformed(e.to_string()))?;
        for node in doc
            .descendants()
            .filter(|n| n.has_tag_name("disable_collisions"))
        {
            let (Some(a), Some(b)) = (node.attribute("link1"), node.attribute("link2")) else {
                return Err(SrdfError::MissingLink);
            };
            pairs.push((index(a)?, index(b)?));
        }
    }
    let mut pairs: Vec<(usize, usize)> = pairs
        .into_iter()
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    Ok(pairs)
}
