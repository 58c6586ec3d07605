//! The group queries: questions about a group of objects against everything
//! stored ([`SceneRequest`]s: clearance, within, nearest, path; the scene
//! service carries them), answered in-process against the store, with a broadphase ([`Broadphase`]:
//! parry3d-f64's BVH over one box per object, following the store's
//! changes) and certified motion bounds (each pair's last certified
//! interval, kept with its warm start in the [`cache`](crate::engine::warm_cache) and
//! widened by how far either object can have moved since). The iceoryx2
//! port calls [`State::scene`].
//!
//! ```
//! use gjkd_server::engine::{Limits, State};
//! use gjkd_proto::{AdminChunk, AdminOp, AdminRequest, SceneKind, SceneRequest, SceneRow, Vertex, WaitMode,
//!     shape_kind};
//!
//! let mut state = State::new(Limits::default(), WaitMode::Spin, 1);
//! let mut reg = AdminRequest::new(AdminOp::Register);
//! reg.shape = shape_kind::CONVEX;
//! reg.piece_count = 1;
//! reg.pieces[0].vertex_count = 1;
//! reg.pieces[0].rounding = 0.5;
//! let ball = state.handle_admin(1, &reg, AdminChunk::from_vertices(&[Vertex::default()])).id;
//! for x in [3.0, 5.0] {
//!     state.handle_admin(1, &reg, AdminChunk::from_vertices(&[Vertex { x, y: 0.0, z: 0.0 }]));
//! }
//! // The object nearest to the ball, with its certified interval.
//! let request = SceneRequest::new(SceneKind::Clearance, ball);
//! let mut rows = [SceneRow::default(); 4];
//! let reply = state.scene(42, &request, &[], &mut rows);
//! assert_eq!((reply.error, reply.total), (0, 1));
//! let row = rows[0].result;
//! assert!(row.lower <= 2.0 && 2.0 <= row.upper);
//! ```

mod advance;
mod broadphase;
mod clearance;
mod continuous;
mod entry;
mod gradients;
mod groups;
mod motion_bound;
mod nearest;
mod pair;
mod path;
mod rows;
mod within;

#[cfg(test)]
mod tests;

use gjkd_proto::{
    ErrorCode, Item, ItemKind, ItemResult, PathMode, SceneKind, SceneReply, SceneRequest, SceneRow,
    item_flags, scene_flags, scene_reply_flags,
};
use nalgebra::Isometry3;
use std::collections::HashMap;

use crate::engine::gradient::{LinkPoses, StepConfigurations};
use crate::engine::warm_cache::FxBuild;

use advance::Lookahead;
pub use broadphase::Broadphase;
use groups::Group;
use pair::Ctx;
use path::{RobotOverlay, item_poses};
use rows::Rows;
use within::Partners;

use crate::engine::state::State;

/// A request's question, checked.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Question {
    kind: SceneKind,
    mode: PathMode,
    /// The margin (within) or cut-off.
    pub margin: f64,
    /// [`scene_flags::CUTOFF`].
    pub cutoff: bool,
    all_pairs: bool,
    /// [`scene_flags::SELF_PAIRS`].
    self_pairs: bool,
    /// [`scene_flags::MOTION_BOUNDS`].
    pub motion: bool,
    /// [`scene_flags::EXACT`]: every reported row converged (no early exit,
    /// no row from motion bounds; bounds still rule pairs out).
    pub exact: bool,
    /// [`scene_flags::WARM_START`].
    pub warm: bool,
    clamp: bool,
    /// [`scene_flags::LINEAR_QUATERNION`].
    linear_quaternion: bool,
    /// [`SceneRequest::bracket`].
    bracket: f64,
    /// Every pair query's options (the margin set per question).
    pub options: gjk::Options,
    /// The accepted absolute width of a motion bound.
    pub accept_absolute: f64,
    /// The accepted relative width of a motion bound.
    pub accept_relative: f64,
    k: usize,
    /// [`scene_flags::GRADIENTS`].
    gradients: bool,
    /// [`scene_flags::GRADIENT_BASE`].
    gradient_base: bool,
    /// [`scene_flags::SIGNED_DISTANCE`].
    signed: bool,
}

