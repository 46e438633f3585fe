//! A fixed adding-doubling workload for instruction counting: `reps` × the 31-λ skin totals
//! (light and dark presets) at `points` quadrature points, one thread.
//! Run: `valgrind --tool=callgrind target/release/examples/ad_workload 24 3`; the difference
//! between `reps` = 3 and 1, halved, is the steady-state count per repetition (caches warm).

use multipole::exact::adding_doubling::{AddingDoublingOptions, DEFAULT_G, skin_totals_spectrum};
use skin_optics::{Preset, SkinParams, WavelengthGrid};

fn main() {
    let mut args = std::env::args().skip(1);
    let points: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(24);
    let reps: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(1);
    let grid = WavelengthGrid::visible();
    let opts = AddingDoublingOptions::new(points, DEFAULT_G).expect("valid knob");
    let mut last = Vec::new();
    for _ in 0..reps {
        for preset in [Preset::Light, Preset::Dark] {
            let skin = SkinParams::preset(preset);
            let totals = skin_totals_spectrum(&skin, &grid, &opts).expect("valid skin");
            last.push(std::hint::black_box(totals));
        }
    }
    // The last repetition's totals, in full precision, to diff the numbers between builds.
    for totals in &last[last.len().saturating_sub(2)..] {
        for t in totals {
            println!("{t:?}");
        }
    }
}
