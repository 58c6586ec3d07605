//! `gjkd objects`: what a stopped server's object store holds, and, on the
//! operator's word, the removal of the objects whose registering client
//! process no longer runs.
//!
//! A client may remove only the objects it registered, and its identity is
//! its iceoryx2 node, which a restarted process does not get back. So the
//! objects of a process that died stay forever as far as clients go. This
//! is the operator's way out, with the server stopped (the store's lock
//! keeps the two apart): list them, then remove them explicitly. A server
//! started with `--remove-departed` uses [`alive_nodes`] to do the same
//! while it runs.

use std::fmt::Write as _;

use iceoryx2::node::NodeView;
use iceoryx2::prelude::*;

use crate::engine::records::{
    Snapshot, StoredObject, StoredOwner, StoredPiece, StoredPose, StoredShape,
};
use crate::persist::database::Database;

/// `gjkd objects`: prints the table of the objects stored at `path` and,
/// with `remove`, removes those whose owner is gone, printing their ids.
/// Opening the store does what a server start would: a file of the old
/// format is migrated, a damaged one set aside.
///
/// # Errors
/// When the store cannot be opened (a server holding it included), the
/// iceoryx2 nodes cannot be listed, or the removal cannot be committed.
pub fn run(path: &std::path::Path, remove: bool) -> Result<(), String> {
    let (mut db, opened) = Database::open(path, 1)
        .map_err(|e| format!("{e} (a server using this file must be stopped first)"))?;
    if opened.fresh {
        println!("no objects stored at {}", path.display());
        return Ok(());
    }
    let mut snapshot = opened.snapshot;
    let alive = alive_nodes()?;
    print!("{}", table(&snapshot, &liveness(&snapshot, &alive)));
    if !remove {
        return Ok(());
    }
    let removed = remove_departed(&mut snapshot, &alive);
    if removed.is_empty() {
        println!("no object has an owner that is gone: nothing removed");
        return Ok(());
    }
    let ids: Vec<u64> = removed.iter().map(|o| o.id).collect();
    // Their registration tokens go with them (nobody can retry them).
    let tokens: Vec<_> = db
        .tokens()
        .map_err(|e| e.to_string())?
        .into_iter()
        .filter(|(_, id)| ids.contains(id))
        .map(|(key, _)| key)
        .collect();
    db.remove(&ids, &tokens).map_err(|e| e.to_string())?;
    println!(
        "removed {} object(s) whose owner is gone: {}",
        removed.len(),
        ids.iter()
            .map(|id| format!("{id:#x}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(())
}

/// Whether the client that registered an object still runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Liveness {
    /// A scene object: it has no client.
    Scene,
    /// Its iceoryx2 node is alive (or its state cannot be read: doubt never
    /// counts as gone).
    Running,
    /// Its node is dead or no longer listed at all.
    Gone,
}

/// The liveness of every object of `snapshot`, in its order, as `alive`
/// says of each owner.
pub fn liveness(snapshot: &Snapshot, alive: impl Fn(u128) -> bool) -> Vec<Liveness> {
    snapshot
        .objects
        .iter()
        .map(|o| match o.owner {
            StoredOwner::Scene => Liveness::Scene,
            StoredOwner::Client(c) if alive(c) => Liveness::Running,
            StoredOwner::Client(_) => Liveness::Gone,
        })
        .collect()
}

/// Removes the objects whose owner is gone; returns them. Scene objects and
/// those of running clients stay; the id counter is left alone, so no
/// removed id is ever handed out again.
pub fn remove_departed(snapshot: &mut Snapshot, alive: impl Fn(u128) -> bool) -> Vec<StoredObject> {
    let states = liveness(snapshot, alive);
    let mut removed = Vec::new();
    let mut kept = Vec::with_capacity(snapshot.objects.len());
    for (o, s) in std::mem::take(&mut snapshot.objects)
        .into_iter()
        .zip(states)
    {
        if s == Liveness::Gone {
            removed.push(o);
        } else {
            kept.push(o);
        }
    }
    snapshot.objects = kept;
    removed
}

/// Whether iceoryx2 node `id` still runs on this host: listed as alive, or
/// listed in a state that cannot be read. A node listed as dead, or not
/// listed (cleaned up, or of a process that ended long ago), does not.
///
/// # Errors
/// When the nodes cannot be listed at all: then nothing can be told.
pub fn alive_nodes() -> Result<impl Fn(u128) -> bool, String> {
    let mut alive = std::collections::HashSet::new();
    Node::<ipc::Service>::list(Config::global_config(), |state| {
        match &state {
            NodeState::Alive(view) => {
                alive.insert(view.id().value());
            }
            NodeState::Inaccessible(node) | NodeState::Undefined(node) => {
                alive.insert(node.value());
            }
            NodeState::Dead(_) => {}
        }
        CallbackProgression::Continue
    })
    .map_err(|e| format!("cannot list the iceoryx2 nodes: {e:?}"))?;
    Ok(move |id| alive.contains(&id))
}

/// One line per object: id, owner and whether it runs, name, geometry.
pub fn table(snapshot: &Snapshot, states: &[Liveness]) -> String {
    let mut out = format!(
        "{:<18}  {:<34}  {:<8}  {:<20}  geometry\n",
        "id", "owner (iceoryx2 node)", "owner is", "name"
    );
    for (o, s) in snapshot.objects.iter().zip(states) {
        let owner = match o.owner {
            StoredOwner::Scene => "scene".to_owned(),
            StoredOwner::Client(c) => format!("{c:032x}"),
        };
        let state = match s {
            Liveness::Scene => "-",
            Liveness::Running => "running",
            Liveness::Gone => "gone",
        };
        let geometry = geometry(&o.shape);
        let _ = writeln!(
            out,
            "{:#018x}  {owner:<34}  {state:<8}  {:<20}  {geometry}",
            o.id,
            o.name.as_deref().unwrap_or("-"),
        );
    }
    out
}

/// The geometry column: kind, pieces, vertices, cylinders.
fn geometry(shape: &StoredShape) -> String {
    let cylinders = |p: &[(StoredPose, StoredPiece)]| {
        p.iter()
            .filter(|(_, p)| matches!(p, StoredPiece::Cylinder(_)))
            .count()
    };
    let vertices = |p: &StoredPiece| match p {
        StoredPiece::Hull(c) => c.vertices.len(),
        StoredPiece::Cylinder(_) => 0,
    };
    match shape {
        StoredShape::Convex(c) => format!("convex, {} vertices", c.vertices.len()),
        StoredShape::Compound(p) => format!(
            "compound, {} pieces, {} vertices",
            p.len(),
            p.iter().map(|(_, c)| c.vertices.len()).sum::<usize>()
        ),
        StoredShape::Piece(StoredPiece::Cylinder(c)) => format!(
            "cylinder, radius {}, half-height {}, rounding {}",
            c.radius, c.half_height, c.rounding
        ),
        StoredShape::Piece(StoredPiece::Hull(c)) => {
            format!("convex, {} vertices", c.vertices.len())
        }
        StoredShape::Pieces(p) => format!(
            "compound, {} pieces ({} cylinders), {} vertices",
            p.len(),
            cylinders(p),
            p.iter().map(|(_, c)| vertices(c)).sum::<usize>()
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::records::StoredConvex;

    /// Object `index` of a store of epoch 3.
    fn object(index: u64, owner: StoredOwner, name: Option<&str>) -> StoredObject {
        StoredObject {
            id: 3 << 32 | index,
            owner,
            name: name.map(str::to_owned),
            pose: StoredPose::from_isometry(&nalgebra::Isometry3::identity()),
            shape: StoredShape::Convex(StoredConvex {
                radius: 0.5,
                vertices: vec![[0.0; 3]],
            }),
            slot: index as u32,
        }
    }

    #[test]
    fn only_objects_of_owners_that_are_gone_are_removed() {
        let mut snapshot = Snapshot {
            epoch: 3,
            next_index: 9,
            objects: vec![
                object(1, StoredOwner::Client(7), Some("arm")),
                object(2, StoredOwner::Scene, Some("floor")),
                object(3, StoredOwner::Client(8), None),
                object(4, StoredOwner::Client(7), None),
            ],
        };
        let alive = |c: u128| c == 8;
        assert_eq!(
            liveness(&snapshot, alive),
            [
                Liveness::Gone,
                Liveness::Scene,
                Liveness::Running,
                Liveness::Gone
            ]
        );
        let text = table(&snapshot, &liveness(&snapshot, alive));
        assert_eq!(text.lines().count(), 5);
        assert!(text.contains("arm") && text.contains("gone") && text.contains("scene"));
        let removed = remove_departed(&mut snapshot, alive);
        let index = |o: &StoredObject| o.id as u32;
        assert_eq!(removed.iter().map(index).collect::<Vec<_>>(), [1, 4]);
        assert_eq!(
            snapshot.objects.iter().map(index).collect::<Vec<_>>(),
            [2, 3]
        );
        // Ids are never reused: the counter stays above every removed one.
        assert_eq!((snapshot.epoch, snapshot.next_index), (3, 9));
        assert!(snapshot.validate().is_ok());
        // Nothing else to remove the second time.
        assert!(remove_departed(&mut snapshot, alive).is_empty());
    }

    #[test]
    fn the_table_describes_cylinders() {
        let can: gjk::Shape = gjk::Convex::cylinder(0.5, 2.0, 0.0).expect("valid").into();
        assert_eq!(
            geometry(&StoredShape::from_shape(&can)),
            "cylinder, radius 0.5, half-height 2, rounding 0"
        );
        let pair = gjk::Compound::new(vec![
            (
                nalgebra::Isometry3::identity(),
                gjk::Convex::cylinder(0.5, 2.0, 0.0).expect("valid"),
            ),
            (
                nalgebra::Isometry3::identity(),
                gjk::Convex::sphere(1.0).expect("valid"),
            ),
        ])
        .expect("valid");
        assert_eq!(
            geometry(&StoredShape::from_shape(&pair.into())),
            "compound, 2 pieces (1 cylinders), 1 vertices"
        );
    }
}
