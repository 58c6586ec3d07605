//! The opaque handle behind `gjkd_client*`: the Rust client and the
//! thread it belongs to.

#![allow(non_camel_case_types)]

use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};

use rust_client::{Client, ClientError, ErrorCode, Item, ItemResult};

use crate::status::{Failure, gjkd_status};

/// Batch size assumed before a server has said its own.
const DEFAULT_MAX_BATCH: usize = 1024;

/// A connection to a gjkd server. Opaque: create it with `gjkd_connect()`,
/// use it from the thread that created it, free it with `gjkd_close()`.
pub struct gjkd_client {
    /// The Rust client.
    pub client: Client,
    /// The thread that created the handle (iceoryx2 ports are bound to it).
    owner: u64,
    /// A chunk's items, made here and then copied into the request in one
    /// piece (faster than writing shared memory item by item), kept from
    /// call to call.
    scratch: Vec<Item>,
}

/// A number per thread, for telling the owner thread from others without
/// the cost of `std::thread::current()`.
fn thread_token() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    thread_local! {
        static TOKEN: Cell<u64> = const { Cell::new(0) };
    }
    TOKEN.with(|t| {
        if t.get() == 0 {
            t.set(NEXT.fetch_add(1, Ordering::Relaxed));
        }
        t.get()
    })
}

impl gjkd_client {
    /// A handle owned by the calling thread.
    pub fn new(client: Client) -> Self {
        gjkd_client {
            client,
            owner: thread_token(),
            scratch: Vec::new(),
        }
    }

    /// Most items the server takes in one request, as last heard.
    pub fn max_batch(&self) -> usize {
        self.client
            .server_info()
            .map_or(DEFAULT_MAX_BATCH, |i| (i.max_batch as usize).max(1))
    }

    /// Sends the `n` items `item(i)` in chunks the server takes, each
    /// made in the handle's scratch buffer and copied into shared memory in
    /// one piece, and hands each chunk's results, straight from shared
    /// memory, to `sink(first_index, results)`.
    ///
    /// # Errors
    /// The first whole-request failure; chunks before it were answered.
    pub fn run(
        &mut self,
        n: usize,
        item: impl Fn(usize) -> Item,
        mut sink: impl FnMut(usize, &[ItemResult]),
    ) -> Result<(), Failure> {
        let mut start = 0;
        while start < n {
            let max = self.max_batch();
            let end = n.min(start + max);
            self.scratch.clear();
            self.scratch.extend((start..end).map(&item));
            let outcome = self
                .client
                .query_batch_read(&self.scratch, |r| sink(start, r));
            match outcome {
                Ok(()) => start = end,
                // The server may have restarted with a smaller limit: the
                // client knows the new one after its reconnect.
                Err(ClientError::Rejected(ErrorCode::BatchTooLarge)) if self.max_batch() < max => {}
                Err(e) => return Err(e.into()),
            }
        }
        Ok(())
    }
}

impl gjkd_client {
    /// Sends `items` in chunks the server takes, each copied into the
    /// request in one piece, and copies each chunk's results, whole, into
    /// the same rows of `out` (as long as `items`).
    ///
    /// # Errors
    /// The first whole-request failure; chunks before it were answered.
    pub fn run_slices(&mut self, items: &[Item], out: &mut [ItemResult]) -> Result<(), Failure> {
        let mut start = 0;
        while start < items.len() {
            let max = self.max_batch();
            let end = items.len().min(start + max);
            let chunk = self
                .client
                .query_batch(&items[start..end], &mut out[start..end]);
            match chunk {
                Ok(()) => start = end,
                // As in `run`.
                Err(ClientError::Rejected(ErrorCode::BatchTooLarge)) if self.max_batch() < max => {}
                Err(e) => return Err(e.into()),
            }
        }
        Ok(())
    }
}

/// Whether the calling thread is the handle's `owner`.
fn check_thread(owner: u64) -> Result<(), Failure> {
    if owner == thread_token() {
        Ok(())
    } else {
        Err(Failure::new(
            gjkd_status::GJKD_ERR_WRONG_THREAD,
            "the handle belongs to another thread: create one handle per thread",
        ))
    }
}

/// Runs `body` on the handle at `client` after the NULL and thread checks.
///
/// # Safety
/// A non-NULL `client` must come from `gjkd_connect()` and not be closed.
pub unsafe fn with_client(
    client: *mut gjkd_client,
    body: impl FnOnce(&mut gjkd_client) -> Result<(), Failure>,
) -> Result<(), Failure> {
    if client.is_null() {
        return Err(Failure::null("client"));
    }
    // The owner is read alone, without a reference to the whole handle,
    // which its own thread may be using at this moment; it never changes.
    // SAFETY: non-NULL, from gjkd_connect() by the caller's promise.
    let owner = unsafe { std::ptr::addr_of!((*client).owner).read() };
    check_thread(owner)?;
    // SAFETY: as above; only the owner thread gets here, one call at a time.
    body(unsafe { &mut *client })
}
