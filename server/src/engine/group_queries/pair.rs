//! One candidate pair: answered from its motion bound when that decides
//! the question or is as narrow as the caller accepts, by GJK (the query
//! service's own pair query, warm-started from the same cache) otherwise.

use gjkd_proto::{ErrorCode, ItemResult, Status};

use super::broadphase::Broadphase;
use super::entry::Entry;
use super::groups::Group;
use super::motion_bound::{
    Widened, accepted, bound_of, bounded_result, carried, moved_since, widen_by,
};
use super::{Counters, Question};
use crate::engine::objects::ObjectStore;
use crate::engine::pair_query::run_pair;
use crate::engine::warm_cache::{EntryAt, PairBound, PairKey, WarmCache};
use gjk::WarmStart;

/// Support points added to an overlapping pair's penetration bound when
/// it is kept as a motion bound for a within question.
const PENETRATION_EXPANSIONS: u32 = 4;

/// The motion bound kept for `key` (objects `ea`, `eb`), when motion
/// bounds are on: the bound, how far any point of either object moved
/// since ([`moved_since`]), and the bound widened by that.
#[inline(always)]
fn kept_bound<'c>(
    q: &Question,
    cache: &'c mut WarmCache,
    key: &PairKey,
    ea: &Entry,
    eb: &Entry,
) -> Option<(EntryAt, &'c PairBound, f64, Widened)> {
    if !q.motion {
        return None;
    }
    let (at, bound) = cache.bound_entry(key)?;
    let d = moved_since(bound, ea, eb);
    Some((at, bound, d, widen_by(bound, d)))
}

/// What is asked of a pair.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Ask {
    /// Is its distance at most this margin?
    Within(f64),
    /// Could it be nearer than this (the current best's upper bound)?
    Below(f64),
    /// As `Below`, but an accepted width does not settle the pair (nearest
    /// k, whose order an approximate answer could get wrong).
    BelowExactly(f64),
}

/// How a pair was settled.
#[derive(Clone, Copy, Debug)]
// The answer travels by value into a row: boxing it would allocate per
// pair, for a variant that is most of what a scene request returns.
#[allow(clippy::large_enum_variant)]
pub(crate) enum Outcome {
    /// Its motion bound answers the question: not within the margin, or
    /// not nearer than the current best.
    Ruled,
    /// Its answer, certified, with status `Bounded` when from its motion
    /// bound; an error row if gjk refused the pair.
    Answer(ItemResult),
}

/// Everything a step's questions work with.
pub(crate) struct Ctx<'a> {
    /// The objects' shapes.
    pub store: &'a ObjectStore,
    /// The objects' poses and boxes.
    pub bp: &'a Broadphase,
    /// Warm starts and motion bounds.
    pub cache: &'a mut WarmCache,
    /// gjk's scratch memory.
    pub workspace: &'a mut gjk::Workspace,
    /// Whose cache entries.
    pub client: u128,
    /// The question.
    pub q: &'a Question,
    /// The group and the allowed pairs.
    pub group: &'a Group,
    /// What it cost.
    pub counters: &'a mut Counters,
}

