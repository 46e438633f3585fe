//! Blender Cycles: the skin as a Principled BSDF whose subsurface part Cycles itself returns as our
//! diffuse reflectance, and as an exact volumetric two-layer slab (docs/physics.md §14.7).
//!
//! **Principled BSDF (Random Walk, Random Walk (Skin)).** Cycles does not solve the medium that
//! OpenPBR defines: its random walk leaves at the first surface hit (no internal reflection), gives
//! up after 256 steps, replaces the phase function by its similarity form after 9, and turns Base
//! Color into a single-scattering albedo by a fitted formula ([`cycles_albedo`]). The Base Color
//! that returns a given reflectance is therefore *measured* in Cycles: a committed table
//! ([`CALIBRATION_CSV`], `skin-export/data/cycles/`) of the subsurface reflectance Cycles renders on
//! a thick slab at normal view for a ladder of grey Base Colors, and a smooth weighted least-squares
//! curve R(c) through two thirds of its rows ([`Calibration`]) whose inverse gives c. The radius is
//! reproduced from Cycles' source: Subsurface Radius × Scale = 4π d (Random Walk) or
//! d / √(3(1 − α′)) (Random Walk (Skin)), d the walk's reduced mean free path, chosen so that the
//! walk's medium (albedo [`cycles_albedo`], no internal reflection) traced by our Monte Carlo has
//! our mean exit radius.
//!
//! **Volumetric.** Two boxes of Principled Volume (Color = single-scattering albedo, Density = σt
//! per scene unit, Absorption Color black, so σs = Color · Density and σa = (1 − Color) · Density
//! in Cycles' `svm_node_principled_volume`) under a smooth glass face: the per-channel layers of
//! [`crate::mitsuba::channel_layers`] (one σt per layer, per-channel albedos solved for our RGB
//! totals), so Cycles solves our transport up to its bounce limit.

use crate::error::{ExportError, check};
use crate::mitsuba::{ChannelLayers, channel_layers};
use crate::rgb::{RgbProfile, shape_error};
use crate::volume::semi_infinite_profile;
use crate::{ExportOptions, Format, Surface, percent3};
use serde_json::{Value, json};
use skin_optics::SkinParams;
use std::f64::consts::PI;
use std::fmt;
use std::str::FromStr;

/// The committed Cycles measurements: `method,base_color,subsurface_reflectance,stderr` with the
/// command, Blender version and settings in its comment lines.
pub const CALIBRATION_CSV: &str = include_str!("../data/cycles/principled_subsurface.csv");
/// Index of refraction of the calibration (Principled IOR and Subsurface IOR).
pub const CALIBRATION_IOR: f64 = 1.4;
/// Principled Roughness of the calibration (√ of the Beckmann m = 0.3 of [DJ06]).
pub const CALIBRATION_ROUGHNESS: f64 = 0.547_723;
/// Principled Specular IOR Level of the calibration (0.5: the dielectric's own Fresnel).
pub const CALIBRATION_SPECULAR_IOR_LEVEL: f64 = 0.5;
/// Principled Subsurface Anisotropy of the calibration. Cycles' albedo remap saturates for g = 0.9
/// (a flat reflectance of 0.893 for every Base Color above 0.7, measured), so the walk is isotropic.
pub const CALIBRATION_ANISOTROPY: f64 = 0.0;
/// Degree of the polynomial in u = √(1 − α) of the calibration curve ([`Calibration`]).
pub const CALIBRATION_DEGREE: usize = 5;
/// Every how many rows of the table (sorted by c) one is held out of the fit (the second of each
/// group, so the first and last rows are fitted and nothing is extrapolated).
pub const HOLD_OUT_EVERY: usize = 3;
/// Version of the Blender (Cycles) that measured the table and that the script is written for.
pub const BLENDER_VERSION: &str = "5.0.1";
/// Gap of vacuum between the volumetric epidermis and dermis boxes, mm: Cycles sums the volumes of
/// nested objects, and two coincident faces may be crossed in either order or once, so the two
/// boxes are apart by this much (an optical thickness of about 0.05 at σt = 50 mm⁻¹, crossed
/// without scattering).
pub const VOLUME_GAP_MM: f64 = 1e-3;
/// Lateral half-width of the volumetric slab, mm.
pub const VOLUME_HALF_WIDTH_MM: f64 = 50.0;

/// Cycles' subsurface method of the Principled BSDF.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CyclesMethod {
    /// `RANDOM_WALK`: refractive entry of the material's roughness, radius × 1/(4π) as d.
    RandomWalk,
    /// `RANDOM_WALK_SKIN`: half the entries diffuse, radius rescaled by the albedo and IOR.
    RandomWalkSkin,
}

