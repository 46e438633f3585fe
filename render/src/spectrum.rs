//! Hero-wavelength spectral sampling: four wavelengths per path, stratified over 380–780 nm
//! (uniformly or by a density that follows the photopic response),
//! and per-material spectral tables evaluated at them (pbrt-v4's `SampledWavelengths`, f32 per ray).
//!
//! Colour science is not re-derived here: the CIE matching functions come from
//! `skin_optics::color::cie_xyz_bar` and are only re-tabulated in f32 at 1 nm for speed.

use skin_optics::color::{cie_xyz_bar, cie_y_integral};
use std::ops::{Add, AddAssign, Div, Mul, MulAssign};
use std::sync::OnceLock;

/// Wavelengths carried per path.
pub const N_WAVELENGTHS: usize = 4;
/// Shortest rendered wavelength, nm.
pub const LAMBDA_MIN_NM: f32 = 380.0;
/// Longest rendered wavelength, nm.
pub const LAMBDA_MAX_NM: f32 = 780.0;

/// How a path's wavelengths are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum WavelengthSampling {
    /// Uniform over 380–780 nm.
    Uniform,
    /// ∝ 1/cosh²(A (λ − 538 nm)), A = 0.0072 nm⁻¹, a smooth bell over the photopic response
    /// ([pbrt] 4th ed. §4.6.5, `SampleVisibleWavelengths`), restricted to 380–780 nm: fewer
    /// samples where ȳ is small, so the luminance (and colour) of a pixel is less noisy.
    #[default]
    Visible,
}

/// Width parameter A of the visible-wavelength density, nm⁻¹ ([pbrt] 4th ed. §4.6.5).
const VISIBLE_A_PER_NM: f32 = 0.0072;
/// Centre of the visible-wavelength density, nm ([pbrt] 4th ed. §4.6.5).
const VISIBLE_CENTRE_NM: f32 = 538.0;

/// tanh(A (λ − 538)) at the two ends of the rendered range: the unnormalised CDF's bounds
/// (computed once: two tanh per wavelength were a few % of a path's time).
fn visible_cdf_bounds() -> (f32, f32) {
    static BOUNDS: std::sync::LazyLock<(f32, f32)> = std::sync::LazyLock::new(|| {
        let t = |nm: f32| (VISIBLE_A_PER_NM * (nm - VISIBLE_CENTRE_NM)).tanh();
        (t(LAMBDA_MIN_NM), t(LAMBDA_MAX_NM))
    });
    *BOUNDS
}

/// Density of [`WavelengthSampling::Visible`] at `nm`, nm⁻¹ (integrates to 1 over 380–780 nm).
#[must_use]
pub fn visible_wavelength_pdf(nm: f32) -> f32 {
    let (t0, t1) = visible_cdf_bounds();
    let c = (VISIBLE_A_PER_NM * (nm - VISIBLE_CENTRE_NM)).cosh();
    VISIBLE_A_PER_NM / (c * c * (t1 - t0))
}

/// The wavelength of [`WavelengthSampling::Visible`] at CDF value `u` in [0, 1), nm.
#[must_use]
pub fn sample_visible_wavelength(u: f32) -> f32 {
    sample_visible_with_pdf(u).0
}

/// The wavelength of [`WavelengthSampling::Visible`] at CDF value `u` in [0, 1) (nm) and its
/// density there (nm⁻¹, [`visible_wavelength_pdf`]). The sampler inverts tanh(A (λ − 538)) = y,
/// y = t₀ + u (t₁ − t₀), so the density's 1/cosh² is 1 − y² = (1 − y)(1 + y) without a cosh, and
/// atanh y = ½ ln((1 + y)/(1 − y)) with one logarithm (|y| ≤ 0.95 here, so the quotient's rounding
/// moves λ by under 10⁻⁵ nm; four cosh and atanh per path were a few % of its instructions).
fn sample_visible_with_pdf(u: f32) -> (f32, f32) {
    let (t0, t1) = visible_cdf_bounds();
    let y = t0 + u * (t1 - t0);
    let atanh = 0.5 * ((1.0 + y) / (1.0 - y)).ln();
    let nm = VISIBLE_CENTRE_NM + atanh / VISIBLE_A_PER_NM;
    if (LAMBDA_MIN_NM..=LAMBDA_MAX_NM).contains(&nm) {
        (nm, VISIBLE_A_PER_NM * ((1.0 - y) * (1.0 + y)) / (t1 - t0))
    } else {
        // Rounding at the ends of the range: the density where the wavelength is kept.
        let nm = nm.clamp(LAMBDA_MIN_NM, LAMBDA_MAX_NM);
        (nm, visible_wavelength_pdf(nm))
    }
}

