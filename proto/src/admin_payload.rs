//! The admin request's slice payload: the vertices of a registration, or
//! the bytes of a robot's text.

use std::fmt;

use iceoryx2::prelude::ZeroCopySend;

use crate::Vertex;

/// Bytes of text one [`AdminChunk`] carries.
pub const TEXT_CHUNK_LEN: usize = 24;

/// One element of the admin request's slice: a [`Vertex`] of a
/// registration ([`AdminOp::Register`](crate::AdminOp::Register)) or
/// [`TEXT_CHUNK_LEN`] bytes of a robot's UTF-8 text
/// ([`AdminOp::AttachRobot`](crate::AdminOp::AttachRobot)), the last chunk
/// padded with zeros. One element type keeps the admin service one
/// zero-copy slice; the union names what each operation puts in it. Both
/// views are padding-free plain old data of the same size, so any bytes
/// are valid in either, and the slice views below cast without copying.
#[derive(Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.AdminChunk")]
pub union AdminChunk {
    /// A vertex of a registration.
    pub vertex: Vertex,
    /// Text bytes of a robot.
    pub text: [u8; TEXT_CHUNK_LEN],
}

const _: () = {
    assert!(size_of::<Vertex>() == TEXT_CHUNK_LEN);
    assert!(size_of::<AdminChunk>() == TEXT_CHUNK_LEN);
    assert!(align_of::<AdminChunk>() == align_of::<Vertex>());
};

impl Default for AdminChunk {
    fn default() -> Self {
        AdminChunk {
            vertex: Vertex::default(),
        }
    }
}

impl From<Vertex> for AdminChunk {
    fn from(vertex: Vertex) -> Self {
        AdminChunk { vertex }
    }
}

impl fmt::Debug for AdminChunk {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // SAFETY: any 24 bytes are a valid `Vertex` (three f64).
        let vertex = unsafe { self.vertex };
        f.debug_struct("AdminChunk")
            .field("vertex", &vertex)
            .finish()
    }
}

impl AdminChunk {
    /// `vertices` seen as a payload, without copying.
    pub fn from_vertices(vertices: &[Vertex]) -> &[AdminChunk] {
        // SAFETY: `AdminChunk` is a `repr(C)` union with `Vertex` as a
        // field, of the same size and alignment (asserted above).
        unsafe { std::slice::from_raw_parts(vertices.as_ptr().cast(), vertices.len()) }
    }

    /// A payload seen as vertices, without copying.
    pub fn vertices(chunks: &[AdminChunk]) -> &[Vertex] {
        // SAFETY: as in `from_vertices`; any bytes are valid f64s.
        unsafe { std::slice::from_raw_parts(chunks.as_ptr().cast(), chunks.len()) }
    }

    /// A payload seen as bytes, without copying.
    pub fn bytes(chunks: &[AdminChunk]) -> &[u8] {
        // SAFETY: the union has no padding, so every byte is initialised;
        // u8 has alignment 1.
        unsafe { std::slice::from_raw_parts(chunks.as_ptr().cast(), chunks.len() * TEXT_CHUNK_LEN) }
    }

    /// `text` in chunks, the last one padded with zeros. The inverse is
    /// [`AdminChunk::text_of`].
    pub fn pack_text(text: &str) -> Vec<AdminChunk> {
        text.as_bytes()
            .chunks(TEXT_CHUNK_LEN)
            .map(|chunk| {
                let mut text = [0u8; TEXT_CHUNK_LEN];
                text[..chunk.len()].copy_from_slice(chunk);
                AdminChunk { text }
            })
            .collect()
    }

    /// The first `len` bytes of `chunks` as text, if the chunks hold exactly
    /// that many (rounded up to whole chunks), the padding is zero and the
    /// bytes are UTF-8.
    pub fn text_of(chunks: &[AdminChunk], len: u64) -> Option<&str> {
        let len = usize::try_from(len).ok()?;
        if chunks.len() != len.div_ceil(TEXT_CHUNK_LEN) {
            return None;
        }
        let (text, padding) = Self::bytes(chunks).split_at(len);
        if padding.iter().any(|&b| b != 0) {
            return None;
        }
        std::str::from_utf8(text).ok()
    }
}
