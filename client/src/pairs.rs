//! Pair queries: pose updates and distances between named pairs, one at a
//! time or in batches.

use std::time::Instant;

use iceoryx2::prelude::*;
use nalgebra::Isometry3;

#[cfg(doc)]
use crate::ServerInfo;
use gjkd_proto::{Gradient, GradientRow, ReplyEntry, item_flags};

use crate::op_error::NO_GRADIENT_BUFFER;
use crate::{
    Answer, Client, ClientError, ErrorCode, Item, ItemResult, ObjectId, PoseError, QueryError,
    QueryOptions, Waited, ipc_err, op_error, reply_accepted,
};

/// The query error of a failure of the shared plumbing: a gradient asked
/// with no room for it is the caller's, the rest as [`op_error`] says.
fn query_error(e: ClientError) -> QueryError {
    match e {
        ClientError::InvalidArgument(NO_GRADIENT_BUFFER) => QueryError::NoRoomForGradient,
        e => op_error(e),
    }
}

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
    /// small allocation per request for its loan bookkeeping). Items that
    /// ask for a gradient go through [`Client::query_batch_gradients`].
    ///
    /// # Errors
    /// [`QueryError::ResultBufferTooSmall`];
    /// [`QueryError::NoRoomForGradient`] when an item asks for a gradient
    /// (nothing is sent); [`QueryError::EmptyBatch`] or
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
        self.batch(items, results).map_err(query_error)
    }

    /// As [`Client::query_batch`], and the gradient of the `k`-th item that
    /// asks for one ([`Item::with_gradient`], see [`Gradient`]) into
    /// `gradients[k]`, a buffer the caller owns and keeps from call to
    /// call ([`Gradient::NONE`] for an item that failed). Only the items
    /// that ask carry a gradient, in the reply too. Returns how many
    /// gradients were written.
    ///
    /// # Errors
    /// As [`Client::query_batch`], and [`QueryError::NoRoomForGradient`]
    /// when `gradients` is shorter than the items that ask for one
    /// (nothing is sent).
    pub fn query_batch_gradients(
        &mut self,
        items: &[Item],
        results: &mut [ItemResult],
        gradients: &mut [Gradient],
    ) -> Result<usize, QueryError> {
        if results.len() < items.len() {
            return Err(QueryError::ResultBufferTooSmall {
                needed: items.len(),
                got: results.len(),
            });
        }
        let asked = ReplyEntry::gradients_asked(items);
        if asked > gradients.len() {
            return Err(QueryError::NoRoomForGradient);
        }
        self.batch_gradients(items, results, gradients)
            .map_err(query_error)?;
        Ok(asked)
    }

    /// [`Client::query_batch_gradients`] for the calls built on it
    /// (`gradients` has room for every gradient asked).
    pub(crate) fn batch_gradients(
        &mut self,
        items: &[Item],
        results: &mut [ItemResult],
        gradients: &mut [Gradient],
    ) -> Result<(), ClientError> {
        self.round_trip(
            items.len(),
            Source::<fn(usize) -> Item>::Slice(items),
            Gradients::Taken,
            |payload, rows| {
                results[..payload.len()].copy_from_slice(payload);
                for (out, row) in gradients.iter_mut().zip(rows) {
                    *out = row.gradient;
                }
            },
        )
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
            Gradients::Refused,
            |payload, _| results[..payload.len()].copy_from_slice(payload),
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
        self.round_trip(
            items.len(),
            Source::<fn(usize) -> Item>::Slice(items),
            Gradients::Refused,
            |results, _| read(results),
        )
        .map_err(query_error)
    }

    /// As [`Client::query_batch_read`], for items that may ask for
    /// gradients: `read` gets the results and, straight from the
    /// response's shared memory too, the gradient rows, one per item that
    /// asked, in item order ([`GradientRow::item`] names it).
    ///
    /// # Errors
    /// As [`Client::query_batch`], but for gradients.
    pub fn query_batch_read_gradients(
        &mut self,
        items: &[Item],
        read: impl FnOnce(&[ItemResult], &[GradientRow]),
    ) -> Result<(), QueryError> {
        self.round_trip(
            items.len(),
            Source::<fn(usize) -> Item>::Slice(items),
            Gradients::Taken,
            read,
        )
        .map_err(query_error)
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
        self.round_trip(count, Source::Fn(item), Gradients::Refused, |results, _| {
            read(results)
        })
        .map_err(query_error)
    }

    /// Sends `count` items from `source` as one request and hands the
    /// results and the gradient rows to `read`.
    fn round_trip<F: FnMut(usize) -> Item>(
        &mut self,
        count: usize,
        source: Source<'_, F>,
        gradients: Gradients,
        read: impl FnOnce(&[ItemResult], &[GradientRow]),
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
            // A gradient asked with nowhere to go is refused before anything
            // is sent (one pass over the flags, branch-free).
            if matches!(gradients, Gradients::Refused)
                && request.payload().iter().fold(0, |acc, i| acc | i.flags) & item_flags::GRADIENT
                    != 0
            {
                return Err(Waited::Failed(ClientError::InvalidArgument(
                    NO_GRADIENT_BUFFER,
                )));
            }
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
                let rows = header.gradients as usize;
                let split = ReplyEntry::split(payload, count)
                    .filter(|_| header.count as usize == count && payload.len() == count + rows);
                let Some((results, gradient_rows)) = split else {
                    return Err(ClientError::Protocol(format!(
                        "{} entries ({} results, {} gradients) for {} items",
                        payload.len(),
                        header.count,
                        rows,
                        count
                    )));
                };
                if let Some(read) = read.take() {
                    read(results, gradient_rows);
                }
                Ok(Some(()))
            })
        })();
        self.settle(outcome)
    }
}

/// Whether a call takes the gradients its items ask for.
#[derive(Clone, Copy)]
enum Gradients {
    /// It has nowhere to put them: an item that asks is refused.
    Refused,
    /// It hands them to its reader.
    Taken,
}

/// Where the items of a request come from.
enum Source<'a, F> {
    /// A caller's slice, copied as it is.
    Slice(&'a [Item]),
    /// Made one by one into the request.
    Fn(F),
}
