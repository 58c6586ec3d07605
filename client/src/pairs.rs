//! Pair queries: pose updates and distances between named pairs, one at a
//! time or in batches.

use std::time::Instant;

use iceoryx2::prelude::*;
use nalgebra::Isometry3;

#[cfg(doc)]
use crate::ServerInfo;
use crate::{
    Answer, Client, ClientError, ErrorCode, Item, ItemResult, ObjectId, PoseError, QueryError,
    QueryOptions, Waited, ipc_err, op_error, reply_accepted,
};

impl Client {
    /// Stores a new pose for `id`, used by every later query (of any client)
    /// that does not give its own.
    ///
    /// # Errors
    /// [`PoseError::UnknownObject`], [`PoseError::NonFinitePose`],
    /// [`PoseError::BadQuaternion`], and the connection faults.
    pub fn set_pose(&mut self, id: ObjectId, pose: &Isometry3<f64>) -> Result<(), PoseError> {
        self.single(Item::set_pose(id, pose))
            .map(|_| ())
            .map_err(op_error)
    }

    /// Distance between `a` and `b` at their stored poses.
    ///
    /// # Errors
    /// [`QueryError::UnknownObject`], [`QueryError::InvalidOptions`],
    /// [`QueryError::NonFinitePose`] (the two objects too far apart), and
    /// the connection faults.
    pub fn distance(
        &mut self,
        a: ObjectId,
        b: ObjectId,
        options: &QueryOptions,
    ) -> Result<Answer, QueryError> {
        self.single(Item::distance(a, b, options)).map_err(op_error)
    }

    /// Distance between `a` at `pose_a` and `b` at `pose_b`; the stored poses
    /// are neither used nor changed.
    ///
    /// # Errors
    /// As [`Client::distance`], plus [`QueryError::NonFinitePose`] and
    /// [`QueryError::BadQuaternion`] for a pose given.
    pub fn distance_at(
        &mut self,
        a: ObjectId,
        pose_a: &Isometry3<f64>,
        b: ObjectId,
        pose_b: &Isometry3<f64>,
        options: &QueryOptions,
    ) -> Result<Answer, QueryError> {
        self.single(Item::distance_at(a, pose_a, b, pose_b, options))
            .map_err(op_error)
    }

    /// The answer to one item, its refusal as the request's.
    pub(crate) fn single(&mut self, item: Item) -> Result<Answer, ClientError> {
        let mut out = [ItemResult::error(ErrorCode::Internal)];
        self.batch(&[item], &mut out)?;
        out[0].answer().map_err(ClientError::Rejected)
    }

    /// Sends `items` as one request and writes the answer to `items[i]` into
    /// `results[i]`. Items are applied in order, so a pose update affects the
    /// queries after it. Each result has its own error code (see
    /// [`ItemResult::answer`]); the call itself fails only if the whole
    /// request does. Allocates nothing of its own (iceoryx2 0.10 makes one
    /// small allocation per request for its loan bookkeeping).
    ///
    /// # Errors
    /// [`QueryError::ResultBufferTooSmall`]; [`QueryError::EmptyBatch`] or
    /// [`QueryError::BatchTooLarge`] (more than [`ServerInfo::max_batch`]
    /// items); and the connection faults.
    pub fn query_batch(
        &mut self,
        items: &[Item],
        results: &mut [ItemResult],
    ) -> Result<(), QueryError> {
        if results.len() < items.len() {
            return Err(QueryError::ResultBufferTooSmall {
                needed: items.len(),
                got: results.len(),
            });
        }
        self.batch(items, results).map_err(op_error)
    }

    /// [`Client::query_batch`] for the calls built on it, which say what
    /// its failures mean for them; `results` holds one per item.
    pub(crate) fn batch(
        &mut self,
        items: &[Item],
        results: &mut [ItemResult],
    ) -> Result<(), ClientError> {
        self.round_trip(
            items.len(),
            Source::<fn(usize) -> Item>::Slice(items),
            |payload| results[..payload.len()].copy_from_slice(payload),
        )
    }

    /// As [`Client::query_batch`], but the results are handed to `read`
    /// straight from the response's shared memory (`read` is called once,
    /// with `items.len()` results, if the request succeeds): for bindings
    /// that keep results in layouts of their own but can make their items
    /// as a slice first, which is copied into the request in one piece.
    ///
    /// # Errors
    /// As [`Client::query_batch`].
    pub fn query_batch_read(
        &mut self,
        items: &[Item],
        read: impl FnOnce(&[ItemResult]),
    ) -> Result<(), QueryError> {
        self.round_trip(items.len(), Source::<fn(usize) -> Item>::Slice(items), read)
            .map_err(op_error)
    }

    /// As [`Client::query_batch`], but item `i` of the `count` items is
    /// made by `item(i)` and written straight into the request's shared
    /// memory, and the results are handed to `read` straight from the
    /// response's (`read` is called once, with `count` results, if the
    /// request succeeds). For bindings whose callers keep items and
    /// results in layouts of their own: neither needs a buffer in between.
    ///
    /// # Errors
    /// As [`Client::query_batch`].
    pub fn query_batch_with(
        &mut self,
        count: usize,
        item: impl FnMut(usize) -> Item,
        read: impl FnOnce(&[ItemResult]),
    ) -> Result<(), QueryError> {
        self.round_trip(count, Source::Fn(item), read)
            .map_err(op_error)
    }

    /// Sends `count` items from `source` as one request and hands the
    /// results to `read`.
    fn round_trip<F: FnMut(usize) -> Item>(
        &mut self,
        count: usize,
        source: Source<'_, F>,
        read: impl FnOnce(&[ItemResult]),
    ) -> Result<(), ClientError> {
        let deadline = Instant::now() + self.timeout;
        self.ensure_connected(deadline)?;
        let conn = self.conn.as_ref().ok_or_else(|| self.gone())?;
        let mut read = Some(read);
        let outcome = (|| {
            if conn.query_service.dynamic_config().number_of_servers() == 0 {
                return Err(Waited::Gone);
            }
            let loan = conn
                .query
                .loan_slice_uninit(count)
                .map_err(|e| Waited::Failed(ipc_err("query loan")(e)))?;
            let request = match source {
                Source::Slice(items) => loan.write_from_slice(items),
                Source::Fn(item) => loan.write_from_fn(item),
            };
            let pending = request
                .send()
                .map_err(|e| conn.send_failed(&self.node, "query send", e))?;
            if conn.notify_queries {
                let _ = conn.wake.notify();
            }
            Self::await_reply(&self.node, conn, deadline, self.timeout, || {
                let Some(response) = pending.receive().map_err(ipc_err("query receive"))? else {
                    return Ok(None);
                };
                let header = *response.user_header();
                reply_accepted(header.error)?;
                let payload = response.payload();
                if payload.len() != count {
                    return Err(ClientError::Protocol(format!(
                        "{} results for {} items",
                        payload.len(),
                        count
                    )));
                }
                if let Some(read) = read.take() {
                    read(payload);
                }
                Ok(Some(()))
            })
        })();
        self.settle(outcome)
    }
}

/// Where the items of a request come from.
enum Source<'a, F> {
    /// A caller's slice, copied as it is.
    Slice(&'a [Item]),
    /// Made one by one into the request.
    Fn(F),
}
