//! The disk cache of skin tables (docs/physics.md §16.5). An entry is one file in
//! `multipole::skin::cache_dir()` (`$SKIN_CACHE_DIR`, else `$XDG_CACHE_HOME/skin`, else
//! `~/.cache/skin`) named by a hash of its key, the text of everything the tables depend on (the
//! skin's parameters, the method, every knob and [`CACHE_VERSION`]). The file holds a header line
//! (format, body length, checksum), the key and the body (JSON, which writes every f32 so that it
//! reads back to the same bits). An entry is used only when the key is the one asked for, the
//! length is whole and the checksum matches; otherwise it is rebuilt and rewritten. Files are
//! written through `crate::atomic`, so a reader never sees half of one.

use serde::Serialize;
use serde::de::DeserializeOwned;
use std::path::{Path, PathBuf};

/// Version of the tables' contents: bump it whenever what a given key builds changes.
pub const CACHE_VERSION: u32 = 1;
/// First word of an entry's header.
const MAGIC: &str = "skin-tables";

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

/// 64-bit FNV-1a of `bytes` (the checksum and the file name's hash; not cryptographic: the key
/// stored in the file decides, the hash only finds it).
#[must_use]
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The file of `key` in `dir`.
#[must_use]
pub fn entry_path(dir: &Path, key: &str) -> PathBuf {
    dir.join(format!("skin-tables-{:016x}.json", fnv1a(key.as_bytes())))
}

/// The bytes of an entry.
fn encode(key: &str, body: &[u8]) -> Vec<u8> {
    let mut checked = Vec::with_capacity(key.len() + 1 + body.len());
    checked.extend_from_slice(key.as_bytes());
    checked.push(b'\n');
    checked.extend_from_slice(body);
    let header = format!(
        "{MAGIC} v{CACHE_VERSION} {} {:016x}\n",
        body.len(),
        fnv1a(&checked)
    );
    let mut out = header.into_bytes();
    out.extend_from_slice(&checked);
    out
}

/// The value stored in `bytes` for `key`, or why it is not trusted.
fn decode<T: DeserializeOwned>(bytes: &[u8], key: &str) -> Result<T, &'static str> {
    let nl = bytes.iter().position(|&b| b == b'\n').ok_or("no header")?;
    let header = std::str::from_utf8(&bytes[..nl]).map_err(|_| "bad header")?;
    let fields: Vec<&str> = header.split(' ').collect();
    let [magic, version, len, sum] = fields[..] else {
        return Err("bad header");
    };
    if magic != MAGIC || version != format!("v{CACHE_VERSION}") {
        return Err("other format version");
    }
    let len: usize = len.parse().map_err(|_| "bad header")?;
    let sum = u64::from_str_radix(sum, 16).map_err(|_| "bad header")?;
    let checked = &bytes[nl + 1..];
    if checked.len() != key.len() + 1 + len {
        return Err("truncated or overlong");
    }
    if fnv1a(checked) != sum {
        return Err("checksum mismatch");
    }
    if &checked[..key.len()] != key.as_bytes() || checked[key.len()] != b'\n' {
        return Err("key mismatch");
    }
    serde_json::from_slice(&checked[key.len() + 1..]).map_err(|_| "unreadable body")
}

/// The value of `key`: read from `dir` when a trusted entry is there, else built by `build` and
/// stored; with `dir` `None` built without the cache.
pub fn load_or_build<T, E>(
    dir: Option<&Path>,
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
            Ok(value) => return Ok((value, CacheOutcome::Hit(path))),
            Err(why) => Some(why),
        },
        Err(_) => None,
    };
    let value = build()?;
    let stored = serde_json::to_vec(&value)
        .map_err(|e| e.to_string())
        .and_then(|body| {
            crate::atomic::write_bytes(&path, &encode(key, &body)).map_err(|e| e.to_string())
        });
    let outcome = match (stored, distrust) {
        (Err(why), _) => CacheOutcome::Unwritten(path, why),
        (Ok(()), Some(why)) => CacheOutcome::Rebuilt(path, why),
        (Ok(()), None) => CacheOutcome::Built(path),
    };
    Ok((value, outcome))
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
        let (a, o) = load_or_build(Some(dir.path()), key, || build(&calls)).unwrap();
        assert!(matches!(o, CacheOutcome::Built(_)), "{o:?}");
        let (b, o) = load_or_build(Some(dir.path()), key, || build(&calls)).unwrap();
        assert!(matches!(o, CacheOutcome::Hit(_)), "{o:?}");
        assert_eq!(calls.get(), 1);
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a), bits(&b));
        let path = entry_path(dir.path(), key);
        let good = std::fs::read(&path).unwrap();
        let mut flipped = good.clone();
        let last = flipped.len() - 3;
        flipped[last] ^= 0x01;
        let cases: [(&str, Vec<u8>); 4] = [
            ("checksum mismatch", flipped),
            ("truncated or overlong", good[..good.len() - 5].to_vec()),
            ("no header", b"garbage".to_vec()),
            ("key mismatch", encode("test kez", b"[1.0]")),
        ];
        for (want, bytes) in cases {
            std::fs::write(&path, bytes).unwrap();
            let before = calls.get();
            let (v, o) = load_or_build(Some(dir.path()), key, || build(&calls)).unwrap();
            assert_eq!(o, CacheOutcome::Rebuilt(path.clone(), want));
            assert_eq!((calls.get(), bits(&v)), (before + 1, bits(&a)));
            // ...and the rewritten entry is trusted again.
            let (_, o) = load_or_build(Some(dir.path()), key, || build(&calls)).unwrap();
            assert!(matches!(o, CacheOutcome::Hit(_)), "{o:?}");
        }
        let (_, o) = load_or_build(None, key, || build(&calls)).unwrap();
        assert_eq!(o, CacheOutcome::Off);
    }
}
