//! TEMPORARY stand-in for the scene engine, so that the wire can be built
//! and tested before the engine lands: every pair asked exactly through
//! [`State::handle`], no broadphase, no motion bounds. Removed by the merge
//! of the engine.

use gjkd_proto::{
    ErrorCode, Item, ItemKind, ItemResult, ObjectId, PathMode, Precision, QueryOptions, SceneKind,
    SceneReply, SceneRequest, SceneRow, Status, scene_flags, scene_reply_flags,
};

use crate::state::State;

struct Ask {
    kind: SceneKind,
    path: PathMode,
    options: QueryOptions,
    members: Vec<u64>,
    allowed: Vec<(u64, u64)>,
}

impl State {
    /// Answers a scene request by brute force (temporary).
    pub fn scene(
        &mut self,
        client: u128,
        request: &SceneRequest,
        inputs: &[Item],
        rows: &mut [SceneRow],
    ) -> SceneReply {
        match self.scene_brute(client, request, inputs, rows) {
            Ok(r) => r,
            Err(code) => SceneReply::error(code),
        }
    }

    fn scene_ask(&self, request: &SceneRequest, inputs: &[Item]) -> Result<Ask, ErrorCode> {
        let kind = request.scene_kind().ok_or(ErrorCode::Malformed)?;
        let path = request.path_mode().ok_or(ErrorCode::Malformed)?;
        if request.flags & !scene_flags::ALL != 0 {
            return Err(ErrorCode::Malformed);
        }
        if path == PathMode::FirstHit && kind != SceneKind::Within {
            return Err(ErrorCode::Malformed);
        }
        let bad = |x: f64| !x.is_finite() || x < 0.0;
        if bad(request.tolerance)
            || request.max_iterations == 0
            || request.margin.is_nan()
            || bad(request.accept_absolute)
            || bad(request.accept_relative)
            || (kind == SceneKind::Nearest && request.k == 0)
        {
            return Err(ErrorCode::InvalidOptions);
        }
        let mut members = Vec::new();
        let mut allowed = Vec::new();
        if request.group != 0 {
            if let Some(robot) = self.robots.get(request.group) {
                members.extend(robot.links.iter().flatten());
                for &(i, j) in &robot.allowed {
                    if let (Some(Some(a)), Some(Some(b))) = (robot.links.get(i), robot.links.get(j))
                    {
                        allowed.push((*a, *b));
                    }
                }
            } else if self.object(request.group).is_some() {
                members.push(request.group);
            } else {
                return Err(ErrorCode::UnknownObject);
            }
        }
        for item in inputs {
            match item.item_kind() {
                Some(ItemKind::Member) if request.group == 0 => members.push(item.a),
                Some(ItemKind::Allow) => allowed.push((item.a, item.b)),
                Some(ItemKind::Step) if path == PathMode::Single => {
                    return Err(ErrorCode::Malformed);
                }
                Some(ItemKind::SetPose | ItemKind::SetJoints | ItemKind::Step) => {}
                _ => return Err(ErrorCode::Malformed),
            }
        }
        if members.iter().any(|&m| self.object(m).is_none()) {
            return Err(ErrorCode::UnknownObject);
        }
        members.sort_unstable();
        members.dedup();
        if members.is_empty() || (kind == SceneKind::Nearest && members.len() != 1) {
            return Err(ErrorCode::Malformed);
        }
        let options = QueryOptions {
            tolerance: request.tolerance,
            max_iterations: request.max_iterations,
            margin: (kind == SceneKind::Within).then_some(request.margin),
            warm_start: request.flags & scene_flags::WARM_START != 0,
            precision: if request.flags & scene_flags::SINGLE_PRECISION != 0 {
                Precision::Single
            } else {
                Precision::Double
            },
        };
        Ok(Ask {
            kind,
            path,
            options,
            members,
            allowed,
        })
    }

    fn scene_brute(
        &mut self,
        client: u128,
        request: &SceneRequest,
        inputs: &[Item],
        rows: &mut [SceneRow],
    ) -> Result<SceneReply, ErrorCode> {
        let ask = self.scene_ask(request, inputs)?;
        let mut reply = SceneReply::error(ErrorCode::Ok);
        let poses =
            |i: &&Item| matches!(i.item_kind(), Some(ItemKind::SetPose | ItemKind::SetJoints));
        if ask.path == PathMode::Single {
            let updates: Vec<Item> = inputs.iter().filter(poses).copied().collect();
            self.scene_apply(client, &updates)?;
            reply.steps = 1;
            self.scene_step(client, request, &ask, 0, rows, &mut reply);
            return Ok(reply);
        }
        let saved: Vec<(u64, Item)> = self.scene_saved_poses();
        let mut step = 0u32;
        let mut updates = Vec::new();
        let mut outcome = Ok(());
        for item in inputs {
            if item.item_kind() == Some(ItemKind::Step) {
                if let Err(e) = self.scene_apply(client, &updates) {
                    outcome = Err(e);
                    break;
                }
                updates.clear();
                let before = reply.total;
                self.scene_step(client, request, &ask, step, rows, &mut reply);
                step += 1;
                reply.steps = step;
                if ask.path == PathMode::FirstHit && reply.total > before {
                    reply.first_hit = step - 1;
                    break;
                }
            } else if poses(&item) {
                updates.push(*item);
            }
        }
        let restore: Vec<Item> = saved.into_iter().map(|(_, i)| i).collect();
        let mut out = vec![ItemResult::default(); restore.len()];
        self.handle(client, &restore, &mut out);
        outcome.map(|()| reply)
    }