impl CyclesMethod {
    /// Both methods.
    pub const ALL: [CyclesMethod; 2] = [CyclesMethod::RandomWalk, CyclesMethod::RandomWalkSkin];

    /// The identifier of `ShaderNodeBsdfPrincipled.subsurface_method`.
    #[must_use]
    pub fn identifier(self) -> &'static str {
        match self {
            CyclesMethod::RandomWalk => "RANDOM_WALK",
            CyclesMethod::RandomWalkSkin => "RANDOM_WALK_SKIN",
        }
    }
}

impl fmt::Display for CyclesMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.identifier())
    }
}

impl FromStr for CyclesMethod {
    type Err = ExportError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        CyclesMethod::ALL
            .into_iter()
            .find(|m| m.identifier() == s.trim())
            .ok_or_else(|| ExportError::Calibration {
                line: 0,
                message: format!("unknown method '{s}' (valid: RANDOM_WALK, RANDOM_WALK_SKIN)"),
            })
    }
}

/// One row of the calibration table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CalibrationPoint {
    /// Principled Base Color (grey), linear.
    pub base_color: f64,
    /// Subsurface reflectance Cycles rendered (pixel minus the specular face alone).
    pub reflectance: f64,
    /// Its standard error.
    pub stderr: f64,
    /// Whether the row was left out of the fit.
    pub held_out: bool,
}

/// The measured curve of one method: R(c) = s(c) Σₖ aₖ uᵏ with u = √(1 − α(c)) and s(c) =
/// min(α_raw(c)/0.2, 1), α the walk's albedo ([`cycles_albedo`], floored at 0.2 with the throughput
/// scaled by s, as Cycles does): diffusion makes a half-space's reflectance analytic in √(1 − α),
/// and the floor's kink is Cycles' own. Weighted least squares on the rows not held out.
#[derive(Debug, Clone, PartialEq)]
pub struct Calibration {
    /// The method measured.
    pub method: CyclesMethod,
    /// The table's rows of this method, by increasing Base Color.
    pub points: Vec<CalibrationPoint>,
    /// Coefficients a₀ … a_[`CALIBRATION_DEGREE`] of the polynomial in u.
    pub coefficients: Vec<f64>,
}

