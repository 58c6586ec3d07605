//! `Client::query_batch` allocates nothing of its own once connected:
//! checked with a global allocator that counts this thread's allocations.
//!
//! iceoryx2 0.10 itself makes exactly one small allocation per request: each
//! loan creates an `Rc` for its bookkeeping
//! (`ChunkMutSharedState::new` via `SingleThreaded::new`), and there is no
//! loan without one. The bound asserted is therefore one per call: anything
//! of gjkd's would add to it.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::time::Duration;

use gjkd_client::{Item, ItemResult, QueryOptions};
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
    // The first calls may set up connections to the server's ports.
    for _ in 0..10 {
        client.query_batch(&items, &mut results).expect("batch");
        client
            .distance(a, b, &QueryOptions::default())
            .expect("single");
    }
    let before = allocations();
    for _ in 0..200 {
        client.query_batch(&items, &mut results).expect("batch");
        client
            .distance(a, b, &QueryOptions::default())
            .expect("single");
    }
    let during = allocations() - before;
    assert!(during <= 400, "{during} allocations in 400 calls");
    let d = results[0].answer().expect("ok").distance;
    assert!((d - 1.2).abs() < 1e-9, "{d}");
}
