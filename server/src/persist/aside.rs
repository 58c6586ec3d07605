//! Where a damaged or replaced file is kept: beside it, under a name no
//! earlier file took.

use std::path::{Path, PathBuf};

/// `<file>.<tag>-<unix seconds>`, with a suffix if that exists already.
pub fn aside_name(path: &Path, tag: &str) -> PathBuf {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    (0..)
        .map(|n| {
            let mut a = path.as_os_str().to_owned();
            a.push(format!(".{tag}-{secs}"));
            if n > 0 {
                a.push(format!(".{n}"));
            }
            PathBuf::from(a)
        })
        .find(|a| !a.exists())
        .unwrap_or_else(|| path.with_extension(tag))
}
