//! The film: per-pixel CIE XYZ sums, written as linear-sRGB OpenEXR (f32) and as a tone-mapped
//! sRGB PNG, both through `skin_io::atomic` (unique temporary name, then rename).

use crate::error::RenderError;
use skin_io::atomic;
use std::collections::BTreeMap;
use std::path::Path;

/// `v` as f32, saturating at ±`f32::MAX` (a finite f64 may exceed f32's range).
fn to_finite_f32(v: f64) -> f32 {
    if v.is_nan() {
        0.0
    } else {
        v.clamp(-f64::from(f32::MAX), f64::from(f32::MAX)) as f32
    }
}

/// Accumulated CIE XYZ per pixel (row-major, top row first) and the samples per pixel in it.
///
/// A sample with a non-finite channel is dropped, not summed: it is counted (see
/// [`Film::dropped_samples`]) and its pixel averages over the samples it kept.
#[derive(Debug, Clone, PartialEq)]
pub struct Film {
    width: usize,
    height: usize,
    sum_xyz: Vec<[f64; 3]>,
    spp: u32,
    /// Samples dropped per pixel, for the pixels that dropped any (normally none).
    dropped: BTreeMap<usize, u32>,
    /// Samples dropped before they reached this film (by an adaptive accumulator).
    dropped_upstream: u64,
    /// Estimated variance of each pixel's mean luminance Y (zero when not estimated).
    variance_y: Vec<f64>,
    /// Samples kept at each pixel, for films whose pixels took different counts (None: every
    /// pixel took `spp`, less its dropped samples).
    samples: Option<Vec<u32>>,
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
            dropped: BTreeMap::new(),
            dropped_upstream: 0,
            variance_y: vec![0.0; width * height],
            samples: None,
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
            dropped: BTreeMap::new(),
            dropped_upstream: 0,
            samples: None,
        }
    }

    /// The film, holding `counts[i]` samples at pixel i (row-major; the `samples` pass).
    #[must_use]
    pub fn with_samples(mut self, counts: Vec<u32>) -> Self {
        debug_assert_eq!(counts.len(), self.width * self.height);
        self.samples = Some(counts);
        self
    }

    /// Samples averaged into pixel (x, y) (the `samples` pass): the count the pixel kept.
    #[must_use]
    pub fn samples(&self, x: usize, y: usize) -> u32 {
        let i = y * self.width + x;
        match &self.samples {
            Some(counts) => counts[i],
            None => self.spp - self.dropped.get(&i).copied().unwrap_or(0),
        }
    }

    /// The film, reporting `n` more non-finite samples dropped before its means were formed.
    #[must_use]
    pub fn with_dropped(mut self, n: u64) -> Self {
        self.dropped_upstream += n;
        self
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

    /// Non-finite samples dropped so far, over all pixels.
    #[must_use]
    pub fn dropped_samples(&self) -> u64 {
        self.dropped_upstream + self.dropped.values().map(|&n| u64::from(n)).sum::<u64>()
    }

    /// Add one sample per pixel for the whole image: `pass[i]` is pixel i's XYZ estimate.
    pub fn add_pass(&mut self, pass: &[[f32; 3]]) {
        debug_assert_eq!(pass.len(), self.sum_xyz.len());
        for (i, (acc, v)) in self.sum_xyz.iter_mut().zip(pass).enumerate() {
            if v.iter().all(|c| c.is_finite()) {
                for c in 0..3 {
                    acc[c] += f64::from(v[c]);
                }
            } else {
                *self.dropped.entry(i).or_insert(0) += 1;
            }
        }
        self.spp += 1;
    }

    fn mean_xyz(&self, x: usize, y: usize) -> [f64; 3] {
        let i = y * self.width + x;
        let kept = self.spp - self.dropped.get(&i).copied().unwrap_or(0);
        let n = f64::from(kept.max(1));
        self.sum_xyz[i].map(|v| v / n)
    }

    /// Mean XYZ of pixel (x, y) (finite: beyond f32's range it saturates at `f32::MAX`).
    #[must_use]
    pub fn xyz(&self, x: usize, y: usize) -> [f32; 3] {
        self.mean_xyz(x, y).map(to_finite_f32)
    }

    /// Mean linear sRGB of pixel (x, y) (unclamped, but finite).
    #[must_use]
    pub fn linear_srgb(&self, x: usize, y: usize) -> [f32; 3] {
        skin_optics::color::Xyz(self.mean_xyz(x, y))
            .to_linear_srgb()
            .0
            .map(to_finite_f32)
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
        // Finite for any exposure, so a black pixel stays black (0 × ∞ would be NaN).
        let scale = exposure_stops.exp2().min(f32::MAX);
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
        Ok(atomic::commit(vec![self.stage_png(path, exposure_stops)?])?)
    }

    /// The tone-mapped sRGB PNG, staged beside `path` for [`atomic::commit`] (so it can be
    /// committed together with the EXR).
    pub fn stage_png(
        &self,
        path: &Path,
        exposure_stops: f32,
    ) -> Result<atomic::Staged, RenderError> {
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
        Ok(atomic::stage_bytes(path, &bytes)?)
    }
}

