//! Chromophore maps fitted to a skin's albedo texture at scene load (`fit_maps`): the inversion of
//! `skin maps` (`skin_fit::maps`, docs/physics.md §18) with its default options and the given
//! exposure, kept in the disk cache, so a scene can show a texture's per-texel skin without a
//! maps file beside it.

use crate::material::maps::ValueImage;
use crate::texture::Texture;
use serde::{Deserialize, Serialize};
use skin_fit::maps::{Eumelanin, Exposure, MapsModel, MapsOptions};

/// What the cache keeps: the maps of one texture.
#[derive(Debug, Serialize, Deserialize)]
struct Stored {
    width: usize,
    height: usize,
    /// C_m, β_m, C_h per texel.
    values: [Vec<f32>; 3],
    /// 1 where the texel was fitted under the thin epidermis, 0 elsewhere (`None`: no texel was).
    thin: Option<Vec<f32>>,
}

/// The maps of a texture as fitted at load.
#[derive(Debug, Clone)]
pub(super) struct Fitted {
    /// C_m, β_m, C_h.
    pub parameters: [ValueImage; 3],
    /// 1 where the texel was fitted under the thin epidermis, and that epidermis' thickness, mm
    /// (`None` when no texel was).
    pub thin: Option<(ValueImage, f64)>,
}

/// The options of a fit under `exposure`: `skin maps`' defaults (β_m fitted, the thin-epidermis
/// skin of `thin_epidermis_mm` for texels out of gamut, none when `None`), the shared disk cache.
fn options(exposure: Exposure, thin_epidermis_mm: Option<f64>) -> Result<MapsOptions, String> {
    Ok(MapsOptions {
        eumelanin: Eumelanin::Fit,
        exposure,
        thin_epidermis_mm,
        cache_dir: skin_io::cache::cache_dir(),
        cache_max_bytes: skin_io::cache::max_bytes().map_err(|e| e.to_string())?,
        ..MapsOptions::default()
    })
}

/// The cache key of the maps of `texels` (`width` × `height`) fitted with `opts`. Where the
/// cache is and how large it may grow change no texel: they are left out, so another cache
/// folder or limit finds the same entry instead of fitting again.
fn entry_key(width: usize, height: usize, texels: &[[f32; 3]], opts: &MapsOptions) -> String {
    let bytes: Vec<u8> = texels
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    let fitted_by = MapsOptions {
        cache_dir: None,
        cache_max_bytes: 0,
        ..opts.clone()
    };
    format!(
        "fitted-chromophore-maps v3; {width}x{height}; texels {:016x}; options {:016x}",
        skin_io::cache::fnv1a(&bytes),
        skin_io::cache::fnv1a(format!("{fitted_by:?}").as_bytes()),
    )
}

/// The maps (melanin, eumelanin, hemoglobin, thin epidermis) of `texture` fitted under the
/// exposure `spec` (`1`, `auto`, `auto-rgb`, `G` or `R,G,B`, as `skin maps --exposure`), texels
/// out of gamut fitted again under an epidermis `thin_epidermis_mm` thick (none: `None`), from the
/// disk cache when an earlier load fitted the same texels with the same options.
pub(super) fn fit(
    texture: &Texture,
    spec: &str,
    thin_epidermis_mm: Option<f64>,
) -> Result<Fitted, String> {
    let exposure: Exposure = spec.parse()?;
    let opts = options(exposure, thin_epidermis_mm)?;
    let (width, height) = texture.size();
    let texels = texture.texels();
    let key = entry_key(width, height, texels, &opts);
    let build = || -> Result<Stored, String> {
        let model = MapsModel::load(&opts).map_err(|e| e.to_string())?;
        let maps = model
            .fit(texels, None, &opts, &|_| {})
            .map_err(|e| e.to_string())?;
        let beta = maps
            .eumelanin_map
            .clone()
            .unwrap_or_else(|| vec![maps.eumelanin as f32; texels.len()]);
        let thin = maps
            .thin_epidermis
            .map(|t| t.texels.iter().map(|&f| f32::from(u8::from(f))).collect());
        Ok(Stored {
            width,
            height,
            values: [maps.melanin, beta, maps.hemoglobin],
            thin,
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
        && stored
            .values
            .iter()
            .chain(&stored.thin)
            .all(|v| v.len() == width * height);
    let stored = if whole { stored } else { build()? };
    let image = |values| ValueImage {
        width,
        height,
        values,
    };
    Ok(Fitted {
        parameters: stored.values.map(image),
        thin: stored
            .thin
            .zip(opts.thin_epidermis_mm)
            .map(|(v, mm)| (image(v), mm)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The key follows the texels and the fit's options, not the cache's folder or limit.
    #[test]
    fn the_maps_key_leaves_out_the_cache_folder() {
        let texels = [[0.5, 0.4, 0.3], [0.6, 0.45, 0.35]];
        let opts = options(Exposure::Auto, Some(0.05)).unwrap();
        let key = entry_key(2, 1, &texels, &opts);
        let elsewhere = MapsOptions {
            cache_dir: Some("/elsewhere".into()),
            cache_max_bytes: 1 << 20,
            ..opts.clone()
        };
        assert_eq!(entry_key(2, 1, &texels, &elsewhere), key);
        let other_fit = options(Exposure::WhiteBalance, Some(0.05)).unwrap();
        let other_texel = [[0.5, 0.4, 0.3], [0.6, 0.45, 0.36]];
        assert_ne!(entry_key(2, 1, &texels, &other_fit), key);
        assert_ne!(entry_key(2, 1, &other_texel, &opts), key);
        assert_ne!(entry_key(1, 2, &texels, &opts), key);
    }
}
