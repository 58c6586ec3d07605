//! The objects as the server stores them: plain, serde-encodable images of
//! the in-memory objects (postcard inside the database's values, see
//! [`crate::persist::database`]), and the checks every loaded object must pass.
//!
//! A loaded object is held to the rules of a registration (geometry, pose,
//! name) and of the store (id of its epoch and below the counter, unique
//! ids, names and journal slots), so that what was never accepted cannot
//! come back from a file either.

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

/// An exact cylinder as stored: its dimensions, as registered.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StoredCylinder {
    /// Radius of the disk.
    pub radius: f64,
    /// Half its length along the piece's z axis.
    pub half_height: f64,
    /// Rounding radius.
    pub rounding: f64,
}

/// A convex piece of any kind, as stored by the shapes added with
/// cylinders ([`StoredShape::Piece`], [`StoredShape::Pieces`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum StoredPiece {
    /// A hull of vertices grown by a radius.
    Hull(StoredConvex),
    /// An exact cylinder.
    Cylinder(StoredCylinder),
}

/// A shape as stored.
///
/// postcard writes a variant as its position, so variants are only ever
/// added at the end: a store written before cylinders holds only the first
/// two and still loads. A shape without a cylinder is still written with
/// those two, so a store without cylinders stays readable by a server
/// older than them; only a shape holding a cylinder takes the last two.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum StoredShape {
    /// One convex hull.
    Convex(StoredConvex),
    /// Hulls with their offsets, in registration order.
    Compound(Vec<(StoredPose, StoredConvex)>),
    /// One piece of any kind (a cylinder: a hull is written as `Convex`).
    Piece(StoredPiece),
    /// Pieces of any kind with their offsets, in registration order (a
    /// compound with at least one cylinder).
    Pieces(Vec<(StoredPose, StoredPiece)>),
}

impl StoredPiece {
    /// The stored form of `c`.
    fn of(c: &Convex) -> Self {
        match c.cylinder_dimensions() {
            Some((radius, half_height)) => StoredPiece::Cylinder(StoredCylinder {
                radius,
                half_height,
                rounding: c.radius(),
            }),
            None => StoredPiece::Hull(StoredConvex {
                radius: c.radius(),
                vertices: c.vertices().iter().map(|p| [p.x, p.y, p.z]).collect(),
            }),
        }
    }

    /// The piece, with the checks of a registration.
    fn to_convex(&self) -> Result<Convex, String> {
        match self {
            StoredPiece::Hull(c) => {
                let points: Vec<Point3<f64>> = c.vertices.iter().map(|&v| v.into()).collect();
                Convex::new(points, c.radius).map_err(|e| e.to_string())
            }
            StoredPiece::Cylinder(c) => {
                crate::engine::checks::cylinder(c.radius, c.half_height, c.rounding)
                    .map_err(|e| format!("cylinder {c:?}: {e}"))
            }
        }
    }
}

impl StoredShape {
    /// The stored form of `shape`: the old variants unless it holds a
    /// cylinder.
    pub fn from_shape(shape: &Shape) -> Self {
        let hull = |p: StoredPiece| match p {
            StoredPiece::Hull(c) => Ok(c),
            cylinder => Err(cylinder),
        };
        match shape {
            Shape::Convex(c) => match hull(StoredPiece::of(c)) {
                Ok(c) => StoredShape::Convex(c),
                Err(p) => StoredShape::Piece(p),
            },
            Shape::Compound(c) => {
                let pieces: Vec<(StoredPose, StoredPiece)> = c
                    .pieces()
                    .iter()
                    .map(|(o, p)| (StoredPose::from_isometry(o), StoredPiece::of(p)))
                    .collect();
                if pieces
                    .iter()
                    .all(|(_, p)| matches!(p, StoredPiece::Hull(_)))
                {
                    StoredShape::Compound(
                        pieces
                            .into_iter()
                            .filter_map(|(o, p)| hull(p).ok().map(|c| (o, c)))
                            .collect(),
                    )
                } else {
                    StoredShape::Pieces(pieces)
                }
            }
        }
    }

    /// Rebuilds the shape with the same checks as a registration.
    ///
    /// # Errors
    /// A description of what is wrong.
    pub fn to_shape(&self) -> Result<Shape, String> {
        match self {
            StoredShape::Convex(c) => Ok(StoredPiece::Hull(c.clone()).to_convex()?.into()),
            StoredShape::Piece(p) => Ok(p.to_convex()?.into()),
            StoredShape::Compound(pieces) => compound(
                pieces
                    .iter()
                    .map(|(o, c)| (o, StoredPiece::Hull(c.clone()).to_convex())),
                pieces.len(),
            ),
            StoredShape::Pieces(pieces) => {
                compound(pieces.iter().map(|(o, p)| (o, p.to_convex())), pieces.len())
            }
        }
    }
}

