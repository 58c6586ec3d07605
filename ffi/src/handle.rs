//! The opaque handle behind `gjkd_client*`: the Rust client, the flag
//! that lets one call at a time use it, from any thread, and what this
//! handle registered to remove when it closes.
//!
//! The Rust client is not `Send`: iceoryx2's ports share their state
//! through `Rc`s, which two threads must never touch at once. Every one
//! of those `Rc`s lives inside this handle, so a handle used by one call
//! at a time (the `busy` flag, taken with `Acquire` and given back with
//! `Release`, orders each call after the previous one, on whatever thread)
//! never has two threads touching them at once: moving it from thread to
//! thread between calls, and closing it on another thread, is sound.

#![allow(non_camel_case_types)]

use std::sync::atomic::{AtomicBool, Ordering};

use rust_client::{Client, Item, ItemResult, ObjectId, QueryError};

use crate::status::{Failure, gjkd_status};
use crate::types::gjkd_registration_options;

/// Batch size assumed before a server has said its own.
const DEFAULT_MAX_BATCH: usize = 1024;

/// A connection to a gjkd server. Opaque: create it with `gjkd_connect()`,
/// use it from any thread, one call at a time, free it with `gjkd_close()`.
pub struct gjkd_client {
    /// The Rust client.
    pub client: Client,
    /// Set while a call uses the handle (see the module's words).
    busy: AtomicBool,
    /// A chunk's items, made here and then copied into the request in one
    /// piece (faster than writing shared memory item by item), kept from
    /// call to call.
    scratch: Vec<Item>,
    /// How registrations treat names and the handle's end.
    pub registration: gjkd_registration_options,
    /// Objects to remove when the handle closes (registered while
    /// `registration.remove_on_close` was set).
    pub doomed_objects: Vec<ObjectId>,
    /// Robots (by name) to remove when the handle closes.
    pub doomed_robots: Vec<String>,
}

impl gjkd_client {
    /// A handle, idle.
    pub fn new(client: Client) -> Self {
        gjkd_client {
            client,
            busy: AtomicBool::new(false),
            scratch: Vec::new(),
            registration: gjkd_registration_options::default(),
            doomed_objects: Vec::new(),
            doomed_robots: Vec::new(),
        }
    }

    /// Notes a registered object, to remove at close if so asked.
    pub fn registered(&mut self, id: ObjectId) {
        if self.registration.remove_on_close {
            self.doomed_objects.push(id);
        }
    }

    /// Notes a registered robot, to remove at close if so asked.
    pub fn registered_robot(&mut self, name: &str) {
        if self.registration.remove_on_close && !self.doomed_robots.iter().any(|n| n == name) {
            self.doomed_robots.push(name.to_owned());
        }
    }

    /// Removes what was registered to end with the handle: robots whole,
    /// then the other objects. Best effort: an object removed already, or
    /// a server gone, is skipped (a server gone keeps them; see
    /// `gjkd_registration_options`).
    pub fn remove_doomed(&mut self) {
        for name in std::mem::take(&mut self.doomed_robots) {
            let _ = self.client.remove_robot(&name);
        }
        for id in std::mem::take(&mut self.doomed_objects) {
            let _ = self.client.remove(id);
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
                Err(QueryError::BatchTooLarge) if self.max_batch() < max => {}
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
                Err(QueryError::BatchTooLarge) if self.max_batch() < max => {}
                Err(e) => return Err(e.into()),
            }
        }
        Ok(())
    }
}

impl gjkd_client {
    /// As [`gjkd_client::run_slices`], and the gradient of the `k`-th item
    /// that asks for one into `gradients[k]` (long enough for all of
    /// them); returns how many were written.
    ///
    /// # Errors
    /// As [`gjkd_client::run_slices`].
    pub fn run_slices_gradients(
        &mut self,
        items: &[Item],
        out: &mut [ItemResult],
        gradients: &mut [gjkd_proto::Gradient],
    ) -> Result<usize, Failure> {
        let (mut start, mut written) = (0, 0);
        while start < items.len() {
            let max = self.max_batch();
            let end = items.len().min(start + max);
            let chunk = self.client.query_batch_gradients(
                &items[start..end],
                &mut out[start..end],
                &mut gradients[written..],
            );
            match chunk {
                Ok(n) => {
                    start = end;
                    written += n;
                }
                // As in `run`.
                Err(QueryError::BatchTooLarge) if self.max_batch() < max => {}
                Err(e) => return Err(e.into()),
            }
        }
        Ok(written)
    }
}

/// Gives the handle back when a call ends, also by a panic.
struct Release<'a>(&'a AtomicBool);

impl Drop for Release<'_> {
    fn drop(&mut self) {
        self.0.store(false, Ordering::Release);
    }
}

/// Runs `body` on the handle at `client` after the NULL check, holding the
/// handle's `busy` flag: a call on another thread at the same moment is
/// refused with `GJKD_ERR_BUSY`, not run beside this one.
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
    // The flag is reached alone, without a reference to the whole handle,
    // which another thread may be using at this moment.
    // SAFETY: non-NULL, from gjkd_connect() by the caller's promise; an
    // atomic may be shared.
    let busy = unsafe { &*std::ptr::addr_of!((*client).busy) };
    if busy
        .compare_exchange(false, true, Ordering::Acquire, Ordering::Relaxed)
        .is_err()
    {
        return Err(Failure::new(
            gjkd_status::GJKD_ERR_BUSY,
            "the handle is in a call on another thread: a handle serves one call at a \
             time (hold a mutex around its calls, or use one handle per thread)",
        ));
    }
    let _release = Release(busy);
    // SAFETY: as above; the flag makes this the only call using it.
    body(unsafe { &mut *client })
}
