//! Distance gradients: which way each joint (or an object's pose) should
//! move to increase a pair's distance, answered by the server in the same
//! round trip as the distance.
//!
//! [`Client::distance_gradient`] asks one pair;
//! [`Client::query_batch_gradients`] a batch, the gradients of the items
//! that ask ([`Item::with_gradient`]) into a buffer the caller owns (only
//! they carry one, on the wire too). A scene question asks every row's
//! with [`SceneQuery::gradients`](crate::SceneQuery::gradients), each
//! row's [`Gradient`] then in the caller's row buffer
//! ([`SceneRow::gradient`]), and [`gradient_matrix`] copies them into one
//! `(rows, columns)` array.
//!
//! The coordinates are those that move the pair's first object: a robot
//! link's robot's moving joints (in `RobotHandle::joint_names`
//! order; a self-collision pair's other link moves with them), then, when
//! asked, the base pose's twist `[v, ω]`; any other object, its pose's
//! twist (world frame, turning about its origin). For overlapping objects
//! it is the signed distance's (`distance − penetration`).

use gjkd_proto::{ErrorCode, Gradient, Item, ItemResult, ObjectId, QueryOptions, SceneRow};

use crate::{Answer, Client, ClientError, QueryError, op_error};

impl Client {
    /// Distance between `a` and `b` at their stored poses, with its
    /// gradient ([`Answer::gradient`]) with respect to the coordinates that
    /// move `a`; `base` adds a robot base's twist.
    ///
    /// # Errors
    /// As [`Client::distance`], and [`QueryError::InvalidOptions`] for a
    /// robot with more than [`GRADIENT_COLUMNS`](gjkd_proto::GRADIENT_COLUMNS)
    /// coordinates.
    pub fn distance_gradient(
        &mut self,
        a: ObjectId,
        b: ObjectId,
        options: &QueryOptions,
        base: bool,
    ) -> Result<Answer, QueryError> {
        let mut out = [ItemResult::error(ErrorCode::Internal)];
        let mut gradient = [Gradient::NONE];
        self.batch_gradients(
            &[Item::distance(a, b, options).with_gradient(base)],
            &mut out,
            &mut gradient,
        )
        .and_then(|()| {
            out[0]
                .answer_with(Some(&gradient[0]))
                .map_err(ClientError::Rejected)
        })
        .map_err(op_error)
    }
}

/// Copies the gradients of `rows` into `out`, row `i` at
/// `out[i * columns..(i + 1) * columns]` (row-major `(rows, columns)`),
/// entries past a row's own columns zero, and returns the rows copied
/// (those that fit in `out`). Allocates nothing.
pub fn gradient_matrix(rows: &[SceneRow], columns: usize, out: &mut [f64]) -> usize {
    let fit = out.len().checked_div(columns).unwrap_or(0).min(rows.len());
    for (row, slot) in rows[..fit].iter().zip(out.chunks_exact_mut(columns.max(1))) {
        let values = row.gradient.as_slice();
        let n = values.len().min(columns);
        slot[..n].copy_from_slice(&values[..n]);
        slot[n..].fill(0.0);
    }
    fit
}

/// A row's gradient, `None` when it was not asked or not computed.
pub fn row_gradient(row: &SceneRow) -> Option<&Gradient> {
    row.gradient.is_present().then_some(&row.gradient)
}