impl Calibration {
    /// Parse `csv` (the format of [`CALIBRATION_CSV`]) and fit the curve of `method`.
    pub fn from_csv(csv: &str, method: CyclesMethod) -> Result<Self, ExportError> {
        let mut points = Vec::new();
        for (i, line) in csv.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') || line.starts_with("method,") {
                continue;
            }
            let bad = |message: String| ExportError::Calibration {
                line: i + 1,
                message,
            };
            let f: Vec<&str> = line.split(',').collect();
            if f.len() != 4 {
                return Err(bad(format!("{} fields (expected 4)", f.len())));
            }
            if f[0]
                .parse::<CyclesMethod>()
                .map_err(|e| bad(e.to_string()))?
                != method
            {
                continue;
            }
            let num = |k: usize, name: &str| -> Result<f64, ExportError> {
                f[k].trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| bad(format!("{name} '{}' is not a number", f[k])))
            };
            let (base_color, reflectance, stderr) = (
                num(1, "base_color")?,
                num(2, "subsurface_reflectance")?,
                num(3, "stderr")?,
            );
            if !(0.0..=1.0).contains(&base_color) || stderr <= 0.0 {
                return Err(bad(
                    "base_color outside [0, 1] or stderr not positive".to_string()
                ));
            }
            points.push(CalibrationPoint {
                base_color,
                reflectance,
                stderr,
                held_out: false,
            });
        }
        points.sort_by(|a, b| a.base_color.total_cmp(&b.base_color));
        for (k, p) in points.iter_mut().enumerate() {
            p.held_out = k % HOLD_OUT_EVERY == 1;
        }
        let fitted: Vec<_> = points.iter().filter(|p| !p.held_out).collect();
        if fitted.len() < 2 * (CALIBRATION_DEGREE + 1) {
            return Err(ExportError::Calibration {
                line: 0,
                message: format!(
                    "{method}: {} rows to fit (need at least {})",
                    fitted.len(),
                    2 * (CALIBRATION_DEGREE + 1)
                ),
            });
        }
        // Normal equations of the weighted fit: basis φₖ(c) = s(c) u(c)ᵏ, weights 1/σ².
        let n = CALIBRATION_DEGREE + 1;
        let mut a = vec![vec![0.0; n + 1]; n];
        for p in &fitted {
            let w = 1.0 / (p.stderr * p.stderr);
            let phi = basis(p.base_color);
            for r in 0..n {
                for c in 0..n {
                    a[r][c] += w * phi[r] * phi[c];
                }
                a[r][n] += w * phi[r] * p.reflectance;
            }
        }
        let coefficients = solve_linear(a).ok_or_else(|| ExportError::Calibration {
            line: 0,
            message: format!("{method}: the calibration's normal equations are singular"),
        })?;
        Ok(Self {
            method,
            points,
            coefficients,
        })
    }

    /// The committed table's curve for `method`.
    pub fn committed(method: CyclesMethod) -> Result<Self, ExportError> {
        Self::from_csv(CALIBRATION_CSV, method)
    }

    /// Cycles' subsurface reflectance at Base Color `c` (the fitted curve).
    #[must_use]
    pub fn reflectance(&self, c: f64) -> f64 {
        basis(c)
            .iter()
            .zip(&self.coefficients)
            .map(|(p, a)| p * a)
            .sum()
    }

    /// The measured range of Base Color.
    #[must_use]
    pub fn base_color_range(&self) -> (f64, f64) {
        (
            self.points[0].base_color,
            self.points[self.points.len() - 1].base_color,
        )
    }

    /// The Base Color whose subsurface reflectance is `target`: bisection on the curve within the
    /// measured range (where it increases), to 1e-12.
    pub fn base_color(&self, target: f64) -> Result<f64, ExportError> {
        let (lo, hi) = self.base_color_range();
        let (r_lo, r_hi) = (self.reflectance(lo), self.reflectance(hi));
        if !(r_lo..=r_hi).contains(&target) {
            return Err(ExportError::OutOfRange {
                name: "subsurface reflectance for the Cycles calibration",
                value: target,
                range: "the table's measured range (see `Calibration::base_color_range`)",
            });
        }
        let (mut a, mut b) = (lo, hi);
        while b - a > 1e-12 {
            let m = 0.5 * (a + b);
            if self.reflectance(m) < target {
                a = m;
            } else {
                b = m;
            }
        }
        Ok(0.5 * (a + b))
    }

    /// χ² of the rows (held out or fitted) against the curve: Σ ((R − R(c)) / σ)², and their count.
    #[must_use]
    pub fn chi_squared(&self, held_out: bool) -> (f64, usize) {
        self.points
            .iter()
            .filter(|p| p.held_out == held_out)
            .fold((0.0, 0), |(s, n), p| {
                let z = (p.reflectance - self.reflectance(p.base_color)) / p.stderr;
                (s + z * z, n + 1)
            })
    }

    /// Largest |R − R(c)| over the table's rows.
    #[must_use]
    pub fn max_residual(&self) -> f64 {
        self.points
            .iter()
            .map(|p| (p.reflectance - self.reflectance(p.base_color)).abs())
            .fold(0.0, f64::max)
    }
}

/// The calibration curve's basis s(c) u(c)ᵏ, k = 0 … [`CALIBRATION_DEGREE`].
fn basis(c: f64) -> Vec<f64> {
    let raw = cycles_albedo_raw(c, CALIBRATION_ANISOTROPY);
    let scale = (raw / CYCLES_MIN_ALPHA).min(1.0);
    let u = (1.0 - raw.max(CYCLES_MIN_ALPHA)).sqrt();
    (0..=CALIBRATION_DEGREE)
        .map(|k| scale * u.powi(k as i32))
        .collect()
}

