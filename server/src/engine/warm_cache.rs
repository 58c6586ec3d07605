//! The per-pair warm-start cache: the last simplex of each (client, A, B),
//! bounded by a capacity, with CLOCK (second-chance) eviction.
//!
//! With the simplex, an entry may keep the pair's last certified answer and
//! the poses it held at ([`PairBound`]), from which the scene service's
//! motion bounds ([`crate::engine::group_queries`]) answer later questions without
//! running GJK.
//!
//! The key includes the client so that two clients querying the same pair at
//! different poses never feed each other simplices from elsewhere on the
//! path: a foreign simplex would still give a correct answer (gjk checks the
//! indices and converges from any start) but a slow one.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use gjk::WarmStart;
use nalgebra::{Isometry3, Point3, Vector3};

/// Whose simplex, for which ordered pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PairKey {
    /// The querying client (iceoryx2's unique client port id).
    pub client: u128,
    /// Object A.
    pub a: u64,
    /// Object B.
    pub b: u64,
}

/// A multiply-rotate hasher in the style of FxHash: the keys are ids the
/// server hands out or port ids, not attacker-chosen strings, and SipHash
/// would cost more than the lookup it guards.
#[derive(Default, Clone, Copy)]
pub struct FxHasher(u64);

impl Hasher for FxHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(word));
        }
    }

    #[inline]
    fn write_u64(&mut self, n: u64) {
        self.0 = (self.0.rotate_left(5) ^ n).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }

    #[inline]
    fn write_u128(&mut self, n: u128) {
        self.write_u64(n as u64);
        self.write_u64((n >> 64) as u64);
    }

    #[inline]
    fn write_u32(&mut self, n: u32) {
        self.write_u64(u64::from(n));
    }

    #[inline]
    fn write_usize(&mut self, n: usize) {
        self.write_u64(n as u64);
    }

    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

/// `BuildHasher` of [`FxHasher`].
pub type FxBuild = BuildHasherDefault<FxHasher>;

/// A pair's last certified answer and where the objects were: the start
/// of a motion bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairBound {
    /// Certified lower bound of the distance at `pose_a`, `pose_b`.
    pub lower: f64,
    /// Certified upper bound.
    pub upper: f64,
    /// The distance answered.
    pub distance: f64,
    /// Certified lower bound on the penetration depth then (0 when
    /// separated): while the objects move by less, they still overlap.
    pub penetration: f64,
    /// A's pose then.
    pub pose_a: Isometry3<f64>,
    /// B's pose then.
    pub pose_b: Isometry3<f64>,
    /// The nearest point on A, in A's body frame.
    pub point_a: Point3<f64>,
    /// The nearest point on B, in B's body frame.
    pub point_b: Point3<f64>,
    /// The normal, in A's body frame.
    pub normal: Vector3<f64>,
    /// The pieces that realised the distance.
    pub pieces: [u32; 2],
}

/// Where an entry of a [`WarmCache`] is, from [`WarmCache::bound_entry`]:
/// valid until the cache next stores or forgets an entry, which may move
/// or drop it.
#[derive(Clone, Copy, Debug)]
pub struct EntryAt(u32);

#[derive(Clone, Copy, Debug)]
struct Slot {
    key: PairKey,
    warm: WarmStart,
    bound: Option<PairBound>,
    referenced: bool,
}

/// Counters of a [`WarmCache`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CacheStats {
    /// Look-ups that found an entry.
    pub hits: u64,
    /// Look-ups that found none.
    pub misses: u64,
    /// Entries dropped to make room.
    pub evictions: u64,
}

/// Bounded map from [`PairKey`] to the pair's last [`WarmStart`].
#[derive(Debug)]
pub struct WarmCache {
    index: HashMap<PairKey, u32, FxBuild>,
    slots: Vec<Slot>,
    hand: usize,
    capacity: usize,
    stats: CacheStats,
}

impl WarmCache {
    /// An empty cache of at most `capacity` entries (0 disables it; at most
    /// `u32::MAX` are kept).
    pub fn new(capacity: usize) -> Self {
        let capacity = capacity.min(u32::MAX as usize);
        // Start small and grow with the pairs actually queried: a table sized
        // for the cap spreads a few dozen live entries over megabytes, one
        // page (and TLB miss) each, which cost a batch of 64 pairs several µs.
        let start = capacity.min(256);
        WarmCache {
            index: HashMap::with_capacity_and_hasher(start, FxBuild::default()),
            slots: Vec::with_capacity(start),
            hand: 0,
            capacity,
            stats: CacheStats::default(),
        }
    }

    /// The cached simplex of `key`, marking the entry as recently used.
    #[inline]
    pub fn get(&mut self, key: &PairKey) -> Option<WarmStart> {
        match self.index.get(key) {
            Some(&i) => {
                let slot = &mut self.slots[i as usize];
                slot.referenced = true;
                self.stats.hits += 1;
                Some(slot.warm)
            }
            None => {
                self.stats.misses += 1;
                None
            }
        }
    }

    /// The last certified answer kept for `key`, marking the entry as
    /// recently used (not counted as a hit or miss: a look-up for the
    /// simplex follows when the answer does not do), and where the entry
    /// is, so that the calls `_at` that follow need no second look-up.
    #[inline]
    pub fn bound_entry(&mut self, key: &PairKey) -> Option<(EntryAt, &PairBound)> {
        let &i = self.index.get(key)?;
        let slot = &mut self.slots[i as usize];
        slot.referenced = true;
        slot.bound.as_ref().map(|bound| (EntryAt(i), bound))
    }

