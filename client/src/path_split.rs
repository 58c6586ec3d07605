//! Paths longer than one request: a path whose items exceed the server's
//! [`ServerInfo::max_batch`](crate::ServerInfo::max_batch), or whose rows
//! may exceed its [`ServerInfo::max_rows`](crate::ServerInfo::max_rows),
//! is sent as several requests of consecutive steps, and their rows come
//! back to the caller as one answer, steps numbered from the path's start.
//!
//! Each later request repeats the group's members and allowed pairs, and
//! the first step's pose and joint items (the poses given with
//! [`SceneQuery::with_poses`](crate::SceneQuery::with_poses) among them)
//! ahead of its own first step: the objects that no later step moves stand
//! where the first step put them, as in one request. Every path the
//! clients build moves the same objects at every step, so the answers are
//! those of one request; each row is certified either way. Warm starts and
//! motion bounds carry over from one request to the next as from one scene
//! question to the next.

use gjkd_proto::{
    ErrorCode, Item, ItemKind, PathMode, SceneReply, SceneRequest, SceneRow, item_flags,
    scene_reply_flags,
};

use crate::{Client, ClientError, SceneSummary};

/// Buffers of split paths, kept from one call to the next.
#[derive(Debug, Default)]
pub(crate) struct SplitScratch {
    /// The request's items.
    items: Vec<Item>,
    /// The first step's pose and joint items, none ending a step.
    replay: Vec<Item>,
    /// Those of `replay` a later request repeats.
    now: Vec<Item>,
    /// Index (in `items`) of the last item of each step.
    ends: Vec<usize>,
    /// Rows received so far, steps numbered from the path's start.
    rows: Vec<SceneRow>,
}

/// The limits of one request, from the server's hello.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RequestLimits {
    /// Most items a request.
    pub(crate) items: usize,
    /// Most rows an answer.
    pub(crate) rows: usize,
}

impl RequestLimits {
    /// Whether `request` with `count` items is a path that one request
    /// cannot carry whole.
    pub(crate) fn must_split(&self, request: &SceneRequest, count: usize) -> bool {
        request.path != PathMode::Single as u32
            && (count > self.items || request.max_rows as usize > self.rows)
    }
}

/// Where a step ends: a step marker, or a pose or joint item flagged so.
fn ends_step(item: &Item) -> bool {
    item.kind == ItemKind::Step as u32 || item.flags & item_flags::END_STEP != 0
}

/// Whether `a` and `b` set the same thing: one object's pose, or the same
/// joints of one robot.
fn same_target(a: &Item, b: &Item) -> bool {
    a.kind == b.kind
        && a.a == b.a
        && (a.kind != ItemKind::SetJoints as u32
            || (a.joints().first == b.joints().first
                && a.joints().count == b.joints().count
                && (a.flags ^ b.flags) & !item_flags::END_STEP == 0))
}

/// Whether `item` belongs to every request of a split path.
fn is_head(item: &Item) -> bool {
    item.kind == ItemKind::Member as u32 || item.kind == ItemKind::Allow as u32
}

impl Client {
    /// Sends the path `request` with `count` items in requests that fit
    /// `limits` (see the [module documentation](self)) and hands all the
    /// rows received to `read` at once.
    pub(crate) fn scene_split(
        &mut self,
        request: &SceneRequest,
        count: usize,
        mut item: impl FnMut(usize) -> Item,
        read: impl FnOnce(&[SceneRow]),
        limits: RequestLimits,
    ) -> Result<SceneSummary, ClientError> {
        let mut scratch = std::mem::take(&mut self.split_scratch);
        scratch.items.clear();
        scratch.items.extend((0..count).map(&mut item));
        let outcome = self.split_into(request, &mut scratch, limits);
        if outcome.is_ok() {
            read(&scratch.rows);
        }
        scratch.rows.clear();
        self.split_scratch = scratch;
        outcome
    }

