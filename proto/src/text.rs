//! Text carried in a vertex slice.

use crate::Vertex;

/// Text packed into vertices, 24 bytes each (the admin service's slice
/// carries only vertices), the last one padded with zeros. The inverse is
/// [`unpack_text`].
pub fn pack_text(text: &str) -> Vec<Vertex> {
    text.as_bytes()
        .chunks(24)
        .map(|chunk| {
            let mut bytes = [0u8; 24];
            bytes[..chunk.len()].copy_from_slice(chunk);
            let word = |i: usize| {
                let mut w = [0u8; 8];
                w.copy_from_slice(&bytes[8 * i..8 * i + 8]);
                f64::from_bits(u64::from_le_bytes(w))
            };
            Vertex {
                x: word(0),
                y: word(1),
                z: word(2),
            }
        })
        .collect()
}

/// The first `len` bytes packed in `vertices` by [`pack_text`], if there
/// are that many, the padding is zero and they are UTF-8.
pub fn unpack_text(vertices: &[Vertex], len: u64) -> Option<String> {
    let len = usize::try_from(len).ok()?;
    if vertices.len() != len.div_ceil(24) {
        return None;
    }
    let mut bytes = Vec::with_capacity(vertices.len() * 24);
    for v in vertices {
        for c in [v.x, v.y, v.z] {
            bytes.extend(c.to_bits().to_le_bytes());
        }
    }
    if bytes[len..].iter().any(|&b| b != 0) {
        return None;
    }
    bytes.truncate(len);
    String::from_utf8(bytes).ok()
}
