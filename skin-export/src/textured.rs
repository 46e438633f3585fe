//! Exports of a skin whose chromophores vary over a texture (the maps of `skin maps`): the RGB
//! engine formats with texture images in place of their colours and radii (docs/physics.md §14.8).
//!
//! Every texel is fitted by the rules of the scalar export, through a table: the scalar fit
//! ([`VolumeFit`] for OpenPBR and Standard Surface, [`BurleyFit`] for Unreal and HDRP) runs at the
//! nodes of a grid over the box of (C_m, C_h, β_m) the texture uses, and each texel interpolates
//! the fitted colour and the logarithm of the fitted length (Catmull–Rom in each of the axes
//! u = ln(1 + C_m / c₀), v = ln C_h and β_m, [CR74]). The interpolation error is measured on every export
//! against the scalar fit run at texels off the nodes, and printed with it.
//!
//! - OpenPBR and Standard Surface read per-texel images: the subsurface colour, and the radius
//!   colour (mean free path per channel over the texture's largest, which is the scalar radius).
//! - Unreal's Subsurface Profile and HDRP's diffusion profile are one per material: the texture
//!   gets a per-texel base colour (Burley's albedo A) and one profile, the fit at the texels'
//!   median skin; the spread of the texels' own lengths about that profile is reported.

use crate::burley::BurleyFit;
use crate::volume::VolumeFit;
use crate::{
    ExportError, ExportOptions, Format, Surface, engines, header_note, materialise_notes,
    materialx, rgb_profile,
};
use rayon::prelude::*;
use skin_optics::SkinParams;

/// Knee c₀ of the melanin axis u = ln(1 + C_m / c₀): linear in C_m below it, logarithmic above.
const MELANIN_KNEE: f64 = 0.005;

/// Per-texel chromophores of a texture, row-major from the top row (the orientation of the
/// albedo texture they were fitted from, so they map onto a mesh as it does).
#[derive(Debug, Clone, PartialEq)]
pub struct ChromophoreTexture {
    /// Width, texels.
    pub width: usize,
    /// Height, texels.
    pub height: usize,
    /// Melanin fraction C_m per texel, [0, 1].
    pub melanin: Vec<f32>,
    /// Eumelanin blend β_m per texel, [0, 1].
    pub eumelanin: Vec<f32>,
    /// Hemoglobin fraction C_h per texel, (0, 1].
    pub hemoglobin: Vec<f32>,
    /// The texels under a thinner epidermis than the base skin's (`maps.exr`'s `thin_epidermis`
    /// channel), `None` when every texel has the base skin's.
    pub thin: Option<ThinTexels>,
}

/// Texels whose skin has a thinner epidermis than the base skin (the lip vermilion of
/// docs/physics.md §18, "Thin epidermis").
#[derive(Debug, Clone, PartialEq)]
pub struct ThinTexels {
    /// The thin epidermis' thickness, mm (within `SkinParams`' epidermis range).
    pub epidermis_mm: f64,
    /// Per texel, row-major from the top row: whether it has the thin epidermis.
    pub texels: Vec<bool>,
}

impl ChromophoreTexture {
    /// Check the sizes and that every value is finite and in its range; an error names the
    /// channel and the first bad texel.
    pub fn validate(&self) -> Result<(), ExportError> {
        let n = self.width * self.height;
        if n == 0 {
            return Err(texture_error(
                "size",
                format!("{}×{} texels", self.width, self.height),
            ));
        }
        for (name, values, lo_open) in [
            ("melanin", &self.melanin, false),
            ("eumelanin", &self.eumelanin, false),
            ("hemoglobin", &self.hemoglobin, true),
        ] {
            if values.len() != n {
                return Err(texture_error(
                    name,
                    format!(
                        "{} values for {}×{} texels",
                        values.len(),
                        self.width,
                        self.height
                    ),
                ));
            }
            let bad = |v: f32| !(0.0..=1.0).contains(&v) || (lo_open && v == 0.0);
            if let Some(k) = values.iter().position(|v| bad(*v)) {
                return Err(texture_error(
                    name,
                    format!(
                        "{} at texel ({}, {}) outside {}",
                        values[k],
                        k % self.width,
                        k / self.width,
                        if lo_open { "(0, 1]" } else { "[0, 1]" }
                    ),
                ));
            }
        }
        if let Some(thin) = &self.thin
            && thin.texels.len() != n
        {
            return Err(texture_error(
                "thin_epidermis",
                format!(
                    "{} flags for {}×{} texels",
                    thin.texels.len(),
                    self.width,
                    self.height
                ),
            ));
        }
        Ok(())
    }

