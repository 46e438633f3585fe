//! What was chosen for each skin material and why (`skin render --explain`), and the one warning
//! for diffusion inside its known failure region (docs/physics.md §9, §16).

use super::photons::PhotonChoice;
use super::{Fidelity, Lod, WavelengthChoice};
use crate::media::SkinMedia;
use multipole::Method;
use multipole::skin::DIFFUSION_OK;
use skin_io::cache::CacheOutcome;
use skin_optics::{SkinParams, Wavelength};
use std::fmt::Write;

/// How a skin's body is shaded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TransportChoice {
    /// The separable BSSRDF, and the volumetric walk at thin parts where the pixel footprint is
    /// below `walk_below_mm` (`crate::volumetric::thin`); `transport_mfp_mm` is the dermis'
    /// largest transport mean free path 1/(σa + σs') over 380–780 nm, for scale.
    Bssrdf {
        /// Largest transport mean free path, mm.
        transport_mfp_mm: f64,
        /// Pixel footprint below which a thin part takes the walk, mm (`None`: never).
        walk_below_mm: Option<f32>,
    },
    /// The Lambertian stand-in (`--no-subsurface`).
    Lambertian,
}

impl TransportChoice {
    /// The pixel footprint below which a thin part takes the walk, mm, if it ever does.
    #[must_use]
    pub fn walk_below_mm(&self) -> Option<f32> {
        match self {
            TransportChoice::Bssrdf { walk_below_mm, .. } => *walk_below_mm,
            TransportChoice::Lambertian => None,
        }
    }

    /// The BSSRDF with the dermis' largest transport mean free path of the material's layers
    /// `media`, and the walk below `walk_below_mm`.
    #[must_use]
    pub fn bssrdf(media: &SkinMedia, walk_below_mm: Option<f32>) -> Self {
        Self::Bssrdf {
            transport_mfp_mm: media.largest_transport_mfp_mm,
            walk_below_mm,
        }
    }
}

/// Where diffusion is wrong for one skin: wavelengths and layers.
#[derive(Debug, Clone, PartialEq)]
pub struct DiffusionFailures {
    /// Wavelengths (every 10 nm) where |multipole / exact − 1| ≥ `DIFFUSION_OK`, nm.
    pub wavelengths_nm: Vec<f64>,
    /// The worst relative error there.
    pub worst: f64,
    /// Layers whose own diffusion totals are off by ≥ `DIFFUSION_OK` at one of them.
    pub layers: Vec<&'static str>,
}

/// Where multipole diffusion misses the exact (adding-doubling) total of the skin `params`, whose
/// layers at the material's g are `media`, under the same Fresnel faces, by 2% or more, every 10 nm over 380–780 nm, and which
/// layers' own totals are off there (`multipole::skin::layer_scales`); `None` where it is accurate
/// everywhere.
#[must_use]
pub fn diffusion_failures(params: &SkinParams, media: &SkinMedia) -> Option<DiffusionFailures> {
    let mut out = DiffusionFailures {
        wavelengths_nm: Vec::new(),
        worst: 0.0,
        layers: Vec::new(),
    };
    for (nm, medium) in media.every_10nm() {
        let Ok(l) = Wavelength::new(nm) else { continue };
        // Diffusion's boundary is Fresnel's (the paper's A): its transport error is measured
        // against exact transport under that same face, whatever surface the material renders.
        let fresnel = medium.clone().with_surface(multipole::Surface::Fresnel);
        let (Ok(m), Ok(e)) = (
            multipole::skin::medium_total_reflectance(medium, Method::Multipole),
            multipole::skin::medium_total_reflectance(&fresnel, Method::Exact),
        ) else {
            continue;
        };
        let err = m / e - 1.0;
        if err.abs() < DIFFUSION_OK {
            continue;
        }
        out.wavelengths_nm.push(nm);
        if err.abs() > out.worst.abs() {
            out.worst = err;
        }
        if let Ok((scales, _)) = multipole::skin::layer_scales(params, l) {
            let off = |x: f64| (x - 1.0).abs() >= DIFFUSION_OK;
            for (name, s) in ["epidermis", "dermis"].into_iter().zip(&scales) {
                if [s.r_down, s.t_down, s.r_up, s.t_up].into_iter().any(off)
                    && !out.layers.contains(&name)
                {
                    out.layers.push(name);
                }
            }
        }
    }
    (!out.wavelengths_nm.is_empty()).then_some(out)
}

/// Wavelengths on a 10-nm grid as ranges: "380–450, 600 nm".
#[must_use]
pub fn ranges_nm(nms: &[f64]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut i = 0;
    while i < nms.len() {
        let mut j = i;
        while j + 1 < nms.len() && (nms[j + 1] - nms[j] - 10.0).abs() < 1e-9 {
            j += 1;
        }
        parts.push(if j > i {
            format!("{}–{}", nms[i], nms[j])
        } else {
            format!("{}", nms[i])
        });
        i = j + 1;
    }
    format!("{} nm", parts.join(", "))
}

