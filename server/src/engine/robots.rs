//! Robots: a kinematic tree attached to the objects that are its links, so
//! that one [`ItemKind::SetJoints`](gjkd_proto::ItemKind::SetJoints) item
//! moves every link.
//!
//! A robot named `R` moves the objects named `R/<link>`; a link with no such
//! object (a link without collision geometry) only carries its children.
//! The objects are registered first, as any others (by the client, or from
//! the scene file), so they are stored and persisted as any others; the
//! robot itself, its kinematics, is held in memory only: after a restart a
//! client attaches it again (its link objects, restored, keep their ids).
//!
//! Robot ids are their own namespace, not object ids.

use std::collections::HashMap;

use gjkd_model::{Kinematics, LimitMode, disabled_pairs};
use gjkd_proto::{ErrorCode, Item, item_flags};
use nalgebra::Isometry3;

use super::checks::check_pose;
use super::objects::{ObjectStore, Owner};

/// Set in every robot id, so that a robot id is never mistaken for an
/// object id in logs.
const ROBOT_ID_BIT: u64 = 1 << 31;

/// One robot.
#[derive(Clone, Debug)]
pub struct Robot {
    /// Its name, the prefix of its links' object names.
    pub name: String,
    /// Its kinematic tree.
    pub kinematics: Kinematics,
    /// The object of each link (in [`Kinematics::link_names`] order), if the
    /// link has one.
    pub links: Vec<Option<u64>>,
    /// Allowed pairs (link indices): the SRDF's `disable_collisions` and the
    /// adjacent links.
    pub allowed: Vec<(usize, usize)>,
    /// Current joint positions (robot joint order).
    pub positions: Vec<f64>,
    /// Current base pose.
    pub base: Isometry3<f64>,
    /// Who attached it.
    pub owner: Owner,
}

/// Every robot the server holds.
#[derive(Debug, Default)]
pub struct Robots {
    by_id: HashMap<u64, Robot>,
    names: HashMap<String, u64>,
    next: u32,
    /// Scratch buffers of forward kinematics, reused from one item to the
    /// next.
    poses: Vec<Isometry3<f64>>,
    positions: Vec<f64>,
}

impl Robots {
    /// The robot with this id.
    pub fn get(&self, id: u64) -> Option<&Robot> {
        self.by_id.get(&id)
    }

    /// The robot and link index whose object `object` is, if any.
    pub fn link_of(&self, object: u64) -> Option<(u64, usize)> {
        self.by_id.iter().find_map(|(&id, robot)| {
            let link = robot.links.iter().position(|l| *l == Some(object))?;
            Some((id, link))
        })
    }

    /// The id of the robot with this name.
    pub fn lookup(&self, name: &str) -> Option<u64> {
        self.names.get(name).copied()
    }

    /// Takes robot `id` out (its link objects are the caller's to
    /// remove).
    pub fn take(&mut self, id: u64) -> Option<Robot> {
        let robot = self.by_id.remove(&id)?;
        self.names.remove(&robot.name);
        Some(robot)
    }

    /// Number of robots.
    pub fn len(&self) -> usize {
        self.by_id.len()
    }

    /// Whether there is no robot.
    pub fn is_empty(&self) -> bool {
        self.by_id.is_empty()
    }

    /// Drops the robots attached by clients for which `alive` is false, and
    /// returns how many: their link objects go with their client (see
    /// [`State::remove_departed`](crate::engine::State::remove_departed)), so their kinematics would only move
    /// nothing while holding their names.
    pub fn drop_departed(&mut self, alive: impl Fn(u128) -> bool) -> usize {
        let before = self.by_id.len();
        self.by_id.retain(|_, r| match r.owner {
            Owner::Client(c) => alive(c),
            Owner::Scene => true,
        });
        let by_id = &self.by_id;
        self.names.retain(|_, id| by_id.contains_key(id));
        before - self.by_id.len()
    }
}

/// What a robot starts as.
#[derive(Clone, Debug)]
pub struct NewRobot<'a> {
    /// Its name.
    pub name: &'a str,
    /// URDF text.
    pub urdf: &'a str,
    /// SRDF text, if any.
    pub srdf: Option<&'a str>,
    /// Base pose.
    pub base: Isometry3<f64>,
    /// Initial joint positions; `None` for zero clamped into the limits.
    pub positions: Option<Vec<f64>>,
    /// Who attaches it.
    pub owner: Owner,
}