/// What a request cost, for the reply.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Counters {
    /// Pair queries that ran GJK.
    pub gjk_runs: u64,
    /// Pairs answered or ruled out by motion bounds alone.
    pub bounded: u64,
    /// Pairs the broadphase could not rule out.
    pub candidates: u64,
}

/// The engine's state: the broadphase and the buffers reused from one
/// request to the next.
#[derive(Debug, Default)]
pub struct GroupQueries {
    broadphase: Broadphase,
    group: Group,
    overlay: RobotOverlay,
    poses: Vec<(u64, Isometry3<f64>)>,
    /// Slots a path moved, to put back.
    touched: Vec<u32>,
    /// A path's moves, in order: slot and pose.
    plan: Vec<(u32, Isometry3<f64>)>,
    /// Per step of a path, the end of its moves in `plan`.
    plan_ends: Vec<usize>,
    /// Per member, its lookahead along a path ([`advance`]).
    lookahead: Vec<Lookahead>,
    found: Vec<(u32, ItemResult)>,
    /// Clearance's candidates answered from accepted motion bounds.
    approximate: Vec<(u32, f64)>,
    /// Each (client, member)'s nearest object at its last clearance, tried
    /// first the next time.
    nearest: HashMap<(u128, u64), u64, FxBuild>,
    /// Robot link poses of the rows' gradients.
    link_poses: LinkPoses,
    /// Where a path's robots stand at each step, for the rows' gradients.
    step_configurations: StepConfigurations,
}

/// Most remembered nearest objects; beyond, the memory starts over.
const MAX_REMEMBERED: usize = 1 << 16;

impl GroupQueries {
    /// The broadphase (as of the last scene request).
    pub fn broadphase(&self) -> &Broadphase {
        &self.broadphase
    }

    /// Forgets the remembered nearest objects of every client for which
    /// `alive` is false: a departed client's members are never asked again.
    pub fn retain_clients(&mut self, alive: impl Fn(u128) -> bool) {
        self.nearest.retain(|&(client, _), _| alive(client));
    }
}

/// Checks a request's header.
///
/// # Errors
/// [`ErrorCode::Malformed`] for an unknown kind, path mode or flag, a
/// first-hit or continuous path of another kind than within, linear
/// quaternions outside a continuous path, the group's own pairs asked of
/// nearest, signed distances asked of a continuous path; [`ErrorCode::InvalidOptions`]
/// for a margin, tolerance or accuracy that is not a finite number `>= 0`,
/// no iterations, `k = 0` for nearest, or a continuous path's bracket that
/// is not a finite number `> 0`.
fn decode(r: &SceneRequest) -> Result<Question, ErrorCode> {
    let kind = r.scene_kind().ok_or(ErrorCode::Malformed)?;
    let mode = r.path_mode().ok_or(ErrorCode::Malformed)?;
    let within_only = matches!(mode, PathMode::FirstHit | PathMode::Continuous);
    let linear_quaternion = r.flags & scene_flags::LINEAR_QUATERNION != 0;
    if r.flags & !scene_flags::ALL != 0
        || (within_only && kind != SceneKind::Within)
        || (linear_quaternion && mode != PathMode::Continuous)
        || (r.flags & scene_flags::SELF_PAIRS != 0 && kind == SceneKind::Nearest)
        || (r.flags & scene_flags::SIGNED_DISTANCE != 0 && mode == PathMode::Continuous)
    {
        return Err(ErrorCode::Malformed);
    }
    if mode == PathMode::Continuous && !(r.bracket > 0.0 && r.bracket <= f64::MAX) {
        return Err(ErrorCode::InvalidOptions);
    }
    let number = |x: f64| (0.0..=f64::MAX).contains(&x);
    if ![r.margin, r.tolerance, r.accept_absolute, r.accept_relative]
        .into_iter()
        .all(number)
        || r.max_iterations == 0
        || (kind == SceneKind::Nearest && r.k == 0)
    {
        return Err(ErrorCode::InvalidOptions);
    }
    let has = |bit: u32| r.flags & bit != 0;
    Ok(Question {
        kind,
        mode,
        margin: r.margin,
        cutoff: has(scene_flags::CUTOFF),
        all_pairs: has(scene_flags::ALL_PAIRS),
        self_pairs: has(scene_flags::SELF_PAIRS),
        motion: has(scene_flags::MOTION_BOUNDS),
        exact: has(scene_flags::EXACT),
        warm: has(scene_flags::WARM_START),
        clamp: has(scene_flags::CLAMP),
        linear_quaternion,
        bracket: r.bracket,
        options: gjk::Options {
            tolerance: r.tolerance,
            max_iterations: r.max_iterations,
            margin: None,
            warm_start: has(scene_flags::WARM_START),
            precision: if has(scene_flags::SINGLE_PRECISION) {
                gjk::Precision::Single
            } else {
                gjk::Precision::Double
            },
            penetration_expansions: 0,
        },
        accept_absolute: r.accept_absolute,
        accept_relative: r.accept_relative,
        k: usize::try_from(r.k).unwrap_or(usize::MAX),
        gradients: has(scene_flags::GRADIENTS),
        gradient_base: has(scene_flags::GRADIENT_BASE),
        signed: has(scene_flags::SIGNED_DISTANCE),
    })
}

