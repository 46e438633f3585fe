//! Files written whole or not at all. Every writer of the workspace goes through here: the bytes go
//! to a uniquely named temporary file in the target's own folder (`tempfile`, so two writers of the
//! same target never share a temporary and the final rename stays on one file system), which is
//! persisted over the target only once complete; on failure it is removed. A target that exists and
//! is not a regular file (directory, symlink, FIFO, device) is never replaced.

use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why an atomic write did not happen.
#[derive(Debug, Error)]
pub enum AtomicWriteError {
    /// The target exists and is not a regular file, so it is left alone.
    #[error("{path} exists and is a {kind}, not a regular file: not replaced")]
    NotARegularFile {
        /// The target path.
        path: PathBuf,
        /// What it is ("directory", "symlink", "FIFO, socket or device").
        kind: &'static str,
    },
    /// Creating the folder or the temporary file, writing or renaming failed.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The target path.
        path: PathBuf,
        /// The underlying I/O error.
        source: io::Error,
    },
}

/// Refuse a target that exists and is not a regular file (a missing target is fine).
fn check_target(path: &Path) -> Result<(), AtomicWriteError> {
    let Ok(meta) = fs::symlink_metadata(path) else {
        return Ok(());
    };
    let t = meta.file_type();
    let kind = if t.is_file() {
        return Ok(());
    } else if t.is_dir() {
        "directory"
    } else if t.is_symlink() {
        "symlink"
    } else {
        "FIFO, socket or device"
    };
    Err(AtomicWriteError::NotARegularFile {
        path: path.to_path_buf(),
        kind,
    })
}

/// Write `path` through `fill`, which receives the path of a fresh temporary file (in the same
/// folder) to write; on success it is renamed over `path`, on failure it is removed. Parent
/// folders are created.
pub fn write_via_temp<E>(path: &Path, fill: impl FnOnce(&Path) -> Result<(), E>) -> Result<(), E>
where
    E: From<AtomicWriteError>,
{
    let io_err = |source| AtomicWriteError::Io {
        path: path.to_path_buf(),
        source,
    };
    check_target(path)?;
    let dir = match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => {
            fs::create_dir_all(dir).map_err(io_err)?;
            dir
        }
        None => Path::new("."),
    };
    let mut prefix = path
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    prefix.push(".");
    let tmp = tempfile::Builder::new()
        .prefix(&prefix)
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(io_err)?;
    // On an error `tmp` is dropped here, which deletes the temporary file.
    fill(tmp.path())?;
    check_target(path)?;
    tmp.persist(path).map_err(|e| io_err(e.error))?;
    Ok(())
}

/// Write `bytes` to `path` atomically (unique temporary name, then rename).
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), AtomicWriteError> {
    write_via_temp(path, |tmp| {
        let io_err = |source| AtomicWriteError::Io {
            path: path.to_path_buf(),
            source,
        };
        let mut f = fs::File::create(tmp).map_err(io_err)?;
        f.write_all(bytes).map_err(io_err)?;
        f.sync_all().map_err(io_err)
    })
}

/// Names in `dir` other than `keep` (for tests: no temporary file may be left behind).
#[must_use]
pub fn leftovers(dir: &Path, keep: &[&str]) -> Vec<String> {
    fs::read_dir(dir)
        .map(|it| {
            it.filter_map(Result::ok)
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| !keep.contains(&n.as_str()))
                .collect()
        })
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_dir(tag: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("skin-atomic-{tag}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn failed_write_leaves_nothing() {
        let dir = temp_dir("fail");
        let target = dir.join("a.txt");
        let r: Result<(), AtomicWriteError> = write_via_temp(&target, |tmp| {
            fs::write(tmp, b"half").unwrap();
            Err(AtomicWriteError::Io {
                path: tmp.to_path_buf(),
                source: io::Error::other("boom"),
            })
        });
        assert!(r.is_err());
        assert!(!target.exists());
        assert!(
            leftovers(&dir, &[]).is_empty(),
            "{:?}",
            leftovers(&dir, &[])
        );
        write_bytes(&target, b"whole").unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"whole");
        assert!(leftovers(&dir, &["a.txt"]).is_empty());
        fs::remove_dir_all(&dir).unwrap();
    }

    /// Two writers of one target each get their own temporary file: both complete, and the target
    /// holds one of the two contents whole.
    #[test]
    fn concurrent_writers_do_not_collide() {
        let dir = temp_dir("race");
        let target = dir.join("b.txt");
        let (a, b) = (vec![b'a'; 1 << 20], vec![b'b'; 1 << 20]);
        std::thread::scope(|s| {
            let ha = s.spawn(|| write_bytes(&target, &a));
            let hb = s.spawn(|| write_bytes(&target, &b));
            ha.join().unwrap().unwrap();
            hb.join().unwrap().unwrap();
        });
        let got = fs::read(&target).unwrap();
        assert!(got == a || got == b);
        assert!(leftovers(&dir, &["b.txt"]).is_empty());
        fs::remove_dir_all(&dir).unwrap();
    }

    /// A directory, a symlink and a FIFO in the target's place are left as they are, with a typed
    /// error naming what they are (the symlink's own target keeps its bytes).
    #[cfg(unix)]
    #[test]
    fn non_regular_targets_are_not_replaced() {
        let dir = temp_dir("special");
        fs::create_dir_all(dir.join("c.png")).unwrap();
        fs::write(dir.join("real.txt"), b"keep").unwrap();
        std::os::unix::fs::symlink(dir.join("real.txt"), dir.join("link.txt")).unwrap();
        let fifo = std::process::Command::new("mkfifo")
            .arg(dir.join("pipe.csv"))
            .status()
            .is_ok_and(|s| s.success());
        let mut cases = vec![("c.png", "directory"), ("link.txt", "symlink")];
        if fifo {
            cases.push(("pipe.csv", "FIFO, socket or device"));
        }
        for (name, want) in cases {
            match write_bytes(&dir.join(name), b"x") {
                Err(AtomicWriteError::NotARegularFile { kind, .. }) => assert_eq!(kind, want),
                other => panic!("{name}: {other:?}"),
            }
        }
        assert!(dir.join("c.png").is_dir());
        assert_eq!(fs::read(dir.join("real.txt")).unwrap(), b"keep");
        assert!(leftovers(&dir, &["c.png", "real.txt", "link.txt", "pipe.csv"]).is_empty());
        fs::remove_dir_all(&dir).unwrap();
    }
}
