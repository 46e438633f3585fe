//! Tables are built once per (g, n, knobs) and kept: in memory for the process, on disk between
//! runs (the white run takes seconds; reading it back, milliseconds).

use super::{ShapeTable, ShapeTableOptions};
use crate::error::MultipoleError;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError};

/// Tables built or read in this process.
static TABLES: Mutex<Vec<Arc<ShapeTable>>> = Mutex::new(Vec::new());

/// First bytes of a table file (format version in the last byte).
const MAGIC: &[u8; 8] = b"SKINSHT1";

/// Where tables are kept between runs: `$SKIN_CACHE_DIR`, else `$XDG_CACHE_HOME/skin`, else
/// `$HOME/.cache/skin`; `None` when none is set (tables then live only in memory).
#[must_use]
pub fn cache_dir() -> Option<PathBuf> {
    let var = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("SKIN_CACHE_DIR")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("skin")))
        .or_else(|| var("HOME").map(|d| d.join(".cache").join("skin")))
}

/// The table for (`g`, `n`, `opts`): from memory, else from [`cache_dir`], else built (on all
/// rayon threads' worth of plain threads) and written there. Holding the lock while building means
/// concurrent callers wait for one build instead of each starting their own.
pub fn cached_table(
    g: f64,
    n: f64,
    opts: &ShapeTableOptions,
) -> Result<Arc<ShapeTable>, MultipoleError> {
    let mut tables = TABLES.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(t) = tables
        .iter()
        .find(|t| t.g == g && t.n == n && t.opts == *opts)
    {
        return Ok(Arc::clone(t));
    }
    let path = cache_dir().map(|d| d.join(file_name(g, n, opts)));
    let table = match path.as_deref().and_then(|p| read(p, g, n, opts)) {
        Some(t) => t,
        None => {
            eprintln!(
                "building the exact-profile shape table (g {g}, n {n}, {} photons; once{})",
                opts.photons,
                path.as_deref()
                    .map_or(String::new(), |p| format!(", kept in {}", p.display()))
            );
            let t = ShapeTable::build(g, n, opts, rayon::current_num_threads(), |_| {})?;
            // A cache that cannot be written costs time on the next run, not correctness.
            if let Some(p) = &path {
                let _ = write(p, &t);
            }
            t
        }
    };
    let table = Arc::new(table);
    tables.push(Arc::clone(&table));
    Ok(table)
}

/// File name: every input of the table, so a change of knob never reads a stale file.
fn file_name(g: f64, n: f64, o: &ShapeTableOptions) -> String {
    format!(
        "shape-table-g{g}-n{n}-p{}-d{}-r{}-l{}-s{:x}.bin",
        o.photons, o.depths_per_octave, o.radial_per_decade, o.path_per_decade, o.seed
    )
}

/// The table stored at `path`, or `None` if it is missing or not a complete table of this shape.
fn read(path: &Path, g: f64, n: f64, opts: &ShapeTableOptions) -> Option<ShapeTable> {
    let bytes = std::fs::read(path).ok()?;
    let mut table = ShapeTable::empty(g, n, *opts);
    let body = bytes.strip_prefix(MAGIC.as_slice())?;
    if body.len() != 4 * table.counts.len() {
        return None;
    }
    for (c, b) in table.counts.iter_mut().zip(body.chunks_exact(4)) {
        *c = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    }
    Some(table)
}

/// Write `table` to `path` through a uniquely named temporary file in the same directory
/// (`tempfile`), persisted onto the path: a reader never sees a half-written table, and two
/// writers never share a temporary.
fn write(path: &Path, table: &ShapeTable) -> std::io::Result<()> {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)?;
    let mut bytes = Vec::with_capacity(MAGIC.len() + 4 * table.counts.len());
    bytes.extend_from_slice(MAGIC);
    for c in &table.counts {
        bytes.extend_from_slice(&c.to_le_bytes());
    }
    let mut tmp = tempfile::NamedTempFile::new_in(dir)?;
    tmp.write_all(&bytes)?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_written_table_reads_back_whole_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let opts = ShapeTableOptions::default();
        let mut table = ShapeTable::empty(0.9, 1.4, opts);
        for (i, c) in table.counts.iter_mut().enumerate() {
            *c = i as f32;
        }
        let path = dir.path().join("new").join(file_name(0.9, 1.4, &opts));
        write(&path, &table).unwrap();
        let back = read(&path, 0.9, 1.4, &opts).expect("a complete table");
        assert_eq!(back.counts, table.counts);
        let files = std::fs::read_dir(path.parent().unwrap()).unwrap().count();
        assert_eq!(files, 1, "only the table itself is left");
    }
}
