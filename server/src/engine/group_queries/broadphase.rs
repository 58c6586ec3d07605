//! The broadphase: one axis-aligned box per object in parry3d-f64's BVH,
//! and a bounding sphere about each object's centroid for the motion
//! bounds. Every box contains its object (widened for round-off), so the
//! distance between two boxes is a lower bound on the objects' distance
//! and pruning by it never loses a pair.
//!
//! The index follows the store through its change list
//! ([`ObjectStore::take_changes`]): objects added, moved or removed since
//! the last scene question are refreshed when the next one comes, and only
//! those leaves of the tree are refitted.

use std::collections::HashMap;

use gjk::{Convex, Shape};
use nalgebra::{Isometry3, Point3};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector;
use parry3d_f64::partitioning::{Bvh, BvhNode};

use super::entry::{Entry, ROUND_OFF, displacement_from};
use crate::engine::objects::ObjectStore;
use crate::engine::warm_cache::FxBuild;

/// The index: slots, the BVH over their boxes, and the ids' slots.
#[derive(Debug, Default)]
pub struct Broadphase {
    entries: Vec<Entry>,
    slots: HashMap<u64, u32, FxBuild>,
    free: Vec<u32>,
    bvh: Bvh,
    /// Slots whose box changed since the tree was last refitted.
    moved: Vec<u32>,
    /// Scratch list of the store's changes.
    changes: Vec<u64>,
}

impl Broadphase {
    /// Brings the index up to date with the store.
    pub(crate) fn sync(&mut self, store: &mut ObjectStore) {
        let mut changes = std::mem::take(&mut self.changes);
        if store.take_changes(&mut changes) {
            for &id in &changes {
                match store.object(id) {
                    Some(object) => self.upsert(id, &object.shape, &object.pose),
                    None => self.remove(id),
                }
            }
        } else {
            self.resync(store);
        }
        self.changes = changes;
        self.refit();
    }

    /// Looks at every object: drops the departed, refreshes the others.
    fn resync(&mut self, store: &ObjectStore) {
        for i in 0..self.entries.len() {
            let e = self.entries[i];
            if e.live && store.object(e.id).is_none() {
                self.remove(e.id);
            }
        }
        for (id, object) in store.objects() {
            self.upsert(id, &object.shape, &object.pose);
        }
    }

    fn upsert(&mut self, id: u64, shape: &Shape, pose: &Isometry3<f64>) {
        let slot = match self.slots.get(&id) {
            Some(&slot) => slot,
            None => {
                let (centre, extent, reach) = bounding_sphere(shape);
                let (mins, maxs) = shape_box(shape, &Isometry3::identity(), reach);
                let entry = Entry {
                    id,
                    centre,
                    extent,
                    reach,
                    local_centre: std::array::from_fn(|i| 0.5 * (mins[i] + maxs[i])),
                    local_half: std::array::from_fn(|i| 0.5 * (maxs[i] - mins[i])),
                    pose: *pose,
                    world_centre: pose * centre,
                    mins: [0.0; 3],
                    maxs: [0.0; 3],
                    live: true,
                    overlaid: false,
                    queued: false,
                    travel: 0.0,
                };
                let slot = match self.free.pop() {
                    Some(slot) => {
                        self.entries[slot as usize] = entry;
                        slot
                    }
                    None => {
                        self.entries.push(entry);
                        (self.entries.len() - 1) as u32
                    }
                };
                self.slots.insert(id, slot);
                slot
            }
        };
        self.place(slot, pose);
        self.entries[slot as usize].overlaid = false;
        self.entries[slot as usize].travel = 0.0;
    }

    fn remove(&mut self, id: u64) {
        if let Some(slot) = self.slots.remove(&id) {
            self.entries[slot as usize].live = false;
            self.entries[slot as usize].queued = false;
            self.bvh.remove(slot);
            self.moved.retain(|&s| s != slot);
            self.free.push(slot);
        }
    }

