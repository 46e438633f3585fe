//! The images of `skin maps`: albedo textures and masks in (sRGB JPEG or PNG, 8 or 16 bit;
//! linear OpenEXR), the maps' EXR and PNGs out. Sizes a file declares are checked against
//! [`MAX_SIDE`] and [`MAX_TEXELS`] before anything is allocated; a truncated JPEG is refused
//! (strict decoding), not padded.

use anyhow::{Context, bail};
use skin_optics::color::{srgb_decode, srgb_encode};
use std::path::Path;

/// Widest or tallest image accepted, texels.
pub const MAX_SIDE: usize = 16_384;
/// Most texels an image may have (8192 × 4096; the maps of one take about 1.3 GB).
pub const MAX_TEXELS: usize = 8192 * 4096;
/// Most chunks (scan-line blocks or tiles) an EXR may declare (its offset table is read whole).
pub const MAX_EXR_CHUNKS: usize = 1 << 22;

/// A decoded image: linear Rec.709 texels, row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearImage {
    /// Width, texels.
    pub width: usize,
    /// Height, texels.
    pub height: usize,
    /// Linear values (sRGB transfer undone for PNG and JPEG; EXR as stored, unchecked).
    pub texels: Vec<[f32; 3]>,
}

fn check_size(width: usize, height: usize) -> anyhow::Result<()> {
    if width == 0 || height == 0 {
        bail!("empty image ({width}×{height})");
    }
    if width > MAX_SIDE || height > MAX_SIDE || width.saturating_mul(height) > MAX_TEXELS {
        bail!(
            "{width}×{height} texels, over the cap of {MAX_SIDE} per side and {MAX_TEXELS} in all"
        );
    }
    Ok(())
}

/// Read an albedo texture or mask through [`skin_io::input::ALBEDO`] and decode it.
pub fn read(path: &Path) -> anyhow::Result<LinearImage> {
    let bytes = skin_io::input::ALBEDO.read(path)?;
    decode(&bytes).with_context(|| format!("{}", path.display()))
}

/// Decode the bytes of a JPEG, PNG or OpenEXR file (told apart by their signatures).
pub fn decode(bytes: &[u8]) -> anyhow::Result<LinearImage> {
    if bytes.starts_with(&[0xFF, 0xD8]) {
        decode_jpeg(bytes)
    } else if bytes.starts_with(&[0x76, 0x2F, 0x31, 0x01]) {
        decode_exr(bytes)
    } else {
        decode_png(bytes)
    }
}

fn decode_jpeg(bytes: &[u8]) -> anyhow::Result<LinearImage> {
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
        .map_err(|e| anyhow::anyhow!("JPEG: {e}"))?;
    let (width, height) = decoder
        .dimensions()
        .context("JPEG without a frame header")?;
    check_size(width, height)?;
    let rgb = decoder.decode().map_err(|e| anyhow::anyhow!("JPEG: {e}"))?;
    if rgb.len() != width * height * 3 {
        bail!("JPEG decoded to the wrong number of pixels");
    }
    let lut: Vec<f32> = (0..256)
        .map(|i| srgb_decode(f64::from(i) / 255.0) as f32)
        .collect();
    let texels = rgb
        .chunks_exact(3)
        .map(|p| [lut[p[0] as usize], lut[p[1] as usize], lut[p[2] as usize]])
        .collect();
    Ok(LinearImage {
        width,
        height,
        texels,
    })
}

fn decode_png(bytes: &[u8]) -> anyhow::Result<LinearImage> {
    use image::DynamicImage;
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .context("image format")
    };
    let (w, h) = reader()?.into_dimensions()?;
    let (width, height) = (w as usize, h as usize);
    check_size(width, height)?;
    let img = reader()?.decode()?;
    let deep = matches!(
        img,
        DynamicImage::ImageLuma16(_)
            | DynamicImage::ImageLumaA16(_)
            | DynamicImage::ImageRgb16(_)
            | DynamicImage::ImageRgba16(_)
    );
    let texels = if deep {
        let lut: Vec<f32> = (0..65536)
            .map(|i| srgb_decode(f64::from(i) / 65535.0) as f32)
            .collect();
        img.to_rgb16()
            .into_raw()
            .chunks_exact(3)
            .map(|p| [lut[p[0] as usize], lut[p[1] as usize], lut[p[2] as usize]])
            .collect()
    } else {
        let lut: Vec<f32> = (0..256)
            .map(|i| srgb_decode(f64::from(i) / 255.0) as f32)
            .collect();
        img.to_rgb8()
            .into_raw()
            .chunks_exact(3)
            .map(|p| [lut[p[0] as usize], lut[p[1] as usize], lut[p[2] as usize]])
            .collect()
    };
    Ok(LinearImage {
        width,
        height,
        texels,
    })
}

fn decode_exr(bytes: &[u8]) -> anyhow::Result<LinearImage> {
    use exr::prelude::*;
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
        .map_err(|e| anyhow::anyhow!("EXR: {e}"))?;
    for h in &meta.headers {
        check_size(h.layer_size.0, h.layer_size.1)?;
        if h.chunk_count > MAX_EXR_CHUNKS {
            bail!("{} chunks, over the cap of {MAX_EXR_CHUNKS}", h.chunk_count);
        }
    }
    let img = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |size, _| (size.0, size.1, vec![[0.0f32; 3]; size.0 * size.1]),
            |t: &mut (usize, usize, Vec<[f32; 3]>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                t.2[pos.1 * t.0 + pos.0] = [r, g, b];
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| anyhow::anyhow!("EXR: {e}"))?;
    let (width, height, texels) = img.layer_data.channel_data.pixels;
    Ok(LinearImage {
        width,
        height,
        texels,
    })
}

/// Linear → 8-bit sRGB, exactly rounded: the code whose decoded midpoints bracket the value.
pub struct SrgbEncoder {
    /// Linear value of the midpoint between codes k and k + 1.
    thresholds: [f32; 255],
}

impl Default for SrgbEncoder {
    fn default() -> Self {
        Self {
            thresholds: std::array::from_fn(|k| srgb_decode((k as f64 + 0.5) / 255.0) as f32),
        }
    }
}

impl SrgbEncoder {
    /// The 8-bit code of linear `c` (clamped to [0, 1]; NaN is 0).
    #[must_use]
    pub fn encode(&self, c: f32) -> u8 {
        // partition_point counts the thresholds below c: at most 255.
        self.thresholds.partition_point(|t| *t < c) as u8
    }
}

/// 8-bit sRGB code of a linear value through the transfer curve itself (for tests).
#[must_use]
pub fn encode_exact(c: f64) -> u8 {
    (srgb_encode(c.clamp(0.0, 1.0)) * 255.0).round() as u8
}

/// PNG bytes of an 8-bit RGB image (fast compression: textures are large).
pub fn png_bytes(width: usize, height: usize, rgb: &[u8]) -> anyhow::Result<Vec<u8>> {
    use image::ImageEncoder;
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let mut out = Vec::new();
    PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Adaptive)
        .write_image(
            rgb,
            u32::try_from(width)?,
            u32::try_from(height)?,
            image::ExtendedColorType::Rgb8,
        )?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_encoder_rounds_like_the_transfer_curve() {
        let e = SrgbEncoder::default();
        for k in 0..=4000 {
            let c = f64::from(k) / 4000.0;
            assert_eq!(e.encode(c as f32), encode_exact(c), "{c}");
        }
        assert_eq!(e.encode(-1.0), 0);
        assert_eq!(e.encode(f32::NAN), 0);
        assert_eq!(e.encode(7.0), 255);
    }
}