/// Filmic tone curve: Narkowicz's 2015 fit of the ACES reference rendering transform, clamped
/// to [0, 1]. Linear near black, rolls highlights off smoothly (f(1) ≈ 0.80, f(∞) → 1).
/// Above x = 1 the same rational function is evaluated divided through by x², so no square
/// overflows: any x ≥ 0 up to +∞ maps into [0, 1].
#[must_use]
pub fn filmic(x: f32) -> f32 {
    let (a, b, c, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
    let v = if x > 1.0 {
        let r = 1.0 / x;
        (a + b * r) / (c + r * (d + e * r))
    } else {
        (x * (a * x + b)) / (x * (c * x + d) + e)
    };
    if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) }
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
    fn tone_curve_does_not_overflow_bright_pixels_to_black() {
        // x(ax + b) overflowed to ∞ above x ≈ 1e19 and ∞/∞ = NaN became 0 in the PNG.
        for x in [10.0, 1e19, 1e30, f32::MAX, f32::INFINITY] {
            assert!(filmic(x) > 0.99, "filmic({x}) = {}", filmic(x));
        }
        // Both branches agree at the switch point (one rational function).
        assert!((filmic(1.0) - filmic(1.000_001)).abs() < 1e-5);
        assert!((filmic(1.0) - 0.8038).abs() < 1e-3, "{}", filmic(1.0));
    }

    #[test]
    fn exposure_100_and_1e30_stops_keep_bright_pixels_white_and_black_pixels_black() {
        let mut film = Film::new(2, 1);
        film.add_pass(&[xyz_white(), [0.0; 3]]);
        for stops in [100.0, 1e30] {
            let px = film.to_srgb8(stops);
            assert_eq!(&px[..3], &[255, 255, 255], "{stops} stops");
            assert_eq!(&px[3..], &[0, 0, 0], "{stops} stops");
        }
    }

    #[test]
    fn non_finite_samples_are_counted_and_dropped() {
        let mut film = Film::new(3, 1);
        let w = xyz_white();
        film.add_pass(&[w, w, [f32::NAN, 0.0, 0.0]]);
        film.add_pass(&[[f32::INFINITY; 3], w, w]);
        film.add_pass(&[w, w, [0.0, f32::NEG_INFINITY, 0.0]]);
        assert_eq!(film.dropped_samples(), 3);
        // Each pixel averages the samples it kept: all white.
        for x in 0..3 {
            assert!((film.linear_srgb(x, 0)[0] - 1.0).abs() < 2e-3, "{x}");
        }
        // A pixel that kept nothing is black, not NaN.
        let mut film = Film::new(1, 1);
        film.add_pass(&[[f32::NAN; 3]]);
        assert_eq!(film.linear_srgb(0, 0), [0.0; 3]);
    }

    #[test]
    fn film_never_writes_a_non_finite_value() {
        // Finite samples near f32::MAX turn into linear sRGB beyond f32's range: saturated.
        let mut film = Film::new(1, 1);
        film.add_pass(&[[f32::MAX, 0.0, f32::MAX]]);
        assert!(film.linear_srgb(0, 0).iter().all(|v| v.is_finite()));
        assert!(film.xyz(0, 0).iter().all(|v| v.is_finite()));
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
