//! Images used while rendering: sRGB JPEG/PNG albedo maps (linearised on load) and linear
//! lat-long EXR environment maps, with bilinear lookup.

use crate::error::RenderError;
use glam::Vec2;
use skin_optics::color::srgb_decode;
use std::path::Path;

/// Widest or tallest image accepted, texels.
pub const MAX_SIDE: usize = 16_384;
/// Most texels an image may have (8192 × 4096: a 400 MB linear texture), checked against the
/// size the file declares before anything is allocated.
pub const MAX_TEXELS: usize = 8192 * 4096;
/// Largest linear texel value of an EXR map: far above any sky (the sun is about 1e9 in display
/// units), far enough below f32's 3.4e38 that scales and spectra built from it stay finite.
pub const MAX_TEXEL: f32 = 1e20;
/// Most chunks (scan-line blocks or tiles) an EXR file may declare (its offset table is read whole).
pub const MAX_EXR_CHUNKS: usize = 1 << 22;

/// A linear-RGB image (rows top to bottom).
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    width: usize,
    height: usize,
    texels: Vec<[f32; 3]>,
    /// The luminance of every texel: a third of the texels' memory, so the skin's per-probe
    /// modulation lookups (luminance only) miss the cache less.
    luminance: Vec<f32>,
}

fn image_err(path: &Path, message: impl Into<String>) -> RenderError {
    RenderError::Image {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

/// Refuse a declared size over [`MAX_SIDE`] or [`MAX_TEXELS`].
pub(crate) fn check_size(width: usize, height: usize, path: &Path) -> Result<(), RenderError> {
    if width == 0 || height == 0 {
        return Err(image_err(path, format!("empty image ({width}×{height})")));
    }
    if width > MAX_SIDE || height > MAX_SIDE || width.saturating_mul(height) > MAX_TEXELS {
        return Err(image_err(
            path,
            format!(
                "{width}×{height} texels, over the cap of {MAX_SIDE} per side and {MAX_TEXELS} in all"
            ),
        ));
    }
    Ok(())
}

impl Texture {
    /// Decode an 8-bit sRGB JPEG or PNG and undo the sRGB transfer curve. The declared size is
    /// checked before decoding; a JPEG whose data ends early is refused (strict decoding), not
    /// padded with grey.
    pub fn from_srgb_bytes(bytes: &[u8], path: &Path) -> Result<Self, RenderError> {
        let (width, height, rgb) = if bytes.starts_with(&[0xFF, 0xD8]) {
            decode_jpeg(bytes, path)?
        } else {
            decode_other(bytes, path)?
        };
        let lut: Vec<f32> = (0..256)
            .map(|i| srgb_decode(f64::from(i) / 255.0) as f32)
            .collect();
        let texels = rgb
            .chunks_exact(3)
            .map(|p| [lut[p[0] as usize], lut[p[1] as usize], lut[p[2] as usize]])
            .collect();
        Ok(Self::from_texels(width, height, texels))
    }

    /// Decode a linear RGB(A) OpenEXR image (alpha ignored). The headers are read and the sizes
    /// they declare checked first; texels must be finite, ≥ 0 and at most [`MAX_TEXEL`].
    pub fn from_exr_bytes(bytes: &[u8], path: &Path) -> Result<Self, RenderError> {
        use exr::prelude::*;
        check_exr_headers(bytes, path)?;
        let img = read()
            .no_deep_data()
            .largest_resolution_level()
            .rgba_channels(
                |size, _| (size.0, size.1, vec![[0.0f32; 3]; size.0 * size.1]),
                |t: &mut (usize, usize, Vec<[f32; 3]>),
                 pos,
                 (r, g, b, _a): (f32, f32, f32, f32)| {
                    t.2[pos.1 * t.0 + pos.0] = [r, g, b];
                },
            )
            .first_valid_layer()
            .all_attributes()
            .from_buffered(std::io::Cursor::new(bytes))
            .map_err(|e| image_err(path, e.to_string()))?;
        let (width, height, texels) = img.layer_data.channel_data.pixels;
        if let Some(v) = texels
            .iter()
            .flatten()
            .find(|v| !(v.is_finite() && (0.0..=MAX_TEXEL).contains(*v)))
        {
            return Err(image_err(
                path,
                format!(
                    "texel value {} outside [0, {MAX_TEXEL:e}]",
                    skin_optics::echo::Num(f64::from(*v))
                ),
            ));
        }
        Ok(Self::from_texels(width, height, texels))
    }

    /// A texture from raw linear texels (row-major, `width × height`).
    #[must_use]
    pub fn from_texels(width: usize, height: usize, texels: Vec<[f32; 3]>) -> Self {
        assert_eq!(texels.len(), width * height, "texel count");
        let luminance = texels.iter().map(|&t| luminance(t)).collect();
        Self {
            width,
            height,
            texels,
            luminance,
        }
    }

    /// The linear texels, row-major from the top row.
    #[must_use]
    pub fn texels(&self) -> &[[f32; 3]] {
        &self.texels
    }

    /// Width × height, texels.
    #[must_use]
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Row-major index of texel (x, y), x wrapped, y clamped.
    fn index(&self, x: i64, y: i64) -> usize {
        let (w, h) = (self.width as i64, self.height as i64);
        // Inside the image (nearly always) no division is needed.
        let x = if (0..w).contains(&x) {
            x
        } else {
            x.rem_euclid(w)
        };
        (y.clamp(0, h - 1) * w + x) as usize
    }

    /// The four texels around `uv` (row-major indices) and their bilinear weights.
    fn footprint(&self, uv: Vec2) -> ([usize; 4], [f32; 4]) {
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        (
            [
                self.index(x0, y0),
                self.index(x0 + 1, y0),
                self.index(x0, y0 + 1),
                self.index(x0 + 1, y0 + 1),
            ],
            [
                (1.0 - fx) * (1.0 - fy),
                fx * (1.0 - fy),
                (1.0 - fx) * fy,
                fx * fy,
            ],
        )
    }

    /// Bilinear lookup at `uv` (u right, v down the rows, both in [0, 1], u wraps).
    #[must_use]
    pub fn lookup(&self, uv: Vec2) -> [f32; 3] {
        let (idx, wt) = self.footprint(uv);
        std::array::from_fn(|c| (0..4).map(|k| self.texels[idx[k]][c] * wt[k]).sum())
    }

    /// Bilinear lookup of the luminance ([`luminance`]) at `uv`: the luminance of
    /// [`Texture::lookup`] (both are linear in the texels), from a third of the memory.
    #[must_use]
    pub fn lookup_luminance(&self, uv: Vec2) -> f32 {
        let (idx, wt) = self.footprint(uv);
        (0..4).map(|k| self.luminance[idx[k]] * wt[k]).sum()
    }

    /// [lo, hi] of each channel over every value [`Texture::lookup`] returns at uv in the box
    /// [u₀, u₁] × [v₀, v₁]: the texels of their bilinear footprints, with one texel of margin on
    /// each side for the f32 rounding of uv and of the footprint.
    #[must_use]
    pub fn range_over(&self, u: [f32; 2], v: [f32; 2]) -> [[f32; 2]; 3] {
        let (w, h) = (self.width as i64, self.height as i64);
        let first = |t: f32, n: i64| (t * n as f32 - 0.5).floor() as i64 - 1;
        let last = |t: f32, n: i64| (t * n as f32 - 0.5).floor() as i64 + 2;
        let (x0, x1) = (first(u[0], w), last(u[1], w));
        // u wraps: a span of the width or more holds every column.
        let (x0, x1) = if x1.saturating_sub(x0) + 1 >= w || x1 < x0 {
            (0, w - 1)
        } else {
            (x0, x1)
        };
        let (y0, y1) = (
            first(v[0], h).clamp(0, h - 1),
            last(v[1], h).clamp(0, h - 1),
        );
        let mut out = [[f32::INFINITY, f32::NEG_INFINITY]; 3];
        for y in y0..=y1 {
            for x in x0..=x1 {
                let t = self.texels[self.index(x, y)];
                for c in 0..3 {
                    out[c] = [out[c][0].min(t[c]), out[c][1].max(t[c])];
                }
            }
        }
        out
    }

    /// Mean of each channel over all texels.
    #[must_use]
    pub fn mean(&self) -> [f32; 3] {
        let mut s = [0.0f64; 3];
        for t in &self.texels {
            for c in 0..3 {
                s[c] += f64::from(t[c]);
            }
        }
        s.map(|v| (v / self.texels.len() as f64) as f32)
    }
}

/// Read an EXR's headers and refuse sizes over [`MAX_SIDE`], [`MAX_TEXELS`] or
/// [`MAX_EXR_CHUNKS`] before any texel is allocated.
pub(crate) fn check_exr_headers(bytes: &[u8], path: &Path) -> Result<(), RenderError> {
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
        .map_err(|e| image_err(path, e.to_string()))?;
    for h in &meta.headers {
        check_size(h.layer_size.0, h.layer_size.1, path)?;
        if h.chunk_count > MAX_EXR_CHUNKS {
            return Err(image_err(
                path,
                format!("{} chunks, over the cap of {MAX_EXR_CHUNKS}", h.chunk_count),
            ));
        }
    }
    Ok(())
}

/// A baseline or progressive JPEG as 8-bit RGB, decoded strictly (a truncated file is an error).
fn decode_jpeg(bytes: &[u8], path: &Path) -> Result<(usize, usize, Vec<u8>), RenderError> {
    use zune_core::bytestream::ZCursor;
    use zune_core::colorspace::ColorSpace;
    use zune_core::options::DecoderOptions;
    let options = DecoderOptions::default()
        .set_strict_mode(true)
        .set_max_width(MAX_SIDE)
        .set_max_height(MAX_SIDE)
        .jpeg_set_out_colorspace(ColorSpace::RGB);
    let mut decoder = zune_jpeg::JpegDecoder::new_with_options(ZCursor::new(bytes), options);
    decoder
        .decode_headers()
        .map_err(|e| image_err(path, format!("JPEG: {e}")))?;
    let (width, height) = decoder
        .dimensions()
        .ok_or_else(|| image_err(path, "JPEG without a frame header"))?;
    check_size(width, height, path)?;
    let rgb = decoder
        .decode()
        .map_err(|e| image_err(path, format!("JPEG: {e}")))?;
    if rgb.len() != width * height * 3 {
        return Err(image_err(
            path,
            "JPEG decoded to the wrong number of pixels",
        ));
    }
    Ok((width, height, rgb))
}

/// A PNG (or another format `image` knows) as 8-bit RGB, its declared size checked first.
fn decode_other(bytes: &[u8], path: &Path) -> Result<(usize, usize, Vec<u8>), RenderError> {
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| image_err(path, e.to_string()))
    };
    let (w, h) = reader()?
        .into_dimensions()
        .map_err(|e| image_err(path, e.to_string()))?;
    check_size(w as usize, h as usize, path)?;
    let img = reader()?
        .decode()
        .map_err(|e| image_err(path, e.to_string()))?
        .to_rgb8();
    Ok((img.width() as usize, img.height() as usize, img.into_raw()))
}