    /// Whether texel `k` has the thin epidermis.
    fn is_thin(&self, k: usize) -> bool {
        self.thin.as_ref().is_some_and(|t| t.texels[k])
    }
}

fn texture_error(key: &'static str, message: String) -> ExportError {
    ExportError::Texture { key, message }
}

/// The knobs of a textured export.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TexturedOptions {
    /// Grid nodes along C_m and along C_h over the texture's range, [2, 33] (default 9; the
    /// β_m axis gets 3 where β_m varies, else 1).
    pub nodes: usize,
    /// Texels off the nodes where the interpolation is checked against the scalar fit, [0, 64]
    /// (default 8).
    pub checks: usize,
}

impl Default for TexturedOptions {
    fn default() -> Self {
        Self {
            nodes: 9,
            checks: 8,
        }
    }
}

/// One image of a textured export: linear RGB per texel in the texture's size and orientation.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportImage {
    /// The file name the material text refers to.
    pub file_name: &'static str,
    /// Values per texel, row-major from the top row, in the export's colour space.
    pub rgb: Vec<[f32; 3]>,
}

/// A textured export: the material text, the images it refers to, and its notes.
#[derive(Debug, Clone, PartialEq)]
pub struct TexturedExport {
    /// The format.
    pub format: Format,
    /// The material file's text (notes included as comments or a `notes` array).
    pub text: String,
    /// The images, written beside the material file.
    pub images: Vec<ExportImage>,
    /// One line each: units, conventions, the interpolation's measured error.
    pub notes: Vec<String>,
}

/// The fitted values of one skin: colour per channel and a length per channel, mm (the mean
/// free path for OpenPBR and Standard Surface, Burley's d for Unreal and HDRP).
type Fitted = ([f64; 3], [f64; 3]);

/// The scalar export's fit of `skin` for `format`.
fn fit_skin(
    format: Format,
    skin: &SkinParams,
    opts: &ExportOptions,
) -> Result<Fitted, ExportError> {
    match format {
        Format::OpenPbr | Format::StandardSurface => {
            let rgb = rgb_profile(
                skin,
                &ExportOptions {
                    colour_space: crate::ColourSpace::LinRec709,
                    ..*opts
                },
            )?;
            let fit = VolumeFit::fit(&rgb, multipole::DEFAULT_G, skin.eta(), opts.volume_photons)?;
            Ok((fit.colour, fit.mean_free_path_mm))
        }
        _ => {
            let fit = BurleyFit::fit(&rgb_profile(skin, opts)?)?;
            Ok((fit.albedo, fit.d_mm))
        }
    }
}

/// One axis of the grid: `n` nodes evenly over [lo, hi] in the axis coordinate.
#[derive(Debug, Clone, Copy)]
struct Axis {
    lo: f64,
    hi: f64,
    n: usize,
}

impl Axis {
    fn over(values: impl Iterator<Item = f64>, nodes: usize) -> Self {
        let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
        let n = if hi - lo > 1e-9 { nodes } else { 1 };
        Self { lo, hi, n }
    }

    fn node(&self, i: usize) -> f64 {
        if self.n == 1 {
            self.lo
        } else {
            self.lo + (self.hi - self.lo) * i as f64 / (self.n - 1) as f64
        }
    }

