//! How the serving loop spends a turn with nothing to answer: spin (look
//! again at once) or sleep on the wake event until a client notifies.
//!
//! The policy never yields the CPU while spinning. `sched_yield` gives the
//! CPU to any other runnable thread on it, and when that thread is a busy
//! neighbour (a perception process, a compiler) the server gets the CPU back
//! only when the neighbour's time slice ends, milliseconds later; a request
//! arriving meanwhile waits all that time, because a thread that is
//! runnable but not running cannot be woken any sooner. That was the
//! collapse of the old `adaptive` mode beside one busy process. A thread
//! that sleeps on an event instead is woken by the client's notify; with a
//! short time slice (`gjkd_rt::request_short_slice`, which the server asks
//! for when it may sleep) the scheduler lets it preempt the neighbour at
//! once.
//!
//! `adaptive` spins only while spinning pays: it keeps a running estimate
//! of the idle time before each request (the time from one answer to the
//! next request, sleeps included) and, while that estimate is below
//! [`MAX_SPIN`], spins for about twice it before sleeping. Back-to-back
//! requests (idle times of a few µs) are answered at spinning speed; paced
//! ones whose gap is longer than [`MAX_SPIN`] (a control loop's) find the
//! server asleep and woken at once, exactly as `block` serves them, without
//! a spin that would hold the CPU from the client or a neighbour for
//! nothing.
//!
//! A spin that ends without a request is a miss, and each miss doubles the
//! number of requests served without spinning (up to [`MAX_BACKOFF`]); a
//! spin that catches a request halves it again. That covers the case the estimate cannot see: a client
//! the scheduler put on the server's own CPU cannot send while the server
//! spins, so every spin misses, and the server must sleep at once to let
//! it run, as `block` does.

use std::time::{Duration, Instant};

use gjkd_proto::WaitMode;

/// The longest `adaptive` spins after a request before it sleeps, and the
/// estimated idle time above which it does not spin at all. Long enough to
/// cover a client's turnaround between the queries of one control cycle,
/// short enough that a spin never holds the CPU long from a neighbour.
pub const MAX_SPIN: Duration = Duration::from_micros(50);

/// The shortest spin `adaptive` does when it spins: covers the client's own
/// turnaround between back-to-back requests.
pub const MIN_SPIN: Duration = Duration::from_micros(5);

/// Most requests served without spinning after spins that missed.
pub const MAX_BACKOFF: u32 = 256;

/// What to do with an idle turn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Idle {
    /// Look for requests again at once.
    Spin,
    /// Sleep on the wake event until a client notifies (or the loop's
    /// housekeeping slice passes).
    Sleep,
}

/// The wait policy of one serving loop: its mode, when it last served and
/// what it learnt about the idle times between requests.
#[derive(Clone, Copy, Debug)]
pub struct WaitPolicy {
    mode: WaitMode,
    /// When the last request was answered.
    last_request: Instant,
    /// When the loop last found nothing to answer (or woke from a sleep).
    last_idle: Instant,
    /// Running estimate of the idle time before a request, in ns (each new
    /// idle time, capped at twice [`MAX_SPIN`], counts for half).
    idle_estimate_ns: u64,
    /// Spins that ended without a request, less those that caught one
    /// since (the back-off's exponent).
    misses: u32,
    /// Requests still to be served without spinning after them.
    backoff: u32,
    /// Whether the current idle time began with a spin that already
    /// counted as a miss, or slept: only its first expiry is a miss.
    settled: bool,
}

impl WaitPolicy {
    /// The policy of `mode`, as if a request had just been served at `now`
    /// after no idle time (a fresh `adaptive` server starts out spinning).
    pub fn new(mode: WaitMode, now: Instant) -> Self {
        WaitPolicy {
            mode,
            last_request: now,
            last_idle: now,
            idle_estimate_ns: 0,
            misses: 0,
            backoff: 0,
            settled: false,
        }
    }

