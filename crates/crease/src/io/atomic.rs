//! Outputs replaced atomically: every file crease writes is written in full to a temporary
//! file in the destination's folder, then renamed over the destination. A run killed while
//! writing leaves the previous file (or none), never a truncated one, and two runs writing the
//! same destination each rename a complete file of their own (the last one stays) instead of
//! interleaving. The temporary name keeps the destination's extension (the LAS writer reads it
//! to choose LAZ compression) and is removed when the writing fails.
//!
//! The data is not `fsync`ed: a killed process loses nothing that reached the page cache, and a
//! power cut was not the failure measured (see issue 33). A rename within one folder is atomic
//! on the file systems crease targets.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::{Error, Result};

/// A temporary path beside `path`: `.NAME.crease-PID-N.EXT` in the same folder.
fn temp_path(path: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = path
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.crease-{}-{n}{ext}", std::process::id()))
}

/// Runs `write` on a temporary path beside `path` and renames the result over `path`. Errors
/// (the writer's, naming `path` instead of the temporary file, or the rename's) leave `path`
/// as it was.
pub fn replace(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let tmp = temp_path(path);
    if let Err(e) = write(&tmp) {
        let _ = std::fs::remove_file(&tmp);
        return Err(renamed(e, &tmp, path));
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::io(path, e)
    })
}

/// `e` with the temporary path replaced by the destination.
fn renamed(e: Error, tmp: &Path, path: &Path) -> Error {
    let fix = |p: PathBuf| if p == tmp { path.to_path_buf() } else { p };
    match e {
        Error::Io { path: p, error } => Error::Io {
            path: fix(p),
            error,
        },
        Error::Format { path: p, message } => Error::Format {
            path: fix(p),
            message,
        },
        Error::Unsupported { path: p, message } => Error::Unsupported {
            path: fix(p),
            message,
        },
        Error::UnknownFormat {
            path: p,
            ext,
            known,
        } => Error::UnknownFormat {
            path: fix(p),
            ext,
            known,
        },
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_write_leaves_the_previous_file_and_no_temporary() {
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("out.ply");
        std::fs::write(&path, b"previous").expect("write");
        let e = replace(&path, |tmp| {
            std::fs::write(tmp, b"half").map_err(|e| Error::io(tmp, e))?;
            Err(Error::format(tmp, "disk full"))
        })
        .expect_err("failed writer");
        assert_eq!(e.to_string(), format!("{}: disk full", path.display()));
        assert_eq!(std::fs::read(&path).expect("read"), b"previous");
        let names: Vec<_> = std::fs::read_dir(dir.path()).expect("dir").collect();
        assert_eq!(names.len(), 1, "the temporary file was removed");
        replace(&path, |tmp| {
            std::fs::write(tmp, b"new").map_err(|e| Error::io(tmp, e))
        })
        .expect("write");
        assert_eq!(std::fs::read(&path).expect("read"), b"new");
    }
}
