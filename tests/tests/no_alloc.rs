//! `Client::query_batch` and `query_batch_gradients` allocate nothing of
//! their own once connected: checked with a global allocator that counts
//! this thread's allocations.
//!
//! iceoryx2 0.10 itself makes exactly one small allocation per request: each
//! loan creates an `Rc` for its bookkeeping
//! (`ChunkMutSharedState::new` via `SingleThreaded::new`), and there is no
//! loan without one. The bound asserted is therefore one per call: anything
//! of gjkd's would add to it. Calls slow enough to reach the client's
//! liveness check (which lists iceoryx2's nodes) are not counted.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::time::{Duration, Instant};

use gjkd_client::{Gradient, Item, ItemResult, QueryOptions};
use gjkd_e2e::Server;
use nalgebra::{Isometry3, Vector3};

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

// SAFETY: forwards to the system allocator; the counter is a thread-local
// `Cell` of a `Copy` integer, which neither allocates nor panics.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Well below the client's first liveness check (20 ms into a wait), which
/// allocates.
const SLOW_PATH_AFTER: Duration = Duration::from_millis(10);

fn allocations() -> u64 {
    ALLOCATIONS.with(Cell::get)
}

#[test]
fn batches_and_single_queries_allocate_nothing_of_their_own() {
    let server = Server::start("alloc", &["--wait", "spin"]);
    let mut client = server.client(Duration::from_secs(5));
    let a = client
        .register_cuboid(Vector3::new(0.5, 0.5, 0.5), 0.0)
        .expect("a");
    let b = client.register_sphere(0.3).expect("b");
    let items: Vec<Item> = (0..64)
        .map(|k| {
            Item::distance(a, b, &QueryOptions::default()).with_pose_b(&Isometry3::translation(
                2.0 + 0.01 * k as f64,
                0.0,
                0.0,
            ))
        })
        .collect();
    let mut results = vec![ItemResult::default(); items.len()];
    // Every other item asks for its gradient, into the caller's buffer.
    let asking: Vec<Item> = items
        .iter()
        .enumerate()
        .map(|(k, i)| {
            if k % 2 == 1 {
                i.with_gradient(false)
            } else {
                *i
            }
        })
        .collect();
    let mut gradients = vec![Gradient::NONE; items.len() / 2];
    // The first calls may set up connections to the server's ports.
    for _ in 0..10 {
        client.query_batch(&items, &mut results).expect("batch");
        client
            .query_batch_gradients(&asking, &mut results, &mut gradients)
            .expect("gradients");
        client
            .distance(a, b, &QueryOptions::default())
            .expect("single");
    }
    // A call that waits long for its answer (a loaded machine) checks that
    // the server still lives, which lists iceoryx2's nodes and allocates:
    // that is the slow path's business, not the hot path's. Such calls are
    // told apart by their duration and left out of the count.
    let mut fast_calls = 0u64;
    let mut fast_allocations = 0u64;
    let mut measure = |call: &mut dyn FnMut()| {
        let before = allocations();
        let start = Instant::now();
        call();
        let spent = start.elapsed();
        let made = allocations() - before;
        if spent < SLOW_PATH_AFTER {
            fast_calls += 1;
            fast_allocations += made;
        }
    };
    for _ in 0..200 {
        measure(&mut || {
            client.query_batch(&items, &mut results).expect("batch");
        });
        measure(&mut || {
            client
                .distance(a, b, &QueryOptions::default())
                .expect("single");
        });
        measure(&mut || {
            client
                .query_batch_gradients(&asking, &mut results, &mut gradients)
                .expect("gradients");
        });
    }
    assert!(fast_calls > 0, "every call waited on the slow path");
    assert!(
        fast_allocations <= fast_calls,
        "{fast_allocations} allocations in {fast_calls} calls"
    );
    let d = results[0].answer().expect("ok").distance;
    assert!((d - 1.2).abs() < 1e-9, "{d}");
    // The sphere moves off along x, away from the box: moving the box
    // (A) along +x closes the gap one for one.
    assert!(
        gradients
            .iter()
            .all(|g| g.columns == 6 && (g.values[0] + 1.0).abs() < 1e-9),
        "{:?}",
        gradients[0]
    );
}
