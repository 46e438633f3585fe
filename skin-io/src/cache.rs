//! The disk cache of built tables (docs/physics.md §16.5). An entry is one file in [`cache_dir`]
//! (`$SKIN_CACHE_DIR`, else `$XDG_CACHE_HOME/skin`, else `~/.cache/skin`) named by a hash of its
//! key, the text of everything the tables depend on (the skin's parameters, the method, every
//! knob and the versions of what builds them). The file holds a header line (format, body length,
//! CRC-32 of key and body), the key and the body ([postcard], which keeps every f32 as its four
//! bytes, so it reads back to the same bits). An entry is used only when the key is the one asked
//! for, the length is whole, the checksum matches and the body decodes to its last byte;
//! otherwise it is rebuilt and rewritten. Files are written through `crate::atomic`, so a reader
//! never sees half of one.
//!
//! The folder is bounded: after each write the entries beyond [`DEFAULT_MAX_BYTES`] (or
//! `$SKIN_CACHE_MAX_MIB` MiB) are removed, least recently used first (a hit refreshes its file's
//! modification time), never the entry just written and never a file that is not an entry. An
//! entry of the former JSON format (`.json`, [`CACHE_VERSION`] 2) counts as an entry: it is
//! removed when its key is rewritten, and otherwise ages out as the least recently used.

use serde::Serialize;
use serde::de::DeserializeOwned;
use std::path::{Path, PathBuf};

/// Version of an entry's file format (header, key, body); what a key builds is versioned by the
/// key itself.
pub const CACHE_VERSION: u32 = 3;
/// First word of an entry's header.
const MAGIC: &str = "skin-tables";
/// Largest total size of the entries in the folder, bytes (2 GiB; `$SKIN_CACHE_MAX_MIB`
/// overrides): a light-skin table at full fidelity is about 0.1 MiB, and one skin with chromophore
/// maps keeps a grid of a few hundred (the three heads of `builtin:three-heads` about 220 MiB
/// at 768×384, 700 MiB in the former JSON), which must fit or every load rebuilds what the last one
/// evicted.
pub const DEFAULT_MAX_BYTES: u64 = 2 << 30;
/// Prefix of an entry's file name.
const PREFIX: &str = "skin-tables-";
/// Suffix of an entry's file name.
const SUFFIX: &str = ".bin";
/// Suffix of an entry of the former JSON format.
const LEGACY_SUFFIX: &str = ".json";

/// Where cached tables are kept between runs: `$SKIN_CACHE_DIR`, else `$XDG_CACHE_HOME/skin`,
/// else `$HOME/.cache/skin`; `None` when none is set (tables then live only in memory).
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

/// `$SKIN_CACHE_MAX_MIB` is not a whole number of MiB in [1, 2²⁰].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("SKIN_CACHE_MAX_MIB = {value:?} outside a whole number of MiB in [1, 1048576]")]
pub struct CacheLimitError {
    /// The variable's text.
    pub value: String,
}

/// The folder's size limit in bytes: `$SKIN_CACHE_MAX_MIB` MiB when set (a whole number in
/// [1, 2²⁰], else an error naming the variable), else [`DEFAULT_MAX_BYTES`].
pub fn max_bytes() -> Result<u64, CacheLimitError> {
    let Some(text) = std::env::var_os("SKIN_CACHE_MAX_MIB") else {
        return Ok(DEFAULT_MAX_BYTES);
    };
    let text = text.to_string_lossy();
    match text.trim().parse::<u64>() {
        Ok(mib) if (1..=1 << 20).contains(&mib) => Ok(mib << 20),
        _ => Err(CacheLimitError {
            value: text.trim().to_string(),
        }),
    }
}

/// What the cache did for one entry.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CacheOutcome {
    /// Not used (`--no-cache`, or no cache folder).
    Off,
    /// Read from this file.
    Hit(PathBuf),
    /// Built and written to this file (no entry before).
    Built(PathBuf),
    /// An entry was there but not trusted (why), so the tables were rebuilt and rewritten.
    Rebuilt(PathBuf, &'static str),
    /// Built, but the file could not be written (why).
    Unwritten(PathBuf, String),
}

