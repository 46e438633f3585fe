//! MCX / pmcx JSON input ([FB09]): a voxelised slab, the epidermis and a finite dermis as z-layers
//! of media with μa, μs (mm⁻¹, not reduced), g and n, a pencil beam at normal incidence,
//! refractive-index mismatch on, and one detector that takes every photon leaving through the top
//! face (docs/physics.md §14.5).
//!
//! MCX launches its photons inside the first voxel, past the air–skin face: its reflectance is per
//! photon *entering* the skin (our `total`), where `skin spectrum`'s `diffuse_reflectance` is per
//! photon incident from air; the two differ by the factor 1 − F(0) (F(0) = 2.78% at η = 1.4).

use crate::ExportOptions;
use crate::error::ExportError;
use crate::spectral::SpectralSkin;
use serde_json::json;

/// Voxels across the epidermis (its thickness sets the voxel size).
pub const EPIDERMIS_VOXELS: usize = 5;
/// Lateral size of the volume, mm.
pub const WIDTH_MM: f64 = 20.0;
/// Detector radius over the half-diagonal of the top face (a sphere about the beam's entry point
/// that holds the whole face; it reaches no deeper than the face's half-diagonal, so photons
/// leaving through the bottom are not counted).
const DETECTOR_OVER_HALF_DIAGONAL: f64 = 1.001;

/// The JSON of the first row of `spectral` and its notes.
pub fn write(
    spectral: &SpectralSkin,
    opts: &ExportOptions,
) -> Result<(String, Vec<String>), ExportError> {
    let row = &spectral.rows[0];
    let epidermis_mm = row.layers[0].thickness_mm.unwrap_or(0.0);
    let voxel_mm = epidermis_mm / EPIDERMIS_VOXELS as f64;
    let nx = (WIDTH_MM / voxel_mm).round() as usize;
    let nz_dermis = (opts.dermis_thickness_mm / voxel_mm).round() as usize;
    let nz = EPIDERMIS_VOXELS + nz_dermis;
    let centre = nx as f64 / 2.0;
    let detector_r = DETECTOR_OVER_HALF_DIAGONAL * centre * std::f64::consts::SQRT_2;
    if detector_r >= nz as f64 {
        return Err(ExportError::OutOfRange {
            name: "dermis thickness (mm)",
            value: opts.dermis_thickness_mm,
            range: "> 14.2 mm for MCX (the top-face detector must not reach the bottom face)",
        });
    }
    let f0 = ((row.layers[0].n - spectral.n_above) / (row.layers[0].n + spectral.n_above)).powi(2);
    let media: Vec<_> =
        std::iter::once(json!({ "mua": 0.0, "mus": 0.0, "g": 1.0, "n": spectral.n_above }))
            .chain(row.layers.iter().map(
                |l| json!({ "mua": l.sigma_a_per_mm, "mus": l.sigma_s_per_mm, "g": l.g, "n": l.n }),
            ))
            .collect();
    let value = json!({
        "Session": {
            "ID": format!("skin_{}nm", row.lambda_nm),
            "Photons": opts.photons,
            "RNGSeed": 1,
            "DoMismatch": 1,
            "DoAutoThread": 1,
            "DoPartialPath": 1,
            "SaveDataMask": "DPW",
        },
        "Forward": { "T0": 0.0, "T1": 5e-9, "Dt": 5e-9 },
        "Domain": {
            "OriginType": 1,
            "LengthUnit": voxel_mm,
            "Media": media,
            "Dim": [nx, nx, nz],
        },
        "Shapes": [
            { "Grid": { "Tag": 2, "Size": [nx, nx, nz] } },
            { "ZLayers": [[1, EPIDERMIS_VOXELS, 1]] },
        ],
        "Optode": {
            "Source": { "Type": "pencil", "Pos": [centre, centre, 0.0], "Dir": [0.0, 0.0, 1.0] },
            "Detector": [{ "Pos": [centre, centre, 0.0], "R": detector_r }],
        },
    });
    let notes = vec![
        format!(
            "units: MCX's: mua and mus in mm⁻¹ (mus not reduced), LengthUnit = voxel edge = {voxel_mm} mm; volume {nx} × {nx} × {nz} voxels; wavelength {} nm",
            row.lambda_nm
        ),
        format!(
            "conventions: Media[0] = air (n = {}), Media[1] = epidermis (z-layers 1-{EPIDERMIS_VOXELS}), Media[2] = dermis ({} mm, finite); pencil beam at the top centre, DoMismatch on",
            spectral.n_above, opts.dermis_thickness_mm
        ),
        format!(
            "detector: Detector[0] at the beam's entry point, radius {detector_r:.1} voxels, takes every photon leaving through the top face; reflectance = sum of detected weights (w0 · exp(−Σ mua·ppath)) / Photons"
        ),
        format!(
            "normalisation: MCX launches photons inside the skin, so its reflectance is per photon entering (exact here: {:.6}); per photon incident from air (skin spectrum's diffuse_reflectance, {:.6}) multiply by 1 − F(0) = {:.6}",
            row.total,
            row.diffuse_reflectance,
            1.0 - f0
        ),
        "engine model: MCX voxel Monte Carlo; accuracy: our layers, so nothing lost by construction; lateral and depth truncation of the volume are MCX's only departures from the model".to_string(),
    ];
    Ok((
        serde_json::to_string_pretty(&value).expect("a JSON value serialises"),
        notes,
    ))
}