/// Checks the items' layout; returns the number of path steps.
///
/// # Errors
/// [`ErrorCode::Malformed`] for unknown kinds or flags, a non-zero
/// reserved word, a distance item, a step (or a step's end flagged on
/// anything but a pose item) outside a path, a path with no step or with
/// pose items after its last.
fn check_layout(q: &Question, items: &[Item]) -> Result<u32, ErrorCode> {
    let mut steps: u32 = 0;
    let mut pending = false;
    for item in items {
        // A joint item's body has no reserved word; its `b` is zero instead.
        let unused = match ItemKind::from_raw(item.kind) {
            Some(ItemKind::SetJoints) => item.b,
            _ => u64::from(item.pair().reserved),
        };
        if item.flags & !item_flags::ALL != 0 || unused != 0 {
            return Err(ErrorCode::Malformed);
        }
        let ends = item.flags & item_flags::END_STEP != 0;
        match ItemKind::from_raw(item.kind) {
            Some(ItemKind::SetPose | ItemKind::SetJoints) if ends => {
                if q.mode == PathMode::Single {
                    return Err(ErrorCode::Malformed);
                }
                steps = steps.checked_add(1).ok_or(ErrorCode::Malformed)?;
                pending = false;
            }
            _ if ends => return Err(ErrorCode::Malformed),
            Some(ItemKind::SetPose | ItemKind::SetJoints) => pending = true,
            Some(ItemKind::Member | ItemKind::Allow) => {}
            Some(ItemKind::Step) if q.mode != PathMode::Single => {
                steps = steps.checked_add(1).ok_or(ErrorCode::Malformed)?;
                pending = false;
            }
            Some(ItemKind::Step | ItemKind::Distance) | None => return Err(ErrorCode::Malformed),
        }
    }
    if q.mode != PathMode::Single && (steps == 0 || pending) {
        return Err(ErrorCode::Malformed);
    }
    Ok(steps)
}

impl State {
    /// Answers one scene request from `client` (its iceoryx2 client port
    /// id, which keys its warm starts and motion bounds): `inputs` are the
    /// request's items, `rows` the answer's room (its length is the most
    /// rows written). Returns the reply header; on a whole-request error
    /// no row is meaningful and nothing changed (for a path, poses are
    /// never stored; for a single question, they are applied only once the
    /// whole request is checked).
    pub fn scene(
        &mut self,
        client: u128,
        request: &SceneRequest,
        inputs: &[Item],
        rows: &mut [SceneRow],
    ) -> SceneReply {
        match self.scene_checked(client, request, inputs, rows) {
            Ok(reply) => reply,
            Err(code) => {
                self.groups.group.clear();
                SceneReply::error(code)
            }
        }
    }

