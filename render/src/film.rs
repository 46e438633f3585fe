//! The film: per-pixel CIE XYZ sums, written as linear-sRGB OpenEXR (f32) and as a tone-mapped
//! sRGB PNG, both through `render::atomic` (unique temporary name, then rename).

use crate::atomic;
use crate::error::RenderError;
use crate::spectrum::xyz_to_linear_srgb;
use std::path::Path;

/// Accumulated CIE XYZ per pixel (row-major, top row first) and the samples per pixel in it.
#[derive(Debug, Clone, PartialEq)]
pub struct Film {
    width: usize,
    height: usize,
    sum_xyz: Vec<[f64; 3]>,
    spp: u32,
    /// Estimated variance of each pixel's mean luminance Y (zero when not estimated).
    variance_y: Vec<f64>,
}

impl Film {
    /// An empty film of `width × height` pixels.
    #[must_use]
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            sum_xyz: vec![[0.0; 3]; width * height],
            spp: 0,
            variance_y: vec![0.0; width * height],
        }
    }

    /// A film from each pixel's mean XYZ and the variance of its mean luminance (row-major), for
    /// renders whose pixels took different sample counts; `spp` is the largest count.
    #[must_use]
    pub fn from_means(
        width: usize,
        height: usize,
        mean_xyz: Vec<[f64; 3]>,
        variance_y: Vec<f64>,
        spp: u32,
    ) -> Self {
        debug_assert_eq!(mean_xyz.len(), width * height);
        debug_assert_eq!(variance_y.len(), width * height);
        let n = f64::from(spp.max(1));
        Self {
            width,
            height,
            sum_xyz: mean_xyz.into_iter().map(|m| m.map(|v| v * n)).collect(),
            spp,
            variance_y,
        }
    }

    /// Estimated variance of pixel (x, y)'s mean luminance Y (the `variance` pass).
    #[must_use]
    pub fn variance(&self, x: usize, y: usize) -> f64 {
        self.variance_y[y * self.width + x]
    }

    /// Width and height, pixels.
    #[must_use]
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Samples per pixel accumulated so far.
    #[must_use]
    pub fn spp(&self) -> u32 {
        self.spp
    }

    /// Add one sample per pixel for the whole image: `pass[i]` is pixel i's XYZ estimate.
    pub fn add_pass(&mut self, pass: &[[f32; 3]]) {
        debug_assert_eq!(pass.len(), self.sum_xyz.len());
        for (acc, v) in self.sum_xyz.iter_mut().zip(pass) {
            for c in 0..3 {
                acc[c] += f64::from(v[c]);
            }
        }
        self.spp += 1;
    }

    /// Mean XYZ of pixel (x, y).
    #[must_use]
    pub fn xyz(&self, x: usize, y: usize) -> [f32; 3] {
        let n = f64::from(self.spp.max(1));
        self.sum_xyz[y * self.width + x].map(|v| (v / n) as f32)
    }

    /// Mean linear sRGB of pixel (x, y) (unclamped).
    #[must_use]
    pub fn linear_srgb(&self, x: usize, y: usize) -> [f32; 3] {
        xyz_to_linear_srgb(self.xyz(x, y))
    }

    /// Write linear sRGB primaries as 32-bit float OpenEXR.
    pub fn write_exr(&self, path: &Path) -> Result<(), RenderError> {
        let out_err = |message: String| RenderError::Output {
            path: path.to_path_buf(),
            message,
        };
        atomic::write_via_temp(path, |tmp| {
            exr::prelude::write_rgb_file(tmp, self.width, self.height, |x, y| {
                let [r, g, b] = self.linear_srgb(x, y);
                (r, g, b)
            })
            .map_err(|e| out_err(e.to_string()))
        })
        .map_err(|e: RenderError| match e {
            e @ (RenderError::Output { .. } | RenderError::Write(_)) => e,
            other => out_err(other.to_string()),
        })
    }

    /// 8-bit sRGB pixels after exposure (`2^exposure_stops`) and the filmic tone curve.
    #[must_use]
    pub fn to_srgb8(&self, exposure_stops: f32) -> Vec<u8> {
        let scale = exposure_stops.exp2();
        let mut out = Vec::with_capacity(self.width * self.height * 3);
        for y in 0..self.height {
            for x in 0..self.width {
                for c in self.linear_srgb(x, y) {
                    let v = filmic(c.max(0.0) * scale);
                    out.push((skin_optics::color::srgb_encode(f64::from(v)) * 255.0).round() as u8);
                }
            }
        }
        out
    }

    /// Write the tone-mapped sRGB PNG.
    pub fn write_png(&self, path: &Path, exposure_stops: f32) -> Result<(), RenderError> {
        use image::ImageEncoder;
        let mut bytes = Vec::new();
        image::codecs::png::PngEncoder::new(&mut bytes)
            .write_image(
                &self.to_srgb8(exposure_stops),
                self.width as u32,
                self.height as u32,
                image::ExtendedColorType::Rgb8,
            )
            .map_err(|e| RenderError::Output {
                path: path.to_path_buf(),
                message: e.to_string(),
            })?;
        Ok(atomic::write_bytes(path, &bytes)?)
    }
}

/// Filmic tone curve: Narkowicz's 2015 fit of the ACES reference rendering transform, clamped
/// to [0, 1]. Linear near black, rolls highlights off smoothly (f(1) ≈ 0.80, f(∞) → 1).
#[must_use]
pub fn filmic(x: f32) -> f32 {
    let (a, b, c, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
    ((x * (a * x + b)) / (x * (c * x + d) + e)).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tone_curve_is_monotone_and_bounded() {
        let mut prev = 0.0;
        for i in 0..1000 {
            let v = filmic(i as f32 * 0.02);
            assert!(v >= prev && v <= 1.0);
            prev = v;
        }
        assert_eq!(filmic(0.0), 0.0);
    }

    #[test]
    fn exr_and_png_round_trip() {
        let dir = std::env::temp_dir().join(format!("skin-film-{}", std::process::id()));
        let mut film = Film::new(4, 3);
        let white = xyz_white();
        film.add_pass(&[white; 12]);
        film.write_exr(&dir.join("a.exr")).unwrap();
        film.write_png(&dir.join("a.png"), 0.0).unwrap();
        let img = exr::prelude::read_first_rgba_layer_from_file(
            dir.join("a.exr"),
            |_, _| Vec::new(),
            |v: &mut Vec<f32>, _, (r, _g, _b, _a): (f32, f32, f32, f32)| v.push(r),
        )
        .unwrap();
        assert!(
            img.layer_data
                .channel_data
                .pixels
                .iter()
                .all(|&r| (r - 1.0).abs() < 2e-3)
        );
        let left = atomic::leftovers(&dir, &["a.exr", "a.png"]);
        assert!(left.is_empty(), "left behind: {left:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// XYZ of linear sRGB white (1, 1, 1).
    fn xyz_white() -> [f32; 3] {
        skin_optics::color::LinearSrgb([1.0; 3])
            .to_xyz()
            .0
            .map(|v| v as f32)
    }
}
