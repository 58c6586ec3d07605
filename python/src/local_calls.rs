//! `gjkd.Local`'s robot and scene calls: the requests the Rust client sends
//! a server for `register_robot_text`, `open_robot`, `remove_robot`,
//! `set_joints_with` and `scene_with`, built with the client's and the
//! protocol's own builders (`Geometry::encode`, `RobotHandle::joint_items`,
//! `AdminChunk::pack_text`, `SceneSummary::new`) and answered by the
//! server's engine in this process. A refusal comes back as the
//! `ClientError` the Rust client returns for it, so that Python raises the
//! same exception from `Local` as from `Client`.

use gjk::Shape;
use gjkd_client::{
    ClientError, Kinematics, LimitMode, ObjectId, RobotHandle, RobotModel, SceneSummary,
    with_geometry,
};
use gjkd_proto::{
    AdminChunk, AdminOp, AdminRequest, ErrorCode, Item, ItemResult, PathMode, Pose, SceneRequest,
    SceneRow, lookup_kind,
};
use nalgebra::Isometry3;

use crate::backend::RobotText;
use crate::server_lib::Store;

/// Buffers of scene questions, kept from one call to the next.
#[derive(Default)]
pub struct SceneScratch {
    items: Vec<Item>,
    rows: Vec<SceneRow>,
    results: Vec<ItemResult>,
}

/// A robot that cannot be read, with the model's words (as the client).
fn robot_err(e: impl std::fmt::Display) -> ClientError {
    ClientError::InvalidRobot(e.to_string())
}

/// The client's refusal of a name it cannot send.
const NAME_TOO_LONG: ClientError = ClientError::InvalidArgument("name longer than MAX_NAME_LEN");

/// An admin request about the object or robot named `name`.
fn named(op: AdminOp, name: &str) -> Result<AdminRequest, ClientError> {
    let mut request = AdminRequest::new(op);
    if !request.set_name(name) {
        return Err(NAME_TOO_LONG);
    }
    Ok(request)
}

/// Answers `request` (with its payload), as the client's admin round trip.
fn admin(
    store: &mut Store,
    request: &AdminRequest,
    payload: &[AdminChunk],
) -> Result<u64, ClientError> {
    store.admin(request, payload).map_err(ClientError::Rejected)
}

/// Registers a link's shape as the object `name`, at the identity.
fn register_link(store: &mut Store, name: &str, shape: &Shape) -> Result<u64, ClientError> {
    let mut request = named(AdminOp::Register, name)?;
    let mut vertices = Vec::new();
    with_geometry(shape, |g| g.encode(&mut request, &mut vertices))
        .map_err(|e| ClientError::InvalidArgument(e.describe()))?;
    admin(store, &request, AdminChunk::from_vertices(&vertices))
}

/// The handle of robot `id`: its links' objects (by name, as the client
/// finds them) and its joints at zero within their limits.
fn handle(
    store: &Store,
    id: u64,
    name: &str,
    kinematics: Kinematics,
) -> Result<RobotHandle, ClientError> {
    let links = kinematics
        .link_names()
        .iter()
        .map(|link| {
            store
                .lookup(&format!("{name}/{link}"))
                .map(ObjectId::from_raw)
        })
        .collect();
    let mut positions = vec![0.0; kinematics.dof()];
    kinematics
        .check_positions(&mut positions, LimitMode::Clamp)
        .map_err(robot_err)?;
    Ok(RobotHandle {
        id: ObjectId::from_raw(id),
        name: name.to_owned(),
        kinematics,
        links,
        positions,
    })
}

