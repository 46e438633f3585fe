//! Cross-crate properties and Monte Carlo agreement, one test binary (house style).
//!
//! Photon counts are scaled down in debug builds (`cargo test` without `--release`): every
//! tolerance is stated in standard errors, so the tests stay meaningful at either count.

/// One `#[test]` per row `name: args;`, each calling `$check(args)`, skipped in debug builds for
/// the reason `$why` (the cases are too large to run unoptimised).
macro_rules! release_cases {
    ($check:ident, $why:literal; $($name:ident: $($arg:expr),+;)*) => {$(
        #[test]
        #[cfg_attr(debug_assertions, ignore = $why)]
        fn $name() {
            $check($($arg),+);
        }
    )*};
}

mod exact;
mod memory_bound;
mod module_graph;
mod montecarlo;
mod properties;