    /// Moves slot `slot` to `pose`; the tree is refitted by
    /// [`Broadphase::refit`]. Its box is its body-frame box turned (the
    /// box of a turned box: a few operations whatever the vertex count).
    pub(crate) fn place(&mut self, slot: u32, pose: &Isometry3<f64>) {
        let e = &mut self.entries[slot as usize];
        e.pose = *pose;
        e.world_centre = pose * e.centre;
        let r = pose.rotation.to_rotation_matrix();
        let m = r.matrix();
        let c = pose * Point3::from(e.local_centre);
        let t = pose.translation.vector;
        let slack = ROUND_OFF * (t.abs().sum() + e.reach) + f64::MIN_POSITIVE;
        for i in 0..3 {
            let half = (0..3)
                .map(|j| m[(i, j)].abs() * e.local_half[j])
                .sum::<f64>()
                * (1.0 + ROUND_OFF);
            e.mins[i] = c[i] - half - slack;
            e.maxs[i] = c[i] + half + slack;
        }
        if !e.queued {
            e.queued = true;
            self.moved.push(slot);
        }
    }

    /// Moves slot `slot` to a path's `pose`, adding to its travel the
    /// largest distance any of its points moved.
    pub(crate) fn move_along(&mut self, slot: u32, pose: &Isometry3<f64>) {
        let (from, from_centre) = {
            let e = &self.entries[slot as usize];
            (e.pose, e.world_centre)
        };
        self.place(slot, pose);
        let e = &mut self.entries[slot as usize];
        e.travel += displacement_from(e, &from, &from_centre);
    }

    /// Marks slot `slot` as holding a path's pose, or back at its stored
    /// one (see [`Entry::overlaid`]); either way its travel starts at 0.
    pub(crate) fn set_overlaid(&mut self, slot: u32, overlaid: bool) {
        let e = &mut self.entries[slot as usize];
        e.overlaid = overlaid;
        e.travel = 0.0;
    }

    /// Refits the tree to the boxes moved since the last refit.
    pub(crate) fn refit(&mut self) {
        if self.moved.is_empty() {
            return;
        }
        self.moved.sort_unstable();
        self.moved.dedup();
        for &slot in &self.moved {
            let e = &mut self.entries[slot as usize];
            e.queued = false;
            let aabb = Aabb::new(Vector::from(e.mins), Vector::from(e.maxs));
            self.bvh.insert_or_update_partially(aabb, slot, 0.0);
        }
        self.bvh.refit_partial(&[], &self.moved);
        self.moved.clear();
    }

    /// The slot of object `id`.
    #[inline]
    pub(crate) fn slot(&self, id: u64) -> Option<u32> {
        self.slots.get(&id).copied()
    }

    /// The entry in slot `slot`.
    #[inline]
    pub(crate) fn entry(&self, slot: u32) -> &Entry {
        &self.entries[slot as usize]
    }

    /// Number of slots (live or free).
    pub(crate) fn slot_count(&self) -> usize {
        self.entries.len()
    }

    /// The tree.
    pub(crate) fn bvh(&self) -> &Bvh {
        &self.bvh
    }
}

/// A lower bound on the distance between two boxes, rounded down.
#[inline]
pub(crate) fn box_gap(amin: &[f64; 3], amax: &[f64; 3], bmin: &[f64; 3], bmax: &[f64; 3]) -> f64 {
    let mut sum = 0.0;
    for i in 0..3 {
        let gap = (bmin[i] - amax[i]).max(amin[i] - bmax[i]).max(0.0);
        sum += gap * gap;
    }
    sum.sqrt() * (1.0 - 4.0 * f64::EPSILON)
}

/// The square of [`box_gap`], rounded down, for comparisons with
/// [`square_up`] without a square root.
#[inline]
pub(crate) fn box_gap_squared(
    amin: &[f64; 3],
    amax: &[f64; 3],
    bmin: &[f64; 3],
    bmax: &[f64; 3],
) -> f64 {
    let mut sum = 0.0;
    for i in 0..3 {
        let gap = (bmin[i] - amax[i]).max(amin[i] - bmax[i]).max(0.0);
        sum += gap * gap;
    }
    sum * (1.0 - 8.0 * f64::EPSILON)
}

/// The square of [`box_gap`] between a box and a tree node, rounded down:
/// the search compares squares and so takes no square root per node.
#[inline]
pub(crate) fn node_gap_squared(amin: &[f64; 3], amax: &[f64; 3], node: &BvhNode) -> f64 {
    let (m, x) = (node.mins(), node.maxs());
    let (bmin, bmax) = ([m.x, m.y, m.z], [x.x, x.y, x.z]);
    let mut sum = 0.0;
    for i in 0..3 {
        let gap = (bmin[i] - amax[i]).max(amin[i] - bmax[i]).max(0.0);
        sum += gap * gap;
    }
    sum * (1.0 - 8.0 * f64::EPSILON)
}

