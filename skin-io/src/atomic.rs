//! Files written whole or not at all. Every writer of the workspace goes through here: the bytes go
//! to a uniquely named temporary file in the target's own folder (`tempfile`, so two writers of the
//! same target never share a temporary and the final rename stays on one file system), which is
//! persisted over the target only once complete; on failure it is removed. A target that exists and
//! is not a regular file (directory, symlink, FIFO, device) is never replaced. Files that belong
//! together (a render's EXR and PNG) are staged first and committed as a group ([`stage`],
//! [`commit`]): all are replaced, or on an error none is.

use std::collections::HashSet;
use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};
use thiserror::Error;

/// Temporary files of writes under way, so an interrupt can remove them (a signal ends the
/// process without running destructors). Commits hold the lock while they rename, so an interrupt
/// never lands in the middle of one.
static LIVE: Mutex<Option<HashSet<PathBuf>>> = Mutex::new(None);

fn live() -> MutexGuard<'static, Option<HashSet<PathBuf>>> {
    LIVE.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Removes every temporary file still registered and returns how many it removed (what the
/// interrupt handler does before exiting).
pub fn remove_live_temporaries() -> usize {
    remove_registered(&mut live())
}

fn remove_registered(live: &mut Option<HashSet<PathBuf>>) -> usize {
    live.take()
        .unwrap_or_default()
        .iter()
        .filter(|p| fs::remove_file(p).is_ok())
        .count()
}

/// Install the handler for SIGINT, SIGTERM and SIGHUP (once per process; later calls do nothing):
/// it waits for a commit under way to finish, removes the temporary files of writes under way,
/// tells `report` how many it removed, and exits with status 130. The binaries call it first
/// thing and decide what to print.
pub fn remove_temporaries_on_interrupt(report: fn(usize)) {
    let _ = ctrlc::set_handler(move || {
        let mut guard = live();
        let n = remove_registered(&mut guard);
        report(n);
        std::process::exit(130);
    });
}

/// A registered temporary path, unregistered on drop.
#[derive(Debug)]
struct Registered(PathBuf);

impl Registered {
    fn new(path: &Path) -> Self {
        live()
            .get_or_insert_with(HashSet::new)
            .insert(path.to_path_buf());
        Self(path.to_path_buf())
    }
}

impl Drop for Registered {
    fn drop(&mut self) {
        if let Some(set) = live().as_mut() {
            set.remove(&self.0);
        }
    }
}

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

/// A complete temporary file waiting to be persisted over its target (see [`commit`]); dropped
/// uncommitted, it is removed.
#[derive(Debug)]
pub struct Staged {
    target: PathBuf,
    // Dropped in this order: the file is removed before it leaves the interrupt registry.
    tmp: tempfile::NamedTempFile,
    _registered: Registered,
}

/// The I/O error of an atomic write of `path`.
fn io_error(path: &Path) -> impl Fn(io::Error) -> AtomicWriteError + '_ {
    move |source| AtomicWriteError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// A fresh, uniquely named temporary file beside `path` (`name.XXXXXX.tmp`), creating the folder.
fn temp_beside(path: &Path) -> Result<tempfile::NamedTempFile, AtomicWriteError> {
    let dir = match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => {
            fs::create_dir_all(dir).map_err(io_error(path))?;
            dir
        }
        None => Path::new("."),
    };
    let mut prefix = path
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    prefix.push(".");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    // An ordinary file's mode (0666 less the umask, which the OS applies at creation), not the
    // 0600 that temporary files get by default: the renamed file is the user's output.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    builder.tempfile_in(dir).map_err(io_error(path))
}

/// Write the future contents of `path` through `fill`, which receives the path of a fresh
/// temporary file in the same folder; nothing at `path` changes until [`commit`]. On failure the
/// temporary file is removed.
pub fn stage<E>(path: &Path, fill: impl FnOnce(&Path) -> Result<(), E>) -> Result<Staged, E>
where
    E: From<AtomicWriteError>,
{
    check_target(path)?;
    let tmp = temp_beside(path)?;
    let staged = Staged {
        target: path.to_path_buf(),
        _registered: Registered::new(tmp.path()),
        tmp,
    };
    // On an error `staged` is dropped here, which deletes the temporary file.
    fill(staged.tmp.path())?;
    Ok(staged)
}