/// Gaussian elimination with partial pivoting of the augmented n × (n + 1) system.
fn solve_linear(mut a: Vec<Vec<f64>>) -> Option<Vec<f64>> {
    let n = a.len();
    for col in 0..n {
        let pivot = (col..n).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, pivot);
        let pivot_row = a[col].clone();
        for row in a.iter_mut().skip(col + 1) {
            let f = row[col] / pivot_row[col];
            for (v, p) in row.iter_mut().zip(&pivot_row).skip(col) {
                *v -= f * p;
            }
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|k| a[row][k] * x[k]).sum();
        x[row] = (a[row][n] - s) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// The floor of Cycles' walk albedo (`subsurface_random_walk_coefficients`: below it Cycles raises
/// α to it and scales the throughput by α/0.2 instead).
pub const CYCLES_MIN_ALPHA: f64 = 0.2;

/// The single-scattering albedo of Cycles' walk for Base Color `c` and anisotropy `g`: the remap
/// floored at [`CYCLES_MIN_ALPHA`].
#[must_use]
pub fn cycles_albedo(c: f64, g: f64) -> f64 {
    cycles_albedo_raw(c, g).max(CYCLES_MIN_ALPHA)
}

/// Cycles' remap of Base Color `c` and anisotropy `g` to a single-scattering albedo
/// (`subsurface_random_walk_remap`, after [WVH17]'s fit; Cycles 5.0 source), clamped to
/// [0, 0.999999] as Cycles clamps it.
#[must_use]
pub fn cycles_albedo_raw(c: f64, g: f64) -> f64 {
    let p = |k: [f64; 8]| -> f64 { k.iter().rev().fold(0.0, |acc, a| acc * g + a) };
    let e = |k0: f64, k1: f64, k: [f64; 7]| -> f64 {
        k0 + k1 * (k.iter().rev().fold(0.0, |acc, a| acc * g + a) * g).exp()
    };
    let a = p([
        1.826_052_378_2,
        -1.284_510_564_36,
        -1.799_046_293_12,
        9.193_932_892_02,
        -22.821_558_586_2,
        32.023_487_425_9,
        -23.626_480_333_3,
        7.210_670_026_58,
    ]);
    let b = e(
        4.985_111_943_85,
        0.127_355_959_438,
        [
            31.149_158_143_3,
            -201.847_017_512,
            841.576_016_723,
            -2_018.092_885_05,
            2_731.715_602_86,
            -1_935.414_242_44,
            559.009_054_474,
        ],
    );
    let cc = p([
        1.096_861_024_24,
        -0.394_704_063_468,
        1.052_581_159_41,
        -8.839_637_127_26,
        28.864_323_066_1,
        -46.880_291_358_1,
        38.540_283_751_8,
        -12.718_104_253_8,
    ]);
    let d = p([
        0.496_310_210_422,
        0.360_146_581_622,
        -2.151_393_097_47,
        17.889_689_921_7,
        -55.298_401_033_3,
        82.065_982_243,
        -58.510_600_857_8,
        15.847_829_502_1,
    ]);
    let ee = e(
        4.231_902_997_01,
        0.003_106_039_490_88,
        [
            76.731_625_395_2,
            -594.356_773_233,
            2_448.883_420_3,
            -5_576.685_289_98,
            7_116.601_719_12,
            -4_763.544_678_87,
            1_303.531_805_5,
        ],
    );
    let f = p([
        2.406_029_994_08,
        -2.518_148_446_09,
        9.184_949_083_56,
        -79.219_170_868_2,
        259.082_868_209,
        -403.613_804_597,
        302.857_124_36,
        -87.437_047_356_7,
    ]);
    let blend = c.powf(0.25);
    let alpha = (1.0 - blend) * a * (b * c).atan().powf(cc) + blend * d * (ee * c).atan().powf(f);
    alpha.clamp(0.0, 0.999_999)
}

/// Cycles' diffuse-reflectance inversion of Random Walk (Skin) (`bssrdf_dipole_compute_alpha_prime`:
/// 12 bisection steps on the dipole R_d(α′) = ½α′(1 + e^{−(4/3)A s}) e^{−s}, s = √(3(1 − α′)),
/// A = (1 + F_dr)/(1 − F_dr) with Cycles' F_dr(η) fit).
#[must_use]
pub fn cycles_skin_alpha_prime(c: f64, ior: f64) -> f64 {
    if c < 1e-4 {
        return 0.0;
    }
    if c >= 0.995 {
        return 0.999_999;
    }
    let inv = 1.0 / ior;
    let f_dr = inv * (-1.440 * inv + 0.710) + 0.668 + 0.0636 * ior;
    let four_thirds_a = (4.0 / 3.0) * (1.0 + f_dr) / (1.0 - f_dr);
    let rd = |ap: f64| {
        let s = (3.0 * (1.0 - ap)).sqrt();
        0.5 * ap * (1.0 + (-four_thirds_a * s).exp()) * (-s).exp()
    };
    let (mut x0, mut x1, mut mid) = (0.0, 1.0, 0.5);
    for _ in 0..12 {
        mid = 0.5 * (x0 + x1);
        if rd(mid) < c {
            x0 = mid;
        } else {
            x1 = mid;
        }
    }
    mid
}

/// Subsurface Radius × Scale (mm) that gives Cycles' walk the reduced mean free path `d_mm`.
#[must_use]
pub fn cycles_radius_mm(method: CyclesMethod, d_mm: f64, base_color: f64, ior: f64) -> f64 {
    match method {
        CyclesMethod::RandomWalk => 4.0 * PI * d_mm,
        CyclesMethod::RandomWalkSkin => {
            d_mm / (3.0 * (1.0 - cycles_skin_alpha_prime(base_color, ior))).sqrt()
        }
    }
}

/// The Principled BSDF of one method, fitted per channel.
#[derive(Debug, Clone, PartialEq)]
pub struct PrincipledFit {
    /// The subsurface method.
    pub method: CyclesMethod,
    /// Base Color, linear Rec.709, from the calibration's inverse.
    pub base_color: [f64; 3],
    /// Subsurface Radius × Scale per channel, mm.
    pub radius_mm: [f64; 3],
    /// Cycles' single-scattering albedo of each channel (its remap of the Base Color).
    pub walk_albedo: [f64; 3],
    /// Energy-weighted shape error of the walk's medium (our Monte Carlo) against our profile.
    pub shape_error: [f64; 3],
    /// Largest |measured − curve| of the calibration table.
    pub calibration_residual: f64,
}

impl PrincipledFit {
    /// Fit `method` to `targets` (Cycles' subsurface part, per incident photon) and `rgb`'s mean
    /// exit radii, tracing the walk's medium with `photons` histories per channel.
    pub fn fit(
        method: CyclesMethod,
        targets: [f64; 3],
        rgb: &RgbProfile,
        photons: u64,
    ) -> Result<Self, ExportError> {
        let cal = Calibration::committed(method)?;
        let g = CALIBRATION_ANISOTROPY;
        let mut fit = Self {
            method,
            base_color: [0.0; 3],
            radius_mm: [0.0; 3],
            walk_albedo: [0.0; 3],
            shape_error: [0.0; 3],
            calibration_residual: cal.max_residual(),
        };
        for (c, &target) in targets.iter().enumerate() {
            let base = cal.base_color(target)?;
            let alpha = cycles_albedo(base, g);
            // The walk at d = 1 mm: σt = 1/(1 − g); it leaves at the first surface hit, which is
            // our medium under an index-matched face.
            let sigma_t = 1.0 / (1.0 - g);
            let (profile, mean_at_unit_d) =
                semi_infinite_profile((1.0 - alpha) * sigma_t, alpha * sigma_t, g, 1.0, photons)?;
            let d = rgb.mean_radius_mm(c) / mean_at_unit_d;
            fit.base_color[c] = base;
            fit.walk_albedo[c] = alpha;
            fit.radius_mm[c] = cycles_radius_mm(method, d, base, CALIBRATION_IOR);
            fit.shape_error[c] = shape_error(&rgb.channel(c)?, |r| profile.eval(r / d) / (d * d));
        }
        Ok(fit)
    }
}

/// The Blender export: both Principled fits and the volumetric layers.
#[derive(Debug, Clone, PartialEq)]
pub struct BlenderFit {
    /// Our diffuse reflectance per incident photon (`skin spectrum`'s, D65 → linear Rec.709).
    pub target: [f64; 3],
    /// One fit per method, in [`CyclesMethod::ALL`] order.
    pub principled: Vec<PrincipledFit>,
    /// The volumetric layers per channel.
    pub volume: [ChannelLayers; 3],
}

impl BlenderFit {
    /// Fit every Cycles model of `skin` to its RGB profiles `rgb` (per entering photon).
    pub fn fit(
        skin: &SkinParams,
        rgb: &RgbProfile,
        surface: Surface,
        photons: u64,
    ) -> Result<Self, ExportError> {
        check(
            "skin index η for the Cycles calibration",
            surface.eta,
            CALIBRATION_IOR - 1e-9,
            CALIBRATION_IOR + 1e-9,
            "1.4 (the index the Cycles table was measured at)",
        )?;
        let entering = 1.0 - surface.f0();
        let target = rgb.totals().map(|t| t * entering);
        let principled = CyclesMethod::ALL
            .into_iter()
            .map(|m| PrincipledFit::fit(m, target, rgb, photons))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            target,
            principled,
            volume: channel_layers(skin, rgb.totals())?,
        })
    }
}