    /// The nodes around `x` and their weights: Catmull–Rom ([CR74]) on the four nodes around its
    /// cell, a ghost node beyond either end extrapolated linearly from the two nearest (so a
    /// straight line is reproduced exactly); two nodes interpolate linearly, one is constant.
    fn weights(&self, x: f64) -> [(usize, f64); 4] {
        let mut out = [(0, 0.0); 4];
        if self.n == 1 {
            out[0] = (0, 1.0);
            return out;
        }
        let s = ((x - self.lo) / (self.hi - self.lo)).clamp(0.0, 1.0) * (self.n - 1) as f64;
        let i = (s as usize).min(self.n - 2);
        let t = s - i as f64;
        if self.n == 2 {
            out[0] = (0, 1.0 - t);
            out[1] = (1, t);
            return out;
        }
        let (t2, t3) = (t * t, t * t * t);
        let w = [
            -0.5 * t + t2 - 0.5 * t3,
            1.0 - 2.5 * t2 + 1.5 * t3,
            0.5 * t + 2.0 * t2 - 1.5 * t3,
            -0.5 * t2 + 0.5 * t3,
        ];
        let last = self.n - 1;
        for (m, wm) in w.into_iter().enumerate() {
            let k = i as isize + m as isize - 1;
            // Ghosts: v(−1) = 2 v(0) − v(1), v(n) = 2 v(n−1) − v(n−2).
            let (a, b) = if k < 0 {
                ((0, 2.0 * wm), (1, -wm))
            } else if k as usize > last {
                ((last, 2.0 * wm), (last - 1, -wm))
            } else {
                ((k as usize, wm), (k as usize, 0.0))
            };
            for (node, weight) in [a, b] {
                if let Some(slot) = out.iter_mut().find(|(n, w)| *n == node && *w != 0.0) {
                    slot.1 += weight;
                } else if let Some(slot) = out.iter_mut().find(|(_, w)| *w == 0.0) {
                    *slot = (node, weight);
                }
            }
        }
        out
    }
}

fn u_of(c_m: f64) -> f64 {
    (c_m / MELANIN_KNEE).ln_1p()
}

fn melanin_of(u: f64) -> f64 {
    MELANIN_KNEE * u.exp_m1()
}

/// The fitted values on the grid and their trilinear interpolant.
struct Grid {
    axes: [Axis; 3],
    /// Per node (index `(b · n_v + j) · n_u + i`): colour and ln(length).
    nodes: Vec<([f64; 3], [f64; 3])>,
}

impl Grid {
    fn at(&self, u: f64, v: f64, b: f64) -> Fitted {
        let [au, av, ab] = self.axes;
        let (wu, wv, wb) = (au.weights(u), av.weights(v), ab.weights(b));
        let mut colour = [0.0; 3];
        let mut log_len = [0.0; 3];
        for (k, xb) in wb {
            for (j, xv) in wv {
                for (i, xu) in wu {
                    let w = xb * xv * xu;
                    if w == 0.0 {
                        continue;
                    }
                    let (c, l) = self.nodes[(k * av.n + j) * au.n + i];
                    for ch in 0..3 {
                        colour[ch] += w * c[ch];
                        log_len[ch] += w * l[ch];
                    }
                }
            }
        }
        (colour, log_len.map(f64::exp))
    }
}

/// The skin of `base` with the chromophores of one texel.
fn skin_at(base: &SkinParams, c_m: f64, beta: f64, c_h: f64) -> Result<SkinParams, ExportError> {
    Ok(base
        .with_melanin(c_m)?
        .with_eumelanin_blend(beta)?
        .with_hemoglobin(c_h)?)
}

