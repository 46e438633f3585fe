//! Images used while rendering: sRGB JPEG/PNG albedo maps (linearised on load) and linear
//! lat-long EXR environment maps, with bilinear lookup.

use crate::error::RenderError;
use glam::Vec2;
use skin_optics::color::srgb_decode;
use std::path::Path;

/// A linear-RGB image (rows top to bottom).
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    width: usize,
    height: usize,
    texels: Vec<[f32; 3]>,
}

impl Texture {
    /// Decode an 8-bit sRGB JPEG or PNG and undo the sRGB transfer curve.
    pub fn from_srgb_bytes(bytes: &[u8], path: &Path) -> Result<Self, RenderError> {
        let img = image::load_from_memory(bytes)
            .map_err(|e| RenderError::Image {
                path: path.to_path_buf(),
                message: e.to_string(),
            })?
            .to_rgb8();
        let lut: Vec<f32> = (0..256)
            .map(|i| srgb_decode(f64::from(i) / 255.0) as f32)
            .collect();
        let texels = img
            .pixels()
            .map(|p| {
                [
                    lut[p.0[0] as usize],
                    lut[p.0[1] as usize],
                    lut[p.0[2] as usize],
                ]
            })
            .collect();
        Ok(Self {
            width: img.width() as usize,
            height: img.height() as usize,
            texels,
        })
    }

    /// Decode a linear RGB(A) OpenEXR image (alpha ignored).
    pub fn from_exr_bytes(bytes: &[u8], path: &Path) -> Result<Self, RenderError> {
        use exr::prelude::*;
        let img = read()
            .no_deep_data()
            .largest_resolution_level()
            .rgba_channels(
                |size, _| Texture {
                    width: size.0,
                    height: size.1,
                    texels: vec![[0.0; 3]; size.0 * size.1],
                },
                |t: &mut Texture, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                    let w = t.width;
                    t.texels[pos.1 * w + pos.0] = [r, g, b];
                },
            )
            .first_valid_layer()
            .all_attributes()
            .from_buffered(std::io::Cursor::new(bytes))
            .map_err(|e| RenderError::Image {
                path: path.to_path_buf(),
                message: e.to_string(),
            })?;
        let tex = img.layer_data.channel_data.pixels;
        if tex
            .texels
            .iter()
            .flatten()
            .any(|v| !v.is_finite() || *v < 0.0)
        {
            return Err(RenderError::Image {
                path: path.to_path_buf(),
                message: "negative or non-finite texel".into(),
            });
        }
        Ok(tex)
    }

    /// A texture from raw linear texels (row-major, `width × height`).
    #[must_use]
    pub fn from_texels(width: usize, height: usize, texels: Vec<[f32; 3]>) -> Self {
        assert_eq!(texels.len(), width * height, "texel count");
        Self {
            width,
            height,
            texels,
        }
    }

    /// Width × height, texels.
    #[must_use]
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    fn texel(&self, x: i64, y: i64) -> [f32; 3] {
        let x = x.rem_euclid(self.width as i64) as usize;
        let y = y.clamp(0, self.height as i64 - 1) as usize;
        self.texels[y * self.width + x]
    }

    /// Bilinear lookup at `uv` (u right, v down the rows, both in [0, 1], u wraps).
    #[must_use]
    pub fn lookup(&self, uv: Vec2) -> [f32; 3] {
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let a = self.texel(x0, y0);
        let b = self.texel(x0 + 1, y0);
        let c = self.texel(x0, y0 + 1);
        let d = self.texel(x0 + 1, y0 + 1);
        std::array::from_fn(|i| {
            (a[i] * (1.0 - fx) + b[i] * fx) * (1.0 - fy) + (c[i] * (1.0 - fx) + d[i] * fx) * fy
        })
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

/// Relative luminance of linear sRGB (the Y row of the IEC 61966-2-1 matrix).
#[must_use]
pub fn luminance(rgb: [f32; 3]) -> f32 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_lookup_interpolates_between_texel_centres() {
        let t = Texture::from_texels(2, 1, vec![[0.0; 3], [1.0; 3]]);
        assert!((t.lookup(Vec2::new(0.5, 0.5))[0] - 0.5).abs() < 1e-6);
        assert!((t.lookup(Vec2::new(0.25, 0.5))[0]).abs() < 1e-6);
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