/// Persist staged files over their targets as one group: either every target gets its new
/// contents, or (on an error) every target keeps what it had — the old file, or no file — and no
/// temporary file remains. The targets are moved aside first (to unique names beside them) and
/// moved back if a later rename fails. A crash inside this function can still leave the group
/// mixed; an error cannot.
pub fn commit(files: Vec<Staged>) -> Result<(), AtomicWriteError> {
    // Old contents moved aside, per target: restored on failure, deleted (by drop) on success.
    let mut aside: Vec<Option<tempfile::TempPath>> = Vec::with_capacity(files.len());
    let mut done: Vec<&Path> = Vec::with_capacity(files.len());
    // An interrupt waits for this group to be whole (new or old) before it exits.
    let interrupt = live();
    let result = (|| {
        for f in &files {
            check_target(&f.target)?;
        }
        for f in &files {
            aside.push(if f.target.exists() {
                let old = temp_beside(&f.target)?.into_temp_path();
                fs::rename(&f.target, &old).map_err(io_error(&f.target))?;
                Some(old)
            } else {
                None
            });
        }
        for f in &files {
            fs::rename(f.tmp.path(), &f.target).map_err(io_error(&f.target))?;
            done.push(&f.target);
        }
        Ok(())
    })();
    if result.is_err() {
        // Best effort: the error being reported matters more than one from the roll-back.
        for target in &done {
            let _ = fs::remove_file(target);
        }
        for (f, old) in files.iter().zip(&aside) {
            if let Some(old) = old {
                let _ = fs::rename(old, &f.target);
            }
        }
    }
    // The old contents go while the interrupt still waits; then `files` is dropped, which
    // removes any temporary not renamed (and takes the lock itself).
    drop(aside);
    drop(interrupt);
    drop(files);
    result
}

/// Write `path` through `fill` (see [`stage`]) and persist it at once.
pub fn write_via_temp<E>(path: &Path, fill: impl FnOnce(&Path) -> Result<(), E>) -> Result<(), E>
where
    E: From<AtomicWriteError>,
{
    let staged = stage(path, fill)?;
    Ok(commit(vec![staged])?)
}

/// Write `bytes` to `path` atomically (unique temporary name, then rename).
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), AtomicWriteError> {
    commit(vec![stage_bytes(path, bytes)?])
}