/// A quantity (radiance, throughput, albedo) at the four sampled wavelengths of a path.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SampledSpectrum(pub [f32; N_WAVELENGTHS]);

impl SampledSpectrum {
    /// All four values equal to `v`.
    #[must_use]
    pub const fn splat(v: f32) -> Self {
        Self([v; N_WAVELENGTHS])
    }
    /// Zero at every wavelength.
    #[must_use]
    pub const fn zero() -> Self {
        Self::splat(0.0)
    }
    /// Largest of the four values.
    #[must_use]
    pub fn max_value(&self) -> f32 {
        self.0.iter().copied().fold(f32::NEG_INFINITY, f32::max)
    }
    /// Mean of the four values.
    #[must_use]
    pub fn average(&self) -> f32 {
        self.0.iter().sum::<f32>() / N_WAVELENGTHS as f32
    }
    /// True when every value is zero.
    #[must_use]
    pub fn is_black(&self) -> bool {
        self.0.iter().all(|&v| v == 0.0)
    }
    /// True when every value is finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.0.iter().all(|v| v.is_finite())
    }
    /// Apply `f` to each value.
    #[must_use]
    pub fn map(self, f: impl Fn(f32) -> f32) -> Self {
        Self(self.0.map(f))
    }
}

impl Add for SampledSpectrum {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self(std::array::from_fn(|i| self.0[i] + o.0[i]))
    }
}
impl AddAssign for SampledSpectrum {
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}
impl Mul for SampledSpectrum {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        Self(std::array::from_fn(|i| self.0[i] * o.0[i]))
    }
}
impl MulAssign for SampledSpectrum {
    fn mul_assign(&mut self, o: Self) {
        *self = *self * o;
    }
}
impl Mul<f32> for SampledSpectrum {
    type Output = Self;
    fn mul(self, s: f32) -> Self {
        self.map(|v| v * s)
    }
}
impl MulAssign<f32> for SampledSpectrum {
    fn mul_assign(&mut self, s: f32) {
        *self = *self * s;
    }
}
impl Div<f32> for SampledSpectrum {
    type Output = Self;
    fn div(self, s: f32) -> Self {
        self.map(|v| v / s)
    }
}

/// Where a wavelength falls on a uniform grid of wavelengths from [`LAMBDA_MIN_NM`]: the node at
/// or below it and the weight of the next one (linear interpolation between nodes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridPosition {
    /// Index of the lower node (at most the last but one).
    index: u32,
    /// Weight of node `index + 1`, in [0, 1].
    weight: f32,
}

impl GridPosition {
    /// `nm` on the grid of `nodes` ≥ 2 nodes `step_nm` apart from [`LAMBDA_MIN_NM`], clamped to
    /// the grid's ends.
    #[must_use]
    #[inline]
    pub fn on_grid(nm: f32, step_nm: f32, nodes: usize) -> Self {
        let x = ((nm - LAMBDA_MIN_NM) / step_nm).clamp(0.0, (nodes - 1) as f32);
        let index = (x as usize).min(nodes - 2);
        Self {
            index: index as u32,
            weight: x - index as f32,
        }
    }

    /// Index of the node at or below the wavelength (at most the last but one).
    #[must_use]
    #[inline]
    pub fn index(self) -> usize {
        self.index as usize
    }

    /// Weight of the node above, in [0, 1].
    #[must_use]
    #[inline]
    pub fn weight(self) -> f32 {
        self.weight
    }

    /// The value between `values[index]` and `values[index + 1]`.
    #[must_use]
    #[inline]
    pub fn lerp(self, values: &[f32]) -> f32 {
        let i = self.index();
        let (a, b) = (values[i], values[i + 1]);
        a + self.weight * (b - a)
    }
}

/// Step of the per-wavelength tables every 10 nm over the rendered range (the BSSRDF's profiles
/// and incidence gain), nm.
pub const GRID_10NM_STEP_NM: f32 = 10.0;
/// Nodes of the 10-nm grid over 380–780 nm.
pub const GRID_10NM_NODES: usize = 41;