    fn scene_saved_poses(&self) -> Vec<(u64, Item)> {
        self.store
            .objects()
            .map(|(id, o)| (id, Item::set_pose(ObjectId::from_raw(id), &o.pose)))
            .collect()
    }

    fn scene_apply(&mut self, client: u128, updates: &[Item]) -> Result<(), ErrorCode> {
        let mut out = vec![ItemResult::default(); updates.len()];
        self.handle(client, updates, &mut out);
        match out.iter().find(|r| r.error != 0) {
            Some(r) => Err(r.error_code()),
            None => Ok(()),
        }
    }

    fn scene_pair(&mut self, client: u128, ask: &Ask, a: u64, b: u64) -> ItemResult {
        let item = Item::distance(ObjectId::from_raw(a), ObjectId::from_raw(b), &ask.options);
        let mut out = [ItemResult::default()];
        self.handle(client, &[item], &mut out);
        out[0]
    }

    fn scene_step(
        &mut self,
        client: u128,
        request: &SceneRequest,
        ask: &Ask,
        step: u32,
        rows: &mut [SceneRow],
        reply: &mut SceneReply,
    ) {
        let mut all: Vec<u64> = self.store.objects().map(|(id, _)| id).collect();
        all.sort_unstable();
        let allowed = |a: u64, b: u64| {
            ask.allowed
                .iter()
                .any(|&(x, y)| (x, y) == (a, b) || (y, x) == (a, b))
        };
        let is_member = |x: u64| ask.members.binary_search(&x).is_ok();
        let cutoff = request.flags & scene_flags::CUTOFF != 0;
        let mut push = |row: SceneRow, reply: &mut SceneReply| {
            let i = reply.total as usize;
            if i < rows.len() {
                rows[i] = row;
            } else {
                reply.flags |= scene_reply_flags::TRUNCATED;
            }
            reply.total += 1;
        };
        match ask.kind {
            SceneKind::Clearance => {
                for &m in &ask.members {
                    let mut best: Option<(u64, ItemResult)> = None;
                    for &o in all.iter().filter(|&&o| !is_member(o) && !allowed(m, o)) {
                        let r = self.scene_pair(client, ask, m, o);
                        reply.gjk_runs += 1;
                        reply.candidates += 1;
                        if best.is_none_or(|(_, b)| r.distance < b.distance) {
                            best = Some((o, r));
                        }
                    }
                    let best = best.filter(|(_, r)| !cutoff || r.distance <= request.margin);
                    let (b, result) = best.unwrap_or((0, ItemResult::default()));
                    push(
                        SceneRow {
                            a: m,
                            b,
                            step,
                            reserved: 0,
                            result,
                        },
                        reply,
                    );
                }
            }
            SceneKind::Within => {
                let all_pairs = request.flags & scene_flags::ALL_PAIRS != 0;
                for (i, &a) in all.iter().enumerate() {
                    for &b in &all[i + 1..] {
                        let wanted = all_pairs || (is_member(a) != is_member(b));
                        if !wanted || allowed(a, b) {
                            continue;
                        }
                        let (a, b) = if is_member(b) && !is_member(a) {
                            (b, a)
                        } else {
                            (a, b)
                        };
                        let r = self.scene_pair(client, ask, a, b);
                        reply.gjk_runs += 1;
                        reply.candidates += 1;
                        if r.error == 0
                            && (r.status == Status::Closer as u32 || r.distance <= request.margin)
                        {
                            push(
                                SceneRow {
                                    a,
                                    b,
                                    step,
                                    reserved: 0,
                                    result: r,
                                },
                                reply,
                            );
                        }
                    }
                }
            }
            SceneKind::Nearest => {
                let m = ask.members[0];
                let mut found: Vec<(u64, ItemResult)> = Vec::new();
                for &o in all.iter().filter(|&&o| o != m && !allowed(m, o)) {
                    let r = self.scene_pair(client, ask, m, o);
                    reply.gjk_runs += 1;
                    reply.candidates += 1;
                    if !cutoff || r.distance <= request.margin {
                        found.push((o, r));
                    }
                }
                found.sort_by(|x, y| x.1.distance.total_cmp(&y.1.distance));
                for (o, r) in found.into_iter().take(request.k as usize) {
                    push(
                        SceneRow {
                            a: m,
                            b: o,
                            step,
                            reserved: 0,
                            result: r,
                        },
                        reply,
                    );
                }
            }
        }
    }
}