/// Stage `bytes` as the future contents of `path` (see [`stage`]).
pub fn stage_bytes(path: &Path, bytes: &[u8]) -> Result<Staged, AtomicWriteError> {
    stage(path, |tmp| {
        let io_err = io_error(path);
        let mut f = fs::File::create(tmp).map_err(&io_err)?;
        f.write_all(bytes).map_err(&io_err)?;
        f.sync_all().map_err(&io_err)
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

    /// A written file has the mode of an ordinary write (0666 less the umask), for a single
    /// write, a staged group and a replaced file alike: not the temporary file's 0600.
    #[cfg(unix)]
    #[test]
    fn written_files_get_an_ordinary_files_mode() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let mode = |p: &Path| fs::metadata(p).unwrap().permissions().mode() & 0o777;
        let plain = dir.path().join("plain.txt");
        fs::write(&plain, b"x").unwrap();
        let ordinary = mode(&plain);
        let one = dir.path().join("one.txt");
        write_bytes(&one, b"1").unwrap();
        let (a, b) = (dir.path().join("a.exr"), dir.path().join("b.png"));
        commit(vec![
            stage_bytes(&a, b"a").unwrap(),
            stage_bytes(&b, b"b").unwrap(),
        ])
        .unwrap();
        write_bytes(&a, b"again").unwrap();
        for p in [&one, &a, &b] {
            assert_eq!(
                mode(p),
                ordinary,
                "{}: {:o} vs {ordinary:o}",
                p.display(),
                mode(p)
            );
        }
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

    /// A group whose last rename fails leaves every target as it was (the old bytes, or no file)
    /// and no temporary or moved-aside file behind; a group that succeeds replaces all of them.
    #[test]
    fn pair_is_committed_together_or_not_at_all() {
        let dir = temp_dir("pair");
        let (exr, png) = (dir.join("render.exr"), dir.join("render.png"));
        let pair = |a: &[u8], b: &[u8]| {
            let staged = vec![stage_bytes(&exr, a).unwrap(), stage_bytes(&png, b).unwrap()];
            // Take the second temporary away: its rename fails after the first one succeeded.
            fs::remove_file(staged[1].tmp.path()).unwrap();
            commit(staged)
        };
        // No previous pair: neither file may appear.
        assert!(matches!(
            pair(b"new exr", b"new png"),
            Err(AtomicWriteError::Io { .. })
        ));
        assert!(!exr.exists() && !png.exists());
        assert!(
            leftovers(&dir, &[]).is_empty(),
            "{:?}",
            leftovers(&dir, &[])
        );
        // A previous pair: both keep their bytes.
        commit(vec![
            stage_bytes(&exr, b"old exr").unwrap(),
            stage_bytes(&png, b"old png").unwrap(),
        ])
        .unwrap();
        assert!(pair(b"new exr", b"new png").is_err());
        assert_eq!(fs::read(&exr).unwrap(), b"old exr");
        assert_eq!(fs::read(&png).unwrap(), b"old png");
        let keep = ["render.exr", "render.png"];
        assert!(
            leftovers(&dir, &keep).is_empty(),
            "{:?}",
            leftovers(&dir, &keep)
        );
        // A target that became a directory after staging: refused before anything moves.
        let staged = vec![
            stage_bytes(&exr, b"new exr").unwrap(),
            stage_bytes(&png, b"new png").unwrap(),
        ];
        fs::remove_file(&png).unwrap();
        fs::create_dir(&png).unwrap();
        assert!(matches!(
            commit(staged),
            Err(AtomicWriteError::NotARegularFile { .. })
        ));
        assert_eq!(fs::read(&exr).unwrap(), b"old exr");
        assert!(png.is_dir());
        assert!(
            leftovers(&dir, &keep).is_empty(),
            "{:?}",
            leftovers(&dir, &keep)
        );
        fs::remove_dir(&png).unwrap();
        commit(vec![
            stage_bytes(&exr, b"new exr").unwrap(),
            stage_bytes(&png, b"new png").unwrap(),
        ])
        .unwrap();
        assert_eq!(fs::read(&exr).unwrap(), b"new exr");
        assert_eq!(fs::read(&png).unwrap(), b"new png");
        assert!(
            leftovers(&dir, &keep).is_empty(),
            "{:?}",
            leftovers(&dir, &keep)
        );
        fs::remove_dir_all(&dir).unwrap();
    }

    /// A staged file is registered for the interrupt handler while it exists, and the handler's
    /// removal deletes it; committed or dropped, it leaves the registry. (Checked on a copy of the
    /// registry: the real one also holds other tests' writes under way.)
    #[test]
    fn interrupt_removes_registered_temporaries() {
        let dir = temp_dir("interrupt");
        let target = dir.join("render.exr");
        let staged = stage_bytes(&target, b"half").unwrap();
        let tmp = staged.tmp.path().to_path_buf();
        let registered = |p: &Path| live().as_ref().is_some_and(|set| set.contains(p));
        assert!(tmp.exists() && registered(&tmp));
        let mut copy = Some(HashSet::from([tmp.clone()]));
        assert_eq!(remove_registered(&mut copy), 1);
        assert!(!tmp.exists() && copy.is_none());
        drop(staged);
        assert!(!registered(&tmp));
        let staged = stage_bytes(&target, b"whole").unwrap();
        let tmp = staged.tmp.path().to_path_buf();
        commit(vec![staged]).unwrap();
        assert!(!registered(&tmp));
        assert!(leftovers(&dir, &["render.exr"]).is_empty());
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
