//! The caller's row buffer: rows written while there is room, all counted.

use gjkd_proto::SceneRow;

/// Writes rows into a caller's buffer.
pub(crate) struct Rows<'a> {
    buffer: &'a mut [SceneRow],
    /// Rows written.
    pub written: usize,
    /// Rows that qualified, also those beyond the buffer.
    pub total: u64,
}

impl<'a> Rows<'a> {
    /// An empty answer in `buffer`.
    pub(crate) fn new(buffer: &'a mut [SceneRow]) -> Self {
        Rows {
            buffer,
            written: 0,
            total: 0,
        }
    }

    /// Adds `row`: written if there is room, counted anyway.
    #[inline]
    pub(crate) fn push(&mut self, row: SceneRow) {
        if let Some(slot) = self.buffer.get_mut(self.written) {
            *slot = row;
            self.written += 1;
        }
        self.total += 1;
    }

    /// The rows written from `from` on.
    pub(crate) fn written_since(&mut self, from: usize) -> &mut [SceneRow] {
        &mut self.buffer[from.min(self.written)..self.written]
    }

    /// Forgets the rows from `written` on (a step that is not reported).
    pub(crate) fn truncate(&mut self, written: usize, total: u64) {
        self.written = written;
        self.total = total;
    }
}