impl std::fmt::Display for CacheOutcome {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CacheOutcome::Off => f.write_str("off"),
            CacheOutcome::Hit(_) => f.write_str("hit"),
            CacheOutcome::Built(_) => f.write_str("miss (built, stored)"),
            CacheOutcome::Rebuilt(_, why) => write!(f, "rebuilt ({why})"),
            CacheOutcome::Unwritten(_, why) => write!(f, "miss (not stored: {why})"),
        }
    }
}

/// 64-bit FNV-1a of `bytes` (the file name's hash; not cryptographic: the key stored in the file
/// decides, the hash only finds it).
#[must_use]
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The CRC-32 (IEEE) of `bytes`: an entry's checksum. It detects every burst error up to 32 bits,
/// and `crc32fast` folds 64 bytes a step with carry-less multiplies, where FNV-1a waits on one
/// multiply per byte: a skin with chromophore maps reads hundreds of MiB of entries per load.
#[must_use]
pub fn checksum(bytes: &[u8]) -> u32 {
    crc32fast::hash(bytes)
}

/// The file of `key` in `dir`.
#[must_use]
pub fn entry_path(dir: &Path, key: &str) -> PathBuf {
    dir.join(format!("{PREFIX}{:016x}{SUFFIX}", fnv1a(key.as_bytes())))
}

/// Whether `name` is the name of an entry (`skin-tables-` + 16 hex digits + `.bin`, or `.json`
/// for the former format).
fn is_entry_name(name: &str) -> bool {
    name.strip_prefix(PREFIX)
        .and_then(|rest| {
            rest.strip_suffix(SUFFIX)
                .or_else(|| rest.strip_suffix(LEGACY_SUFFIX))
        })
        .is_some_and(|hex| hex.len() == 16 && hex.bytes().all(|b| b.is_ascii_hexdigit()))
}

/// Remove entries of `dir`, least recently modified first, until they total at most `max_bytes`;
/// `keep` (the entry just written) is never removed. Returns the entries removed. A file that
/// cannot be read or removed is skipped: the limit is kept as far as the folder lets it.
pub fn evict(dir: &Path, max_bytes: u64, keep: &Path) -> usize {
    let Ok(listing) = std::fs::read_dir(dir) else {
        return 0;
    };
    let mut entries: Vec<(std::time::SystemTime, u64, PathBuf)> = listing
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_str().is_some_and(is_entry_name))
        .filter_map(|e| {
            let meta = e.metadata().ok().filter(std::fs::Metadata::is_file)?;
            Some((meta.modified().ok()?, meta.len(), e.path()))
        })
        .collect();
    let mut total: u64 = entries.iter().map(|e| e.1).sum();
    entries.sort();
    let mut removed = 0;
    for (_, len, path) in entries {
        if total <= max_bytes {
            break;
        }
        if path != keep && std::fs::remove_file(&path).is_ok() {
            total -= len;
            removed += 1;
        }
    }
    removed
}

/// The bytes of an entry.
fn encode(key: &str, body: &[u8]) -> Vec<u8> {
    let mut checked = Vec::with_capacity(key.len() + 1 + body.len());
    checked.extend_from_slice(key.as_bytes());
    checked.push(b'\n');
    checked.extend_from_slice(body);
    let header = format!(
        "{MAGIC} v{CACHE_VERSION} {} {:08x}\n",
        body.len(),
        checksum(&checked)
    );
    let mut out = header.into_bytes();
    out.extend_from_slice(&checked);
    out
}

/// The value stored in `bytes` for `key`, or why it is not trusted.
fn decode<T: DeserializeOwned>(bytes: &[u8], key: &str) -> Result<T, &'static str> {
    // The header is short: look for its end in its first bytes only, not through a binary body.
    let nl = bytes
        .iter()
        .take(128)
        .position(|&b| b == b'\n')
        .ok_or("no header")?;
    let header = std::str::from_utf8(&bytes[..nl]).map_err(|_| "bad header")?;
    let fields: Vec<&str> = header.split(' ').collect();
    let [magic, version, len, sum] = fields[..] else {
        return Err("bad header");
    };
    if magic != MAGIC || version != format!("v{CACHE_VERSION}") {
        return Err("other format version");
    }
    let len: usize = len.parse().map_err(|_| "bad header")?;
    let sum = u32::from_str_radix(sum, 16).map_err(|_| "bad header")?;
    let checked = &bytes[nl + 1..];
    if checked.len() != key.len() + 1 + len {
        return Err("truncated or overlong");
    }
    if checksum(checked) != sum {
        return Err("checksum mismatch");
    }
    if &checked[..key.len()] != key.as_bytes() || checked[key.len()] != b'\n' {
        return Err("key mismatch");
    }
    match postcard::take_from_bytes(&checked[key.len() + 1..]) {
        Ok((value, [])) => Ok(value),
        _ => Err("unreadable body"),
    }
}

