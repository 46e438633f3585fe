//! Chromophore maps: per-texel skin parameters (C_m, β_m, C_h) over a mesh's texture coordinates
//! (docs/physics.md §19, "Heterogeneous skin"), read from the `maps.exr` of `skin maps` or from one
//! file per parameter, edited at load, and checked: every texel finite and in [0, 1] after the
//! edits (an error names the key, the file, the texel and the range; nothing is clamped).
//!
//! A per-parameter file is a single-channel OpenEXR (its one channel, or the channel named after
//! the parameter) or a grey PNG whose 8- or 16-bit values hold the parameter directly
//! (value / 255 or value / 65535; no transfer curve). Sizes are capped as textures are
//! (`crate::texture::MAX_TEXELS`), checked before anything is allocated.
//!
//! `maps.exr`'s `thin_epidermis` channel (1 where a texel was fitted under the thin epidermis of
//! §18, 0 where it has the material's) is read with the thickness its `thin_epidermis_mm` header
//! attribute records (or the scene's `thin_epidermis_mm`): the epidermis per texel (§19).

use crate::error::RenderError;
use crate::texture::{Texture, check_exr_headers, check_size};
use glam::Vec2;
use std::path::{Path, PathBuf};

/// A skin parameter a map may hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parameter {
    /// Melanin fraction C_m.
    Melanin,
    /// Eumelanin blend β_m.
    Eumelanin,
    /// Hemoglobin fraction C_h.
    Hemoglobin,
}

impl Parameter {
    /// All three, in texel order (C_m, β_m, C_h).
    pub const ALL: [Parameter; 3] = [Self::Melanin, Self::Eumelanin, Self::Hemoglobin];

    /// The channel name in `maps.exr` (and the scene key's stem).
    #[must_use]
    pub fn channel(self) -> &'static str {
        match self {
            Self::Melanin => "melanin",
            Self::Eumelanin => "eumelanin",
            Self::Hemoglobin => "hemoglobin",
        }
    }
}

/// One parameter's values, row-major, rows top to bottom (v = 0 at the top row).
#[derive(Debug, Clone, PartialEq)]
pub struct ValueImage {
    /// Width, texels.
    pub width: usize,
    /// Height, texels.
    pub height: usize,
    /// The values, `width × height`.
    pub values: Vec<f32>,
}

/// A load-time edit of a parameter: v' = v + m (s v + o − v), m the mask's value (1 without one).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Edit {
    /// Scale s (scene key `melanin_scale`, `hemoglobin_scale`; default 1).
    pub scale: f64,
    /// Offset o (scene key `melanin_offset`, `hemoglobin_offset`; default 0).
    pub offset: f64,
}

/// Where one parameter comes from: a map (its scene key and file) or the material's scalar.
#[derive(Debug, Clone)]
pub enum Source {
    /// A map read from `path` under scene key `key`.
    Map {
        /// Dotted scene key.
        key: String,
        /// The file as given.
        path: PathBuf,
        /// The values.
        image: ValueImage,
    },
    /// The same value at every texel (the material's scalar or preset).
    Scalar(f64),
}

/// The thin-epidermis flag of a skin's maps as given, before assembly.
#[derive(Debug, Clone)]
pub struct ThinInput {
    /// Dotted scene key the flag came with (`maps` or `fit_maps`).
    pub key: String,
    /// The file as given.
    pub path: PathBuf,
    /// Per texel, 1 where the texel has the thin epidermis, 0 where it has the material's.
    pub image: ValueImage,
    /// The thin epidermis' thickness, mm (checked by the caller, which knows its key).
    pub thickness_mm: f32,
}

/// Where a skin has a thinner epidermis than the material's (docs/physics.md §19): a flag per
/// texel, bilinearly filtered like the maps and read as thin where the filtered flag is ≥ ½.
#[derive(Debug, Clone)]
pub struct ThinEpidermisMap {
    /// The thin epidermis' thickness, mm.
    pub thickness_mm: f32,
    flag: Texture,
    /// [lo, hi] of each parameter (C_m, β_m, C_h) over the texels a filtered lookup where the
    /// flag is not 0 can read: those within one texel of a thin texel.
    range: [[f32; 2]; 3],
}

impl ThinEpidermisMap {
    /// The filtered flag at `uv`: 1 in thin skin, 0 in the material's, a fraction between.
    #[must_use]
    #[inline]
    pub fn at(&self, uv: Vec2) -> f32 {
        self.flag.lookup(uv)[0]
    }