/// `x²` rounded up, for comparisons with [`node_gap_squared`].
#[inline]
pub(crate) fn square_up(x: f64) -> f64 {
    x * x * (1.0 + 8.0 * f64::EPSILON)
}

/// The distance whose [`square_up`] is `x2`, rounded up.
#[inline]
pub(crate) fn root_up(x2: f64) -> f64 {
    x2.sqrt() * (1.0 + 4.0 * f64::EPSILON)
}

/// [`box_gap`] between a box and a tree node.
#[inline]
pub(crate) fn node_gap(amin: &[f64; 3], amax: &[f64; 3], node: &BvhNode) -> f64 {
    let (m, x) = (node.mins(), node.maxs());
    box_gap(amin, amax, &[m.x, m.y, m.z], &[x.x, x.y, x.z])
}

/// A lower bound on the distance between two objects from their bounding
/// spheres at their index poses.
#[inline]
pub(crate) fn sphere_gap(a: &Entry, b: &Entry) -> f64 {
    let (ca, cb) = (a.world_centre, b.world_centre);
    let round = ROUND_OFF * (ca.coords.abs().sum() + cb.coords.abs().sum() + a.reach + b.reach);
    (ca - cb).norm() * (1.0 - 4.0 * f64::EPSILON) - a.extent - b.extent - round
}

/// A shape's centroid (the mean of its pieces' centroids), its extent about
/// it and its reach about the body origin, both radius included and rounded
/// up.
pub(crate) fn bounding_sphere(shape: &Shape) -> (Point3<f64>, f64, f64) {
    match shape {
        Shape::Convex(c) => {
            let centre = c.centroid();
            let extent = c.size() + c.radius();
            (centre, up(extent), up(centre.coords.norm() + extent))
        }
        Shape::Compound(compound) => {
            let pieces = compound.pieces();
            let mut sum = nalgebra::Vector3::zeros();
            for (offset, c) in pieces {
                sum += (offset * c.centroid()).coords;
            }
            let centre = Point3::from(sum / pieces.len().max(1) as f64);
            let mut extent: f64 = 0.0;
            for (offset, c) in pieces {
                let d = (offset * c.centroid() - centre).norm();
                extent = extent.max(d + c.size() + c.radius());
            }
            (centre, up(extent), up(centre.coords.norm() + extent))
        }
    }
}

fn up(x: f64) -> f64 {
    x * (1.0 + ROUND_OFF) + f64::MIN_POSITIVE
}

/// The box of `shape` at `pose`, widened for round-off (`reach` as
/// [`bounding_sphere`]'s).
pub(crate) fn shape_box(shape: &Shape, pose: &Isometry3<f64>, reach: f64) -> ([f64; 3], [f64; 3]) {
    let mut mins = [f64::INFINITY; 3];
    let mut maxs = [f64::NEG_INFINITY; 3];
    match shape {
        Shape::Convex(c) => convex_box(c, pose, &mut mins, &mut maxs),
        Shape::Compound(compound) => {
            for (offset, c) in compound.pieces() {
                convex_box(c, &(pose * offset), &mut mins, &mut maxs);
            }
        }
    }
    let t = pose.translation.vector;
    let slack = ROUND_OFF * (t.abs().sum() + reach) + f64::MIN_POSITIVE;
    for i in 0..3 {
        mins[i] -= slack;
        maxs[i] += slack;
    }
    (mins, maxs)
}

/// Grows `mins`, `maxs` to hold `c` at `pose`: its vertices', or for a
/// cylinder its bounding sphere's, box, then its radius.
fn convex_box(c: &Convex, pose: &Isometry3<f64>, mins: &mut [f64; 3], maxs: &mut [f64; 3]) {
    let r = c.radius();
    if c.vertices().is_empty() {
        let centre = pose * c.centroid();
        let extent = c.size() + r;
        for i in 0..3 {
            mins[i] = mins[i].min(centre[i] - extent);
            maxs[i] = maxs[i].max(centre[i] + extent);
        }
        return;
    }
    for v in c.vertices() {
        let p = pose * v;
        for i in 0..3 {
            mins[i] = mins[i].min(p[i] - r);
            maxs[i] = maxs[i].max(p[i] + r);
        }
    }
}
