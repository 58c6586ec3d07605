//! Arbitrary bytes as the request payloads a client can put in shared
//! memory: query items and admin requests with their vertex slices, fed to
//! the server's pure handlers. Nothing panics, and every answer is either an
//! error code or a result with ordered, NaN-free bounds.

#![no_main]

use std::sync::Mutex;

use gjkd_server::engine::{Limits, State};
use gjkd_proto::{
    AdminChunk, AdminOp, AdminRequest, Item, ItemResult, Vertex, WaitMode, shape_kind,
};
use libfuzzer_sys::fuzz_target;

/// Reinterprets bytes as `T`s: every wire type is plain old data whose every
/// bit pattern is valid (integers and floats only), which is what the
/// server relies on when it reads a client's shared memory.
fn read<T: Copy>(bytes: &[u8]) -> Vec<T> {
    let size = std::mem::size_of::<T>();
    bytes
        .chunks_exact(size)
        .map(|c| {
            // SAFETY: `c` is `size` bytes; `T` is a repr(C) wire type of
            // integers and floats, valid for any bits; read_unaligned copes
            // with the byte buffer's alignment.
            unsafe { std::ptr::read_unaligned(c.as_ptr().cast::<T>()) }
        })
        .collect()
}

/// One store shared by all runs, so that registrations from one input are
/// there for the queries of the next (as in a long-lived server); reset
/// when it gets big, so memory stays bounded.
static STATE: Mutex<Option<State>> = Mutex::new(None);

fuzz_target!(|data: &[u8]| {
    let Some((&op, rest)) = data.split_first() else {
        return;
    };
    let mut guard = STATE.lock().unwrap_or_else(|e| e.into_inner());
    if guard.as_ref().is_none_or(|s| s.len() > 256) {
        let limits = Limits {
            max_vertices: 4096,
            max_objects: 512,
            cache_capacity: 256,
            ..Limits::default()
        };
        *guard = Some(State::new(limits, WaitMode::Spin, 7));
    }
    let state = guard.as_mut().expect("just set");
    let client = u128::from(op % 3);
    if op % 2 == 0 {
        // The header is larger than libFuzzer's default input limit, so the
        // input overwrites a prefix of a plausible registration (chosen by
        // the first byte, in 8-byte steps) and the rest is the vertex slice.
        let Some((&len, rest)) = rest.split_first() else {
            return;
        };
        let split = (usize::from(len) * 8)
            .min(rest.len())
            .min(std::mem::size_of::<AdminRequest>());
        let (head, tail) = rest.split_at(split);
        let mut request = AdminRequest::new(AdminOp::Register);
        request.shape = shape_kind::CONVEX;
        request.piece_count = 1;
        let mut vertices = read::<Vertex>(tail);
        if op & 0x10 != 0 && !vertices.is_empty() {
            // Large enough for the block search (512 vertices and up), which
            // inputs of libFuzzer's usual sizes never reach on their own:
            // scaled copies of the given points, so that extremes and exact
            // ties repeat across blocks.
            let n = vertices.len();
            let steps = [1.0, 0.5, 0.25, 1.0 - 1e-9, 0.999];
            vertices = (0..512 + n)
                .map(|k| {
                    let (v, s) = (vertices[k % n], steps[(k / n) % steps.len()]);
                    Vertex {
                        x: v.x * s,
                        y: v.y * s,
                        z: v.z * s,
                    }
                })
                .collect();
        }
        request.pieces[0].vertex_count = vertices.len() as u32;
        // SAFETY: `head` is at most the size of AdminRequest, a repr(C)
        // struct of integers, floats and byte arrays, valid for any bits.
        unsafe {
            std::ptr::copy_nonoverlapping(
                head.as_ptr(),
                (&raw mut request).cast::<u8>(),
                head.len(),
            );
        }
        // Often a real operation, so the decoder gets past the first check.
        if op % 4 == 0 {
            request.op = AdminOp::Register as u32;
        }
        let reply = state.handle_admin(client, &request, AdminChunk::from_vertices(&vertices));
        if reply.error == 0 && request.op == AdminOp::Register as u32 {
            assert!(state.object(reply.id).is_some(), "acknowledged but absent");
        }
    } else {
        let mut items = read::<Item>(rest);
        // Point some items at objects that exist, so queries get computed.
        let ids: Vec<u64> = state.snapshot().objects.iter().map(|o| o.id).collect();
        if !ids.is_empty() {
            for (k, item) in items.iter_mut().enumerate() {
                if item.flags & 0x100 != 0 {
                    item.a = ids[(item.a as usize) % ids.len()];
                    item.b = ids[(item.b as usize).wrapping_add(k) % ids.len()];
                    item.flags &= 0xff;
                    item.kind = 1 + item.kind % 2;
                }
            }
        }
        let len = items.len();
        if state.check_batch(len).is_err() {
            return;
        }
        let mut results = vec![ItemResult::default(); len];
        state.handle(client, &items, &mut results);
        for r in &results {
            if let Ok(a) = r.answer() {
                if a.status.is_none() {
                    continue;
                }
                assert!(!a.distance.is_nan() && !a.lower.is_nan() && !a.upper.is_nan());
                assert!(a.lower <= a.distance && a.distance <= a.upper, "{a:?}");
            }
        }
    }
});