    /// Whether the skin at `uv` has the thin epidermis: the filtered flag at least ½, so the
    /// border between the two skins is the flag's smooth ½ contour, between the texel centres
    /// (docs/physics.md §19.2).
    #[must_use]
    #[inline]
    pub fn is_thin(&self, uv: Vec2) -> bool {
        self.at(uv) >= 0.5
    }

    /// [lo, hi] of each parameter (C_m, β_m, C_h) wherever the flag is not 0.
    #[must_use]
    pub fn range(&self) -> [[f32; 2]; 3] {
        self.range
    }

    /// [lo, hi] of the filtered flag ([`Self::at`]) at uv in [u₀, u₁] × [v₀, v₁].
    #[must_use]
    pub fn flag_range_over(&self, u: [f32; 2], v: [f32; 2]) -> [f32; 2] {
        self.flag.range_over(u, v)[0]
    }
}

/// What the scene gives for a skin's maps, before assembly.
#[derive(Debug, Clone)]
pub struct MapInputs {
    /// The material's scene key, e.g. `materials.skin`.
    pub material_key: String,
    /// Per parameter (C_m, β_m, C_h), where its values come from.
    pub sources: [Source; 3],
    /// Edits of C_m and C_h (β_m is not edited), each under its scene key stem.
    pub edits: [(Parameter, Edit); 2],
    /// The mask weighting the edits (`edit_mask`): scene key, file and values in [0, 1].
    pub mask: Option<(String, PathBuf, ValueImage)>,
    /// The thin-epidermis flag (`None`: every texel has the material's epidermis).
    pub thin: Option<ThinInput>,
}

/// Per-texel (C_m, β_m, C_h) of one skin material, bilinearly filtered like a texture (u wraps,
/// v clamps), with each parameter's range over the texels.
#[derive(Debug, Clone)]
pub struct ChromophoreMaps {
    texels: Texture,
    range: [[f32; 2]; 3],
    typical: [f32; 3],
    thin: Option<ThinEpidermisMap>,
}

fn map_err(key: &str, path: &Path, message: impl Into<String>) -> RenderError {
    RenderError::ChromophoreMap {
        key: key.to_string(),
        path: path.to_path_buf(),
        message: message.into(),
    }
}

