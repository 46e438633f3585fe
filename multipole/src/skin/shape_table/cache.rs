//! Tables are built once per (g, n, knobs) and kept: in memory for the process, on disk between
//! runs (the white run takes seconds; reading it back, milliseconds).

use super::{ShapeTable, ShapeTableOptions};
use crate::error::MultipoleError;
use std::path::Path;
use std::sync::{Arc, Mutex, PoisonError};

/// Tables built or read in this process.
static TABLES: Mutex<Vec<Arc<ShapeTable>>> = Mutex::new(Vec::new());

/// First bytes of a table file (format version in the last byte).
const MAGIC: &[u8; 8] = b"SKINSHT2";

use skin_io::cache::cache_dir;

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
            log::info!(
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
        "shape-table-g{g}-n{n}-p{}-d{}-r{}-a{}-s{:x}.bin",
        o.photons, o.depths_per_octave, o.radial_per_decade, o.alpha_per_decade, o.seed
    )
}

/// The table stored at `path`, or `None` if it is missing or not a complete table of this shape.
fn read(path: &Path, g: f64, n: f64, opts: &ShapeTableOptions) -> Option<ShapeTable> {
    let bytes = std::fs::read(path).ok()?;
    let mut table = ShapeTable::empty(g, n, *opts);
    let body = bytes.strip_prefix(MAGIC.as_slice())?;
    if body.len() != 4 * table.log_sums.len() {
        return None;
    }
    for (c, b) in table.log_sums.iter_mut().zip(body.chunks_exact(4)) {
        *c = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    }
    Some(table)
}

/// Write `table` to `path` whole or not at all ([`skin_io::atomic`]).
fn write(path: &Path, table: &ShapeTable) -> Result<(), skin_io::atomic::AtomicWriteError> {
    let mut bytes = Vec::with_capacity(MAGIC.len() + 4 * table.log_sums.len());
    bytes.extend_from_slice(MAGIC);
    for c in &table.log_sums {
        bytes.extend_from_slice(&c.to_le_bytes());
    }
    skin_io::atomic::write_bytes(path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_written_table_reads_back_whole_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let opts = ShapeTableOptions::default();
        let mut table = ShapeTable::empty(0.9, 1.4, opts);
        for (i, c) in table.log_sums.iter_mut().enumerate() {
            *c = i as f32;
        }
        let path = dir.path().join("new").join(file_name(0.9, 1.4, &opts));
        write(&path, &table).unwrap();
        let back = read(&path, 0.9, 1.4, &opts).expect("a complete table");
        assert_eq!(back.log_sums, table.log_sums);
        let files = std::fs::read_dir(path.parent().unwrap()).unwrap().count();
        assert_eq!(files, 1, "only the table itself is left");
    }
}