/// The four wavelengths of one path (nm) and their sampling densities (nm⁻¹).
///
/// The hero wavelength λ₀ is uniform in [380, 780] nm and the other three are rotated by a quarter
/// of the range each, so the four are stratified ([Wilkie et al. 2014] hero wavelength sampling).
/// A BSSRDF that samples with the hero's profile can call [`SampledWavelengths::terminate_secondary`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampledWavelengths {
    lambda_nm: [f32; N_WAVELENGTHS],
    pdf: [f32; N_WAVELENGTHS],
    /// Each wavelength's place on [`SpectrumTable`]'s grid and on the 10-nm grid, found once per
    /// path: every table a path reads at its wavelengths shares them.
    on_5nm: [GridPosition; N_WAVELENGTHS],
    on_10nm: [GridPosition; N_WAVELENGTHS],
}

impl SampledWavelengths {
    /// The wavelengths `lambda_nm` with densities `pdf`, and their places on the shared grids.
    fn new(lambda_nm: [f32; N_WAVELENGTHS], pdf: [f32; N_WAVELENGTHS]) -> Self {
        Self {
            lambda_nm,
            pdf,
            on_5nm: lambda_nm.map(SpectrumTable::position),
            on_10nm: lambda_nm
                .map(|nm| GridPosition::on_grid(nm, GRID_10NM_STEP_NM, GRID_10NM_NODES)),
        }
    }

    /// Where wavelength `i` falls on the 10-nm grid from 380 nm ([`GRID_10NM_NODES`] nodes).
    #[must_use]
    #[inline]
    pub fn on_10nm(&self, i: usize) -> GridPosition {
        self.on_10nm[i]
    }

    /// Stratified sample of the visible range from `u` in [0, 1).
    #[must_use]
    pub fn sample_visible(u: f32) -> Self {
        let range = LAMBDA_MAX_NM - LAMBDA_MIN_NM;
        let lambda_nm = std::array::from_fn(|i| {
            let mut x = u + i as f32 / N_WAVELENGTHS as f32;
            if x >= 1.0 {
                x -= 1.0;
            }
            LAMBDA_MIN_NM + x * range
        });
        Self::new(lambda_nm, [1.0 / range; N_WAVELENGTHS])
    }

    /// Four wavelengths from `u` in [0, 1) by `how`: the hero at CDF value u, the others at
    /// u + i/4 (mod 1), so they are stratified in the sampling density and each is distributed
    /// by it; each carries its own density.
    #[must_use]
    pub fn sample(u: f32, how: WavelengthSampling) -> Self {
        match how {
            WavelengthSampling::Uniform => Self::sample_visible(u),
            WavelengthSampling::Visible => {
                let drawn: [(f32, f32); N_WAVELENGTHS] = std::array::from_fn(|i| {
                    let mut x = u + i as f32 / N_WAVELENGTHS as f32;
                    if x >= 1.0 {
                        x -= 1.0;
                    }
                    sample_visible_with_pdf(x)
                });
                Self::new(drawn.map(|(nm, _)| nm), drawn.map(|(_, pdf)| pdf))
            }
        }
    }

    /// All four wavelengths at `nm` (a one-wavelength render, `--wavelength`): the radiance is
    /// read with [`SampledWavelengths::to_grey_xyz`], not integrated over the visible range.
    #[must_use]
    pub fn fixed(nm: f32) -> Self {
        Self::new([nm; N_WAVELENGTHS], [1.0; N_WAVELENGTHS])
    }

    /// The XYZ of a grey of linear sRGB R = G = B = L, L the radiance at a [`Self::fixed`]
    /// wavelength (the mean over the lanes still carried; a terminated lane holds 0 and the hero
    /// carries N times its share).
    #[must_use]
    pub fn to_grey_xyz(&self, l: &SampledSpectrum) -> [f32; 3] {
        let grey = l.average();
        grey_white_xyz().map(|w| w * grey)
    }

    /// Wavelength `i`, nm (`i = 0` is the hero).
    #[must_use]
    pub fn nm(&self, i: usize) -> f32 {
        self.lambda_nm[i]
    }

    /// All four wavelengths, nm.
    #[must_use]
    pub fn all_nm(&self) -> [f32; N_WAVELENGTHS] {
        self.lambda_nm
    }

    /// Sampling density of each wavelength, nm⁻¹ (0 once terminated).
    #[must_use]
    pub fn pdf(&self) -> [f32; N_WAVELENGTHS] {
        self.pdf
    }

    /// Keep only the hero wavelength (for wavelength-dependent sampling decisions, as pbrt-v4):
    /// the others get pdf 0 and stop contributing, the hero's estimate is scaled to stay unbiased.
    pub fn terminate_secondary(&mut self) {
        if self.pdf[1] == 0.0 {
            return;
        }
        for p in &mut self.pdf[1..] {
            *p = 0.0;
        }
        self.pdf[0] /= N_WAVELENGTHS as f32;
    }