impl Robots {
    /// Attaches a robot to its link objects (already in `store`), moves them to
    /// its initial configuration and returns its id. A robot of the same name
    /// is replaced if `owner` attached it (or it came from the scene and so
    /// does this one).
    ///
    /// # Errors
    /// [`ErrorCode::InvalidRobot`] for a malformed URDF or SRDF or an
    /// unsupported tree, [`ErrorCode::NotOwner`] for another owner's robot
    /// name, [`ErrorCode::OutOfLimits`], [`ErrorCode::NonFinitePose`] and
    /// [`ErrorCode::Malformed`] (wrong count) for the initial positions; nothing
    /// is changed then.
    pub fn attach(&mut self, store: &mut ObjectStore, new: NewRobot<'_>) -> Result<u64, ErrorCode> {
        let kinematics = Kinematics::from_urdf_str(new.urdf).map_err(|e| {
            tracing::info!(robot = new.name, "robot refused: {e}");
            ErrorCode::InvalidRobot
        })?;
        let allowed = disabled_pairs(new.srdf, &kinematics, true).map_err(|e| {
            tracing::info!(robot = new.name, "robot refused: {e}");
            ErrorCode::InvalidRobot
        })?;
        if let Some(old) = self.lookup(new.name).and_then(|id| self.get(id))
            && old.owner != new.owner
        {
            return Err(ErrorCode::NotOwner);
        }
        let links = kinematics
            .link_names()
            .iter()
            .map(|link| store.lookup(&format!("{}/{link}", new.name)))
            .collect();
        // Given positions are checked; the default, zero, is clamped into the
        // limits of joints whose range excludes it.
        let mode = if new.positions.is_some() {
            LimitMode::Reject
        } else {
            LimitMode::Clamp
        };
        let mut positions = new.positions.unwrap_or_else(|| vec![0.0; kinematics.dof()]);
        let mut poses = Vec::new();
        kinematics
            .link_poses_into(&new.base, &mut positions, mode, &mut poses)
            .map_err(joint_code)?;
        let robot = Robot {
            name: new.name.to_owned(),
            kinematics,
            links,
            allowed,
            positions,
            base: new.base,
            owner: new.owner,
        };
        store_link_poses(store, &robot.links, &poses)?;
        let epoch = store.id_epoch();
        let robots = self;
        let id = match robots.names.get(new.name) {
            Some(&id) => id,
            None => {
                robots.next += 1;
                let id = epoch | ROBOT_ID_BIT | u64::from(robots.next);
                robots.names.insert(new.name.to_owned(), id);
                id
            }
        };
        robots.by_id.insert(id, robot);
        Ok(id)
    }

    /// Applies one [`ItemKind::SetJoints`](gjkd_proto::ItemKind::SetJoints)
    /// item: checks everything, then stores the robot's new positions, base
    /// and every link's pose; on error nothing changes.
    ///
    /// # Errors
    /// [`ErrorCode::UnknownObject`] for an unknown robot or a link object
    /// removed since, [`ErrorCode::Malformed`] for a count or range outside the
    /// robot's joints, [`ErrorCode::NonFinitePose`] for a NaN position or base,
    /// [`ErrorCode::BadQuaternion`], [`ErrorCode::OutOfLimits`].
    pub fn set_joints(&mut self, store: &mut ObjectStore, item: &Item) -> Result<(), ErrorCode> {
        let values = item.joint_positions().ok_or(ErrorCode::Malformed)?;
        // `b` is no field of a joint update: refused, not ignored.
        if item.b != 0 {
            return Err(ErrorCode::Malformed);
        }
        let robots = &mut *self;
        let robot = robots.by_id.get(&item.a).ok_or(ErrorCode::UnknownObject)?;
        let count = values.len();
        let first = item.joints().first as usize;
        let end = first.checked_add(count).ok_or(ErrorCode::Malformed)?;
        if end > robot.positions.len() {
            return Err(ErrorCode::Malformed);
        }
        let base = if item.flags & item_flags::POSE_A != 0 {
            check_pose(&item.pose_a)?
        } else {
            robot.base
        };
        let mode = if item.flags & item_flags::CLAMP != 0 {
            LimitMode::Clamp
        } else {
            LimitMode::Reject
        };
        let mut positions = std::mem::take(&mut robots.positions);
        positions.clear();
        positions.extend_from_slice(&robot.positions);
        positions[first..end].copy_from_slice(values);
        let mut poses = std::mem::take(&mut robots.poses);
        let computed = robot
            .kinematics
            .link_poses_into(&base, &mut positions, mode, &mut poses)
            .map_err(joint_code);
        let links = robot.links.clone();
        let stored = computed.and_then(|()| store_link_poses(store, &links, &poses));
        let robots = self;
        if stored.is_ok()
            && let Some(robot) = robots.by_id.get_mut(&item.a)
        {
            robot.positions.copy_from_slice(&positions);
            robot.base = base;
        }
        robots.positions = positions;
        robots.poses = poses;
        stored
    }
}

