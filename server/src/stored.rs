//! The objects as the server stores them: plain, serde-encodable images of
//! the in-memory objects (postcard inside the database's values, see
//! [`crate::database`]), and the checks every loaded object must pass.
//!
//! A loaded object is held to the rules of a registration (geometry, pose,
//! name) and of the store (id of its epoch and below the counter, unique
//! ids, names and journal slots), so that what was never accepted cannot
//! come back from a file either.

use std::path::PathBuf;

use gjk::{Compound, Convex, Shape};
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion};
use serde::{Deserialize, Serialize};

/// Journal slots above this are refused on load (a journal of 4 Mi slots
/// is 288 MiB; the default object limit is 1 Mi).
pub const MAX_SLOTS: u32 = 1 << 22;

/// A pose as stored: translation and quaternion `[i, j, k, w]`, exactly the
/// bits of the in-memory isometry.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StoredPose {
    /// Translation.
    pub translation: [f64; 3],
    /// Unit quaternion `[i, j, k, w]`.
    pub rotation: [f64; 4],
}

impl StoredPose {
    /// The stored form of `iso`, bit for bit.
    pub fn from_isometry(iso: &Isometry3<f64>) -> Self {
        let t = iso.translation.vector;
        let q = iso.rotation.coords;
        StoredPose {
            translation: [t.x, t.y, t.z],
            rotation: [q.x, q.y, q.z, q.w],
        }
    }

    /// The isometry with exactly these bits, if finite and of unit length to
    /// round-off (what the server stored was checked on the way in, so
    /// anything else is corruption).
    pub fn to_isometry(&self) -> Option<Isometry3<f64>> {
        if !self
            .translation
            .iter()
            .chain(&self.rotation)
            .all(|c| c.is_finite())
        {
            return None;
        }
        let [i, j, k, w] = self.rotation;
        let q = Quaternion::new(w, i, j, k);
        if (q.norm() - 1.0).abs() > 1e-9 {
            return None;
        }
        let [x, y, z] = self.translation;
        Some(Isometry3::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::new_unchecked(q),
        ))
    }
}

/// A convex piece as stored: the vertices as registered (their order is
/// kept, so answers after a reload equal the ones before bit for bit) and the
/// radius.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StoredConvex {
    /// Rounding radius.
    pub radius: f64,
    /// Vertices in the body frame, in registration order.
    pub vertices: Vec<[f64; 3]>,
}

/// A shape as stored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum StoredShape {
    /// One convex piece.
    Convex(StoredConvex),
    /// Pieces with their offsets, in registration order.
    Compound(Vec<(StoredPose, StoredConvex)>),
}

impl StoredShape {
    /// The stored form of `shape`.
    pub fn from_shape(shape: &Shape) -> Self {
        fn convex(c: &Convex) -> StoredConvex {
            StoredConvex {
                radius: c.radius(),
                vertices: c.vertices().iter().map(|p| [p.x, p.y, p.z]).collect(),
            }
        }
        match shape {
            Shape::Convex(c) => StoredShape::Convex(convex(c)),
            Shape::Compound(c) => StoredShape::Compound(
                c.pieces()
                    .iter()
                    .map(|(o, p)| (StoredPose::from_isometry(o), convex(p)))
                    .collect(),
            ),
        }
    }

    /// Rebuilds the shape with the same checks as a registration.
    ///
    /// # Errors
    /// A description of what is wrong.
    pub fn to_shape(&self) -> Result<Shape, String> {
        fn convex(c: &StoredConvex) -> Result<Convex, String> {
            let points: Vec<Point3<f64>> = c.vertices.iter().map(|&v| v.into()).collect();
            Convex::new(points, c.radius).map_err(|e| e.to_string())
        }
        match self {
            StoredShape::Convex(c) => Ok(convex(c)?.into()),
            StoredShape::Compound(pieces) => {
                if pieces.len() > gjkd_proto::MAX_PIECES {
                    return Err(format!("compound of {} pieces", pieces.len()));
                }
                let pieces = pieces
                    .iter()
                    .map(|(o, c)| {
                        let offset = o.to_isometry().ok_or("bad piece offset")?;
                        Ok((offset, convex(c)?))
                    })
                    .collect::<Result<Vec<_>, String>>()?;
                Ok(Compound::new(pieces).map_err(|e| e.to_string())?.into())
            }
        }
    }
}