/// The plain values (the `blender-json` file and the script's `VALUES`).
fn values(fit: &BlenderFit, skin: &SkinParams, surface: Surface, opts: &ExportOptions) -> Value {
    let unit = opts.scene_unit_mm;
    let principled: serde_json::Map<String, Value> = fit
        .principled
        .iter()
        .map(|p| {
            let scale = p.radius_mm.iter().copied().fold(0.0, f64::max);
            (
                p.method.identifier().to_string(),
                json!({
                    "base_color": p.base_color,
                    "subsurface_radius": p.radius_mm.map(|r| r / scale),
                    "subsurface_scale": scale / unit,
                    "walk_single_scattering_albedo": p.walk_albedo,
                    "shape_error": p.shape_error,
                    "calibration_max_residual": p.calibration_residual,
                }),
            )
        })
        .collect();
    let layer = |i: usize| {
        let ch = &fit.volume;
        let sigma_t = ch[1].layers[i].sigma_t_per_mm();
        let albedo = [0, 1, 2].map(|c| ch[c].layers[i].albedo());
        json!({
            "color": albedo,
            "density": sigma_t * unit,
            "anisotropy": ch[1].layers[i].g,
            "absorption_color": [0.0, 0.0, 0.0],
        })
    };
    let epidermis_mm = skin.epidermis_thickness_mm();
    let per_entering = [0, 1, 2].map(|c| fit.volume[c].total);
    json!({
        "blender": BLENDER_VERSION,
        "scene_unit_mm": unit,
        "colour_space": "lin_rec709 (Blender's default scene-linear working space)",
        "target_diffuse_reflectance": fit.target,
        "ior": surface.eta,
        "roughness": CALIBRATION_ROUGHNESS,
        "specular_ior_level": CALIBRATION_SPECULAR_IOR_LEVEL,
        "subsurface_anisotropy": CALIBRATION_ANISOTROPY,
        "default_method": CyclesMethod::RandomWalk.identifier(),
        "principled": principled,
        "volume": {
            "epidermis": layer(0),
            "dermis": layer(1),
            "epidermis_thickness": epidermis_mm / unit,
            "dermis_thickness": opts.dermis_thickness_mm / unit,
            "half_width": VOLUME_HALF_WIDTH_MM / unit,
            "gap": VOLUME_GAP_MM / unit,
            "glass_ior": surface.eta,
            "bounces": 1024,
            "per_entering_totals": per_entering,
        },
    })
}

