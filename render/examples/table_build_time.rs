//! Build time of the default scene's three skin profile tables (light, medium, dark presets) with the
//! default method and table options, and each table's reach and red total. Reads the process's CPU
//! time (`cpu-time`), so the figure holds on a loaded machine.
//!
//! `cargo run --release -p render --example table_build_time`

use multipole::Method;
use render::bssrdf::{ProfileTable, TableOptions};
use skin_optics::{Preset, SkinParams};

fn main() {
    let start = cpu_time::ProcessTime::now();
    for p in [Preset::Light, Preset::Medium, Preset::Dark] {
        let t = ProfileTable::build(
            &SkinParams::preset(p),
            Method::default(),
            &TableOptions::default(),
        )
        .expect("the presets build");
        println!(
            "{p:?}: r_max(450 nm) = {:.2} mm, r_max(650 nm) = {:.2} mm, R_tot(650 nm) = {:.3}",
            t.r_max_mm(450.0),
            t.r_max_mm(650.0),
            t.total(650.0)
        );
    }
    println!(
        "three presets' profile tables: {:.3} s of CPU time",
        start.elapsed().as_secs_f64()
    );
}