/// Registers a robot's links, then attaches its kinematics; on a failure
/// the links registered so far are removed again (as the client does).
pub fn register_robot(
    store: &mut Store,
    robot: &RobotText<'_>,
) -> Result<RobotHandle, ClientError> {
    let model = RobotModel::from_urdf_str(robot.urdf, robot.mesh_base, robot.packages)
        .map_err(robot_err)?;
    gjkd_model::disabled_pairs(robot.srdf, &model.kinematics, true).map_err(robot_err)?;
    let mut registered = Vec::new();
    let outcome = (|| {
        for link in &model.links {
            let Some(shape) = &link.shape else { continue };
            let object = format!("{}/{}", robot.name, link.name);
            registered.push(register_link(store, &object, shape)?);
        }
        attach_robot(store, robot.name, robot.urdf, robot.srdf, robot.base)
    })();
    if outcome.is_err() {
        for id in registered {
            let mut request = AdminRequest::new(AdminOp::Remove);
            request.object = id;
            let _ = store.admin(&request, &[]);
        }
    }
    let id = outcome?;
    handle(store, id, robot.name, model.kinematics)
}

/// Attaches a robot's kinematics (URDF, and SRDF after a NUL, as the
/// server reads them) to its link objects, at `base`.
fn attach_robot(
    store: &mut Store,
    name: &str,
    urdf: &str,
    srdf: Option<&str>,
    base: &Isometry3<f64>,
) -> Result<u64, ClientError> {
    let text = match srdf {
        Some(srdf) => format!("{urdf}\0{srdf}"),
        None => urdf.to_owned(),
    };
    let mut request = named(AdminOp::AttachRobot, name)?;
    request.text_len = u32::try_from(text.len())
        .map_err(|_| ClientError::InvalidArgument("robot text longer than 4 GiB"))?;
    request.pose = Pose::from_isometry(base);
    admin(store, &request, &AdminChunk::pack_text(&text))
}

/// The robot named `name`, read with its URDF text.
pub fn open_robot(store: &mut Store, name: &str, urdf: &str) -> Result<RobotHandle, ClientError> {
    let kinematics = Kinematics::from_urdf_str(urdf).map_err(robot_err)?;
    let mut request = named(AdminOp::Lookup, name)?;
    request.lookup = lookup_kind::ROBOT;
    let id = admin(store, &request, &[])?;
    handle(store, id, name, kinematics)
}

/// Removes the robot named `name` with every link.
pub fn remove_robot(store: &mut Store, name: &str) -> Result<(), ClientError> {
    admin(store, &named(AdminOp::RemoveRobot, name)?, &[]).map(|_| ())
}

/// Sets every joint of `robot` (and its base) with the client's joint
/// items and its reading of their results.
pub fn set_joints(
    store: &mut Store,
    scratch: &mut SceneScratch,
    robot: &mut RobotHandle,
    positions: &[f64],
    base: Option<&Isometry3<f64>>,
    mode: LimitMode,
) -> Result<(), ClientError> {
    let items = robot.set_joints_items(positions, base, mode)?;
    scratch.results.clear();
    scratch.results.resize(items.len(), ItemResult::default());
    store.handle(&items, &mut scratch.results);
    Ok(robot.joints_answered(positions, &scratch.results)?)
}

/// Answers a scene question. A question about one moment is held to the
/// server's limits (items and rows of one request) as a server holds it;
/// a path is answered in one go, whole, as the client's transparent split
/// of a long path returns it.
pub fn scene(
    store: &mut Store,
    scratch: &mut SceneScratch,
    request: &SceneRequest,
    count: usize,
    item: &mut dyn FnMut(usize) -> Item,
    read: &mut dyn FnMut(&[SceneRow]),
) -> Result<SceneSummary, ClientError> {
    let mut room = request.max_rows as usize;
    if request.path == PathMode::Single as u32 {
        let limits = store.limits();
        if count > limits.max_batch {
            return Err(ClientError::Rejected(ErrorCode::BatchTooLarge));
        }
        room = room.min(limits.max_rows);
    }
    scratch.items.clear();
    scratch.items.extend((0..count).map(item));
    if scratch.rows.len() < room {
        scratch.rows.resize(room, SceneRow::default());
    }
    let reply = store.scene(request, &scratch.items, &mut scratch.rows[..room]);
    match reply.error_code() {
        ErrorCode::Ok => {}
        code => return Err(ClientError::Rejected(code)),
    }
    let written = usize::try_from(reply.total).map_or(room, |t| t.min(room));
    read(&scratch.rows[..written]);
    Ok(SceneSummary::new(&reply, written))
}