/// The compound of `len` stored pieces, with the checks of a registration.
fn compound<'a>(
    pieces: impl Iterator<Item = (&'a StoredPose, Result<Convex, String>)>,
    len: usize,
) -> Result<Shape, String> {
    if len > gjkd_proto::MAX_PIECES {
        return Err(format!("compound of {len} pieces"));
    }
    let pieces = pieces
        .map(|(o, c)| Ok((o.to_isometry().ok_or("bad piece offset")?, c?)))
        .collect::<Result<Vec<_>, String>>()?;
    Ok(Compound::new(pieces).map_err(|e| e.to_string())?.into())
}

/// Who owns a stored object; mirrors [`crate::engine::state::Owner`].
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
    /// Its slot in the pose journal ([`crate::persist::journal`]).
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

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn decode(hex: &str) -> StoredObject {
        let bytes: Vec<u8> = (0..hex.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).expect("hex"))
            .collect();
        match postcard::take_from_bytes(&bytes) {
            Ok((o, [])) => o,
            other => panic!("does not decode whole: {other:?}"),
        }
    }

    /// Objects exactly as a server before cylinders wrote them (postcard
    /// bytes captured from that version): a compound of a ball and a
    /// segment, and a convex ball owned by the scene. They still load,
    /// and are written back byte for byte as before.
    #[test]
    fn objects_written_before_cylinders_still_load() {
        let compound = "8380808070010501036f6c64000000000000f03f00000000000000c0000000000000e03f000000000000000000000000000000000000000000000000000000000000f03f0102000000000000f03f00000000000000c0000000000000e03f000000000000000000000000000000000000000000000000000000000000f03f000000000000d03f01000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000f03f000000000000000002000000000000f03f000000000000000000000000000000000000000000000000000000000000f03f000000000000000002";
        let convex = "83808080700000000000000000f03f00000000000000c0000000000000e03f000000000000000000000000000000000000000000000000000000000000f03f00000000000000e03f0100000000000000000000000000000000000000000000f03f02";
        for (hex, pieces) in [(compound, 2), (convex, 1)] {
            let o = decode(hex);
            check_object(7, &o).expect("valid");
            let shape = o.shape.to_shape().expect("loads");
            assert_eq!(shape.piece_count(), pieces);
            assert_eq!(StoredShape::from_shape(&shape), o.shape);
            let again = postcard::to_stdvec(&o).expect("encodes");
            let again: String = again.iter().map(|b| format!("{b:02x}")).collect();
            assert_eq!(again, hex);
        }
        let o = decode(compound);
        assert_eq!((o.id, o.slot), ((7 << 32) | 3, 2));
        assert_eq!(o.name.as_deref(), Some("old"));
        let Shape::Compound(c) = o.shape.to_shape().expect("loads") else {
            panic!("not a compound");
        };
        assert_eq!(c.pieces()[0].1.radius(), 0.25);
        assert_eq!(c.pieces()[1].1.vertices().len(), 2);
    }

    /// A cylinder, alone or in a compound, round-trips through postcard to
    /// the same shape; a shape without one keeps the old variants.
    #[test]
    fn cylinders_round_trip_and_hulls_keep_the_old_form() {
        let can = Convex::cylinder(0.5, 2.0, 0.125).expect("valid");
        let ball = Convex::sphere(0.3).expect("valid");
        let offset = Isometry3::new(Vector3::new(1.0, 2.0, 3.0), Vector3::new(0.1, 0.2, 0.3));
        let shapes: [Shape; 3] = [
            can.clone().into(),
            Compound::new(vec![
                (offset, can.clone()),
                (Isometry3::identity(), ball.clone()),
            ])
            .expect("valid")
            .into(),
            Compound::new(vec![(offset, ball)]).expect("valid").into(),
        ];
        for (shape, kind) in shapes.iter().zip([2u8, 3, 1]) {
            let stored = StoredShape::from_shape(shape);
            let bytes = postcard::to_stdvec(&stored).expect("encodes");
            assert_eq!(bytes[0], kind, "{stored:?}");
            let back: StoredShape = postcard::from_bytes(&bytes).expect("decodes");
            assert_eq!(&back.to_shape().expect("valid"), shape);
        }
    }

    /// A stored cylinder is held to a registration's rules.
    #[test]
    fn bad_stored_cylinders_are_refused() {
        for (radius, half_height, rounding) in [
            (-1.0, 1.0, 0.0),
            (1.0, f64::NAN, 0.0),
            (1.0, 1.0, -0.5),
            (4e300, 4e300, 0.0),
        ] {
            let c = StoredCylinder {
                radius,
                half_height,
                rounding,
            };
            assert!(
                StoredShape::Piece(StoredPiece::Cylinder(c))
                    .to_shape()
                    .is_err()
            );
            let pose = StoredPose::from_isometry(&Isometry3::identity());
            let pieces = StoredShape::Pieces(vec![(pose, StoredPiece::Cylinder(c))]);
            assert!(pieces.to_shape().is_err(), "{c:?}");
        }
    }
}