/// Relative luminance of linear sRGB (the Y row of the IEC 61966-2-1 matrix).
#[must_use]
pub fn luminance(rgb: [f32; 3]) -> f32 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// The bytes of a 32-bit float OpenEXR holding `channels` (name, row-major values from the top
/// row) at `width` × `height`: how chromophore maps are written (`skin maps`, texture exports).
pub fn channels_exr_bytes(
    width: usize,
    height: usize,
    channels: Vec<(&str, Vec<f32>)>,
) -> Result<Vec<u8>, String> {
    channels_exr_bytes_with(width, height, channels, &[])
}

/// [`channels_exr_bytes`] with float attributes `attributes` (name, value) in the layer's header:
/// what makes a channel's meaning self-describing (maps.exr's `thin_epidermis_mm`).
pub fn channels_exr_bytes_with(
    width: usize,
    height: usize,
    channels: Vec<(&str, Vec<f32>)>,
    attributes: &[(&str, f32)],
) -> Result<Vec<u8>, String> {
    use exr::prelude::*;
    let list: Vec<AnyChannel<FlatSamples>> = channels
        .into_iter()
        .map(|(name, data)| AnyChannel::new(name, FlatSamples::F32(data)))
        .collect();
    let mut layer_attributes = LayerAttributes::default();
    for (name, value) in attributes {
        layer_attributes
            .other
            .insert(Text::from(*name), AttributeValue::F32(*value));
    }
    let layer = Layer::new(
        (width, height),
        layer_attributes,
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(list.into()),
    );
    let mut out = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut out)
        .map_err(|e| format!("EXR: {e}"))?;
    Ok(out.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_lookup_interpolates_between_texel_centres() {
        let t = Texture::from_texels(2, 1, vec![[0.0; 3], [1.0; 3]]);
        assert!((t.lookup(Vec2::new(0.5, 0.5))[0] - 0.5).abs() < 1e-6);
        assert!((t.lookup(Vec2::new(0.25, 0.5))[0]).abs() < 1e-6);
        // The luminance lookup is the luminance of the colour lookup, wrapping in u too.
        let t3 = Texture::from_texels(
            3,
            2,
            (0..6).map(|i| [i as f32, 0.5, 6.0 - i as f32]).collect(),
        );
        for uv in [(0.1, 0.3), (0.95, 0.8), (1.3, 0.5), (-0.2, 1.2)] {
            let uv = Vec2::new(uv.0, uv.1);
            let (a, b) = (t3.lookup_luminance(uv), luminance(t3.lookup(uv)));
            assert!((a - b).abs() < 1e-5, "{uv}: {a} against {b}");
        }
    }

    /// A small EXR written by the `exr` crate, then its data window patched to `x_max`, `y_max`.
    fn exr_bytes(texel: f32, x_max: i32, y_max: i32) -> Vec<u8> {
        use exr::prelude::*;
        let mut bytes = Vec::new();
        let img = Image::from_channels(
            (2, 2),
            SpecificChannels::rgb(|_: Vec2<usize>| (texel, texel, texel)),
        );
        img.write()
            .to_buffered(std::io::Cursor::new(&mut bytes))
            .unwrap();
        let key = b"dataWindow\0box2i\0";
        let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
        bytes[at + 8..at + 12].copy_from_slice(&x_max.to_le_bytes());
        bytes[at + 12..at + 16].copy_from_slice(&y_max.to_le_bytes());
        bytes
    }

    #[test]
    fn exr_built_here_loads() {
        let t = Texture::from_exr_bytes(&exr_bytes(0.5, 1, 1), Path::new("e.exr")).unwrap();
        assert_eq!(t.size(), (2, 2));
        assert_eq!(t.mean(), [0.5; 3]);
    }

    #[test]
    fn exr_header_declaring_100000_by_100000_is_refused_before_allocating() {
        let e = Texture::from_exr_bytes(&exr_bytes(0.5, 99_999, 99_999), Path::new("e.exr"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("100000×100000") && e.contains(&MAX_TEXELS.to_string()),
            "{e}"
        );
    }

    #[test]
    fn exr_texels_of_3e38_are_refused() {
        let e = Texture::from_exr_bytes(&exr_bytes(3e38, 1, 1), Path::new("e.exr"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("outside [0, 1e20]"), "{e}");
        assert!(Texture::from_exr_bytes(&exr_bytes(f32::NAN, 1, 1), Path::new("e.exr")).is_err());
        assert!(Texture::from_exr_bytes(&exr_bytes(-1.0, 1, 1), Path::new("e.exr")).is_err());
    }

    #[test]
    fn truncated_jpeg_texture_is_refused() {
        let full = include_bytes!("../assets/Map-COL.jpg");
        for keep in [full.len() / 2, full.len() - 100] {
            let e = Texture::from_srgb_bytes(&full[..keep], Path::new("t.jpg"));
            assert!(e.is_err(), "{keep} bytes of {} accepted", full.len());
        }
    }

    #[test]
    fn image_size_cap_is_named_in_the_error() {
        let e = check_size(MAX_SIDE + 1, 1, Path::new("t.png"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("16384"), "{e}");
        assert!(check_size(8192, 4096, Path::new("t.png")).is_ok());
        assert!(check_size(8192, 4097, Path::new("t.png")).is_err());
        assert!(check_size(0, 5, Path::new("t.png")).is_err());
    }

    #[test]
    fn head_colour_map_decodes() {
        let t = Texture::from_srgb_bytes(
            include_bytes!("../assets/Map-COL.jpg"),
            Path::new("Map-COL.jpg"),
        )
        .unwrap();
        assert_eq!(t.size(), (1024, 1024));
        let m = t.mean();
        assert!(m[0] > m[2], "skin texture is redder than blue: {m:?}");
    }
}