    /// Records that requests were answered at `now`: the idle time that
    /// ended with them (from the previous answer to the last idle turn or
    /// wake-up before them) goes into the estimate.
    pub fn served(&mut self, now: Instant) {
        let cap = 2 * MAX_SPIN.as_nanos() as u64;
        let idle = self.last_idle.saturating_duration_since(self.last_request);
        if !self.settled && self.backoff == 0 && idle < self.spin_window() {
            // Caught while spinning: the spin paid, and the next miss backs
            // off a little less. Not all the way: a client that shares the
            // server's CPU now and then is still caught by a spin at times,
            // and starting the back-off over at each such catch would spend
            // a spin-long delay on a request every few hundred.
            self.misses = self.misses.saturating_sub(1);
        }
        let sample = (idle.as_nanos() as u64).min(cap);
        self.idle_estimate_ns = (self.idle_estimate_ns + sample) / 2;
        self.backoff = self.backoff.saturating_sub(1);
        self.settled = false;
        self.last_request = now;
        self.last_idle = now;
    }

    /// Records that the loop woke from a sleep at `now`.
    pub fn woke(&mut self, now: Instant) {
        self.last_idle = now;
    }

    /// When a request was last answered.
    pub fn last_request(&self) -> Instant {
        self.last_request
    }

    /// The estimated idle time before the next request.
    pub fn idle_estimate(&self) -> Duration {
        Duration::from_nanos(self.idle_estimate_ns)
    }

    /// How long `adaptive` spins after a request before sleeping, given
    /// what it learnt: zero when requests come further apart than
    /// [`MAX_SPIN`] or while backing off after misses.
    pub fn spin_window(&self) -> Duration {
        match self.mode {
            WaitMode::Spin => Duration::MAX,
            WaitMode::Block => Duration::ZERO,
            WaitMode::Adaptive if self.backoff > 0 => Duration::ZERO,
            WaitMode::Adaptive => {
                let estimate = self.idle_estimate();
                if estimate >= MAX_SPIN {
                    Duration::ZERO
                } else {
                    (2 * estimate).clamp(MIN_SPIN, MAX_SPIN)
                }
            }
        }
    }

    /// What an idle turn at `now` does.
    pub fn idle(&mut self, now: Instant) -> Idle {
        self.last_idle = now;
        let window = self.spin_window();
        if now.duration_since(self.last_request) < window {
            return Idle::Spin;
        }
        if !self.settled && window > Duration::ZERO && self.mode == WaitMode::Adaptive {
            // The spin ran out: a miss, and a longer backoff.
            self.misses = (self.misses + 1).min(MAX_BACKOFF.ilog2());
            self.backoff = 1 << self.misses;
        }
        self.settled = true;
        Idle::Sleep
    }