    /// Each active lane's weight in the luminance estimate, ȳ(λ_i) / p(λ_i) (nm; `None` once
    /// terminated): what [`Self::to_xyz`] multiplies the lane's radiance by for Y, up to a constant.
    #[must_use]
    pub fn luminance_weights(&self) -> [Option<f32>; N_WAVELENGTHS] {
        let table = cmf_table();
        std::array::from_fn(|i| {
            (self.pdf[i] > 0.0).then(|| table.at(self.lambda_nm[i])[1] / self.pdf[i])
        })
    }

    /// Monte Carlo estimate of CIE XYZ from radiance `l` at these wavelengths, normalised so a
    /// constant spectral radiance 1 has Y = 1: XYZ = ∫ L {x̄,ȳ,z̄} dλ / ∫ ȳ dλ.
    #[must_use]
    pub fn to_xyz(&self, l: &SampledSpectrum) -> [f32; 3] {
        let table = cmf_table();
        let mut xyz = [0.0f32; 3];
        for i in 0..N_WAVELENGTHS {
            if self.pdf[i] == 0.0 || l.0[i] == 0.0 {
                continue;
            }
            let cmf = table.at(self.lambda_nm[i]);
            let w = l.0[i] / self.pdf[i];
            for c in 0..3 {
                xyz[c] += cmf[c] * w;
            }
        }
        let norm = 1.0 / (N_WAVELENGTHS as f32 * table.y_integral);
        xyz.map(|v| v * norm)
    }
}

/// The XYZ that the film's XYZ → linear sRGB matrix maps to R = G = B = 1: the sRGB white, refined
/// by fixed-point steps so the round trip through the two four-digit matrices is exact to f32.
fn grey_white_xyz() -> [f32; 3] {
    use skin_optics::color::{LinearSrgb, Xyz};
    static W: OnceLock<[f32; 3]> = OnceLock::new();
    *W.get_or_init(|| {
        let mut w = LinearSrgb([1.0; 3]).to_xyz().0;
        for _ in 0..4 {
            let rgb = Xyz(w).to_linear_srgb().0;
            let fix = LinearSrgb(rgb.map(|c| c - 1.0)).to_xyz().0;
            w = std::array::from_fn(|i| w[i] - fix[i]);
        }
        w.map(|v| v as f32)
    })
}

/// CIE 1931 x̄ȳz̄ re-tabulated in f32 at 1 nm over 380–780 nm from `skin_optics::color`.
struct CmfTable {
    rows: Vec<[f32; 3]>,
    y_integral: f32,
}

impl CmfTable {
    fn at(&self, nm: f32) -> [f32; 3] {
        let x = (nm - LAMBDA_MIN_NM).clamp(0.0, (self.rows.len() - 1) as f32);
        let i = (x as usize).min(self.rows.len() - 2);
        let f = x - i as f32;
        let (a, b) = (self.rows[i], self.rows[i + 1]);
        std::array::from_fn(|c| a[c] + f * (b[c] - a[c]))
    }
}

fn cmf_table() -> &'static CmfTable {
    static T: OnceLock<CmfTable> = OnceLock::new();
    T.get_or_init(|| {
        let n = (LAMBDA_MAX_NM - LAMBDA_MIN_NM) as usize + 1;
        let rows = (0..n)
            .map(|i| cie_xyz_bar(f64::from(LAMBDA_MIN_NM) + i as f64).map(|v| v as f32))
            .collect();
        CmfTable {
            rows,
            y_integral: cie_y_integral() as f32,
        }
    })
}

/// Relative luminance Y of a spectrum `s(λ)` (nm → value): ∫ s ȳ dλ / ∫ ȳ dλ over the CIE table.
#[must_use]
pub fn luminance_of(s: impl Fn(f64) -> f64) -> f64 {
    let mut y = 0.0;
    let mut nm = skin_optics::color::CMF_START_NM;
    while nm <= skin_optics::color::CMF_END_NM {
        y += s(nm) * cie_xyz_bar(nm)[1];
        nm += 1.0;
    }
    y / cie_y_integral()
}

/// A spectrum tabulated on a uniform 5-nm grid over 380–780 nm in f32, built once at scene load
/// (albedos, emission) and evaluated at the hero wavelengths by linear interpolation.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectrumTable {
    values: Vec<f32>,
    /// Mean of `values`, cached (light selection reads it per shading point).
    mean: f32,
}