/// Who owns a stored object; mirrors [`crate::state::Owner`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum StoredOwner {
    /// Loaded from the scene file.
    Scene,
    /// Registered by the client whose iceoryx2 node has this id.
    Client(u128),
}

/// One object as stored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StoredObject {
    /// Its id, kept across restarts.
    pub id: u64,
    /// Its owner.
    pub owner: StoredOwner,
    /// Its name, if any.
    pub name: Option<String>,
    /// Its stored pose at the time of the write.
    pub pose: StoredPose,
    /// Its geometry.
    pub shape: StoredShape,
    /// Its slot in the pose journal ([`crate::journal`]).
    pub slot: u32,
}

/// Everything the store holds: the id counter and the objects.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// Upper 32 bits of every id of this store.
    pub epoch: u32,
    /// Lower 32 bits of the next id to hand out: above every id ever handed
    /// out, removed ones included, so ids are never reused across restarts.
    pub next_index: u32,
    /// The objects, in id order.
    pub objects: Vec<StoredObject>,
}

impl Snapshot {
    /// Checks what the database's own checksums cannot: that every id belongs to this
    /// store's epoch and lies below the counter, that ids, names and journal
    /// slots are unique, and that every shape and pose passes the
    /// registration checks.
    ///
    /// # Errors
    /// A description of the first problem.
    pub fn validate(&self) -> Result<(), String> {
        if self.epoch == 0 {
            return Err("epoch 0".into());
        }
        for o in &self.objects {
            check_object(self.epoch, o)?;
            if o.id as u32 >= self.next_index {
                return Err(format!("id {:#x} outside this store", o.id));
            }
        }
        check_unique(self.objects.iter())
    }
}

/// The checks of one object that need no other object: its id is of
/// `epoch` and could have been handed out, its slot, name, pose and geometry
/// are what a registration accepts. Shared by the database and the migration
/// of the old format, so an object is held to the same rules wherever it came from.
pub(crate) fn check_object(epoch: u32, o: &StoredObject) -> Result<(), String> {
    // Slots are reused after removals, so they stay below the peak number
    // of objects; one past MAX_SLOTS could only come from a buggy writer,
    // and would size the journal absurdly.
    if o.slot >= MAX_SLOTS {
        return Err(format!("bad journal slot {}", o.slot));
    }
    // Index u32::MAX is never handed out: the counter stops below it.
    let (id_epoch, index) = ((o.id >> 32) as u32, o.id as u32);
    if id_epoch != epoch || index == 0 || index == u32::MAX {
        return Err(format!("id {:#x} outside this store", o.id));
    }
    if let Some(name) = &o.name
        && (name.is_empty() || name.len() > gjkd_proto::MAX_NAME_LEN)
    {
        return Err(format!("bad name {name:?}"));
    }
    o.pose
        .to_isometry()
        .ok_or_else(|| format!("bad pose of {:#x}", o.id))?;
    o.shape
        .to_shape()
        .map_err(|e| format!("object {:#x}: {e}", o.id))?;
    Ok(())
}

/// Ids, names and journal slots are each unique among `objects`.
pub(crate) fn check_unique<'a>(
    objects: impl Iterator<Item = &'a StoredObject>,
) -> Result<(), String> {
    let mut ids = std::collections::HashSet::new();
    let mut names = std::collections::HashSet::new();
    let mut slots = std::collections::HashSet::new();
    for o in objects {
        if !ids.insert(o.id) {
            return Err(format!("id {:#x} twice", o.id));
        }
        if !slots.insert(o.slot) {
            return Err(format!("repeated journal slot {}", o.slot));
        }
        if let Some(name) = &o.name
            && !names.insert(name.as_str())
        {
            return Err(format!("repeated name {name:?}"));
        }
    }
    Ok(())
}

/// The default store file of `service`:
/// `${XDG_STATE_HOME:-$HOME/.local/state}/gjkd/<service>.objects`, with `/`
/// in the service name replaced by `_`. `None` when neither variable is set.
pub fn default_path(service: &str) -> Option<PathBuf> {
    let base = std::env::var_os("XDG_STATE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| {
            std::env::var_os("HOME")
                .filter(|v| !v.is_empty())
                .map(|h| PathBuf::from(h).join(".local").join("state"))
        })?;
    let file: String = service
        .chars()
        .map(|c| if c == '/' || c == '\0' { '_' } else { c })
        .collect();
    Some(base.join("gjkd").join(format!("{file}.objects")))
}