impl ChromophoreMaps {
    /// Assemble the maps: all given images of one size, the scalars filling the rest, the edits
    /// applied under the mask, every texel finite and in [0, 1] (else an error naming the key, the
    /// file, the texel and the range). `None` when no parameter has a map and no mask is given.
    pub fn assemble(inputs: MapInputs) -> Result<Option<Self>, RenderError> {
        let mut size: Option<(usize, usize, String, PathBuf)> = None;
        let images = inputs
            .sources
            .iter()
            .filter_map(|s| match s {
                Source::Map { key, path, image } => Some((key, path, image)),
                Source::Scalar(_) => None,
            })
            .chain(inputs.mask.iter().map(|(k, p, i)| (k, p, i)))
            .chain(inputs.thin.iter().map(|t| (&t.key, &t.path, &t.image)));
        for (key, path, image) in images {
            if let Some(v) = image.values.iter().position(|v| !v.is_finite()) {
                return Err(map_err(
                    key,
                    path,
                    format!(
                        "texel ({}, {}) is not a number",
                        v % image.width,
                        v / image.width
                    ),
                ));
            }
            match &size {
                None => size = Some((image.width, image.height, key.clone(), path.clone())),
                Some((w, h, first_key, first_path)) if (*w, *h) != (image.width, image.height) => {
                    return Err(map_err(
                        key,
                        path,
                        format!(
                            "{}×{} texels, but `{first_key}` ({}) has {w}×{h}: the maps must \
                             share one size",
                            image.width,
                            image.height,
                            first_path.display()
                        ),
                    ));
                }
                Some(_) => {}
            }
        }
        let Some((width, height, _, first_path)) = size else {
            return Ok(None);
        };
        let n = width * height;
        let mut values: [Vec<f32>; 3] = std::array::from_fn(|k| match &inputs.sources[k] {
            Source::Map { image, .. } => image.values.clone(),
            Source::Scalar(v) => vec![*v as f32; n],
        });
        for (param, edit) in inputs.edits {
            if edit
                == (Edit {
                    scale: 1.0,
                    offset: 0.0,
                })
            {
                continue;
            }
            let k = param as usize;
            for (i, v) in values[k].iter_mut().enumerate() {
                let m = inputs
                    .mask
                    .as_ref()
                    .map_or(1.0, |(_, _, mask)| mask.values[i]);
                let x = f64::from(*v);
                *v = (x + f64::from(m) * (edit.scale * x + edit.offset - x)) as f32;
            }
        }
        if let Some((key, path, mask)) = &inputs.mask
            && let Some(i) = mask.values.iter().position(|v| !(0.0..=1.0).contains(v))
        {
            return Err(map_err(
                key,
                path,
                format!(
                    "texel ({}, {}) = {} outside the mask's range [0, 1]",
                    i % width,
                    i / width,
                    mask.values[i]
                ),
            ));
        }
        for (k, param) in Parameter::ALL.iter().enumerate() {
            if let Some(i) = values[k].iter().position(|v| !(0.0..=1.0).contains(v)) {
                let (key, path) = match &inputs.sources[k] {
                    Source::Map { key, path, .. } => (key.clone(), path.clone()),
                    // A scalar leaves [0, 1] only through its edit: name the edit's key.
                    Source::Scalar(_) => (
                        format!("{}.{}_offset", inputs.material_key, param.channel()),
                        first_path.clone(),
                    ),
                };
                let edited = inputs
                    .edits
                    .iter()
                    .any(|(p, e)| p == param && (e.scale != 1.0 || e.offset != 0.0));
                return Err(map_err(
                    &key,
                    &path,
                    format!(
                        "{} at texel ({}, {}) is {}{}, outside [0, 1]",
                        param.channel(),
                        i % width,
                        i / width,
                        values[k][i],
                        if edited {
                            format!(
                                " after {0}_scale and {0}_offset (nothing is clamped)",
                                param.channel()
                            )
                        } else {
                            String::new()
                        }
                    ),
                ));
            }
        }
        let range = std::array::from_fn(|k| {
            values[k]
                .iter()
                .fold([f32::INFINITY, f32::NEG_INFINITY], |[lo, hi], &v| {
                    [lo.min(v), hi.max(v)]
                })
        });
        let thin = match &inputs.thin {
            Some(t) => thin_map(t, &values, width, height)?,
            None => None,
        };
        let under_material = |i: usize| {
            thin.is_none() || inputs.thin.as_ref().is_none_or(|t| t.image.values[i] < 0.5)
        };
        let typical = std::array::from_fn(|k| {
            let mut v: Vec<f32> = (0..n)
                .filter(|&i| under_material(i))
                .map(|i| values[k][i])
                .collect();
            if v.is_empty() {
                v.clone_from(&values[k]);
            }
            let mid = v.len() / 2;
            *v.select_nth_unstable_by(mid, f32::total_cmp).1
        });
        let texels = (0..n)
            .map(|i| [values[0][i], values[1][i], values[2][i]])
            .collect();
        Ok(Some(Self {
            texels: Texture::from_texels(width, height, texels),
            range,
            typical,
            thin,
        }))
    }

    /// The typical skin of the maps: each parameter's median over the texels under the
    /// material's own epidermis (C_m, β_m, C_h). The material's scalar skin takes it, so that
    /// what reads one skin per material (profile extent, level of detail, the thin-part
    /// criterion, the oblique-incidence gain) reads skin like the maps'.
    #[must_use]
    pub fn typical(&self) -> [f32; 3] {
        self.typical
    }

    /// Where the skin has a thin epidermis (`None`: nowhere).
    #[must_use]
    pub fn thin(&self) -> Option<&ThinEpidermisMap> {
        self.thin.as_ref()
    }

    /// (C_m, β_m, C_h) at `uv`, bilinearly filtered.
    #[must_use]
    #[inline]
    pub fn at(&self, uv: Vec2) -> [f32; 3] {
        self.texels.lookup(uv)
    }

    /// [lo, hi] of each parameter over every value [`ChromophoreMaps::at`] returns at uv in
    /// [u₀, u₁] × [v₀, v₁] (their bilinear footprints, a texel of margin).
    #[must_use]
    pub fn range_over(&self, u: [f32; 2], v: [f32; 2]) -> [[f32; 2]; 3] {
        self.texels.range_over(u, v)
    }

    /// [lo, hi] of each parameter (C_m, β_m, C_h) over the texels.
    #[must_use]
    pub fn range(&self) -> [[f32; 2]; 3] {
        self.range
    }

