//! Running the `skin` binary from the tests, and the render scaffolding of `render::testing`.

pub use render::testing::*;

use std::process::{Command, Output};

/// The export options that keep a textured export's fits quick in tests: 500-escape shapes,
/// 2,000 volume photons, a 20-nm grid.
pub const QUICK_EXPORT: [&str; 6] = [
    "--escapes",
    "500",
    "--volume-photons",
    "2000",
    "--step",
    "20",
];

/// Run the `skin` binary's `subcommand` with `args` to completion.
pub fn skin_cli(subcommand: &str, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_skin"))
        .arg(subcommand)
        .args(args)
        .output()
        .expect("run the skin binary")
}

/// A finished process's standard output, as text.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// A finished process's standard error, as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}