    fn scene_checked(
        &mut self,
        client: u128,
        request: &SceneRequest,
        inputs: &[Item],
        rows: &mut [SceneRow],
    ) -> Result<SceneReply, ErrorCode> {
        let q = decode(request)?;
        let steps = check_layout(&q, inputs)?;
        self.groups.broadphase.sync(&mut self.store);
        self.groups
            .group
            .resolve(&self.groups.broadphase, &self.robots, request.group, inputs)?;
        if q.kind == SceneKind::Nearest && self.groups.group.members.len() != 1 {
            return Err(ErrorCode::Malformed);
        }
        let mut waypoints = None;
        match q.mode {
            PathMode::Single => self.check_poses(&q, inputs)?,
            PathMode::Continuous => waypoints = Some(self.plan_continuous(&q, inputs)?),
            PathMode::EveryStep | PathMode::FirstHit => self.plan_path(&q, inputs)?,
        }
        let mut rows = Rows::new(rows);
        let mut counters = Counters::default();
        let mut reply = SceneReply::error(ErrorCode::Ok);
        self.groups.link_poses.reset();
        if q.mode == PathMode::Single {
            self.apply_poses(&q, inputs)?;
            self.groups.broadphase.sync(&mut self.store);
            self.answer_step(client, &q, 0, &mut rows, &mut counters);
            self.finish_rows(&q, rows.written_since(0), false);
            reply.steps = 1;
        } else if let Some(waypoints) = &waypoints {
            (reply.steps, reply.first_hit) =
                self.answer_continuous(&q, waypoints, &mut rows, &mut counters)?;
        } else {
            (reply.steps, reply.first_hit) =
                self.answer_path(client, &q, steps, &mut rows, &mut counters);
        }
        self.groups.group.clear();
        reply.total = rows.total;
        if rows.total > rows.written as u64 {
            reply.flags |= scene_reply_flags::TRUNCATED;
        }
        reply.gjk_runs = counters.gjk_runs;
        reply.bounded = counters.bounded;
        reply.candidates = counters.candidates;
        Ok(reply)
    }

    /// Computes every pose the items set, storing none, so that an error
    /// in any of them is found before anything changes.
    fn check_poses(&mut self, q: &Question, items: &[Item]) -> Result<(), ErrorCode> {
        let engine = &mut self.groups;
        engine.overlay.reset();
        for item in items.iter().filter(|i| is_pose_item(i)) {
            engine.poses.clear();
            item_poses(
                &self.store,
                &self.robots,
                &mut engine.overlay,
                item,
                q.clamp,
                &mut engine.poses,
            )?;
        }
        Ok(())
    }

    /// Computes every pose a path's items set, storing none (an error in
    /// any of them is found before anything changes), into the plan: each
    /// step's moves as slots and poses.
    fn plan_path(&mut self, q: &Question, items: &[Item]) -> Result<(), ErrorCode> {
        let engine = &mut self.groups;
        engine.overlay.reset();
        engine.plan.clear();
        engine.plan_ends.clear();
        engine.step_configurations.clear();
        // Consecutive pose items mostly move the same object: its checks
        // and slot are looked up once.
        let mut last: Option<(u64, Option<u32>)> = None;
        for item in items {
            if item.kind == ItemKind::SetPose as u32 {
                let slot = match last {
                    Some((id, slot)) if id == item.a => slot,
                    _ => {
                        if self.store.object(item.a).is_none() {
                            return Err(ErrorCode::UnknownObject);
                        }
                        let slot = engine.broadphase.slot(item.a);
                        last = Some((item.a, slot));
                        slot
                    }
                };
                let pose = crate::engine::checks::check_pose(&item.pose_a)?;
                // Every stored object has a slot since the last sync.
                if let Some(slot) = slot {
                    engine.plan.push((slot, pose));
                }
            } else if is_pose_item(item) {
                engine.poses.clear();
                item_poses(
                    &self.store,
                    &self.robots,
                    &mut engine.overlay,
                    item,
                    q.clamp,
                    &mut engine.poses,
                )?;
                for &(id, pose) in &engine.poses {
                    if let Some(slot) = engine.broadphase.slot(id) {
                        engine.plan.push((slot, pose));
                    }
                }
            }
            // `check_layout` let the flag through on pose items only.
            if item.kind == ItemKind::Step as u32 || item.flags & item_flags::END_STEP != 0 {
                if q.gradients {
                    let step = u32::try_from(engine.plan_ends.len()).unwrap_or(u32::MAX);
                    engine.overlay.record(step, &mut engine.step_configurations);
                }
                engine.plan_ends.push(engine.plan.len());
            }
        }
        Ok(())
    }