impl SpectrumTable {
    /// Table step, nm.
    pub const STEP_NM: f32 = 5.0;
    /// Tabulated values: 380–780 nm every [`Self::STEP_NM`].
    const NODES: usize = ((LAMBDA_MAX_NM - LAMBDA_MIN_NM) / Self::STEP_NM) as usize + 1;

    /// Where `nm` falls on the table's grid.
    #[inline]
    fn position(nm: f32) -> GridPosition {
        GridPosition::on_grid(nm, Self::STEP_NM, Self::NODES)
    }

    /// Tabulate `f(λ_nm)` on the 5-nm grid.
    #[must_use]
    pub fn from_fn(f: impl Fn(f64) -> f64) -> Self {
        let values = (0..Self::NODES)
            .map(|i| f(f64::from(LAMBDA_MIN_NM + i as f32 * Self::STEP_NM)) as f32)
            .collect();
        Self::from_values(values)
    }

    fn from_values(values: Vec<f32>) -> Self {
        let mean = values.iter().sum::<f32>() / values.len() as f32;
        Self { values, mean }
    }

    /// The same value at every wavelength.
    #[must_use]
    pub fn constant(v: f32) -> Self {
        Self::from_fn(|_| f64::from(v))
    }

    /// Value at `nm` (clamped to the table's range).
    #[must_use]
    pub fn at_nm(&self, nm: f32) -> f32 {
        Self::position(nm).lerp(&self.values)
    }

    /// Values at the path's four wavelengths.
    #[must_use]
    pub fn eval(&self, wl: &SampledWavelengths) -> SampledSpectrum {
        SampledSpectrum(wl.on_5nm.map(|at| at.lerp(&self.values)))
    }

    /// Largest tabulated value.
    #[must_use]
    pub fn max_value(&self) -> f32 {
        self.values.iter().copied().fold(0.0, f32::max)
    }

    /// Mean of the tabulated values.
    #[must_use]
    pub fn mean(&self) -> f32 {
        self.mean
    }

    /// Multiply every value by `s`.
    #[must_use]
    pub fn scaled(self, s: f32) -> Self {
        Self::from_values(self.values.into_iter().map(|v| v * s).collect())
    }
}

/// Upper edges of the blue and green bands of the sRGB → spectrum box basis, nm.
const BOX_EDGES_NM: [f32; 2] = [490.0, 580.0];

/// A reflectance spectrum for a linear sRGB triple: a box basis (blue below 490 nm, green to
/// 580 nm, red above). Greys map exactly to constant spectra; hues are approximate, which is
/// enough for backdrops and environment maps (skin colour is always computed spectrally).
#[must_use]
pub fn linear_srgb_to_spectrum(rgb: [f32; 3]) -> SpectrumTable {
    SpectrumTable::from_fn(|nm| f64::from(linear_srgb_at_nm(rgb, nm as f32)))
}

/// The box-basis spectrum of a linear sRGB triple (see [`linear_srgb_to_spectrum`]) at `nm`.
#[must_use]
pub fn linear_srgb_at_nm(rgb: [f32; 3], nm: f32) -> f32 {
    if nm < BOX_EDGES_NM[0] {
        rgb[2]
    } else if nm < BOX_EDGES_NM[1] {
        rgb[1]
    } else {
        rgb[0]
    }
}