/// The value of `key`: read from `dir` when a trusted entry is there, else built by `build` and
/// stored, the folder then trimmed to `max_bytes` ([`evict`]); with `dir` `None` built without
/// the cache.
pub fn load_or_build<T, E>(
    dir: Option<&Path>,
    max_bytes: u64,
    key: &str,
    build: impl FnOnce() -> Result<T, E>,
) -> Result<(T, CacheOutcome), E>
where
    T: Serialize + DeserializeOwned,
{
    let Some(dir) = dir else {
        return Ok((build()?, CacheOutcome::Off));
    };
    let path = entry_path(dir, key);
    let distrust = match std::fs::read(&path) {
        Ok(bytes) => match decode(&bytes, key) {
            Ok(value) => {
                // Mark it used, so eviction removes the least recently used entries first.
                let _ = std::fs::File::options()
                    .append(true)
                    .open(&path)
                    .and_then(|f| f.set_modified(std::time::SystemTime::now()));
                return Ok((value, CacheOutcome::Hit(path)));
            }
            Err(why) => Some(why),
        },
        Err(_) => None,
    };
    let value = build()?;
    let outcome = match (store(dir, max_bytes, key, &value), distrust) {
        (Err(why), _) => CacheOutcome::Unwritten(path, why),
        (Ok(path), Some(why)) => CacheOutcome::Rebuilt(path, why),
        (Ok(path), None) => CacheOutcome::Built(path),
    };
    Ok((value, outcome))
}

