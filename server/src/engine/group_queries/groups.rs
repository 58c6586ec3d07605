//! The group a scene question is about, and the pairs never to report.
//!
//! A group is a robot's links (with its allowed pairs: the SRDF's
//! `disable_collisions` and the adjacent links), one object, or the
//! objects listed by [`ItemKind::Member`] items; [`ItemKind::Allow`] items
//! add allowed pairs. Members never meet each other (but with
//! [`scene_flags::ALL_PAIRS`](gjkd_proto::scene_flags::ALL_PAIRS)).

use gjkd_proto::{ErrorCode, Item, ItemKind};

use super::broadphase::Broadphase;
use crate::engine::robots::Robots;

/// A request's group, as broadphase slots, and its allowed pairs; the
/// buffers are reused from one request to the next.
#[derive(Debug, Default)]
pub(crate) struct Group {
    /// Members, in request order, without repeats.
    pub members: Vec<u32>,
    /// Per broadphase slot: whether it is a member.
    in_group: Vec<bool>,
    /// Allowed pairs of ids, smaller first, sorted.
    allowed: Vec<(u64, u64)>,
}

impl Group {
    /// Reads the group of `group` (a robot id, an object id, or 0 for the
    /// `items`' members) and the allowed pairs.
    ///
    /// # Errors
    /// [`ErrorCode::UnknownObject`] for an unknown group, member or allowed
    /// object (or a robot link removed since), [`ErrorCode::Malformed`] for
    /// member items with a non-zero group.
    pub(crate) fn resolve(
        &mut self,
        bp: &Broadphase,
        robots: &Robots,
        group: u64,
        items: &[Item],
    ) -> Result<(), ErrorCode> {
        self.clear();
        self.in_group.resize(bp.slot_count(), false);
        let slot = |id: u64| bp.slot(id).ok_or(ErrorCode::UnknownObject);
        if let Some(robot) = robots.get(group) {
            for id in robot.links.iter().flatten() {
                self.add(slot(*id)?);
            }
            for &(i, j) in &robot.allowed {
                if let (Some(Some(a)), Some(Some(b))) = (robot.links.get(i), robot.links.get(j)) {
                    self.allowed.push(ordered(*a, *b));
                }
            }
        } else if group != 0 {
            self.add(slot(group)?);
        }
        for item in items {
            match ItemKind::from_raw(item.kind) {
                Some(ItemKind::Member) if group != 0 => return Err(ErrorCode::Malformed),
                Some(ItemKind::Member) => self.add(slot(item.a)?),
                Some(ItemKind::Allow) => {
                    slot(item.a)?;
                    slot(item.b)?;
                    self.allowed.push(ordered(item.a, item.b));
                }
                _ => {}
            }
        }
        self.allowed.sort_unstable();
        self.allowed.dedup();
        Ok(())
    }

    fn add(&mut self, slot: u32) {
        if !self.in_group[slot as usize] {
            self.in_group[slot as usize] = true;
            self.members.push(slot);
        }
    }

    /// Forgets the members (the buffers stay).
    pub(crate) fn clear(&mut self) {
        for &m in &self.members {
            self.in_group[m as usize] = false;
        }
        self.members.clear();
        self.allowed.clear();
    }

    /// Whether slot `slot` is a member.
    #[inline]
    pub(crate) fn contains(&self, slot: u32) -> bool {
        self.in_group.get(slot as usize).copied().unwrap_or(false)
    }

    /// Whether the pair of ids `a`, `b` is allowed (never reported).
    #[inline]
    pub(crate) fn allowed(&self, a: u64, b: u64) -> bool {
        !self.allowed.is_empty() && self.allowed.binary_search(&ordered(a, b)).is_ok()
    }
}

fn ordered(a: u64, b: u64) -> (u64, u64) {
    if a <= b { (a, b) } else { (b, a) }
}