/// The builder script around `values_json` (written once; it reads every number from `VALUES`).
const SCRIPT: &str = r#"
import json

import bpy

VALUES = json.loads(r"""@VALUES@""")


def _principled(mat):
    nodes = mat.node_tree.nodes
    for node in nodes:
        if node.bl_idname == "ShaderNodeBsdfPrincipled":
            return node
    p = nodes.new("ShaderNodeBsdfPrincipled")
    out = nodes.get("Material Output") or nodes.new("ShaderNodeOutputMaterial")
    mat.node_tree.links.new(p.outputs["BSDF"], out.inputs["Surface"])
    return p


def subsurface_material(method=VALUES["default_method"], name="skin"):
    """The Principled BSDF of `method` ("RANDOM_WALK" or "RANDOM_WALK_SKIN"), calibrated in Cycles."""
    v = VALUES["principled"][method]
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    p = _principled(mat)
    p.subsurface_method = method
    p.inputs["Base Color"].default_value = (*v["base_color"], 1.0)
    p.inputs["Subsurface Weight"].default_value = 1.0
    p.inputs["Subsurface Radius"].default_value = v["subsurface_radius"]
    p.inputs["Subsurface Scale"].default_value = v["subsurface_scale"]
    p.inputs["Subsurface Anisotropy"].default_value = VALUES["subsurface_anisotropy"]
    if "Subsurface IOR" in p.inputs:
        p.inputs["Subsurface IOR"].default_value = VALUES["ior"]
    p.inputs["IOR"].default_value = VALUES["ior"]
    p.inputs["Roughness"].default_value = VALUES["roughness"]
    p.inputs["Specular IOR Level"].default_value = VALUES["specular_ior_level"]
    return mat


def volume_material(layer, name, glass_above=None):
    """Principled Volume of `layer` ("epidermis" or "dermis"). Its surface is a smooth glass where
    the world z of the hit point is above `glass_above` (Cycles flips the normal of a face hit from
    behind, so position, not normal, tells the top face from the others), and transparent (a volume
    boundary only) elsewhere; all transparent when `glass_above` is None."""
    v = VALUES["volume"][layer]
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    vol = nodes.new("ShaderNodeVolumePrincipled")
    vol.inputs["Color"].default_value = (*v["color"], 1.0)
    vol.inputs["Density"].default_value = v["density"]
    vol.inputs["Anisotropy"].default_value = v["anisotropy"]
    vol.inputs["Absorption Color"].default_value = (*v["absorption_color"], 1.0)
    links.new(vol.outputs["Volume"], out.inputs["Volume"])
    clear = nodes.new("ShaderNodeBsdfTransparent")
    clear.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    if glass_above is not None:
        glass = nodes.new("ShaderNodeBsdfGlass")
        glass.inputs["IOR"].default_value = VALUES["volume"]["glass_ior"]
        glass.inputs["Roughness"].default_value = 0.0
        glass.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        geo = nodes.new("ShaderNodeNewGeometry")
        xyz = nodes.new("ShaderNodeSeparateXYZ")
        above = nodes.new("ShaderNodeMath")
        above.operation = "GREATER_THAN"
        above.inputs[1].default_value = glass_above
        mix = nodes.new("ShaderNodeMixShader")
        links.new(geo.outputs["Position"], xyz.inputs[0])
        links.new(xyz.outputs["Z"], above.inputs[0])
        links.new(above.outputs[0], mix.inputs["Fac"])
        links.new(clear.outputs[0], mix.inputs[1])
        links.new(glass.outputs[0], mix.inputs[2])
        links.new(mix.outputs[0], out.inputs["Surface"])
    else:
        links.new(clear.outputs[0], out.inputs["Surface"])
    return mat


