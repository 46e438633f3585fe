//! MCX / pmcx JSON input ([FB09]): a voxelised slab, the epidermis and a finite dermis as z-layers
//! of media with μa, μs (mm⁻¹, not reduced), g and n, a pencil beam at normal incidence and
//! refractive-index mismatch on (docs/physics.md §14).

use crate::ExportOptions;
use crate::error::ExportError;
use crate::spectral::SpectralSkin;
use serde_json::json;

/// Voxels across the epidermis (its thickness sets the voxel size).
pub const EPIDERMIS_VOXELS: usize = 5;
/// Lateral size of the volume, mm.
pub const WIDTH_MM: f64 = 20.0;

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
            "Source": { "Type": "pencil", "Pos": [nx as f64 / 2.0, nx as f64 / 2.0, 0.0], "Dir": [0.0, 0.0, 1.0] },
            "Detector": [],
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
        "accuracy: nothing lost by construction (our layers); lateral and depth truncation of the volume are MCX's only departures from the model".to_string(),
    ];
    Ok((
        serde_json::to_string_pretty(&value).expect("a JSON value serialises"),
        notes,
    ))
}