/// Stores each link object's pose, after checking that every one still
/// exists (so that a missing one changes nothing).
fn store_link_poses(
    store: &mut ObjectStore,
    links: &[Option<u64>],
    poses: &[Isometry3<f64>],
) -> Result<(), ErrorCode> {
    if links.iter().flatten().any(|&id| store.object(id).is_none()) {
        return Err(ErrorCode::UnknownObject);
    }
    for (id, pose) in links.iter().zip(poses) {
        if let Some(id) = id {
            store.set_pose(*id, *pose)?;
        }
    }
    Ok(())
}

/// The wire code of a joint error.
pub fn joint_code(e: gjkd_model::JointError) -> ErrorCode {
    use gjkd_model::JointError as J;
    match e {
        J::WrongCount { .. } | J::UnknownJoint(_) => ErrorCode::Malformed,
        J::NotFinite(_) | J::BadBase => ErrorCode::NonFinitePose,
        J::OutOfLimits { .. } => ErrorCode::OutOfLimits,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::state::{Limits, NewObject, State};
    use gjk::{Convex, Shape};
    use gjkd_proto::AdminRequest;
    use gjkd_proto::{
        AdminChunk, AdminOp, ItemResult, ObjectId, QueryOptions, WaitMode, result_flags,
    };
    use nalgebra::{Translation3, UnitQuaternion, Vector3};

    /// Two boxes on a revolute and a prismatic joint, a shapeless tool frame
    /// on a fixed joint, and a mimic finger.
    const URDF: &str = r#"<robot name="two">
      <link name="base"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
      <link name="arm"><collision><origin xyz="0.5 0 0"/><geometry><box size="1 0.1 0.1"/></geometry></collision></link>
      <link name="tool"/>
      <link name="finger"><collision><geometry><sphere radius="0.05"/></geometry></collision></link>
      <joint name="swing" type="revolute"><parent link="base"/><child link="arm"/>
        <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
      <joint name="mount" type="fixed"><parent link="arm"/><child link="tool"/><origin xyz="1 0 0"/></joint>
      <joint name="slide" type="prismatic"><parent link="tool"/><child link="finger"/>
        <axis xyz="1 0 0"/><limit lower="0" upper="0.5" effort="1" velocity="1"/></joint>
      <joint name="twin" type="prismatic"><parent link="arm"/><child link="base_twin"/>
        <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="slide" multiplier="2"/></joint>
      <link name="base_twin"/>
    </robot>"#;

    const CLIENT: u128 = 7;

    fn state_with_links() -> State {
        let mut s = State::new(Limits::default(), WaitMode::Spin, 5);
        insert_links(&mut s, CLIENT);
        let ball = NewObject {
            shape: Shape::Convex(Convex::sphere(0.25).unwrap()),
            pose: Isometry3::translation(0.0, 1.5, 0.1),
            name: Some("ball".into()),
        };
        s.insert(ball, Owner::Scene).unwrap();
        s
    }

    /// Registers the links of `URDF` that have geometry for `owner`;
    /// returns how many.
    fn insert_links(s: &mut State, owner: u128) -> usize {
        let model = gjkd_model::RobotModel::from_urdf_str(URDF, None, &Default::default()).unwrap();
        let mut count = 0;
        for link in &model.links {
            if let Some(shape) = &link.shape {
                let new = NewObject {
                    shape: shape.clone(),
                    pose: Isometry3::identity(),
                    name: Some(format!("two/{}", link.name)),
                };
                s.insert(new, Owner::Client(owner)).unwrap();
                count += 1;
            }
        }
        count
    }

    fn attach_text(s: &mut State, text: &str, who: u128) -> Result<u64, ErrorCode> {
        let mut req = AdminRequest::new(AdminOp::AttachRobot);
        req.set_name("two");
        req.text_len = text.len() as u32;
        let reply = s.handle_admin(who, &req, &AdminChunk::pack_text(text));
        match reply.error_code() {
            ErrorCode::Ok => Ok(reply.id),
            e => Err(e),
        }
    }

    fn one(s: &mut State, item: Item) -> ItemResult {
        let mut out = [ItemResult::error(ErrorCode::Internal)];
        s.handle(CLIENT, &[item], &mut out);
        out[0]
    }

    fn pose_of(s: &State, name: &str) -> Isometry3<f64> {
        s.object(s.lookup(name).unwrap()).unwrap().pose
    }

    #[test]
    fn one_item_moves_every_link_by_forward_kinematics() {
        let mut s = state_with_links();
        let id = attach_text(&mut s, URDF, CLIENT).unwrap();
        let robot = ObjectId::from_raw(id);
        assert_eq!(
            s.robots.get(id).unwrap().kinematics.joint_names(),
            ["swing", "slide"]
        );
        let base = Isometry3::from_parts(
            Translation3::new(1.0, 2.0, 0.0),
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 0.3),
        );
        let q = [0.7, 0.25];
        let r = one(&mut s, Item::set_joints(robot, 0, &q, Some(&base), false));
        assert_eq!(r.error_code(), ErrorCode::Ok);
        // By hand: the arm turns by 0.7 about z, 0.1 above the base; the
        // finger sits 1 + 0.25 along the arm.
        let arm =
            base * Isometry3::translation(0.0, 0.0, 0.1) * Isometry3::rotation(Vector3::z() * 0.7);
        let finger = arm * Isometry3::translation(1.25, 0.0, 0.0);
        assert_eq!(pose_of(&s, "two/base"), base);
        assert!((pose_of(&s, "two/arm").to_homogeneous() - arm.to_homogeneous()).norm() < 1e-12);
        let got = pose_of(&s, "two/finger");
        assert!((got.to_homogeneous() - finger.to_homogeneous()).norm() < 1e-12);
        // A later item may set some joints only, and keep the base.
        let r = one(&mut s, Item::set_joints(robot, 1, &[0.0], None, false));
        assert_eq!(r.error_code(), ErrorCode::Ok);
        let finger = arm * Isometry3::translation(1.0, 0.0, 0.0);
        let got = pose_of(&s, "two/finger");
        assert!((got.to_homogeneous() - finger.to_homogeneous()).norm() < 1e-12);
    }

    #[test]
    fn link_distances_equal_those_at_client_computed_poses() {
        let mut s = state_with_links();
        let robot = ObjectId::from_raw(attach_text(&mut s, URDF, CLIENT).unwrap());
        let kin = s.robots.get(robot.raw()).unwrap().kinematics.clone();
        let (finger, ball) = (s.lookup("two/finger").unwrap(), s.lookup("ball").unwrap());
        let options = QueryOptions::default();
        for step in 0..20 {
            let q = [f64::from(step) * 0.1, 0.02 * f64::from(step)];
            let set = Item::set_joints(robot, 0, &q, None, false);
            let mut out = [ItemResult::default(); 2];
            let query = Item::distance(
                ObjectId::from_raw(finger),
                ObjectId::from_raw(ball),
                &options,
            );
            s.handle(CLIENT, &[set, query], &mut out);
            let poses = kin
                .link_poses(&Isometry3::identity(), &q, LimitMode::Reject)
                .unwrap();
            let by_client = Item::distance_at(
                ObjectId::from_raw(finger),
                &poses[3],
                ObjectId::from_raw(ball),
                &Isometry3::translation(0.0, 1.5, 0.1),
                &QueryOptions::cold(),
            );
            let reference = one(&mut s, by_client);
            assert_eq!(out[1].error_code(), ErrorCode::Ok);
            assert_eq!(out[1].distance, reference.distance, "step {step}");
            if step > 0 {
                assert_ne!(out[1].flags & result_flags::WARM_STARTED, 0);
            }
        }
    }

    #[test]
    fn bad_joint_items_get_their_codes_and_change_nothing() {
        let mut s = state_with_links();
        let robot = ObjectId::from_raw(attach_text(&mut s, URDF, CLIENT).unwrap());
        assert_eq!(
            one(&mut s, Item::set_joints(robot, 0, &[0.5, 0.1], None, false)).error,
            0
        );
        let before: Vec<Isometry3<f64>> = ["two/base", "two/arm", "two/finger"]
            .map(|n| pose_of(&s, n))
            .to_vec();
        let check = |s: &mut State, item: Item, code: ErrorCode| {
            assert_eq!(one(s, item).error_code(), code, "{item:?}");
            let now: Vec<Isometry3<f64>> = ["two/base", "two/arm", "two/finger"]
                .map(|n| pose_of(s, n))
                .to_vec();
            assert_eq!(now, before);
            assert_eq!(s.robots.get(robot.raw()).unwrap().positions, [0.5, 0.1]);
        };
        check(
            &mut s,
            Item::set_joints(robot, 0, &[0.5, 0.6], None, false),
            ErrorCode::OutOfLimits,
        );
        check(
            &mut s,
            Item::set_joints(robot, 0, &[f64::NAN, 0.1], None, false),
            ErrorCode::NonFinitePose,
        );
        check(
            &mut s,
            Item::set_joints(robot, 1, &[0.1, 0.1], None, false),
            ErrorCode::Malformed,
        );
        check(
            &mut s,
            Item::set_joints(robot, u32::MAX, &[0.1], None, false),
            ErrorCode::Malformed,
        );
        let nowhere = ObjectId::from_raw(robot.raw() + 1000);
        check(
            &mut s,
            Item::set_joints(nowhere, 0, &[0.1], None, false),
            ErrorCode::UnknownObject,
        );
        let mut bad_base = Item::set_joints(robot, 0, &[0.1], Some(&Isometry3::identity()), false);
        bad_base.pose_a.rotation = [0.0, 0.0, 0.0, 2.0];
        check(&mut s, bad_base, ErrorCode::BadQuaternion);
        let mut over = Item::set_joints(robot, 0, &[0.1], None, false);
        over.joints_mut().count = 10;
        check(&mut s, over, ErrorCode::Malformed);
        // `b` is no field of a joint update: a non-zero one is refused.
        let mut with_b = Item::set_joints(robot, 0, &[0.1], None, false);
        with_b.b = 1;
        check(&mut s, with_b, ErrorCode::Malformed);
        // No position: the base alone moves (here to where it is), the
        // joints stay.
        let before = s.robots.get(robot.raw()).unwrap().positions.clone();
        let r = one(&mut s, Item::set_joints(robot, 0, &[], None, false));
        assert_eq!(r.error_code(), ErrorCode::Ok);
        assert_eq!(s.robots.get(robot.raw()).unwrap().positions, before);
        // Clamping moves the slide to its upper limit.
        let r = one(&mut s, Item::set_joints(robot, 0, &[0.5, 0.6], None, true));
        assert_eq!(r.error_code(), ErrorCode::Ok);
        assert_eq!(s.robots.get(robot.raw()).unwrap().positions, [0.5, 0.5]);
        // A link object removed: the robot answers unknown object, moves nothing.
        let finger = s.lookup("two/finger").unwrap();
        s.remove(finger, CLIENT).unwrap();
        let arm = pose_of(&s, "two/arm");
        let r = one(&mut s, Item::set_joints(robot, 0, &[0.0, 0.0], None, false));
        assert_eq!(r.error_code(), ErrorCode::UnknownObject);
        assert_eq!(pose_of(&s, "two/arm"), arm);
    }

    #[test]
    fn bad_robots_are_refused_and_change_nothing() {
        let mut s = state_with_links();
        let arm = pose_of(&s, "two/arm");
        assert_eq!(
            attach_text(&mut s, "<robot", CLIENT),
            Err(ErrorCode::InvalidRobot)
        );
        let floating = URDF.replace(r#"type="revolute""#, r#"type="floating""#);
        assert_eq!(
            attach_text(&mut s, &floating, CLIENT),
            Err(ErrorCode::InvalidRobot)
        );
        let srdf =
            format!("{URDF}\0<robot><disable_collisions link1=\"arm\" link2=\"nope\"/></robot>");
        assert_eq!(
            attach_text(&mut s, &srdf, CLIENT),
            Err(ErrorCode::InvalidRobot)
        );
        assert!(s.robots.is_empty());
        assert_eq!(pose_of(&s, "two/arm"), arm);
        // Text that does not unpack.
        let mut req = AdminRequest::new(AdminOp::AttachRobot);
        req.set_name("two");
        req.text_len = 5;
        assert_eq!(
            s.handle_admin(CLIENT, &req, &AdminChunk::pack_text(URDF))
                .error_code(),
            ErrorCode::Malformed
        );
        // A valid robot with an SRDF keeps its allowed pairs; another client
        // cannot take its name.
        let srdf =
            format!("{URDF}\0<robot><disable_collisions link1=\"base\" link2=\"finger\"/></robot>");
        let id = attach_text(&mut s, &srdf, CLIENT).unwrap();
        assert_eq!(
            s.robots.get(id).unwrap().allowed,
            [(0, 1), (0, 3), (1, 2), (1, 4), (2, 3)]
        );
        assert_eq!(
            attach_text(&mut s, URDF, CLIENT + 1),
            Err(ErrorCode::NotOwner)
        );
        assert_eq!(attach_text(&mut s, URDF, CLIENT), Ok(id));
    }

    #[test]
    fn departed_clients_robots_go_with_their_links() {
        let mut s = state_with_links();
        let id = attach_text(&mut s, URDF, CLIENT).unwrap();
        // A living owner keeps its robot.
        let (removed, failed) = s.remove_departed(|c| c == CLIENT);
        assert_eq!((removed.len(), failed), (0, None));
        assert_eq!(s.robots.lookup("two"), Some(id));
        let (removed, failed) = s.remove_departed(|c| c != CLIENT);
        // The three links with geometry, not the scene's ball.
        assert_eq!((removed.len(), failed), (3, None));
        assert!(s.robots.is_empty());
        assert_eq!(s.robots.lookup("two"), None);
        assert!(s.lookup("ball").is_some());
        let r = one(
            &mut s,
            Item::set_joints(ObjectId::from_raw(id), 0, &[0.1], None, false),
        );
        assert_eq!(r.error_code(), ErrorCode::UnknownObject);
        // The name is free again for the next client.
        assert_eq!(insert_links(&mut s, CLIENT + 1), 3);
        assert!(attach_text(&mut s, URDF, CLIENT + 1).is_ok());
    }

    fn remove_robot(s: &mut State, name: &str, who: u128) -> Result<u64, ErrorCode> {
        let mut req = AdminRequest::new(AdminOp::RemoveRobot);
        req.set_name(name);
        let reply = s.handle_admin(who, &req, &[]);
        match reply.error_code() {
            ErrorCode::Ok => Ok(reply.id),
            e => Err(e),
        }
    }

    /// A robot is removed as a whole, by its owner only, all or nothing:
    /// its links, its kinematics and its name go together.
    #[test]
    fn a_robot_is_removed_with_every_link_by_its_owner_only() {
        let mut s = state_with_links();
        let id = attach_text(&mut s, URDF, CLIENT).unwrap();
        let before = s.len();
        let links: Vec<u64> = ["two/base", "two/arm", "two/finger"]
            .iter()
            .map(|n| s.lookup(n).unwrap())
            .collect();
        assert_eq!(
            remove_robot(&mut s, "two", CLIENT + 1),
            Err(ErrorCode::NotOwner)
        );
        assert_eq!(
            remove_robot(&mut s, "nobody", CLIENT),
            Err(ErrorCode::UnknownName)
        );
        assert_eq!(s.len(), before, "nothing removed on refusal");
        assert!(s.robots.get(id).is_some());
        assert_eq!(remove_robot(&mut s, "two", CLIENT), Ok(id));
        assert_eq!(s.len(), before - links.len());
        for l in links {
            assert!(s.object(l).is_none(), "link {l} left behind");
        }
        assert!(s.robots.get(id).is_none());
        assert_eq!(s.robots.lookup("two"), None);
        let r = one(
            &mut s,
            Item::set_joints(ObjectId::from_raw(id), 0, &[0.0, 0.0], None, false),
        );
        assert_eq!(r.error_code(), ErrorCode::UnknownObject);
        assert_eq!(
            remove_robot(&mut s, "two", CLIENT),
            Err(ErrorCode::UnknownName)
        );
        // The scene's ball is untouched; the names are free again.
        assert!(s.lookup("ball").is_some());
        assert_eq!(insert_links(&mut s, CLIENT), 3);
        assert!(attach_text(&mut s, URDF, CLIENT).is_ok());
    }

    /// A link another client registered makes the removal refused whole.
    #[test]
    fn a_robot_with_another_clients_link_is_not_removed_at_all() {
        let mut s = State::new(Limits::default(), WaitMode::Spin, 5);
        insert_links(&mut s, CLIENT + 1);
        let id = attach_text(&mut s, URDF, CLIENT).unwrap();
        let before = s.len();
        assert_eq!(
            remove_robot(&mut s, "two", CLIENT),
            Err(ErrorCode::NotOwner)
        );
        assert_eq!(s.len(), before);
        assert!(s.robots.get(id).is_some());
    }
}