    /// Width × height, texels.
    #[must_use]
    pub fn size(&self) -> (usize, usize) {
        self.texels.size()
    }
}

/// The flag of `input` checked (every texel in [0, 1], else an error naming its key, file and
/// texel), with the parameters' range over the texels within one texel of a thin one (u wraps,
/// v clamps, as the filter reads them); `None` when no texel is thin.
fn thin_map(
    input: &ThinInput,
    values: &[Vec<f32>; 3],
    width: usize,
    height: usize,
) -> Result<Option<ThinEpidermisMap>, RenderError> {
    let flag = &input.image.values;
    if let Some(i) = flag.iter().position(|v| !(0.0..=1.0).contains(v)) {
        return Err(map_err(
            &input.key,
            &input.path,
            format!(
                "thin_epidermis at texel ({}, {}) is {}, outside [0, 1] (1: the texel has the \
                 thin epidermis, 0: the material's)",
                i % width,
                i / width,
                flag[i]
            ),
        ));
    }
    if flag.iter().all(|&f| f == 0.0) {
        return Ok(None);
    }
    let mut near = vec![false; width * height];
    for (i, _) in flag.iter().enumerate().filter(|(_, f)| **f > 0.0) {
        let (x, y) = ((i % width) as isize, (i / width) as isize);
        for dy in -1..=1isize {
            let yy = (y + dy).clamp(0, height as isize - 1) as usize;
            for dx in -1..=1isize {
                let xx = (x + dx).rem_euclid(width as isize) as usize;
                near[yy * width + xx] = true;
            }
        }
    }
    let range = std::array::from_fn(|k| {
        values[k]
            .iter()
            .zip(&near)
            .filter(|(_, n)| **n)
            .fold([f32::INFINITY, f32::NEG_INFINITY], |[lo, hi], (&v, _)| {
                [lo.min(v), hi.max(v)]
            })
    });
    Ok(Some(ThinEpidermisMap {
        thickness_mm: input.thickness_mm,
        flag: Texture::from_texels(width, height, flag.iter().map(|&f| [f, 0.0, 0.0]).collect()),
        range,
    }))
}

/// Name of maps.exr's thin-epidermis flag channel.
pub const THIN_EPIDERMIS_CHANNEL: &str = "thin_epidermis";

/// Name of maps.exr's header attribute holding the thin epidermis' thickness, mm.
pub const THIN_EPIDERMIS_ATTRIBUTE: &str = "thin_epidermis_mm";

/// What a `maps.exr` holds for the renderer.
#[derive(Debug, Clone)]
pub struct MapsExr {
    /// The channels `melanin`, `eumelanin`, `hemoglobin` (each `None` when absent).
    pub parameters: [Option<ValueImage>; 3],
    /// The `thin_epidermis` channel, if present.
    pub thin_epidermis: Option<ValueImage>,
    /// The `thin_epidermis_mm` header attribute, mm, if present (unchecked).
    pub thin_epidermis_mm: Option<f64>,
}

/// The channels `melanin`, `eumelanin`, `hemoglobin` and `thin_epidermis` of a `maps.exr` with
/// its `thin_epidermis_mm` attribute (other channels are ignored). An error when none of the
/// three parameters is present.
pub fn read_maps_exr(bytes: &[u8], path: &Path) -> Result<MapsExr, RenderError> {
    let (channels, attributes) = exr_contents(bytes, path)?;
    let found: [Option<ValueImage>; 3] = std::array::from_fn(|k| {
        channels
            .iter()
            .find(|(name, _)| name == Parameter::ALL[k].channel())
            .map(|(_, image)| image.clone())
    });
    if found.iter().all(Option::is_none) {
        let names: Vec<&str> = channels.iter().map(|(n, _)| n.as_str()).collect();
        return Err(RenderError::Image {
            path: path.to_path_buf(),
            message: format!(
                "none of the channels melanin, eumelanin, hemoglobin (found {})",
                names.join(", ")
            ),
        });
    }
    let thin_epidermis = channels
        .iter()
        .find(|(name, _)| name == THIN_EPIDERMIS_CHANNEL)
        .map(|(_, image)| image.clone());
    let thin_epidermis_mm = attributes
        .iter()
        .find(|(name, _)| name == THIN_EPIDERMIS_ATTRIBUTE)
        .map(|(_, v)| *v);
    Ok(MapsExr {
        parameters: found,
        thin_epidermis,
        thin_epidermis_mm,
    })
}