/// Write `value` as the entry of `key` in `dir`, replacing any (and the same key's entry in the
/// former format), then trim the folder to `max_bytes` ([`evict`]); the entry's file, or why it
/// could not be written.
pub fn store<T: Serialize>(
    dir: &Path,
    max_bytes: u64,
    key: &str,
    value: &T,
) -> Result<PathBuf, String> {
    let path = entry_path(dir, key);
    let _ = std::fs::remove_file(path.with_extension(&LEGACY_SUFFIX[1..]));
    let body = postcard::to_stdvec(value).map_err(|e| e.to_string())?;
    crate::atomic::write_bytes(&path, &encode(key, &body)).map_err(|e| e.to_string())?;
    evict(dir, max_bytes, &path);
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn build(calls: &std::cell::Cell<u32>) -> Result<Vec<f32>, ()> {
        calls.set(calls.get() + 1);
        Ok(vec![0.1, 1.0 / 3.0, f32::MIN_POSITIVE, 7.5e-39, 1e38])
    }

    /// Stored values read back bit for bit; a corrupted byte, a truncated file, another key under
    /// the same name and a foreign file are each detected, rebuilt and rewritten.
    #[test]
    fn entries_are_verified_before_use() {
        let dir = tempfile::tempdir().unwrap();
        let calls = std::cell::Cell::new(0);
        let key = "test key";
        let (a, o) =
            load_or_build(Some(dir.path()), DEFAULT_MAX_BYTES, key, || build(&calls)).unwrap();
        assert!(matches!(o, CacheOutcome::Built(_)), "{o:?}");
        let (b, o) =
            load_or_build(Some(dir.path()), DEFAULT_MAX_BYTES, key, || build(&calls)).unwrap();
        assert!(matches!(o, CacheOutcome::Hit(_)), "{o:?}");
        assert_eq!(calls.get(), 1);
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a), bits(&b));
        let path = entry_path(dir.path(), key);
        let good = std::fs::read(&path).unwrap();
        let mut flipped = good.clone();
        let last = flipped.len() - 3;
        flipped[last] ^= 0x01;
        let body = postcard::to_stdvec(&a).unwrap();
        let mut overlong = body.clone();
        overlong.push(0);
        let older = String::from_utf8_lossy(&good).replacen(" v3 ", " v2 ", 1);
        let cases: [(&str, Vec<u8>); 7] = [
            ("checksum mismatch", flipped),
            ("truncated or overlong", good[..good.len() - 5].to_vec()),
            ("no header", b"garbage".to_vec()),
            ("key mismatch", encode("test kez", &body)),
            ("unreadable body", encode(key, &body[..body.len() - 1])),
            ("unreadable body", encode(key, &overlong)),
            ("other format version", older.into_bytes()),
        ];
        for (want, bytes) in cases {
            std::fs::write(&path, bytes).unwrap();
            let before = calls.get();
            let (v, o) =
                load_or_build(Some(dir.path()), DEFAULT_MAX_BYTES, key, || build(&calls)).unwrap();
            assert_eq!(o, CacheOutcome::Rebuilt(path.clone(), want));
            assert_eq!((calls.get(), bits(&v)), (before + 1, bits(&a)));
            // ...and the rewritten entry is trusted again.
            let (_, o) =
                load_or_build(Some(dir.path()), DEFAULT_MAX_BYTES, key, || build(&calls)).unwrap();
            assert!(matches!(o, CacheOutcome::Hit(_)), "{o:?}");
        }
        let (_, o) = load_or_build(None, DEFAULT_MAX_BYTES, key, || build(&calls)).unwrap();
        assert_eq!(o, CacheOutcome::Off);
    }

    /// Over the limit, the least recently used entries go first; the entry just written stays
    /// even when it alone is over the limit; a hit counts as a use; files that are not entries
    /// are never touched.
    #[test]
    fn the_folder_is_trimmed_to_its_limit_oldest_first() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let calls = std::cell::Cell::new(0);
        let stranger = d.join("notes.txt");
        std::fs::write(&stranger, vec![b'x'; 10_000]).unwrap();
        let put = |key: &str, limit: u64| {
            load_or_build(Some(d), limit, key, || build(&calls)).unwrap();
            // Modification times are kept to the file system's resolution: space the uses out.
            std::thread::sleep(std::time::Duration::from_millis(20));
        };
        let size = {
            put("a", DEFAULT_MAX_BYTES);
            std::fs::metadata(entry_path(d, "a")).unwrap().len()
        };
        put("b", DEFAULT_MAX_BYTES);
        put("c", DEFAULT_MAX_BYTES);
        put("a", DEFAULT_MAX_BYTES); // a hit: "a" is now the most recently used
        // Room for two entries: writing "d" removes "b" (oldest), then "c".
        put("d", 2 * size);
        let there = |k: &str| entry_path(d, k).exists();
        assert!(there("a") && there("d") && !there("b") && !there("c"));
        // A limit below one entry keeps the one just written.
        put("e", 1);
        assert!(there("e") && !there("a") && !there("d"));
        assert!(stranger.exists(), "a file that is not an entry was removed");
        assert!(is_entry_name("skin-tables-00112233445566ff.bin"));
        assert!(is_entry_name("skin-tables-00112233445566ff.json"));
        assert!(!is_entry_name("skin-tables-0011.bin") && !is_entry_name(".tmpXYZ"));
    }

    /// An entry of the former JSON format is replaced when its key is rewritten, and another
    /// key's former entry counts against the limit (it is the least recently used).
    #[test]
    fn entries_of_the_former_format_are_replaced_and_evicted() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let calls = std::cell::Cell::new(0);
        let legacy = |key: &str| entry_path(d, key).with_extension("json");
        std::fs::write(legacy("a"), vec![b'x'; 100]).unwrap();
        std::fs::write(legacy("b"), vec![b'x'; 100]).unwrap();
        let (_, o) = load_or_build(Some(d), DEFAULT_MAX_BYTES, "a", || build(&calls)).unwrap();
        assert!(matches!(o, CacheOutcome::Built(_)), "{o:?}");
        assert!(!legacy("a").exists() && legacy("b").exists());
        let size = std::fs::metadata(entry_path(d, "a")).unwrap().len();
        load_or_build(Some(d), size, "c", || build(&calls)).unwrap();
        assert!(!legacy("b").exists() && entry_path(d, "c").exists());
    }
}