/// Export `format` (OpenPBR, Standard Surface, Unreal or HDRP) for the skin `base` with the
/// chromophores of `texture`; `progress(done, total)` is called as the grid's fits finish.
pub fn export_textured(
    format: Format,
    base: &SkinParams,
    texture: &ChromophoreTexture,
    opts: &ExportOptions,
    topts: &TexturedOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<TexturedExport, ExportError> {
    let mut out = fitted_export(format, base, texture, opts, topts, progress)?;
    let mut notes = vec![header_note(base, format, opts).replacen(
        "C_m = ",
        "the texture's chromophores over a base skin of C_m = ",
        1,
    )];
    notes.append(&mut out.notes);
    notes.push(format!(
        "measured in the engine: {}",
        format.measured_in_engine()
    ));
    out.text = materialise_notes(format, &notes, &out.text);
    out.notes = notes;
    Ok(out)
}

/// The export with its own notes only (no header, not yet in the text).
fn fitted_export(
    format: Format,
    base: &SkinParams,
    texture: &ChromophoreTexture,
    opts: &ExportOptions,
    topts: &TexturedOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<TexturedExport, ExportError> {
    opts.validate()?;
    opts.check_format(format)?;
    if !matches!(
        format,
        Format::OpenPbr | Format::StandardSurface | Format::Unreal | Format::Hdrp
    ) {
        return Err(texture_error(
            "format",
            format!(
                "{format} takes no textures (valid with maps: openpbr, standard-surface, unreal, hdrp)"
            ),
        ));
    }
    if !(2..=33).contains(&topts.nodes) {
        return Err(ExportError::OutOfRange {
            name: "texture grid nodes",
            value: topts.nodes as f64,
            range: "[2, 33]",
        });
    }
    if topts.checks > 64 {
        return Err(ExportError::OutOfRange {
            name: "interpolation checks",
            value: topts.checks as f64,
            range: "[0, 64]",
        });
    }
    texture.validate()?;
    let n = texture.melanin.len();
    let coords = |k: usize| {
        (
            u_of(f64::from(texture.melanin[k])),
            f64::from(texture.hemoglobin[k]).ln(),
            f64::from(texture.eumelanin[k]),
        )
    };
    // One grid per epidermis: the texels under the thin one take their own base skin, so that
    // each texel is fitted as the scalar export fits its own skin.
    let thin_base = match &texture.thin {
        Some(t) if t.texels.iter().any(|&b| b) => Some(
            base.with_epidermis_thickness_mm(t.epidermis_mm)
                .map_err(|e| texture_error("thin_epidermis_mm", e.to_string()))?,
        ),
        _ => None,
    };
    let groups: Vec<(SkinParams, Vec<usize>)> =
        [(false, *base), (true, thin_base.unwrap_or(*base))]
            .into_iter()
            .filter(|(thin, _)| !thin || thin_base.is_some())
            .map(|(thin, skin)| {
                (
                    skin,
                    (0..n).filter(|&k| texture.is_thin(k) == thin).collect(),
                )
            })
            .filter(|(_, texels): &(SkinParams, Vec<usize>)| !texels.is_empty())
            .collect();
    let axes_of = |texels: &[usize]| {
        [
            Axis::over(texels.iter().map(|&k| coords(k).0), topts.nodes),
            Axis::over(texels.iter().map(|&k| coords(k).1), topts.nodes),
            Axis::over(texels.iter().map(|&k| coords(k).2), 3),
        ]
    };
    let all_axes: Vec<[Axis; 3]> = groups.iter().map(|(_, t)| axes_of(t)).collect();
    let total: usize = all_axes
        .iter()
        .map(|a| a.iter().map(|x| x.n).product::<usize>())
        .sum();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let mut fitted: Vec<Fitted> = vec![([0.0; 3], [0.0; 3]); n];
    let mut grids = Vec::with_capacity(groups.len());
    let mut check = (0, 0.0f64, 0.0f64);
    for ((skin, texels), axes) in groups.iter().zip(all_axes) {
        let cells = axes.iter().map(|a| a.n).product::<usize>();
        let nodes = (0..cells)
            .into_par_iter()
            .map(|idx| {
                let (i, j, k) = (
                    idx % axes[0].n,
                    (idx / axes[0].n) % axes[1].n,
                    idx / (axes[0].n * axes[1].n),
                );
                let node = skin_at(
                    skin,
                    melanin_of(axes[0].node(i)),
                    axes[2].node(k),
                    axes[1].node(j).exp(),
                )?;
                let (colour, length) = fit_skin(format, &node, opts)?;
                let d = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress(d, total);
                Ok((colour, length.map(f64::ln)))
            })
            .collect::<Result<Vec<_>, ExportError>>()?;
        let grid = Grid { axes, nodes };
        let values: Vec<Fitted> = texels
            .par_iter()
            .map(|&k| {
                let (u, v, b) = coords(k);
                grid.at(u, v, b)
            })
            .collect();
        for (&k, f) in texels.iter().zip(values) {
            fitted[k] = f;
        }
        let c = interpolation_error(format, skin, texture, texels, opts, topts.checks, &fitted)?;
        check = (check.0 + c.0, check.1.max(c.1), check.2.max(c.2));
        grids.push(grid);
    }
    let to_space = |v: [f64; 3]| opts.colour_space.from_rec709(v);
    let surface = Surface::of(base);
    let space = opts.colour_space.materialx_name();
    let describe = |axes: &[Axis; 3]| {
        format!(
            "{}×{}×{} grid over C_m {:.4}–{:.4}, C_h {:.4}–{:.4}, β_m {:.3}–{:.3}",
            axes[0].n,
            axes[1].n,
            axes[2].n,
            melanin_of(axes[0].lo),
            melanin_of(axes[0].hi),
            axes[1].lo.exp(),
            axes[1].hi.exp(),
            axes[2].lo,
            axes[2].hi,
        )
    };
    let grid_text = if thin_base.is_none() {
        describe(&grids[0].axes)
    } else {
        groups
            .iter()
            .zip(&grids)
            .map(|((skin, texels), grid)| {
                format!(
                    "{} for the {} texels under a {:.3} mm epidermis",
                    describe(&grid.axes),
                    texels.len(),
                    skin.epidermis_thickness_mm()
                )
            })
            .collect::<Vec<_>>()
            .join(" and a ")
    };
    let grid_note = format!(
        "texture: {}×{} texels from the chromophore maps, top row first (the albedo texture's orientation); each texel fitted by the scalar export's rules through a {grid_text} (Catmull–Rom in ln(1 + C_m/0.005), ln C_h, β_m; lengths through their logarithm); measured against the scalar fit at {} texels off the nodes: colour within {:.2} %, length within {:.2} % (largest over channels)",
        texture.width,
        texture.height,
        check.0,
        100.0 * check.1,
        100.0 * check.2,
    );
    match format {
        Format::OpenPbr | Format::StandardSurface => {
            let mfp_units: Vec<[f64; 3]> = fitted
                .iter()
                .map(|(_, l)| to_space(l.map(|x| x / opts.scene_unit_mm)))
                .collect();
            let radius = mfp_units.iter().flatten().copied().fold(0.0, f64::max);
            let colour_image = ExportImage {
                file_name: "subsurface_color.exr",
                rgb: fitted
                    .iter()
                    .map(|(c, _)| to_space(*c).map(|x| x as f32))
                    .collect(),
            };
            let radius_image = ExportImage {
                file_name: if format == Format::OpenPbr {
                    "subsurface_radius_scale.exr"
                } else {
                    "subsurface_radius.exr"
                },
                rgb: mfp_units
                    .iter()
                    .map(|l| l.map(|x| (x / radius) as f32))
                    .collect(),
            };
            let text = materialx::write_textured(
                format,
                surface,
                space,
                radius,
                colour_image.file_name,
                radius_image.file_name,
            );
            let notes = vec![
                format!(
                    "units: mean free path = radius {radius:.6} scene units of {} mm × the radius image per channel; colour space {space} for the colour and the radius images (the radius image holds mean free paths over their largest, so MaterialX's transform of a color3 returns the fitted lengths, as in the scalar file)",
                    opts.scene_unit_mm
                ),
                grid_note,
                "conventions: as the scalar export (docs/physics.md §14.4): per texel, subsurface colour = our total per unit flux entering, mean free path = 1/μt of the semi-infinite HG medium that returns it with our mean exit radius".to_string(),
            ];
            Ok(TexturedExport {
                format,
                text,
                images: vec![colour_image, radius_image],
                notes,
            })
        }
        _ => {
            // One profile per material: the fit at the median skin of the texels under the
            // material's own epidermis (or of all, when every texel is thin).
            let (mid_base, mid_texels) = &groups[0];
            let median = |v: &[f32]| {
                let mut s: Vec<f32> = mid_texels.iter().map(|&k| v[k]).collect();
                s.sort_by(f32::total_cmp);
                f64::from(s[s.len() / 2])
            };
            let mid = skin_at(
                mid_base,
                median(&texture.melanin),
                median(&texture.eumelanin),
                median(&texture.hemoglobin),
            )?;
            let profile = BurleyFit::fit(&rgb_profile(&mid, opts)?)?;
            let mut spread: Vec<f64> = fitted
                .iter()
                .flat_map(|(_, d)| (0..3).map(move |c| (d[c] / profile.d_mm[c] - 1.0).abs()))
                .collect();
            spread.sort_by(f64::total_cmp);
            let pct = |q: f64| 100.0 * spread[((spread.len() - 1) as f64 * q) as usize];
            let (text, mut notes) = engines::write(format, &profile, surface, opts);
            let base_image = ExportImage {
                file_name: "base_color.exr",
                rgb: fitted
                    .iter()
                    .map(|(a, _)| to_space(*a).map(|x| x as f32))
                    .collect(),
            };
            notes.push(grid_note);
            notes.push(format!(
                "texture: base_color.exr is Burley's albedo A per texel (linear {space}), the material's base colour; the profile is one per material, fitted at the texels' median skin (C_m {:.4}, β_m {:.3}, C_h {:.4}); the texels' own Burley d differs from it by {:.1} % median, {:.1} % p95, {:.1} % at most (over channels), the error of one profile for the texture",
                mid.melanin(),
                mid.eumelanin_blend(),
                mid.hemoglobin(),
                pct(0.5),
                pct(0.95),
                pct(1.0),
            ));
            Ok(TexturedExport {
                format,
                text,
                images: vec![base_image],
                notes,
            })
        }
    }
}

/// The interpolant against the scalar fit of `base` at `checks` texels spread over `texels`:
/// (texels checked, largest colour error, largest length error), relative.
fn interpolation_error(
    format: Format,
    base: &SkinParams,
    texture: &ChromophoreTexture,
    texels: &[usize],
    opts: &ExportOptions,
    checks: usize,
    fitted: &[Fitted],
) -> Result<(usize, f64, f64), ExportError> {
    let n = texels.len();
    let picks: Vec<usize> = (0..checks.min(n))
        .map(|i| texels[(i * 2 + 1) * n / (2 * checks.min(n))])
        .collect();
    let errors = picks
        .par_iter()
        .map(|&k| {
            let skin = skin_at(
                base,
                f64::from(texture.melanin[k]),
                f64::from(texture.eumelanin[k]),
                f64::from(texture.hemoglobin[k]),
            )?;
            let (c, l) = fit_skin(format, &skin, opts)?;
            let (ci, li) = fitted[k];
            let rel = |a: f64, b: f64| (a / b - 1.0).abs();
            Ok((
                (0..3).map(|ch| rel(ci[ch], c[ch])).fold(0.0, f64::max),
                (0..3).map(|ch| rel(li[ch], l[ch])).fold(0.0, f64::max),
            ))
        })
        .collect::<Result<Vec<_>, ExportError>>()?;
    let worst = errors
        .iter()
        .fold((0.0f64, 0.0f64), |(a, b), (c, l)| (a.max(*c), b.max(*l)));
    Ok((picks.len(), worst.0, worst.1))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quick() -> ExportOptions {
        ExportOptions {
            escapes: 500,
            volume_photons: 2000,
            ..ExportOptions::default()
        }
    }

    fn texture(width: usize, height: usize, f: impl Fn(usize) -> [f32; 3]) -> ChromophoreTexture {
        let v: Vec<[f32; 3]> = (0..width * height).map(f).collect();
        ChromophoreTexture {
            width,
            height,
            melanin: v.iter().map(|t| t[0]).collect(),
            eumelanin: v.iter().map(|t| t[1]).collect(),
            hemoglobin: v.iter().map(|t| t[2]).collect(),
            thin: None,
        }
    }

    /// Catmull–Rom with linear ghosts: weights sum to 1, a straight line is reproduced at every
    /// x (ghosts included), a parabola exactly in the inner cells, and nodes are hit exactly.
    #[test]
    fn axis_weights_reproduce_lines_everywhere_and_parabolas_inside() {
        let axis = Axis {
            lo: -1.0,
            hi: 3.0,
            n: 5,
        };
        let eval = |f: &dyn Fn(f64) -> f64, x: f64| -> f64 {
            axis.weights(x)
                .iter()
                .map(|(i, w)| w * f(axis.node(*i)))
                .sum()
        };
        for k in 0..=40 {
            let x = -1.0 + 0.1 * f64::from(k);
            let sum: f64 = axis.weights(x).iter().map(|(_, w)| w).sum();
            assert!((sum - 1.0).abs() < 1e-12, "{x}: {sum}");
            let line = |y: f64| 2.0 - 0.7 * y;
            assert!((eval(&line, x) - line(x)).abs() < 1e-12, "{x}");
            let parabola = |y: f64| y * y - y;
            if (0.0..=2.0).contains(&x) {
                assert!((eval(&parabola, x) - parabola(x)).abs() < 1e-12, "{x}");
            }
        }
        for i in 0..5 {
            let x = axis.node(i);
            let w = axis.weights(x);
            let at: f64 = w.iter().filter(|(n, _)| *n == i).map(|(_, w)| w).sum();
            assert!((at - 1.0).abs() < 1e-12, "node {i}: {w:?}");
        }
    }

    /// A texture of one skin is that skin's scalar export: every texel holds the scalar file's
    /// colour and radius colour, and the radius is its radius (the same fit at the one node, whose
    /// C_m and C_h pass through the axes' logarithms: equal to 1e-6).
    #[test]
    fn a_uniform_texture_is_the_scalar_export() {
        let opts = quick();
        let base = SkinParams::default();
        let tex = texture(3, 2, |_| [0.05, 0.6, 0.02]);
        let topts = TexturedOptions {
            nodes: 4,
            checks: 1,
        };
        let out = export_textured(Format::OpenPbr, &base, &tex, &opts, &topts, &|_, _| {}).unwrap();
        let f = |x: f32| f64::from(x);
        let skin = skin_at(&base, f(0.05), f(0.6), f(0.02)).unwrap();
        let (colour, mfp) = fit_skin(Format::OpenPbr, &skin, &opts).unwrap();
        let radius = mfp.iter().copied().fold(0.0, f64::max);
        let scalar = crate::export(&skin, Format::OpenPbr, &opts).unwrap().text;
        assert!(
            scalar.contains(&format!(
                r#""subsurface_radius" type="float" value="{radius:.6}""#
            )),
            "{scalar}"
        );
        assert!(
            out.text.contains(&format!(
                r#""subsurface_radius" type="float" value="{radius:.6}""#
            )),
            "{}",
            out.text
        );
        let space = crate::ColourSpace::LinRec709;
        let close =
            |a: [f32; 3], b: [f64; 3]| (0..3).all(|c| (f64::from(a[c]) / b[c] - 1.0).abs() < 1e-6);
        for t in &out.images[0].rgb {
            assert!(close(*t, space.from_rec709(colour)), "{t:?} {colour:?}");
        }
        let scale = space.from_rec709(mfp).map(|l| l / radius);
        for t in &out.images[1].rgb {
            assert!(close(*t, scale), "{t:?} {scale:?}");
        }
        assert!(
            out.notes.iter().any(|n| n.contains("1×1×1 grid")),
            "{:?}",
            out.notes
        );
    }

    /// Over C_m 0.01–0.3 and C_h 0.005–0.08 on a 5 × 5 grid, the interpolated colour stays within
    /// 0.5 % of the scalar fit at texels off the nodes (measured 0.17 % on the head's 9 × 9 grid
    /// over a wider box), and the lengths within the Monte Carlo noise of the shapes they come
    /// from (mean radius from 500 escapes per shape: a few percent).
    #[test]
    fn interpolation_follows_the_scalar_fit_between_nodes() {
        let opts = quick();
        let tex = texture(8, 8, |k| {
            let (x, y) = ((k % 8) as f32 / 7.0, (k / 8) as f32 / 7.0);
            [0.01 * 30f32.powf(x), 0.6, 0.005 * 16f32.powf(y)]
        });
        let topts = TexturedOptions {
            nodes: 5,
            checks: 4,
        };
        let out = fitted_export(
            Format::Unreal,
            &SkinParams::default(),
            &tex,
            &opts,
            &topts,
            &|_, _| {},
        )
        .unwrap();
        let note = out
            .notes
            .iter()
            .find(|n| n.contains("measured against the scalar fit"))
            .unwrap();
        let number = |after: &str| -> f64 {
            let rest = &note[note.find(after).unwrap() + after.len()..];
            rest.split_whitespace().next().unwrap().parse().unwrap()
        };
        let (colour, length) = (number("colour within "), number("length within "));
        assert!(colour > 0.0 && colour < 0.5, "{note}");
        assert!(length < 8.0, "{note}");
        assert_eq!(out.images[0].rgb.len(), 64);
    }

    /// Texels flagged thin are fitted under their own epidermis: with one skin per group (a
    /// one-node grid each, exact to 1e-6), the thin texel holds the scalar fit of the skin under
    /// the thin epidermis and the other texel that under the base skin's, which differ by more
    /// than 1 % (less melanin in the light's way).
    #[test]
    fn thin_texels_take_the_fit_of_their_own_epidermis() {
        let opts = quick();
        let base = SkinParams::default();
        let mut tex = texture(2, 1, |_| [0.1, 0.6, 0.05]);
        tex.thin = Some(ThinTexels {
            epidermis_mm: 0.06,
            texels: vec![true, false],
        });
        let topts = TexturedOptions {
            nodes: 4,
            checks: 1,
        };
        let out = fitted_export(Format::OpenPbr, &base, &tex, &opts, &topts, &|_, _| {}).unwrap();
        let skin = skin_at(&base, 0.1, 0.6, 0.05).unwrap();
        let thin_skin = skin.with_epidermis_thickness_mm(0.06).unwrap();
        let (thick, _) = fit_skin(Format::OpenPbr, &skin, &opts).unwrap();
        let (thin, _) = fit_skin(Format::OpenPbr, &thin_skin, &opts).unwrap();
        let close =
            |a: [f32; 3], b: [f64; 3]| (0..3).all(|c| (f64::from(a[c]) / b[c] - 1.0).abs() < 1e-6);
        let rgb = &out.images[0].rgb;
        assert!(close(rgb[0], thin), "{:?} {thin:?}", rgb[0]);
        assert!(close(rgb[1], thick), "{:?} {thick:?}", rgb[1]);
        assert!((0..3).any(|c| (thin[c] / thick[c] - 1.0).abs() > 0.01));
        let note = out.notes.iter().find(|n| n.contains("grid over")).unwrap();
        assert!(
            note.contains("for the 1 texels under a 0.060 mm epidermis"),
            "{note}"
        );
    }

    #[test]
    fn bad_textures_and_options_name_the_key() {
        let base = SkinParams::default();
        let opts = quick();
        let good = texture(2, 2, |_| [0.05, 0.6, 0.02]);
        let run = |format, tex: &ChromophoreTexture, nodes| {
            export_textured(
                format,
                &base,
                tex,
                &opts,
                &TexturedOptions { nodes, checks: 0 },
                &|_, _| {},
            )
            .unwrap_err()
            .to_string()
        };
        let mut nan = good.clone();
        nan.melanin[3] = f32::NAN;
        assert!(run(Format::OpenPbr, &nan, 4).starts_with("melanin: NaN at texel (1, 1)"));
        let mut zero = good.clone();
        zero.hemoglobin[0] = 0.0;
        assert!(
            run(Format::Hdrp, &zero, 4).contains("hemoglobin: 0 at texel (0, 0) outside (0, 1]")
        );
        let mut short = good.clone();
        short.eumelanin.pop();
        assert!(run(Format::OpenPbr, &short, 4).starts_with("eumelanin: 3 values for 2×2"));
        assert!(run(Format::Pbrt, &good, 4).contains("takes no textures"));
        assert!(run(Format::OpenPbr, &good, 1).contains("texture grid nodes = 1 outside [2, 33]"));
        let mut flags = good.clone();
        flags.thin = Some(ThinTexels {
            epidermis_mm: 0.05,
            texels: vec![true],
        });
        assert!(run(Format::OpenPbr, &flags, 4).starts_with("thin_epidermis: 1 flags for 2×2"));
        let mut thick = good.clone();
        thick.thin = Some(ThinTexels {
            epidermis_mm: 50.0,
            texels: vec![true, false, false, false],
        });
        let e = run(Format::OpenPbr, &thick, 4);
        assert!(e.starts_with("thin_epidermis_mm: "), "{e}");
    }
}
