//! Process-wide memo tables for the pieces of a solve that depend only on the angular grid (and g),
//! not on the wavelength: built once, shared by every wavelength and thread.

use std::collections::HashMap;
use std::hash::Hash;
use std::sync::{Arc, Mutex, OnceLock};

/// A memo table: key → shared value, created on first use.
pub(crate) type Memo<K, V> = OnceLock<Mutex<HashMap<K, Arc<V>>>>;

/// The value of `memo` at `key`, built by `build` (outside the lock) the first time it is asked for.
/// Two threads may both build a missing entry; the first insert wins and both get it.
pub(crate) fn memoized<K: Eq + Hash, V>(
    memo: &'static Memo<K, V>,
    key: K,
    build: impl FnOnce() -> V,
) -> Arc<V> {
    let map = memo.get_or_init(|| Mutex::new(HashMap::new()));
    // A poisoned lock only means another thread panicked mid-insert of an independent entry: the map
    // is still valid, so recover it rather than fail.
    if let Some(hit) = map.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return Arc::clone(hit);
    }
    let built = Arc::new(build());
    let mut map = map.lock().unwrap_or_else(|e| e.into_inner());
    Arc::clone(map.entry(key).or_insert(built))
}