def _box(name, half, z_bottom, z_top, material):
    """A box of half-width `half` between `z_bottom` and `z_top`, shifted by half/2 along x so that
    no triangle edge passes under the origin: Cycles lets light through a volume's boundary at the
    shared edge of its triangles (a camera looking down at the centre of a centred box measured
    a 2.5-fold pixel value along the top face's diagonal, +0.002 on the mean)."""
    ys, xs, zs = (-half, half), (-half / 2, 1.5 * half), (z_bottom, z_top)
    verts = [(x, y, z) for z in zs for y in ys for x in xs]
    faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.update()
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def volume_slab(scene=None):
    """The exact two-layer slab: its top face at z = 0, epidermis and dermis boxes of Principled
    Volume, and the scene's bounce limits raised to Cycles' maximum."""
    scene = scene or bpy.context.scene
    v = VALUES["volume"]
    d, gap, w = v["epidermis_thickness"], v["gap"], v["half_width"]
    epi = _box("skin_epidermis", w, -d, 0.0, volume_material("epidermis", "skin_epidermis", -d / 2))
    derm = _box("skin_dermis", w, -d - gap - v["dermis_thickness"], -d - gap,
                volume_material("dermis", "skin_dermis"))
    c = scene.cycles
    for name in ("max_bounces", "volume_bounces", "transmission_bounces",
                 "transparent_max_bounces", "diffuse_bounces", "glossy_bounces"):
        setattr(c, name, v["bounces"])
    return epi, derm


if __name__ == "__main__":
    subsurface_material()
"#;

