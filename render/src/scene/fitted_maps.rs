//! Chromophore maps fitted to a skin's albedo texture at scene load (`fit_maps`): the inversion of
//! `skin maps` (`skin_fit::maps`, docs/physics.md §18) with its default options and the given
//! exposure, kept in the disk cache, so a scene can show a texture's per-texel skin without a
//! maps file beside it.

use crate::material::maps::ValueImage;
use crate::texture::Texture;
use serde::{Deserialize, Serialize};
use skin_fit::maps::{Eumelanin, Exposure, MapsModel, MapsOptions};

/// What the cache keeps: the three maps of one texture.
#[derive(Debug, Serialize, Deserialize)]
struct Stored {
    width: usize,
    height: usize,
    /// C_m, β_m, C_h per texel.
    values: [Vec<f32>; 3],
}

/// The options of a fit under `exposure`: `skin maps`' defaults (β_m fitted, the thin-epidermis
/// skin for texels out of gamut), the shared disk cache.
fn options(exposure: Exposure) -> Result<MapsOptions, String> {
    Ok(MapsOptions {
        eumelanin: Eumelanin::Fit,
        exposure,
        cache_dir: skin_io::cache::cache_dir(),
        cache_max_bytes: skin_io::cache::max_bytes().map_err(|e| e.to_string())?,
        ..MapsOptions::default()
    })
}

/// The maps (melanin, eumelanin, hemoglobin) of `texture` fitted under the exposure `spec`
/// (`1`, `auto`, `auto-rgb`, `G` or `R,G,B`, as `skin maps --exposure`), from the disk cache when
/// an earlier load fitted the same texels with the same options.
pub(super) fn fit(texture: &Texture, spec: &str) -> Result<[ValueImage; 3], String> {
    let exposure: Exposure = spec.parse()?;
    let opts = options(exposure)?;
    let (width, height) = texture.size();
    let texels = texture.texels();
    let bytes: Vec<u8> = texels
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    let key = format!(
        "fitted-chromophore-maps v1; {width}x{height}; texels {:016x}; options {:016x}",
        skin_io::cache::fnv1a(&bytes),
        skin_io::cache::fnv1a(format!("{opts:?}").as_bytes()),
    );
    let build = || -> Result<Stored, String> {
        let model = MapsModel::load(&opts).map_err(|e| e.to_string())?;
        let maps = model
            .fit(texels, None, &opts, &|_| {})
            .map_err(|e| e.to_string())?;
        let beta = maps
            .eumelanin_map
            .clone()
            .unwrap_or_else(|| vec![maps.eumelanin as f32; texels.len()]);
        Ok(Stored {
            width,
            height,
            values: [maps.melanin, beta, maps.hemoglobin],
        })
    };
    let (stored, _) = skin_io::cache::load_or_build(
        opts.cache_dir.as_deref(),
        opts.cache_max_bytes,
        &key,
        build,
    )?;
    let whole = stored.width == width
        && stored.height == height
        && stored.values.iter().all(|v| v.len() == width * height);
    let stored = if whole { stored } else { build()? };
    Ok(stored.values.map(|values| ValueImage {
        width,
        height,
        values,
    }))
}
