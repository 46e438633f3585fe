//! The image-noise metric: per-pixel relative luminance noise of a render, from two renders with
//! different seeds, over the lit pixels.
//!
//! For two independent estimates L₁, L₂ of the same pixel, E[(L₁ − L₂)²] = 2σ², so
//! `sqrt(mean((L₁ − L₂)² / (2 L̄²)))` is the RMS relative standard deviation of one render. Pixels
//! whose mean luminance L̄ is below [`LIT_FRACTION`] of the 95th percentile (background, deep
//! shadow) are left out, so the figure describes what the eye looks at.

use std::path::Path;
use thiserror::Error;

/// Pixels count as lit when their mean luminance is at least this fraction of the 95th percentile.
pub const LIT_FRACTION: f64 = 0.15;

/// Why two images could not be compared.
#[derive(Debug, Error)]
pub enum NoiseError {
    /// An image could not be read as an RGB OpenEXR.
    #[error("reading {path}: {message}")]
    Read {
        /// The file.
        path: std::path::PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The two images differ in size.
    #[error("image sizes differ: {a:?} versus {b:?} pixels")]
    Size {
        /// Width and height of the first.
        a: (usize, usize),
        /// Width and height of the second.
        b: (usize, usize),
    },
    /// No pixel is lit (both images black).
    #[error("no lit pixel: both images are black")]
    Black,
}

/// The metric's result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseReport {
    /// RMS relative standard deviation of one image over the lit pixels (0.02 = 2%).
    pub relative_noise: f64,
    /// Lit pixels the figure is taken over.
    pub lit_pixels: usize,
    /// All pixels.
    pub pixels: usize,
    /// The luminance threshold of a lit pixel (linear, the images' units).
    pub threshold: f64,
}

/// The luminance below which a pixel is not lit: [`LIT_FRACTION`] × the 95th percentile of `mean`.
#[must_use]
pub fn lit_threshold(mean: &[f64]) -> f64 {
    if mean.is_empty() {
        return 0.0;
    }
    let mut sorted: Vec<f64> = mean
        .iter()
        .map(|v| if v.is_finite() { *v } else { 0.0 })
        .collect();
    sorted.sort_by(f64::total_cmp);
    let idx = ((sorted.len() - 1) as f64 * 0.95).round() as usize;
    LIT_FRACTION * sorted[idx]
}

/// The metric on two luminance images of equal length.
pub fn relative_noise(a: &[f64], b: &[f64]) -> Result<NoiseReport, NoiseError> {
    if a.len() != b.len() {
        return Err(NoiseError::Size {
            a: (a.len(), 1),
            b: (b.len(), 1),
        });
    }
    let mean: Vec<f64> = a.iter().zip(b).map(|(x, y)| 0.5 * (x + y)).collect();
    let threshold = lit_threshold(&mean);
    let (mut sum, mut n) = (0.0, 0usize);
    for ((x, y), m) in a.iter().zip(b).zip(&mean) {
        if *m > 0.0 && *m >= threshold && m.is_finite() {
            sum += (x - y).powi(2) / (2.0 * m * m);
            n += 1;
        }
    }
    if n == 0 {
        return Err(NoiseError::Black);
    }
    Ok(NoiseReport {
        relative_noise: (sum / n as f64).sqrt(),
        lit_pixels: n,
        pixels: a.len(),
        threshold,
    })
}

/// Luminance (CIE Y) of linear sRGB.
#[must_use]
pub fn luminance(rgb: [f32; 3]) -> f64 {
    skin_optics::color::LinearSrgb(rgb.map(f64::from))
        .to_xyz()
        .0[1]
}

/// The luminance of every pixel of an RGB OpenEXR (its first RGB layer), and its size.
pub fn read_exr_luminance(path: &Path) -> Result<(Vec<f64>, (usize, usize)), NoiseError> {
    let img = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |res, _| (vec![0.0f64; res.width() * res.height()], res.width()),
        |(v, w): &mut (Vec<f64>, usize), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            v[pos.y() * *w + pos.x()] = luminance([r, g, b]);
        },
    )
    .map_err(|e| NoiseError::Read {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let size = img.layer_data.size;
    let (lum, _) = img.layer_data.channel_data.pixels;
    Ok((lum, (size.width(), size.height())))
}

/// The metric on two RGB OpenEXR renders of the same scene with different seeds.
pub fn compare_exr(a: &Path, b: &Path) -> Result<NoiseReport, NoiseError> {
    let (la, sa) = read_exr_luminance(a)?;
    let (lb, sb) = read_exr_luminance(b)?;
    if sa != sb {
        return Err(NoiseError::Size { a: sa, b: sb });
    }
    relative_noise(&la, &lb)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// Two images of a flat signal with uniform noise of relative σ = 5% (half-width 5%·√3): the
    /// metric returns σ. 10⁴ pixels give the RMS a relative error of about 0.6%; 3% tolerance.
    #[test]
    fn recovers_known_noise() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        let half_width = 0.05 * 3f64.sqrt();
        let mut draw = || {
            (0..10_000)
                .map(|_| 2.0 * (1.0 + rng.random_range(-half_width..half_width)))
                .collect::<Vec<f64>>()
        };
        let (a, b) = (draw(), draw());
        let r = relative_noise(&a, &b).unwrap();
        assert!((r.relative_noise / 0.05 - 1.0).abs() < 0.03, "{r:?}");
        assert_eq!(r.lit_pixels, 10_000);
    }

    /// Dark pixels (below 15% of the 95th percentile) do not count, however noisy.
    #[test]
    fn dark_pixels_are_left_out() {
        let mut a = vec![1.0; 100];
        let mut b = vec![1.0; 100];
        a[0] = 0.0;
        b[0] = 0.1;
        let r = relative_noise(&a, &b).unwrap();
        assert_eq!(r.relative_noise, 0.0);
        assert_eq!(r.lit_pixels, 99);
        assert!(matches!(
            relative_noise(&[0.0; 4], &[0.0; 4]),
            Err(NoiseError::Black)
        ));
    }
}