/// What was chosen for one skin material.
#[derive(Debug, Clone, PartialEq)]
pub struct SkinChoices {
    /// The fidelity asked for.
    pub fidelity: Fidelity,
    /// The reflectance method.
    pub method: Method,
    /// The table's wavelengths.
    pub wavelengths: WavelengthChoice,
    /// Energy tolerance of the row ends (`None`: the profiles' own 99.9%).
    pub energy_tolerance: Option<f64>,
    /// Outer radius of the table, mm.
    pub r_out_mm: f32,
    /// Largest 99% energy radius over the rows, mm.
    pub r99_mm: f32,
    /// Radii of the table.
    pub radii: usize,
    /// Where the profile shapes come from.
    pub shape: String,
    /// How the shapes' photon count was chosen.
    pub photons: PhotonChoice,
    /// The level of detail, if on.
    pub lod: Option<Lod>,
    /// BSSRDF or the stand-in.
    pub transport: TransportChoice,
    /// What the disk cache did.
    pub cache: CacheOutcome,
    /// Time to build or read the tables, ms.
    pub build_ms: f64,
    /// With `--method multipole`: where diffusion is wrong.
    pub diffusion_failures: Option<DiffusionFailures>,
    /// With chromophore maps: their size and the profile grid (`None`: a uniform skin).
    pub maps: Option<MapChoice>,
}

/// The chromophore maps of a skin and the profile grid built over them (docs/physics.md §19).
#[derive(Debug, Clone, PartialEq)]
pub struct MapChoice {
    /// Width × height of the maps, texels.
    pub texels: (usize, usize),
    /// [lo, hi] of C_m, β_m and C_h over the texels.
    pub range: [[f32; 2]; 3],
    /// Nodes of the profile grid per axis (C_m, β_m, C_h).
    pub nodes: [usize; 3],
    /// The grid's measured interpolation error (relative L1 of 2πr R(r), worst wavelength).
    pub max_error: f32,
    /// Its target.
    pub target: f32,
    /// The rule combining the profiles of a path's two ends.
    pub blend: String,
    /// Where texels have a thin epidermis: its thickness (mm), the nodes of its profile grid per
    /// axis and that grid's measured interpolation error.
    pub thin: Option<(f32, [usize; 3], f32)>,
    /// The incidence gain's grids (the material's, then the thin epidermis') and their target.
    pub incidence: Option<(Vec<GridChoice>, f32)>,
}

/// A parameter grid as chosen: its nodes per axis (C_m, β_m, C_h) and its measured error.
pub type GridChoice = ([usize; 3], f32);

/// Why the shapes have their photon count, in words.
fn photon_reason(p: &PhotonChoice) -> String {
    match p {
        PhotonChoice::Fixed => {
            "fixed (full fidelity, diffusion, or no pixel footprint known)".into()
        }
        PhotonChoice::Override => "set by --shape-photons / fidelity.shape_photons".into(),
        PhotonChoice::Footprint {
            footprint_mm,
            visible_share,
            tolerance,
            measured,
        } => format!(
            "from the smallest pixel footprint, {footprint_mm:.3} mm: {:.1}% of the energy \
             leaves beyond half of it, so a {:.1}% shape error is invisible; measured {:.2}%",
            100.0 * visible_share,
            100.0 * tolerance,
            100.0 * measured
        ),
    }
}