impl Ctx<'_> {
    /// The cached simplex of the pair of slots `a`, `b` (for this client),
    /// when warm starts are on.
    pub(crate) fn warm(&mut self, a: u32, b: u32) -> Option<WarmStart> {
        if !self.q.warm {
            return None;
        }
        let key = self.key(a, b);
        self.cache.get(&key)
    }

    /// The pair's motion bound at the current poses, when motion bounds are
    /// on and one is kept: the cached answer and its widened interval.
    pub(crate) fn widened(&mut self, a: u32, b: u32) -> Option<(&PairBound, Widened)> {
        let key = self.key(a, b);
        kept_bound(self.q, self.cache, &key, self.bp.entry(a), self.bp.entry(b))
            .map(|(_, bound, _, w)| (bound, w))
    }

    fn key(&self, a: u32, b: u32) -> PairKey {
        PairKey {
            client: self.client,
            a: self.bp.entry(a).id,
            b: self.bp.entry(b).id,
        }
    }

    /// Settles the pair of slots `a`, `b` for `ask`.
    pub(crate) fn settle(&mut self, a: u32, b: u32, ask: Ask) -> Outcome {
        self.settle_keeping(a, b, ask, None)
    }

    /// [`Ctx::settle`], also writing into `keep` the pair's motion bound
    /// at the current poses (`None` without motion bounds): the answer GJK
    /// kept, or the kept one carried here ([`carried`]).
    pub(crate) fn settle_keeping(
        &mut self,
        a: u32,
        b: u32,
        ask: Ask,
        keep: Option<&mut Option<PairBound>>,
    ) -> Outcome {
        let q = self.q;
        let (ea, eb) = (self.bp.entry(a), self.bp.entry(b));
        let key = self.key(a, b);
        // Where the kept entry is, and its simplex once fetched: a GJK run
        // after a failed recheck starts from it with no second look-up.
        let mut kept: Option<(EntryAt, Option<WarmStart>)> = None;
        if let Some((at, bound, d, w)) = kept_bound(q, self.cache, &key, ea, eb) {
            let ok = accepted(&w, q.accept_absolute, q.accept_relative);
            // An exact question takes bounds to rule pairs out, never to
            // answer a row.
            let (ruled, settled) = match ask {
                Ask::Within(m) => (w.lower > m, !q.exact && (w.upper <= m || ok)),
                Ask::Below(best) => (w.lower >= best, !q.exact && ok),
                Ask::BelowExactly(best) => (w.lower >= best, false),
            };
            let outcome = if ruled {
                Some(Outcome::Ruled)
            } else if settled {
                Some(Outcome::Answer(bounded_result(bound, &w, ea, eb)))
            } else {
                None
            };
            if let Some(outcome) = outcome {
                if let Some(keep) = keep {
                    *keep = Some(carried(bound, d, &w, ea, eb));
                }
                self.counters.bounded += 1;
                return outcome;
            }
            let (bound, d) = (*bound, d);
            let rechecked = if q.exact && bound.penetration > 0.0 {
                // An overlap re-certified answers a row: not exact.
                kept = Some((at, None));
                None
            } else if bound.penetration > 0.0 && matches!(ask, Ask::Within(_)) {
                let warm = self.cache.get_at(at);
                kept = Some((at, Some(warm)));
                self.recheck_overlap(&bound, ea, eb, &warm)
            } else {
                kept = Some((at, None));
                self.recheck(&bound, d, &w, ea, eb, ask)
            };
            if let Some((fresh, outcome)) = rechecked {
                self.cache.replace_bound_at(at, fresh);
                if let Some(keep) = keep {
                    *keep = Some(fresh);
                }
                self.counters.bounded += 1;
                return outcome;
            }
        }
        let warm = match kept {
            _ if !q.warm => None,
            Some((_, Some(warm))) => Some(warm),
            Some((at, None)) => Some(self.cache.get_at(at)),
            None => self.warm(a, b),
        };
        Outcome::Answer(self.run_keeping(a, b, ask, warm, keep))
    }

    /// The kept `bound` of a separated pair re-certified at the current
    /// poses of `ea`, `eb` from its normal ([`gjk::separation_bound`]: two
    /// support values), when that rules the pair out for `ask`: the bound
    /// carried here (moved by at most `d`, widened to `w`) with the new
    /// lower bound. `None` when the pair did not separate, or the
    /// direction no longer proves enough.
    fn recheck(
        &self,
        bound: &PairBound,
        d: f64,
        w: &Widened,
        ea: &Entry,
        eb: &Entry,
        ask: Ask,
    ) -> Option<(PairBound, Outcome)> {
        if bound.lower <= 0.0 {
            return None;
        }
        let (oa, ob) = (self.store.object(ea.id)?, self.store.object(eb.id)?);
        // The normal turned with A: right when A turns about it, or
        // when the pair turns together.
        let normal = ea.pose.rotation * bound.normal;
        let lower = gjk::separation_bound(&oa.shape, &ea.pose, &ob.shape, &eb.pose, &normal);
        let ruled = match ask {
            Ask::Within(m) => lower > m,
            Ask::Below(best) | Ask::BelowExactly(best) => lower >= best,
        };
        if !ruled {
            return None;
        }
        let w = Widened {
            lower: lower.max(w.lower),
            upper: w.upper.max(lower),
        };
        Some((carried(bound, d, &w, ea, eb), Outcome::Ruled))
    }

    /// The kept `bound` of an overlapping pair re-certified at the current
    /// poses of `ea`, `eb` from its cached simplex
    /// (`warm`; [`gjk::penetration_bound`]: no support search), for a
    /// within ask: the pair still overlaps, its distance is 0. `None` when
    /// the simplex no longer proves it.
    fn recheck_overlap(
        &self,
        bound: &PairBound,
        ea: &Entry,
        eb: &Entry,
        warm: &WarmStart,
    ) -> Option<(PairBound, Outcome)> {
        let (oa, ob) = (self.store.object(ea.id)?, self.store.object(eb.id)?);
        let depth = gjk::penetration_bound(&oa.shape, &ea.pose, &ob.shape, &eb.pose, warm);
        if depth <= 0.0 {
            return None;
        }
        let w = Widened {
            lower: 0.0,
            upper: 0.0,
        };
        let fresh = PairBound {
            lower: 0.0,
            upper: 0.0,
            distance: 0.0,
            penetration: depth,
            pose_a: ea.pose,
            pose_b: eb.pose,
            ..*bound
        };
        Some((fresh, Outcome::Answer(bounded_result(bound, &w, ea, eb))))
    }

    /// Runs GJK on the pair of slots `a`, `b` (from `warm` if warm starts
    /// are on) and caches its simplex and, with motion bounds, its answer.
    pub(crate) fn run(&mut self, a: u32, b: u32, ask: Ask, warm: Option<WarmStart>) -> ItemResult {
        self.run_keeping(a, b, ask, warm, None)
    }

    /// [`Ctx::run`], also writing into `keep` the motion bound it kept
    /// (`None` if none).
    fn run_keeping(
        &mut self,
        a: u32,
        b: u32,
        ask: Ask,
        warm: Option<WarmStart>,
        mut keep: Option<&mut Option<PairBound>>,
    ) -> ItemResult {
        if let Some(keep) = keep.as_deref_mut() {
            *keep = None;
        }
        let (ea, eb) = (self.bp.entry(a), self.bp.entry(b));
        let (Some(oa), Some(ob)) = (self.store.object(ea.id), self.store.object(eb.id)) else {
            return ItemResult::error(ErrorCode::UnknownObject);
        };
        let q = self.q;
        let mut options = q.options;
        // A row's gradient needs its nearest points, which an early exit
        // at the margin does not find.
        options.margin = match ask {
            Ask::Within(m) if !q.gradients => Some(m),
            Ask::Within(_) | Ask::Below(_) | Ask::BelowExactly(_) => None,
        };
        // A kept overlap settles the pair within the margin for as long as
        // the motion since stays below its depth: a deeper bound is worth a
        // few support searches then.
        if q.motion && matches!(ask, Ask::Within(_)) {
            options.penetration_expansions = PENETRATION_EXPANSIONS;
        }
        let warm = if q.warm { warm } else { None };
        self.counters.gjk_runs += 1;
        let mut outcome = run_pair(
            self.workspace,
            (&oa.shape, &ea.pose),
            (&ob.shape, &eb.pose),
            &options,
            warm.as_ref(),
        );
        if q.exact
            && let Ok((result, next)) = &outcome
            && result.status == Status::Closer as u32
        {
            // An exact question reports a pair within the margin with its
            // converged distance: on from where the early exit stopped.
            options.margin = None;
            self.counters.gjk_runs += 1;
            outcome = run_pair(
                self.workspace,
                (&oa.shape, &ea.pose),
                (&ob.shape, &eb.pose),
                &options,
                Some(next),
            );
        }
        match outcome {
            Ok((result, next)) => {
                let key = self.key(a, b);
                if q.motion {
                    let bound = bound_of(&result, ea, eb);
                    self.cache.put_with_bound(key, next, bound);
                    if let Some(keep) = keep {
                        *keep = Some(bound);
                    }
                } else if q.warm {
                    self.cache.put(key, next);
                }
                result
            }
            Err(code) => ItemResult::error(code),
        }
    }
}