/// The Python script (`blender`) or the plain values (`blender-json`) and their notes.
pub fn write(
    format: Format,
    skin: &SkinParams,
    rgb: &RgbProfile,
    surface: Surface,
    opts: &ExportOptions,
) -> Result<(String, Vec<String>), ExportError> {
    let fit = BlenderFit::fit(skin, rgb, surface, opts.volume_photons)?;
    let value = values(&fit, skin, surface, opts);
    let json_text = serde_json::to_string_pretty(&value).expect("a JSON value serialises");
    let text = match format {
        Format::Blender => SCRIPT.replace("@VALUES@", &json_text),
        _ => json_text,
    };
    let mut notes = vec![
        format!(
            "units: lengths in scene units of {} mm (set Scene ▸ Units ▸ Unit Scale 0.001 for mm): Subsurface Radius × Scale and the volume's thicknesses; Principled Volume Density = σt per scene unit; colour space: linear Rec.709, Blender's default scene-linear working space",
            opts.scene_unit_mm
        ),
        format!(
            "engine model: Blender {BLENDER_VERSION} Cycles Principled BSDF, Subsurface Weight 1, IOR {CALIBRATION_IOR}, Roughness {CALIBRATION_ROUGHNESS}, Specular IOR Level {CALIBRATION_SPECULAR_IOR_LEVEL}, Subsurface Anisotropy {CALIBRATION_ANISOTROPY} (the settings of the calibration table); the script builds it with subsurface_material(method) and the volumetric slab with volume_slab()"
        ),
        format!(
            "normalisation: per incident photon: Base Color is chosen so that Cycles' subsurface part (the pixel minus the specular face) equals our diffuse reflectance {} (skin spectrum's, D65 → linear Rec.709); Cycles' walk is not OpenPBR's medium, so Base Color comes from a table measured in Cycles (skin-export/data/cycles/, curve residual ≤ {:.5})",
            percent3(fit.target, 2),
            fit.principled[0]
                .calibration_residual
                .max(fit.principled[1].calibration_residual)
        ),
    ];
    for p in &fit.principled {
        notes.push(format!(
            "{}: Base Color {:.5}/{:.5}/{:.5}, Subsurface Radius × Scale {:.4}/{:.4}/{:.4} mm (from Cycles' source: the walk's medium traced by our Monte Carlo has our mean exit radius), shape error of that medium {}",
            p.method,
            p.base_color[0],
            p.base_color[1],
            p.base_color[2],
            p.radius_mm[0],
            p.radius_mm[1],
            p.radius_mm[2],
            percent3(p.shape_error, 1)
        ));
    }
    notes.push(format!(
        "volume_slab(): epidermis {} mm and dermis {} mm of Principled Volume (Color = σs/σt per channel, Density = one σt per layer, the skin's at 549.1 nm), glass face of IOR {}, a {} mm vacuum gap between the boxes; per-entering totals {} (exact in the RGB totals, as Mitsuba's rgb variant); a render is F(0) + our diffuse reflectance per incident photon",
        skin.epidermis_thickness_mm(),
        opts.dermis_thickness_mm,
        surface.eta,
        VOLUME_GAP_MM,
        percent3([0, 1, 2].map(|c| fit.volume[c].total), 2)
    ));
    Ok((text, notes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn remap_at_g_zero_matches_its_closed_coefficients() {
        // At g = 0 the fit's coefficients are their constant terms: A = 1.8260523782,
        // B = 4.98511194385 + 0.127355959438, D = 0.496310210422, E = 4.23190299701 + 0.00310603949088.
        let c: f64 = 0.5;
        let blend = c.powf(0.25);
        let want = (1.0 - blend)
            * 1.826_052_378_2
            * (5.112_467_903_288 * c).atan().powf(1.096_861_024_24)
            + blend * 0.496_310_210_422 * (4.235_009_036_500_88 * c).atan().powf(2.406_029_994_08);
        assert!((cycles_albedo_raw(c, 0.0) - want).abs() < 1e-12);
        // Monotone in c and floored at 0.2 where Cycles floors it.
        assert_eq!(cycles_albedo(1e-4, 0.0), CYCLES_MIN_ALPHA);
        assert!(cycles_albedo(0.3, 0.0) < cycles_albedo(0.6, 0.0));
    }

    #[test]
    fn skin_alpha_prime_inverts_the_dipole_to_its_bisection_width() {
        // 12 halvings of [0, 1]: within 2⁻¹² of the root.
        let ior: f64 = 1.4;
        let inv = 1.0 / ior;
        let f_dr = inv * (-1.440 * inv + 0.710) + 0.668 + 0.0636 * ior;
        let a = (4.0 / 3.0) * (1.0 + f_dr) / (1.0 - f_dr);
        for ap in [0.3_f64, 0.9, 0.99] {
            let s: f64 = (3.0 * (1.0 - ap)).sqrt();
            let rd = 0.5 * ap * (1.0 + (-a * s).exp()) * (-s).exp();
            assert!(
                (cycles_skin_alpha_prime(rd, ior) - ap).abs() < 2.5e-4,
                "{ap}"
            );
        }
    }

    #[test]
    fn a_curve_through_exact_points_is_recovered_and_inverted() {
        // Rows on a curve of the model's own form (s(c)(0.9 − 0.6u + 0.1u²)) with σ = 1e-3: the fit
        // returns the curve, and its inverse the Base Color.
        let curve = |c: f64| {
            let b = basis(c);
            0.9 * b[0] - 0.6 * b[1] + 0.1 * b[2]
        };
        let mut csv = String::from("method,base_color,subsurface_reflectance,stderr\n");
        for k in 0..24 {
            let c = 0.02 + 0.03 * f64::from(k);
            csv += &format!("RANDOM_WALK,{c},{},0.001\n", curve(c));
        }
        let cal = Calibration::from_csv(&csv, CyclesMethod::RandomWalk).unwrap();
        assert!((cal.reflectance(0.5) - curve(0.5)).abs() < 1e-9);
        assert!((cal.base_color(curve(0.5)).unwrap() - 0.5).abs() < 1e-8);
        assert!(cal.base_color(0.99).is_err());
        assert!(Calibration::from_csv("RANDOM_WALK,x,1,1\n", CyclesMethod::RandomWalk).is_err());
    }

    #[test]
    fn committed_table_is_reproduced_by_its_curve_within_its_noise() {
        // 24 rows per method: 16 fitted (6 coefficients, ν = 10) and 8 held out (ν = 8). Each χ² must
        // lie between the 0.1% and 99.9% quantiles of its distribution (χ²₁₀: 1.479, 29.588; χ²₈:
        // 0.857, 26.124): a curve that misses the table fails above, one that follows its noise (or
        // a table whose stated errors are too large) fails below.
        for method in CyclesMethod::ALL {
            let cal = Calibration::committed(method).unwrap();
            let (fit, n_fit) = cal.chi_squared(false);
            let (held, n_held) = cal.chi_squared(true);
            assert_eq!((n_fit, n_held), (16, 8), "{method}");
            assert!((1.479..=29.588).contains(&fit), "{method}: fitted χ² {fit}");
            assert!(
                (0.857..=26.124).contains(&held),
                "{method}: held-out χ² {held}"
            );
            // The inverse map returns each measured row's Base Color within 3.5σ of its noise,
            // carried through the curve's slope.
            for p in &cal.points {
                let c = cal.base_color(p.reflectance.clamp(
                    cal.reflectance(cal.base_color_range().0),
                    cal.reflectance(cal.base_color_range().1),
                ));
                let c = c.unwrap();
                let h = 1e-6;
                let slope = (cal.reflectance(c + h) - cal.reflectance(c - h)) / (2.0 * h);
                let z = (c - p.base_color) * slope / p.stderr;
                assert!(z.abs() < 3.5, "{method} c = {}: z = {z}", p.base_color);
            }
        }
    }
}
