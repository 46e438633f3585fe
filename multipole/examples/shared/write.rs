//! The examples' one way to write a result file: a uniquely named temporary file in the target's
//! folder (`tempfile`), persisted over the target once complete, so a crash or a second run leaves
//! no half-written file and two runs never share a temporary name. (`render::atomic` does the same
//! for the workspace's binaries; `multipole` does not depend on `render`.)

use std::io::Write;
use std::path::Path;

/// Write `bytes` to `path` whole or not at all, creating its folder, and say so on stderr.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => {
            std::fs::create_dir_all(dir)?;
            dir
        }
        None => Path::new("."),
    };
    let mut tmp = tempfile::NamedTempFile::new_in(dir)?;
    tmp.write_all(bytes)?;
    tmp.persist(path).map_err(|e| e.error)?;
    eprintln!("wrote {}", path.display());
    Ok(())
}