/// One parameter's values from a single-channel EXR (its one channel, or the channel named
/// `name`) or a grey 8- or 16-bit PNG (value / 255 or / 65535).
pub fn read_value_image(bytes: &[u8], path: &Path, name: &str) -> Result<ValueImage, RenderError> {
    let image_err = |message: String| RenderError::Image {
        path: path.to_path_buf(),
        message,
    };
    if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        let mut channels = exr_channels(bytes, path)?;
        if let Some(k) = channels.iter().position(|(n, _)| n == name) {
            return Ok(channels.swap_remove(k).1);
        }
        if channels.len() == 1 {
            return Ok(channels.remove(0).1);
        }
        let names: Vec<&str> = channels.iter().map(|(n, _)| n.as_str()).collect();
        return Err(image_err(format!(
            "expected one channel (or one named {name}), found {}",
            names.join(", ")
        )));
    }
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| image_err(e.to_string()))
    };
    let (w, h) = reader()?
        .into_dimensions()
        .map_err(|e| image_err(e.to_string()))?;
    check_size(w as usize, h as usize, path)?;
    let img = reader()?.decode().map_err(|e| image_err(e.to_string()))?;
    let values = match &img {
        image::DynamicImage::ImageLuma8(g) => {
            g.as_raw().iter().map(|&v| f32::from(v) / 255.0).collect()
        }
        image::DynamicImage::ImageLuma16(g) => {
            g.as_raw().iter().map(|&v| f32::from(v) / 65535.0).collect()
        }
        other => {
            return Err(image_err(format!(
                "expected a grey 8- or 16-bit PNG holding the values, found {:?}",
                other.color()
            )));
        }
    };
    Ok(ValueImage {
        width: w as usize,
        height: h as usize,
        values,
    })
}

/// Every channel of an EXR's first layer (largest resolution), by name, as f32.
fn exr_channels(bytes: &[u8], path: &Path) -> Result<Vec<(String, ValueImage)>, RenderError> {
    exr_contents(bytes, path).map(|(channels, _)| channels)
}

/// Named channels and float attributes.
type ExrContents = (Vec<(String, ValueImage)>, Vec<(String, f64)>);

