//! A per-thread cache of homogeneous layers' operators, keyed by everything a layer's operator
//! depends on: the angular grid (quadrature points and the critical cosine it is split at), the
//! albedo, the optical thickness and g, each by its exact bit pattern.
//!
//! A fit's Jacobian changes one parameter at a time, and most parameters belong to one layer only
//! (melanin, the epidermis thickness and its blood to the epidermis; C_h, γ and the dermis scattering
//! scale to the dermis; ρ_s to neither): the other layer's operator is then the one just computed.
//! A hit returns the operator the build would compute from the same inputs, so a cached solve
//! equals an uncached one bit for bit (tested); only the cost changes.
//!
//! Memory is bounded by [`LAYER_CACHE_BYTES`] per thread in two generations: when the current one is
//! full it becomes the old one (the previous old one is dropped) and a hit in the old generation
//! moves its entry back into the current one, so the recently used layers survive.

use super::layer::Operator;
use std::cell::{Cell, RefCell};
use std::collections::HashMap;
use std::rc::Rc;

/// Bytes of layer operators one thread's cache holds at most (both generations: four n × n matrices of
/// f64 per entry).
pub const LAYER_CACHE_BYTES: usize = 16 << 20;

/// What a homogeneous layer's operator depends on, by bit pattern.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct LayerKey {
    quadrature_points: usize,
    bits: [u64; 4],
}

impl LayerKey {
    /// The key of a layer of `albedo`, optical thickness `tau` (may be infinite) and anisotropy `g`
    /// on the grid of `quadrature_points` per hemisphere split at critical cosine `mu_critical`.
    pub(crate) fn new(
        quadrature_points: usize,
        mu_critical: f64,
        albedo: f64,
        tau: f64,
        g: f64,
    ) -> Self {
        Self {
            quadrature_points,
            bits: [
                mu_critical.to_bits(),
                albedo.to_bits(),
                tau.to_bits(),
                g.to_bits(),
            ],
        }
    }
}

#[derive(Default)]
struct Generations {
    current: HashMap<LayerKey, Rc<Operator>>,
    old: HashMap<LayerKey, Rc<Operator>>,
}

thread_local! {
    static CACHE: RefCell<Generations> = RefCell::new(Generations::default());
    static HITS: Cell<u64> = const { Cell::new(0) };
}

/// Entries one generation holds for operators of `n` directions (half the byte budget each).
fn generation_capacity(n: usize) -> usize {
    (LAYER_CACHE_BYTES / 2 / (4 * n * n * std::mem::size_of::<f64>()).max(1)).max(1)
}

/// The operator at `key` from this thread's cache, or `build()` (stored when it succeeds).
pub(crate) fn cached<E>(
    key: LayerKey,
    build: impl FnOnce() -> Result<Operator, E>,
) -> Result<Rc<Operator>, E> {
    let hit = CACHE.with(|c| {
        let mut c = c.borrow_mut();
        if let Some(op) = c.current.get(&key) {
            return Some(Rc::clone(op));
        }
        let op = c.old.remove(&key)?;
        c.current.insert(key, Rc::clone(&op));
        Some(op)
    });
    if let Some(op) = hit {
        HITS.with(|h| h.set(h.get() + 1));
        return Ok(op);
    }
    let op = Rc::new(build()?);
    let capacity = generation_capacity(op.r_down.n());
    CACHE.with(|c| {
        let mut c = c.borrow_mut();
        if c.current.len() >= capacity {
            c.old = std::mem::take(&mut c.current);
        }
        c.current.insert(key, Rc::clone(&op));
    });
    Ok(op)
}

/// Cache hits on this thread so far (for tests: a cache that never hits tests nothing).
#[cfg(test)]
pub(crate) fn hits() -> u64 {
    HITS.with(Cell::get)
}