    /// Stores the poses of a single question's items, as the query
    /// service would (checked before by [`State::check_poses`]).
    fn apply_poses(&mut self, q: &Question, items: &[Item]) -> Result<(), ErrorCode> {
        for item in items {
            match ItemKind::from_raw(item.kind) {
                Some(ItemKind::SetPose) => {
                    let pose = crate::engine::checks::check_pose(&item.pose_a)?;
                    self.store.set_pose(item.a, pose)?;
                }
                Some(ItemKind::SetJoints) => {
                    let mut item = *item;
                    if q.clamp {
                        item.flags |= item_flags::CLAMP;
                    }
                    self.robots.set_joints(&mut self.store, &item)?;
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// Answers a path (planned by [`State::plan_path`]): each step's poses
    /// in the overlay, then the question; the overlay is undone at the end.
    /// Returns the steps answered and the first hit.
    fn answer_path(
        &mut self,
        client: u128,
        q: &Question,
        steps: u32,
        rows: &mut Rows<'_>,
        counters: &mut Counters,
    ) -> (u32, u32) {
        let engine = &mut self.groups;
        engine.touched.clear();
        let plan = std::mem::take(&mut engine.plan);
        let ends = std::mem::take(&mut engine.plan_ends);
        // Members only move: the tree's other leaves stay put, which is
        // what the questions of a group ask of it (members are never
        // their own candidates), and the lookaheads hold.
        let members_only =
            !q.all_pairs && plan.iter().all(|&(slot, _)| engine.group.contains(slot));
        let advance = members_only && q.kind == SceneKind::Within;
        if advance {
            let n = engine.group.members.len();
            if engine.lookahead.len() < n {
                engine.lookahead.resize_with(n, Lookahead::default);
            }
            engine.lookahead[..n].iter_mut().for_each(Lookahead::reset);
        }
        let mut first_hit = u32::MAX;
        let (mut start, mut step) = (0, 0);
        for &end in &ends {
            // Members meet each other only when asked for their own pairs;
            // then the tree must follow them too.
            self.move_step(&plan[start..end], !members_only || q.self_pairs);
            start = end;
            let (written, total) = (rows.written, rows.total);
            let moves = u32::try_from(end).unwrap_or(u32::MAX);
            let hits = if advance {
                self.answer_step_along(client, q, step, moves, rows, counters)
            } else {
                self.answer_step(client, q, step, rows, counters)
            };
            step += 1;
            if q.mode == PathMode::FirstHit && hits == 0 {
                rows.truncate(written, total);
                continue;
            }
            self.finish_rows(q, rows.written_since(written), true);
            if q.mode == PathMode::FirstHit {
                first_hit = step - 1;
                break;
            }
        }
        debug_assert!(step <= steps);
        self.groups.plan = plan;
        self.groups.plan_ends = ends;
        self.restore_overlay();
        (step, first_hit)
    }

    /// Moves the objects of one step of a path in the overlay; with
    /// `refit`, refits the tree to them.
    fn move_step(&mut self, moves: &[(u32, Isometry3<f64>)], refit: bool) {
        let engine = &mut self.groups;
        for (slot, pose) in moves {
            if !engine.broadphase.entry(*slot).overlaid {
                engine.broadphase.set_overlaid(*slot, true);
                engine.touched.push(*slot);
            }
            engine.broadphase.move_along(*slot, pose);
        }
        if refit {
            engine.broadphase.refit();
        }
    }

    /// Within, group against the rest, at one step of a path that moves
    /// members only ([`advance`]); returns the rows found.
    fn answer_step_along(
        &mut self,
        client: u128,
        q: &Question,
        step: u32,
        moves: u32,
        rows: &mut Rows<'_>,
        counters: &mut Counters,
    ) -> u64 {
        let engine = &mut self.groups;
        let mut ctx = Ctx {
            store: &self.store,
            bp: &engine.broadphase,
            cache: &mut self.cache,
            workspace: &mut self.workspace,
            client,
            q,
            group: &engine.group,
            counters,
        };
        let mut hits = 0;
        for (&m, look) in engine.group.members.iter().zip(&mut engine.lookahead) {
            hits += advance::within_along(&mut ctx, look, m, step, moves, rows);
        }
        // The lookaheads hold against objects that stay put; the members'
        // own pairs, both moving, are asked at every step.
        if q.self_pairs {
            for &m in &engine.group.members {
                hits += within::within_of(&mut ctx, m, Partners::Members, step, rows);
            }
        }
        hits
    }

    /// Puts the objects a path moved back at their stored poses.
    fn restore_overlay(&mut self) {
        let engine = &mut self.groups;
        for &slot in &engine.touched {
            let id = engine.broadphase.entry(slot).id;
            if let Some(object) = self.store.object(id) {
                engine.broadphase.place(slot, &object.pose);
            }
            engine.broadphase.set_overlaid(slot, false);
        }
        engine.touched.clear();
        engine.broadphase.refit();
    }

    /// Answers the question at the index's poses; returns the rows found.
    fn answer_step(
        &mut self,
        client: u128,
        q: &Question,
        step: u32,
        rows: &mut Rows<'_>,
        counters: &mut Counters,
    ) -> u64 {
        let engine = &mut self.groups;
        let bp = &engine.broadphase;
        let group = &engine.group;
        let approximate = &mut engine.approximate;
        let nearest = &mut engine.nearest;
        if nearest.len() > MAX_REMEMBERED {
            nearest.clear();
        }
        let mut ctx = Ctx {
            store: &self.store,
            bp,
            cache: &mut self.cache,
            workspace: &mut self.workspace,
            client,
            q,
            group,
            counters,
        };
        let mut hits = 0;
        match q.kind {
            SceneKind::Clearance => {
                for &m in &group.members {
                    let id = bp.entry(m).id;
                    let seed = nearest.get(&(client, id)).copied();
                    let row = clearance::clearance_of(&mut ctx, m, step, seed, approximate);
                    if row.b != 0 {
                        nearest.insert((client, id), row.b);
                    }
                    rows.push(row);
                    hits += 1;
                }
            }
            SceneKind::Within if q.all_pairs => {
                for slot in 0..bp.slot_count() as u32 {
                    if bp.entry(slot).live {
                        hits += within::within_of(&mut ctx, slot, Partners::All, step, rows);
                    }
                }
            }
            SceneKind::Within => {
                for &m in &group.members {
                    hits += within::within_of(&mut ctx, m, Partners::Rest, step, rows);
                }
                if q.self_pairs {
                    for &m in &group.members {
                        hits += within::within_of(&mut ctx, m, Partners::Members, step, rows);
                    }
                }
            }
            SceneKind::Nearest => {
                let before = rows.total;
                let found = &mut engine.found;
                nearest::nearest_of(&mut ctx, group.members[0], q.k, step, found, rows);
                hits = rows.total - before;
            }
        }
        hits
    }
}

fn is_pose_item(item: &Item) -> bool {
    matches!(
        ItemKind::from_raw(item.kind),
        Some(ItemKind::SetPose | ItemKind::SetJoints)
    )
}