    /// Requests left to serve without spinning.
    pub fn backoff(&self) -> u32 {
        self.backoff
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const US: Duration = Duration::from_micros(1);

    /// Feeds `policy` requests `gap` apart, each answered `work` after it
    /// arrived, the loop spinning or sleeping in between as the policy says
    /// (a sleep lasts until the request); returns the number of requests
    /// that found it asleep.
    fn paced(policy: &mut WaitPolicy, start: Instant, gap: Duration, n: u32) -> (Instant, u32) {
        let work = US;
        let mut now = start;
        let mut slept = 0;
        for _ in 0..n {
            let arrival = now + gap;
            // Idle turns every 100 ns until the request or a sleep.
            let mut t = now;
            let mut asleep = false;
            while t < arrival {
                if policy.idle(t) == Idle::Sleep {
                    asleep = true;
                    break;
                }
                t += Duration::from_nanos(100);
            }
            if asleep {
                slept += 1;
                policy.woke(arrival);
            }
            now = arrival + work;
            policy.served(now);
        }
        (now, slept)
    }

    #[test]
    fn spin_never_sleeps_and_block_always_sleeps() {
        let t0 = Instant::now();
        let mut spin = WaitPolicy::new(WaitMode::Spin, t0);
        let mut block = WaitPolicy::new(WaitMode::Block, t0);
        for later in [Duration::ZERO, MAX_SPIN, Duration::from_secs(3600)] {
            assert_eq!(spin.idle(t0 + later), Idle::Spin);
            assert_eq!(block.idle(t0 + later), Idle::Sleep);
        }
        let (_, slept) = paced(&mut block, t0, 2 * US, 50);
        assert_eq!(slept, 50);
        let (_, slept) = paced(&mut spin, t0, 10 * MAX_SPIN, 50);
        assert_eq!(slept, 0);
    }

    #[test]
    fn adaptive_spins_through_back_to_back_requests() {
        let t0 = Instant::now();
        let mut p = WaitPolicy::new(WaitMode::Adaptive, t0);
        let (_, slept) = paced(&mut p, t0, 2 * US, 1000);
        assert_eq!(slept, 0);
        assert!(p.idle_estimate() < 3 * US, "{:?}", p.idle_estimate());
        assert_eq!(p.spin_window(), MIN_SPIN);
    }

    #[test]
    fn adaptive_sleeps_at_once_between_requests_paced_beyond_its_spin() {
        let t0 = Instant::now();
        let mut p = WaitPolicy::new(WaitMode::Adaptive, t0);
        // A 1 kHz loop and a 100 µs one: after the first few requests, every
        // one finds the server asleep, and no spin is spent before sleeping.
        for gap in [1000 * US, 100 * US] {
            let (end, slept) = paced(&mut p, t0, gap, 200);
            assert!(slept >= 198, "gap {gap:?}: {slept} of 200 asleep");
            assert_eq!(p.spin_window(), Duration::ZERO);
            assert_eq!(p.idle(end + Duration::from_nanos(1)), Idle::Sleep);
        }
    }

    /// As `paced`, but the client shares the server's CPU: it cannot send
    /// while the server spins, so each request arrives `gap` after the
    /// server stops spinning (or after the answer, when it sleeps at once).
    fn co_located(
        policy: &mut WaitPolicy,
        start: Instant,
        gap: Duration,
        n: u32,
    ) -> (Instant, u32) {
        let mut now = start;
        let mut spun = 0;
        for _ in 0..n {
            let mut t = now;
            while policy.idle(t) == Idle::Spin {
                t += Duration::from_nanos(100);
            }
            if t > now {
                spun += 1;
            }
            let arrival = t + gap;
            policy.woke(arrival);
            now = arrival + US;
            policy.served(now);
        }
        (now, spun)
    }

    #[test]
    fn adaptive_stops_spinning_when_its_spins_keep_missing() {
        let t0 = Instant::now();
        let mut p = WaitPolicy::new(WaitMode::Adaptive, t0);
        // Every spin misses: after the first few, only one request in
        // MAX_BACKOFF spins before sleeping.
        let (end, spun) = co_located(&mut p, t0, 2 * US, 2000);
        assert!(spun <= 8 + 2000 / MAX_BACKOFF, "{spun} of 2000 spun");
        // The client moves to a CPU of its own: spinning comes back within
        // one backoff.
        let (_, slept) = paced(&mut p, end, 2 * US, 2 * MAX_BACKOFF);
        let (_, slept_after) = paced(&mut p, end, 2 * US, 100);
        assert!(slept <= MAX_BACKOFF + 1, "{slept}");
        assert_eq!(slept_after, 0);
    }

    #[test]
    fn adaptive_seldom_spins_for_a_client_that_mostly_shares_its_cpu() {
        let t0 = Instant::now();
        let mut p = WaitPolicy::new(WaitMode::Adaptive, t0);
        // The scheduler puts the client on the server's CPU for about two
        // requests in three, on the other for the rest (where a spin catches
        // it). A spin that misses delays its request by the spin: fewer
        // than one request in 100 may meet one, or the 99th percentile is
        // a spin slower than `block`'s.
        let mut now = t0;
        let mut rng = 0x2545_f491_4f6c_dd1d_u64;
        let (mut delayed, n) = (0, 20_000);
        for _ in 0..n {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            if rng.is_multiple_of(3) {
                now = paced(&mut p, now, 2 * US, 1).0;
            } else {
                let (end, spun) = co_located(&mut p, now, 2 * US, 1);
                now = end;
                delayed += spun;
            }
        }
        assert!(
            delayed * 100 < n,
            "{delayed} of {n} requests waited for a spin"
        );
    }

    #[test]
    fn adaptive_learns_back_a_burst_after_sleeping() {
        let t0 = Instant::now();
        let mut p = WaitPolicy::new(WaitMode::Adaptive, t0);
        let (end, _) = paced(&mut p, t0, 1000 * US, 50);
        assert_eq!(p.spin_window(), Duration::ZERO);
        // A burst: the first requests find it asleep, then it spins.
        let (end, slept) = paced(&mut p, end, 2 * US, 100);
        assert!(slept <= 8, "{slept} of 100 asleep");
        assert!(p.spin_window() <= 2 * MIN_SPIN);
        // Requests 10 µs apart are caught by the spin too, once the first
        // few have stretched the window.
        let (_, slept) = paced(&mut p, end, 10 * US, 100);
        assert!(slept <= 3, "{slept} of 100 asleep");
        assert!(p.spin_window() >= 15 * US && p.spin_window() <= 25 * US);
    }
}