/// XYZ → linear sRGB (IEC 61966-2-1), through `skin_optics::color`.
#[must_use]
pub fn xyz_to_linear_srgb(xyz: [f32; 3]) -> [f32; 3] {
    skin_optics::color::Xyz(xyz.map(f64::from))
        .to_linear_srgb()
        .0
        .map(|v| v as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wavelengths_are_stratified_and_in_range() {
        let wl = SampledWavelengths::sample_visible(0.9);
        let mut nm = wl.all_nm();
        nm.sort_by(f32::total_cmp);
        for w in nm.windows(2) {
            assert!((w[1] - w[0] - 100.0).abs() < 1e-3, "{nm:?}");
        }
        assert!(
            nm.iter()
                .all(|&l| (LAMBDA_MIN_NM..LAMBDA_MAX_NM).contains(&l))
        );
    }

    #[test]
    fn constant_radiance_has_unit_luminance() {
        // Average the estimator over many stratified hero samples: Y → 1 for L = 1.
        let n = 4000;
        let mut y = 0.0f64;
        for k in 0..n {
            let wl = SampledWavelengths::sample_visible((k as f32 + 0.5) / n as f32);
            y += f64::from(wl.to_xyz(&SampledSpectrum::splat(1.0))[1]);
        }
        y /= f64::from(n);
        assert!((y - 1.0).abs() < 1e-3, "Y = {y}");
    }

    /// The visible density integrates to 1 over 380–780 nm (midpoint rule, 0.1 nm: error far below
    /// 1e-4), and its sampler inverts its CDF: the fraction of the range below the sampled λ(u)
    /// is u.
    #[test]
    fn visible_wavelengths_follow_their_density() {
        let n = 4000;
        let h = (LAMBDA_MAX_NM - LAMBDA_MIN_NM) / n as f32;
        let mut cdf = 0.0f64;
        let mut k = 0;
        for i in 0..n {
            let nm = LAMBDA_MIN_NM + (i as f32 + 0.5) * h;
            cdf += f64::from(visible_wavelength_pdf(nm) * h);
            if i % 400 == 399 {
                k += 1;
                // λ(u) at this CDF value must be the right edge of the bin.
                let edge = LAMBDA_MIN_NM + (i + 1) as f32 * h;
                let nm_u = sample_visible_wavelength(cdf as f32);
                assert!((nm_u - edge).abs() < 0.05, "u = {cdf}: {nm_u} vs {edge}");
            }
        }
        assert_eq!(k, 10);
        assert!((cdf - 1.0).abs() < 1e-4, "∫ p dλ = {cdf}");
    }

    /// The density the sampler returns with each wavelength, (1 − y²) from the inverted tanh, is
    /// the closed-form 1/cosh² density at that wavelength: over 1001 CDF values, within 1e-5
    /// relative (f32 rounding of y, of the wavelength and of cosh: a few 1e-7 each); and the
    /// wavelength is the f64 inverse of the CDF within 1e-3 nm (f32 rounding of 780 nm: 6e-5 nm).
    #[test]
    fn sampled_density_is_the_closed_form_density() {
        let a = f64::from(VISIBLE_A_PER_NM);
        let t = |nm: f64| (a * (nm - f64::from(VISIBLE_CENTRE_NM))).tanh();
        let (t0, t1) = (t(f64::from(LAMBDA_MIN_NM)), t(f64::from(LAMBDA_MAX_NM)));
        for k in 0..=1000 {
            let u = (k as f32 / 1000.0).min(1.0 - f32::EPSILON);
            let (nm, pdf) = sample_visible_with_pdf(u);
            let want = visible_wavelength_pdf(nm);
            assert!(
                (pdf / want - 1.0).abs() < 1e-5,
                "u = {u}: {nm} nm, density {pdf} against {want}"
            );
            let exact = f64::from(VISIBLE_CENTRE_NM) + (t0 + f64::from(u) * (t1 - t0)).atanh() / a;
            assert!(
                (f64::from(nm) - exact).abs() < 1e-3,
                "u = {u}: {nm} nm against {exact} nm"
            );
        }
    }

    /// Visible sampling estimates the luminance of a constant spectrum as 1, with less spread
    /// over u than uniform sampling (its density follows ȳ).
    #[test]
    fn visible_sampling_is_unbiased_and_tighter_on_luminance() {
        let n = 4000;
        let stats = |how| {
            let (mut s, mut s2) = (0.0f64, 0.0f64);
            for k in 0..n {
                let wl = SampledWavelengths::sample((k as f32 + 0.5) / n as f32, how);
                let y = f64::from(wl.to_xyz(&SampledSpectrum::splat(1.0))[1]);
                s += y;
                s2 += y * y;
            }
            let mean = s / f64::from(n);
            (mean, (s2 / f64::from(n) - mean * mean).max(0.0).sqrt())
        };
        let (mean_v, sd_v) = stats(WavelengthSampling::Visible);
        let (mean_u, sd_u) = stats(WavelengthSampling::Uniform);
        assert!((mean_v - 1.0).abs() < 1e-3 && (mean_u - 1.0).abs() < 1e-3);
        assert!(sd_v < 0.5 * sd_u, "σ visible {sd_v} vs uniform {sd_u}");
    }

    #[test]
    fn spectrum_table_interpolates() {
        let t = SpectrumTable::from_fn(|nm| nm / 100.0);
        assert!((t.at_nm(512.5) - 5.125).abs() < 1e-5);
        assert!((t.at_nm(100.0) - 3.8).abs() < 1e-5);
    }
}