/// The `--explain` table: one block per skin material (`name`, its choices).
#[must_use]
pub fn explain_table(skins: &[(&str, &SkinChoices)]) -> String {
    let mut s = String::new();
    for (name, c) in skins {
        let w = &c.wavelengths;
        let de = match (w.delta_e, w.luminance_error) {
            (Some(d), Some(y)) => format!("ΔE2000 {d:.2}, luminance {:.3}% vs 1 nm", 100.0 * y),
            _ => "fixed step".to_string(),
        };
        let extent = match c.energy_tolerance {
            Some(t) => format!("rows end where {:.2}% of the energy is left", 100.0 * t),
            None => "each profile's own 99.9% radius".into(),
        };
        let lod = match &c.lod {
            Some(l) => {
                let (a, b) = l.band_mm();
                format!(
                    "BSSRDF below a {a:.2} mm pixel footprint, diffuse above {b:.2} mm \
                     ({}–{} × the luminance r99 {:.2} mm), blended between",
                    l.band.full_below, l.band.diffuse_above, l.r99_mm
                )
            }
            None => "off (BSSRDF at every hit)".into(),
        };
        let transport = match c.transport {
            TransportChoice::Bssrdf {
                transport_mfp_mm,
                walk_below_mm: Some(t),
            } => format!(
                "BSSRDF; the volumetric walk where the BSSRDF would omit ≥ {:.0}% of the light, from \
                 the slab's exact transmission at the thickness along the inward normal and both \
                 faces' direct light, at pixel footprints below {t:.2} mm ({:.1} × r99; dermis \
                 transport mean free path {transport_mfp_mm:.3} mm); share of hits walked printed \
                 after the render",
                100.0 * super::THIN_OMISSION_SHARE,
                t / c.r99_mm.max(f32::MIN_POSITIVE)
            ),
            TransportChoice::Bssrdf {
                transport_mfp_mm,
                walk_below_mm: None,
            } => format!(
                "BSSRDF everywhere (thin-part walk off; dermis transport mean free path \
                 {transport_mfp_mm:.3} mm)"
            ),
            TransportChoice::Lambertian => "Lambertian stand-in (--no-subsurface)".into(),
        };
        let _ = writeln!(
            s,
            "skin material '{name}' (fidelity {}, method {}):",
            c.fidelity, c.method
        );
        let rows = [
            (
                "wavelengths",
                format!("{} rows every {} nm, 380–780 nm ({de})", w.nodes, w.step_nm),
            ),
            (
                "profile extent",
                format!("{:.2} mm (r99 {:.2} mm); {extent}", c.r_out_mm, c.r99_mm),
            ),
            (
                "table size",
                format!(
                    "{} radii × {} rows ({:.0} KiB)",
                    c.radii,
                    w.nodes,
                    (c.radii * w.nodes * 8) as f64 / 1024.0
                ),
            ),
            ("shapes", c.shape.clone()),
            ("shape photons", photon_reason(&c.photons)),
            ("level of detail", lod),
            ("transport", transport),
            (
                "cache",
                format!("{} ({:.0} ms to get the tables)", c.cache, c.build_ms),
            ),
        ];
        for (k, v) in rows {
            let _ = writeln!(s, "  {k:<16} {v}");
        }
        if let Some(m) = &c.maps {
            let [cm, bm, ch] = m.range;
            let _ = writeln!(
                s,
                "  {:<16} {}×{} texels, C_m {:.3}–{:.3}, β_m {:.3}–{:.3}, C_h {:.4}–{:.4}; profile grid {}×{}×{} tables, interpolation error {:.2}% (target {:.2}%); ends combined: {}",
                "maps",
                m.texels.0,
                m.texels.1,
                cm[0],
                cm[1],
                bm[0],
                bm[1],
                ch[0],
                ch[1],
                m.nodes[0],
                m.nodes[1],
                m.nodes[2],
                100.0 * m.max_error,
                100.0 * m.target,
                m.blend
            );
            if let Some((mm, nodes, error)) = m.thin {
                let _ = writeln!(
                    s,
                    "  {:<16} {mm} mm under the flagged texels; profile grid {}×{}×{} tables, interpolation error {:.2}%",
                    "thin epidermis",
                    nodes[0],
                    nodes[1],
                    nodes[2],
                    100.0 * error,
                );
            }
            if let Some((grids, target)) = &m.incidence {
                let grids: Vec<String> = grids
                    .iter()
                    .map(|(n, e)| {
                        format!("{}×{}×{} nodes, error {:.2}%", n[0], n[1], n[2], 100.0 * e)
                    })
                    .collect();
                let _ = writeln!(
                    s,
                    "  {:<16} oblique-incidence gain per texel: {} (target {:.2}%)",
                    "incidence",
                    grids.join("; thin epidermis "),
                    100.0 * target,
                );
            }
        }
        if let Some(f) = &c.diffusion_failures {
            let _ = writeln!(
                s,
                "  {:<16} diffusion off by ≥ {:.0}% at {} (worst {:+.0}%; layers: {})",
                "warning",
                100.0 * DIFFUSION_OK,
                ranges_nm(&f.wavelengths_nm),
                100.0 * f.worst,
                f.layers.join(", ")
            );
        }
    }
    s
}

/// The one warning to show after a scene loads when `--method multipole` is inside diffusion's
/// failure region for some skin: the materials, wavelengths and layers (`None`: no such skin).
#[must_use]
pub fn diffusion_warning(skins: &[(&str, &SkinChoices)]) -> Option<String> {
    let failing: Vec<String> = skins
        .iter()
        .filter_map(|(name, c)| {
            c.diffusion_failures.as_ref().map(|f| {
                format!(
                    "'{name}' at {} ({}; worst {:+.0}%)",
                    ranges_nm(&f.wavelengths_nm),
                    f.layers.join(", "),
                    100.0 * f.worst
                )
            })
        })
        .collect();
    (!failing.is_empty()).then(|| {
        format!(
            "warning: --method multipole misses the exact total by ≥ {:.0}% for skin {}: \
             diffusion fails there (BENCHMARKS.md, stability map); --method exact is right",
            100.0 * DIFFUSION_OK,
            failing.join("; ")
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use skin_optics::Preset;

    /// The dark preset is the stability map's failure case (diffusion +233% at 400 nm,
    /// BENCHMARKS.md): it is flagged with its blue wavelengths; ranges print compactly.
    #[test]
    fn diffusion_failures_name_wavelengths_and_layers() {
        let dark = SkinParams::preset(Preset::Dark);
        let media = SkinMedia::new(&dark, multipole::DEFAULT_G).unwrap();
        let f = diffusion_failures(&dark, &media).expect("dark fails");
        assert!(f.wavelengths_nm.contains(&400.0), "{f:?}");
        assert!(f.worst > 0.5 && !f.layers.is_empty(), "{f:?}");
        assert_eq!(ranges_nm(&[380.0, 390.0, 400.0, 600.0]), "380–400, 600 nm");
    }
}
