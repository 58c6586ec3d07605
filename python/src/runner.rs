//! Runs a batch of items through whoever answers them (a server through the
//! Rust client, or `gjkd.Local`'s in-process store), in chunks no larger
//! than the answerer takes, with the GIL released for the whole run.

use pyo3::prelude::*;

use gjkd_client::{ClientError, Gradient, Item, ItemResult};

use crate::batch::{Distances, Request, Writer};

/// Whoever answers a batch of items.
pub trait Answerer {
    /// Most items in one call of [`Answerer::answer`].
    fn max_batch(&self) -> usize;
    /// Answers `items` into `results` (as long as `items`).
    ///
    /// # Errors
    /// A failure of the whole call.
    fn answer(&mut self, items: &[Item], results: &mut [ItemResult]) -> Result<(), ClientError>;
    /// As [`Answerer::answer`], for items that may ask for a gradient: the
    /// `k`-th one's into `gradients[k]` (room for all of them).
    ///
    /// # Errors
    /// A failure of the whole call.
    fn answer_gradients(
        &mut self,
        items: &[Item],
        results: &mut [ItemResult],
        gradients: &mut [Gradient],
    ) -> Result<(), ClientError>;
    /// Called after a chunk was refused as too large: learn the new limit.
    /// `false` if it did not change (then the error is reported).
    fn refresh_limit(&mut self) -> bool {
        false
    }
}

/// Buffers kept across calls so that a call allocates nothing per item.
#[derive(Default)]
pub struct Buffers {
    /// Items of the chunk being sent.
    pub items: Vec<Item>,
    /// Its results.
    pub results: Vec<ItemResult>,
    /// Its gradients, when its items ask for them (each does, so the
    /// `k`-th gradient answers the `k`-th item).
    pub gradients: Vec<Gradient>,
}

/// A value moved into [`Python::detach`]'s closure although it is not
/// `Send`. The closure runs on the calling thread, before `detach`
/// returns: nothing crosses a thread. What must not happen without the GIL
/// (touching Python objects) is kept out of the wrapped values, which are
/// plain Rust data and slices of numpy buffers borrowed for the call.
pub struct OnThisThread<T>(T);

// SAFETY: see the type's documentation: the value never leaves the thread.
unsafe impl<T> Send for OnThisThread<T> {}

impl<T> OnThisThread<T> {
    /// Wraps `value`.
    pub fn new(value: T) -> Self {
        OnThisThread(value)
    }

    /// The value (a method, so that a closure captures the whole wrapper
    /// and not just its field).
    pub fn into_inner(self) -> T {
        self.0
    }
}

/// Answers every pair of `request` into `out`, in chunks, the GIL released;
/// the pairs' gradients too when `request` asks for them.
///
/// # Errors
/// The first whole-call failure; rows before its chunk are written.
pub fn run_pairs(
    py: Python<'_>,
    answerer: &mut dyn Answerer,
    buffers: &mut Buffers,
    request: Request<'_>,
    out: &Distances,
) -> PyResult<Result<(), ClientError>> {
    out.with_writer(py, |writer| {
        let job = OnThisThread::new((answerer, buffers, writer));
        Ok(py.detach(move || {
            let (answerer, buffers, mut writer) = job.into_inner();
            run_chunks(answerer, buffers, &request, &mut writer)
        }))
    })
}

fn run_chunks(
    answerer: &mut dyn Answerer,
    buffers: &mut Buffers,
    request: &Request<'_>,
    writer: &mut Writer<'_>,
) -> Result<(), ClientError> {
    let n = request.len();
    let mut start = 0;
    while start < n {
        let end = n.min(start + answerer.max_batch().max(1));
        buffers.items.clear();
        request.push_items(start..end, &mut buffers.items);
        let len = buffers.items.len();
        if buffers.results.len() < len {
            buffers.results.resize(len, ItemResult::default());
        }
        let asks = request.asks_gradients();
        if asks && buffers.gradients.len() < len {
            buffers.gradients.resize(len, Gradient::NONE);
        }
        let answered = if asks {
            answerer.answer_gradients(
                &buffers.items,
                &mut buffers.results[..len],
                &mut buffers.gradients[..len],
            )
        } else {
            answerer.answer(&buffers.items, &mut buffers.results[..len])
        };
        match answered {
            Ok(()) => {}
            Err(ClientError::Rejected(gjkd_client::ErrorCode::BatchTooLarge))
                if answerer.refresh_limit() =>
            {
                continue;
            }
            Err(e) => return Err(e),
        }
        writer.write(start, &buffers.results[..len]);
        if asks {
            writer.write_gradients(start, &buffers.gradients[..len]);
        }
        start = end;
    }
    Ok(())
}

/// Answers one pair `item` that asks for its gradient, the GIL released:
/// its result and its gradient.
///
/// # Errors
/// A failure of the whole call.
pub fn run_gradient(
    py: Python<'_>,
    answerer: &mut dyn Answerer,
    item: Item,
) -> Result<(ItemResult, Gradient), ClientError> {
    let job = OnThisThread::new(answerer);
    py.detach(move || {
        let answerer = job.into_inner();
        let mut result = [ItemResult::default()];
        let mut gradient = [Gradient::NONE];
        answerer.answer_gradients(&[item], &mut result, &mut gradient)?;
        Ok((result[0], gradient[0]))
    })
}

/// Sends the items `make(i)` for `i` in `0..n`, in chunks, the GIL
/// released; each result goes to `check(i, result)`, which may stop the
/// run.
///
/// # Errors
/// The first whole-call failure, or the first error `check` returns.
pub fn run_items(
    py: Python<'_>,
    answerer: &mut dyn Answerer,
    buffers: &mut Buffers,
    n: usize,
    make: &(dyn Fn(usize) -> Item + Sync),
    check: &mut dyn FnMut(usize, &ItemResult) -> Result<(), ClientError>,
) -> Result<(), ClientError> {
    let job = OnThisThread::new((answerer, buffers, make, check));
    py.detach(move || {
        let (answerer, buffers, make, check) = job.into_inner();
        let mut start = 0;
        while start < n {
            let end = n.min(start + answerer.max_batch().max(1));
            buffers.items.clear();
            buffers.items.extend((start..end).map(make));
            let len = end - start;
            if buffers.results.len() < len {
                buffers.results.resize(len, ItemResult::default());
            }
            answerer.answer(&buffers.items, &mut buffers.results[..len])?;
            for (k, r) in buffers.results[..len].iter().enumerate() {
                check(start + k, r)?;
            }
            start = end;
        }
        Ok(())
    })
}