/// [`exr_channels`] with the float attributes of the layer's and the image's headers.
fn exr_contents(bytes: &[u8], path: &Path) -> Result<ExrContents, RenderError> {
    use exr::prelude::*;
    check_exr_headers(bytes, path)?;
    let img = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| RenderError::Image {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    let (width, height) = (img.layer_data.size.0, img.layer_data.size.1);
    let channels = img
        .layer_data
        .channel_data
        .list
        .iter()
        .map(|c| {
            (
                c.name.to_string(),
                ValueImage {
                    width,
                    height,
                    values: c.sample_data.values_as_f32().collect(),
                },
            )
        })
        .collect();
    let attributes = img
        .layer_data
        .attributes
        .other
        .iter()
        .chain(&img.attributes.other)
        .filter_map(|(name, value)| {
            let v = match value {
                AttributeValue::F32(v) => f64::from(*v),
                AttributeValue::F64(v) => *v,
                _ => return None,
            };
            Some((name.to_string(), v))
        })
        .collect();
    Ok((channels, attributes))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(width: usize, height: usize, v: f32) -> ValueImage {
        ValueImage {
            width,
            height,
            values: vec![v; width * height],
        }
    }

    fn inputs(melanin: ValueImage, edit: Edit) -> MapInputs {
        MapInputs {
            material_key: "materials.s".into(),
            sources: [
                Source::Map {
                    key: "materials.s.melanin_map".into(),
                    path: "m.png".into(),
                    image: melanin,
                },
                Source::Scalar(0.5),
                Source::Scalar(0.02),
            ],
            edits: [
                (Parameter::Melanin, edit),
                (
                    Parameter::Hemoglobin,
                    Edit {
                        scale: 1.0,
                        offset: 0.0,
                    },
                ),
            ],
            mask: None,
            thin: None,
        }
    }

    /// A texel is thin where the bilinearly filtered flag is at least ½: between a thin texel
    /// and a normal one the border lies midway between their centres (u wraps, so also across
    /// u = 0); the thin skin's parameter box spans the texels within one texel of a thin one and
    /// no others; a flag that is 0 everywhere gives no thin skin.
    #[test]
    fn thin_texels_border_midway_and_bound_their_box() {
        let mut i = inputs(
            ValueImage {
                width: 4,
                height: 1,
                values: vec![0.1, 0.2, 0.3, 0.4],
            },
            Edit {
                scale: 1.0,
                offset: 0.0,
            },
        );
        let thin = |flags: Vec<f32>| ThinInput {
            key: "materials.s.maps".into(),
            path: "maps.exr".into(),
            image: ValueImage {
                width: 4,
                height: 1,
                values: flags,
            },
            thickness_mm: 0.05,
        };
        i.thin = Some(thin(vec![0.0, 1.0, 0.0, 0.0]));
        let maps = ChromophoreMaps::assemble(i.clone()).unwrap().unwrap();
        let t = maps.thin().expect("a thin texel");
        // Texel centres at u = 0.125 + 0.25 k; texel 1 (u 0.375) is thin.
        for (u, want) in [
            (0.26, true),
            (0.374, true),
            (0.49, true),
            (0.24, false),
            (0.51, false),
        ] {
            assert_eq!(t.is_thin(Vec2::new(u, 0.5)), want, "u = {u}");
        }
        assert_eq!(t.range()[0], [0.1, 0.3]);
        i.thin = Some(thin(vec![1.0, 0.0, 0.0, 0.0]));
        let maps = ChromophoreMaps::assemble(i.clone()).unwrap().unwrap();
        let t = maps.thin().unwrap();
        // The border with texel 3 lies at u = 1 ≡ 0.
        assert!(t.is_thin(Vec2::new(0.01, 0.5)) && !t.is_thin(Vec2::new(0.99, 0.5)));
        assert_eq!(t.range()[0], [0.1, 0.4]);
        i.thin = Some(thin(vec![0.0; 4]));
        assert!(
            ChromophoreMaps::assemble(i)
                .unwrap()
                .unwrap()
                .thin()
                .is_none()
        );
    }

    /// The typical skin is each parameter's median over the texels under the material's
    /// epidermis, after the edits: melanin 0.4, 0.1, 0.9, 0.3, 0.2 plus 0.05 has the median
    /// 0.35; with texels 3 and 4 (0.35, 0.25) thin, the median of the other three is 0.45.
    /// Scalars are their own median.
    #[test]
    fn the_typical_skin_is_the_median_of_the_material_epidermis_texels() {
        let mut i = inputs(
            ValueImage {
                width: 5,
                height: 1,
                values: vec![0.4, 0.1, 0.9, 0.3, 0.2],
            },
            Edit {
                scale: 1.0,
                offset: 0.05,
            },
        );
        let close = |a: [f32; 3], b: [f32; 3]| (0..3).all(|k| (a[k] - b[k]).abs() < 1e-6);
        let typical = ChromophoreMaps::assemble(i.clone())
            .unwrap()
            .unwrap()
            .typical();
        assert!(close(typical, [0.35, 0.5, 0.02]), "{typical:?}");
        i.thin = Some(ThinInput {
            key: "materials.s.maps".into(),
            path: "maps.exr".into(),
            image: ValueImage {
                width: 5,
                height: 1,
                values: vec![0.0, 0.0, 0.0, 1.0, 1.0],
            },
            thickness_mm: 0.05,
        });
        let typical = ChromophoreMaps::assemble(i).unwrap().unwrap().typical();
        assert!(close(typical, [0.45, 0.5, 0.02]), "{typical:?}");
    }

    /// Scalars fill the parameters without a map; the edit v' = s v + o applies everywhere without
    /// a mask; a value pushed past 1 is an error naming the key, the texel and the range.
    #[test]
    fn edits_apply_and_out_of_range_values_are_named() {
        let edit = Edit {
            scale: 2.0,
            offset: 0.1,
        };
        let maps = ChromophoreMaps::assemble(inputs(image(2, 2, 0.1), edit))
            .unwrap()
            .unwrap();
        let [cm, bm, ch] = maps.at(Vec2::new(0.3, 0.6));
        assert!(
            (cm - 0.3).abs() < 1e-6 && bm == 0.5 && ch == 0.02,
            "{cm} {bm} {ch}"
        );
        assert_eq!(maps.range()[0], [0.3, 0.3]);
        let e = ChromophoreMaps::assemble(inputs(image(2, 2, 0.5), edit))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("materials.s.melanin_map") && e.contains("outside [0, 1]"),
            "{e}"
        );
    }
}