    /// The simplex of the entry `at` (as [`WarmCache::get`] counts it).
    #[inline]
    pub fn get_at(&mut self, at: EntryAt) -> WarmStart {
        self.stats.hits += 1;
        self.slots[at.0 as usize].warm
    }

    /// Replaces the certified answer kept in the entry `at` (a bound
    /// re-certified at newer poses; the simplex stays).
    #[inline]
    pub fn replace_bound_at(&mut self, at: EntryAt, bound: PairBound) {
        self.slots[at.0 as usize].bound = Some(bound);
    }

    /// Stores the simplex of `key`, evicting an entry that has not been used
    /// since the clock hand last passed it if the cache is full. A certified
    /// answer already kept stays (it holds at its own poses whatever the
    /// simplex).
    #[inline]
    pub fn put(&mut self, key: PairKey, warm: WarmStart) {
        self.store(key, warm, None);
    }

    /// [`WarmCache::put`], with the pair's certified answer.
    #[inline]
    pub fn put_with_bound(&mut self, key: PairKey, warm: WarmStart, bound: PairBound) {
        self.store(key, warm, Some(bound));
    }

    #[inline]
    fn store(&mut self, key: PairKey, warm: WarmStart, bound: Option<PairBound>) {
        if self.capacity == 0 {
            return;
        }
        if let Some(&i) = self.index.get(&key) {
            let slot = &mut self.slots[i as usize];
            slot.warm = warm;
            if bound.is_some() {
                slot.bound = bound;
            }
            slot.referenced = true;
            return;
        }
        let slot = Slot {
            key,
            warm,
            bound,
            referenced: false,
        };
        if self.slots.len() < self.capacity {
            self.index.insert(key, self.slots.len() as u32);
            self.slots.push(slot);
            return;
        }
        // Second chance: every referenced entry the hand passes loses its bit,
        // so the loop ends within two turns.
        loop {
            let hand = self.hand;
            self.hand = (self.hand + 1) % self.slots.len();
            let victim = &mut self.slots[hand];
            if victim.referenced {
                victim.referenced = false;
                continue;
            }
            self.index.remove(&victim.key);
            *victim = slot;
            self.index.insert(key, hand as u32);
            self.stats.evictions += 1;
            return;
        }
    }

    /// Drops every entry that names object `id` (after it is removed), so the
    /// memory goes back to live pairs at once instead of waiting for eviction.
    pub fn forget_object(&mut self, id: u64) {
        self.forget(|k| k.a == id || k.b == id);
    }

    /// Drops every entry of `client`.
    pub fn forget_client(&mut self, client: u128) {
        self.forget(|k| k.client == client);
    }

    /// Keeps only the entries for which `keep` is true.
    pub fn retain(&mut self, mut keep: impl FnMut(&PairKey) -> bool) {
        self.forget(|k| !keep(k));
    }

    fn forget(&mut self, mut doomed: impl FnMut(&PairKey) -> bool) {
        let before = self.slots.len();
        self.slots.retain(|s| !doomed(&s.key));
        if self.slots.len() != before {
            self.index.clear();
            for (i, s) in self.slots.iter().enumerate() {
                self.index.insert(s.key, i as u32);
            }
            self.hand = 0;
        }
    }

    /// Entries in use.
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// Whether the cache holds no entry.
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Most entries kept.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// Hit, miss and eviction counters.
    pub fn stats(&self) -> CacheStats {
        self.stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(a: u64) -> PairKey {
        PairKey {
            client: 7,
            a,
            b: a + 1,
        }
    }

    fn warm(i: u32) -> WarmStart {
        WarmStart::new([0, 0], &[[i, i]]).expect("one pair")
    }

    #[test]
    fn stays_within_capacity_and_counts_evictions() {
        let mut c = WarmCache::new(4);
        for a in 0..10 {
            c.put(key(a), warm(a as u32));
            assert!(c.len() <= 4);
        }
        assert_eq!(c.len(), 4);
        assert_eq!(c.stats().evictions, 6);
        assert!(c.get(&key(9)).is_some());
        assert!(c.get(&key(0)).is_none());
        assert_eq!(c.stats().hits, 1);
        assert_eq!(c.stats().misses, 1);
    }

    #[test]
    fn referenced_entries_get_a_second_chance() {
        let mut c = WarmCache::new(2);
        c.put(key(1), warm(1));
        c.put(key(2), warm(2));
        assert_eq!(c.get(&key(1)), Some(warm(1)));
        c.put(key(3), warm(3));
        assert_eq!(c.get(&key(1)), Some(warm(1)));
        assert_eq!(c.get(&key(2)), None);
    }

    #[test]
    fn clients_do_not_share_entries() {
        let mut c = WarmCache::new(8);
        c.put(key(1), warm(1));
        let other = PairKey {
            client: 8,
            ..key(1)
        };
        assert_eq!(c.get(&other), None);
    }

    #[test]
    fn forgetting_an_object_drops_its_pairs() {
        let mut c = WarmCache::new(8);
        c.put(key(1), warm(1));
        c.put(key(2), warm(2));
        c.put(key(5), warm(5));
        // key(1) is the pair (1, 2), key(2) the pair (2, 3).
        c.forget_object(2);
        assert_eq!(c.len(), 1);
        assert_eq!(c.get(&key(1)), None);
        assert_eq!(c.get(&key(5)), Some(warm(5)));
        c.forget_client(7);
        assert!(c.is_empty());
        c.put(key(9), warm(9));
        assert_eq!(c.get(&key(9)), Some(warm(9)));
    }

    #[test]
    fn zero_capacity_keeps_nothing() {
        let mut c = WarmCache::new(0);
        c.put(key(1), warm(1));
        assert!(c.is_empty());
        assert_eq!(c.get(&key(1)), None);
    }
}
