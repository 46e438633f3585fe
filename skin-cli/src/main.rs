//! `skin`: spectra, diffusion profiles, surface albedo, fits and renders of human skin.

use clap::{Parser, Subcommand};
use skin_cli as cli;
use std::process::ExitCode;

/// Physically based human skin (Donner & Jensen's spectral model): spectra, profiles and images.
#[derive(Parser, Debug)]
#[command(name = "skin", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Absorption, scattering and diffuse reflectance spectra of a skin, as CSV.
    Spectrum(cli::spectrum::SpectrumArgs),
    /// Radial diffuse reflectance profile R(r) of a skin at one wavelength, as CSV.
    Profile(cli::profile::ProfileArgs),
    /// Directional albedo of the oily surface layer (Torrance-Sparrow), as CSV.
    Brdf(cli::brdf::BrdfArgs),
    /// Render a scene (the built-in three-head scene by default) to images in out/.
    Render(cli::render::RenderArgs),
    /// Fit skin parameters to an sRGB colour or a measured reflectance spectrum.
    Fit(cli::fit::FitArgs),
    /// Write the skin for another renderer or simulator (OpenPBR, Unreal, HDRP, pbrt, Mitsuba, MCML, ...).
    Export(cli::export::ExportArgs),
    /// Chromophore maps (melanin, eumelanin, blood, residual) from an albedo texture, with edits.
    Maps(cli::maps::MapsArgs),
    /// The named skins (paper, medium, dark, measured group/site and ITA° presets) with colour and ITA°.
    Presets(cli::presets::PresetsArgs),
}

fn main() -> ExitCode {
    skin_io::atomic::remove_temporaries_on_interrupt(|n| {
        eprintln!("interrupted: removed {n} temporary file(s); nothing half-written is left");
    });
    cli::init_logging();
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Spectrum(a) => cli::spectrum::run(a),
        Command::Profile(a) => cli::profile::run(a),
        Command::Brdf(a) => cli::brdf::run(a),
        Command::Render(a) => cli::render::run(a),
        Command::Fit(a) => cli::fit::run(a),
        Command::Export(a) => cli::export::run(a),
        Command::Presets(a) => cli::presets::run(a),
        Command::Maps(a) => cli::maps::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", cli::one_line(&e));
            ExitCode::FAILURE
        }
    }
}
