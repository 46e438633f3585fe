//! The examples' one way to write a result file: whole or not at all ([`skin_io::atomic`]).

use std::path::Path;

/// Write `bytes` to `path` whole or not at all, creating its folder, and say so on stderr.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    skin_io::atomic::write_bytes(path, bytes).map_err(std::io::Error::other)?;
    eprintln!("wrote {}", path.display());
    Ok(())
}
