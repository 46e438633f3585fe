//! The image-noise metric: per-pixel relative luminance noise of a render, from two renders with
//! different seeds, over the lit pixels.
//!
//! For two independent estimates L₁, L₂ of the same pixel, E[(L₁ − L₂)²] = 2σ², so
//! `sqrt(mean((L₁ − L₂)² / (2 L̄²)))` is the RMS relative standard deviation of one render. Pixels
//! whose mean luminance L̄ is below [`LIT_FRACTION`] of the 95th percentile (background, deep
//! shadow) are left out, so the figure describes what the eye looks at. The same figure over the
//! lit pixels that see skin (the `mask.skin` pass of the EXR) is the one the skin is judged by.

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
    /// No pixel is lit (both images black, or none lit where the mask holds).
    #[error("no lit pixel: both images are black, or the mask holds on no lit pixel")]
    Black,
    /// The image has no `mask.skin` channel (it was not written by `skin render`).
    #[error("{path} has no mask.skin channel (write it with `skin render`)")]
    NoSkinMask {
        /// The file.
        path: std::path::PathBuf,
    },
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
    let mut values: Vec<f64> = mean
        .iter()
        .map(|v| if v.is_finite() { *v } else { 0.0 })
        .collect();
    let idx = ((values.len() - 1) as f64 * 0.95).round() as usize;
    // Selection, not a full sort: the same order statistic in linear time, since the adaptive
    // sampler asks for it after every pass over the whole image.
    let (_, percentile, _) = values.select_nth_unstable_by(idx, f64::total_cmp);
    LIT_FRACTION * *percentile
}

/// The metric on two luminance images of equal length, over all lit pixels.
pub fn relative_noise(a: &[f64], b: &[f64]) -> Result<NoiseReport, NoiseError> {
    relative_noise_where(a, b, |_| true)
}

/// The metric on two luminance images of equal length, over the lit pixels `i` where `keep(i)`
/// holds; the lit threshold is taken over the whole image, as [`relative_noise`] takes it.
pub fn relative_noise_where(
    a: &[f64],
    b: &[f64],
    keep: impl Fn(usize) -> bool,
) -> Result<NoiseReport, NoiseError> {
    if a.len() != b.len() {
        return Err(NoiseError::Size {
            a: (a.len(), 1),
            b: (b.len(), 1),
        });
    }
    let mean: Vec<f64> = a.iter().zip(b).map(|(x, y)| 0.5 * (x + y)).collect();
    let threshold = lit_threshold(&mean);
    let (mut sum, mut n) = (0.0, 0usize);
    for (i, ((x, y), m)) in a.iter().zip(b).zip(&mean).enumerate() {
        if *m > 0.0 && *m >= threshold && m.is_finite() && keep(i) {
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

/// The `mask.skin` pass of an OpenEXR written by `skin render` (1 where the pixel centre sees
/// skin), or `None` when the file has no such channel.
pub fn read_exr_skin_mask(path: &Path) -> Result<Option<Vec<f32>>, NoiseError> {
    let img =
        exr::prelude::read_first_flat_layer_from_file(path).map_err(|e| NoiseError::Read {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    let channels = &img.layer_data.channel_data.list;
    Ok(channels
        .iter()
        .find(|c| c.name.eq("mask.skin"))
        .map(|c| c.sample_data.values_as_f32().collect()))
}

/// The two luminance images of two RGB OpenEXR renders of the same size.
fn read_pair(a: &Path, b: &Path) -> Result<(Vec<f64>, Vec<f64>), NoiseError> {
    let (la, sa) = read_exr_luminance(a)?;
    let (lb, sb) = read_exr_luminance(b)?;
    if sa != sb {
        return Err(NoiseError::Size { a: sa, b: sb });
    }
    Ok((la, lb))
}

/// The metric on two RGB OpenEXR renders of the same scene with different seeds.
pub fn compare_exr(a: &Path, b: &Path) -> Result<NoiseReport, NoiseError> {
    let (la, lb) = read_pair(a, b)?;
    relative_noise(&la, &lb)
}

/// The metric on two renders over all lit pixels and over the lit skin pixels (by the
/// `mask.skin` pass of `a`), in that order.
pub fn compare_exr_with_skin(a: &Path, b: &Path) -> Result<(NoiseReport, NoiseReport), NoiseError> {
    let (la, lb) = read_pair(a, b)?;
    let mask = read_exr_skin_mask(a)?.ok_or_else(|| NoiseError::NoSkinMask {
        path: a.to_path_buf(),
    })?;
    if mask.len() != la.len() {
        return Err(NoiseError::Size {
            a: (la.len(), 1),
            b: (mask.len(), 1),
        });
    }
    let lit = relative_noise(&la, &lb)?;
    let skin = relative_noise_where(&la, &lb, |i| mask[i] > 0.5)?;
    Ok((lit, skin))
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

    /// The mask picks pixels out of the lit set, and the threshold stays the whole image's: a
    /// noiseless masked half gives 0, the other half its own noise (each pair 1.1, 0.9 has mean 1
    /// and (0.2)²/2 = 0.02 per pixel: √0.02), the whole image the RMS of both (√0.01).
    #[test]
    fn mask_restricts_the_lit_pixels() {
        let a: Vec<f64> = (0..100).map(|i| if i < 50 { 1.0 } else { 1.1 }).collect();
        let b: Vec<f64> = (0..100).map(|i| if i < 50 { 1.0 } else { 0.9 }).collect();
        let quiet = relative_noise_where(&a, &b, |i| i < 50).unwrap();
        assert_eq!((quiet.relative_noise, quiet.lit_pixels), (0.0, 50));
        let noisy = relative_noise_where(&a, &b, |i| i >= 50).unwrap();
        assert!(
            (noisy.relative_noise - 0.02f64.sqrt()).abs() < 1e-12,
            "{noisy:?}"
        );
        let all = relative_noise(&a, &b).unwrap();
        assert!(
            (all.relative_noise - 0.01f64.sqrt()).abs() < 1e-12,
            "{all:?}"
        );
        assert_eq!(quiet.threshold, all.threshold);
        assert!(matches!(
            relative_noise_where(&a, &b, |_| false),
            Err(NoiseError::Black)
        ));
    }
}