    fn split_into(
        &mut self,
        request: &SceneRequest,
        scratch: &mut SplitScratch,
        limits: RequestLimits,
    ) -> Result<SceneSummary, ClientError> {
        let SplitScratch {
            items,
            replay,
            now,
            ends,
            rows,
        } = scratch;
        // Members and allowed pairs first, then the steps, as the server
        // reads them.
        items.sort_by_key(|i| !is_head(i));
        let head = items.iter().take_while(|i| is_head(i)).count();
        ends.clear();
        ends.extend((head..items.len()).filter(|&i| ends_step(&items[i])));
        if items.len() == head || ends.last() != Some(&(items.len() - 1)) {
            // Not a whole path: one request, which the server refuses.
            let (items, count) = (&*items, items.len());
            return self.scene_once(request, count, |i| items[i], |got| rows.extend(got));
        }
        // The first step's items, its end unflagged, open every later request.
        replay.clear();
        replay.extend(
            items[head..=ends[0]]
                .iter()
                .filter(|i| i.kind != ItemKind::Step as u32)
                .map(|i| Item {
                    flags: i.flags & !item_flags::END_STEP,
                    ..*i
                }),
        );
        let first_hit_mode = request.path == PathMode::FirstHit as u32;
        let server_rows = limits.rows.max(1);
        let mut total = SceneReply::error(ErrorCode::Ok);
        let (mut step, mut rows_per_step) = (0usize, 0.0f64);
        while step < ends.len() {
            let start = if step == 0 { head } else { ends[step - 1] + 1 };
            // What the first step set and this one sets again needs no
            // repeating (every step of a pose or joint path sets the same).
            now.clear();
            if step > 0 {
                let own = &items[start..=ends[step]];
                now.extend(
                    replay
                        .iter()
                        .filter(|r| !own.iter().any(|i| same_target(i, r))),
                );
            }
            let fixed = head + now.len();
            // As many steps as the item limit takes (one at least: a step
            // too large for any request is refused as it would be whole),
            // and as many as the rows seen so far say fit.
            let mut n = 1;
            while step + n < ends.len() && fixed + ends[step + n] + 1 - start <= limits.items {
                n += 1;
            }
            if rows_per_step > 0.0 {
                n = n.min(((server_rows as f64 / rows_per_step) as usize).max(1));
            }
            let room = (request.max_rows as usize).saturating_sub(rows.len());
            let mut part = *request;
            part.max_rows = u32::try_from(room.min(server_rows)).unwrap_or(u32::MAX);
            let end = ends[step + n - 1] + 1;
            let base = rows.len();
            let offset = u32::try_from(step).unwrap_or(u32::MAX);
            let (items, replay) = (&*items, &*now);
            let summary = self.scene_once(
                &part,
                fixed + end - start,
                |i| {
                    if i < head {
                        items[i]
                    } else if i < fixed {
                        replay[i - head]
                    } else {
                        items[start + i - fixed]
                    }
                },
                |got| {
                    rows.extend(got.iter().map(|r| SceneRow {
                        step: r.step.saturating_add(offset),
                        ..*r
                    }))
                },
            )?;
            total.gjk_runs += summary.gjk_runs;
            total.bounded += summary.bounded;
            total.candidates += summary.candidates;
            let cut_by_server = summary.truncated && room > server_rows;
            let last = rows.last().map_or(step, |r| r.step as usize);
            if cut_by_server && !first_hit_mode && last > step {
                // Keep the steps answered whole; ask again from the first
                // step cut.
                let kept = rows[base..].partition_point(|r| (r.step as usize) < last);
                rows.truncate(base + kept);
                total.total += kept as u64;
                total.steps += (last - step) as u32;
                rows_per_step = kept as f64 / (last - step) as f64;
                step = last;
                continue;
            }
            total.total += summary.total;
            total.steps += summary.steps;
            if summary.truncated {
                total.flags |= scene_reply_flags::TRUNCATED;
            }
            rows_per_step = rows_per_step.max(summary.total as f64 / n as f64);
            if let Some(hit) = summary.first_hit {
                total.first_hit = offset + hit;
                break;
            }
            step += n;
        }
        Ok(SceneSummary::new(&total, rows.len()))
    }
}
