//! A Mitsuba 3 scene ([Mitsuba3]): the two-layer skin as volumes for `volpath`: a dielectric block
//! (air over index η) filled with the epidermis medium, holding an index-matched (`null`) block of
//! dermis medium below the epidermis' thickness; media `homogeneous` with an HG phase function
//! (docs/physics.md §14.5).
//!
//! Three variant families read three forms of the media:
//! - **spectral** (`scalar_spectral`, `llvm_ad_spectral`): inline `<spectrum>` of `albedo` and
//!   `sigma_t` over 360–830 nm, the range those variants sample (a spectrum that stops short reads
//!   as 0 beyond its ends, and σt = 0 makes every path NaN);
//! - **rgb** (`scalar_rgb`, `llvm_ad_rgb`): `<rgb>` albedo per channel and one σt per layer, carried
//!   by the medium's `scale` with `sigma_t` = 1 (RGB variants clamp a colour to [0, 1]); each
//!   channel's albedos come from the skin's σa at a representative wavelength times one factor
//!   solved so that the two layers return our RGB total of that channel ([`channel_layers`]);
//! - **mono** (`llvm_ad_mono`): `<float>` values at one wavelength.
//!
//! The spectral variants carry four wavelengths per path and sample distances at one of them:
//! `volpath` then weights the others by ratios of transmittances whose variance grows without bound
//! over the hundreds of events of a path in skin; `volpathmis` (spectral MIS) does not, so the
//! spectral scene uses it. `volpath`'s default Russian roulette (from depth 5, survival by
//! throughput) kills paths that an albedo of 0.999 keeps for thousands of events, and the renders
//! converge to values a few % low in the red (BENCHMARKS.md, Engines); [`RR_DEPTH`] moves it past
//! them.

use crate::error::{ExportError, check};
use crate::spectral::{LayerOptics, SpectralSkin, to_stack};
use crate::volume::solve_decreasing;
use crate::{ExportOptions, Surface};
use multipole::exact::adding_doubling::{AddingDoublingOptions, solve};
use multipole::{DEFAULT_G, LayeredMedium, MultipoleError};
use skin_optics::color::reflectance_to_xyz;
use skin_optics::{GridSpectrum, SkinParams, Wavelength, WavelengthGrid};
use std::fmt;
use std::fmt::Write;
use std::str::FromStr;

/// Lateral half-width of the skin block, mm (far beyond any profile's 99.9% radius).
pub const HALF_WIDTH_MM: f64 = 100.0;
/// The wavelengths Mitsuba's spectral variants sample, nm.
pub const SPECTRAL_RANGE_NM: (f64, f64) = (360.0, 830.0);
/// Depth from which `volpath` plays Russian roulette.
pub const RR_DEPTH: u32 = 100_000;
/// Wavelengths whose layers stand for the R, G and B channels, nm: about the dominant wavelengths of
/// the Rec.709 primaries seen from D65 on the CIE 1931 locus ([CIE]); the dermis' σa is solved
/// afterwards, so they only pick the ratio of the two layers' absorption.
pub const CHANNEL_NM: [f64; 3] = [611.3, 549.1, 464.3];
/// Film of the complete scene, pixels per side.
pub const SCENE_FILM_PX: u32 = 16;
/// Samples per pixel of the complete scene.
pub const SCENE_SPP: u32 = 256;

/// The Mitsuba 3 variant family a scene is written for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Variant {
    /// `*_spectral`: spectra over 360–830 nm.
    #[default]
    Spectral,
    /// `*_rgb`: linear Rec.709 triples, σt scaled into [0, 1].
    Rgb,
    /// `*_mono`: one wavelength.
    Mono,
}

impl Variant {
    /// Every variant family.
    pub const ALL: [Variant; 3] = [Variant::Spectral, Variant::Rgb, Variant::Mono];

    /// The command-line name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Variant::Spectral => "spectral",
            Variant::Rgb => "rgb",
            Variant::Mono => "mono",
        }
    }
}

impl fmt::Display for Variant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Variant {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let key = s.trim().to_ascii_lowercase();
        Variant::ALL
            .into_iter()
            .find(|v| v.name() == key)
            .ok_or_else(|| format!("unknown Mitsuba variant '{s}' (valid: spectral, rgb, mono)"))
    }
}

/// The grid the spectral variant is written on: from 360 nm at `step_nm` to the first point at or
/// past 830 nm.
pub fn spectral_grid(step_nm: f64) -> Result<WavelengthGrid, ExportError> {
    let (from, to) = SPECTRAL_RANGE_NM;
    let step = check(
        "wavelength step (nm)",
        step_nm,
        0.01,
        470.0,
        "[0.01, 470] nm",
    )?;
    let last = from + ((to - from) / step - 1e-9).ceil() * step;
    Ok(WavelengthGrid::new(from, last, step)?)
}

/// Total reflectance per unit flux entering of `layers` under air, by adding-doubling.
fn two_layer_total(layers: &[LayerOptics]) -> Result<f64, ExportError> {
    let stack: LayeredMedium = to_stack(layers, 1.0, 1.0)?;
    let t = solve(&stack, &AddingDoublingOptions::default()).map_err(MultipoleError::from)?;
    Ok(t.diffuse_reflectance / (1.0 - t.specular_reflectance))
}

/// One RGB channel's medium: the layers and the total (per entering flux) they return.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelLayers {
    /// Wavelength whose layers were taken, nm.
    pub lambda_nm: f64,
    /// Epidermis, then dermis.
    pub layers: Vec<LayerOptics>,
    /// The factor k on both layers' σa at `lambda_nm`.
    pub absorption_factor: f64,
    /// Our RGB total of the channel (per unit flux entering), the target.
    pub target: f64,
    /// The two layers' adding-doubling total.
    pub total: f64,
}

/// Our RGB totals (linear Rec.709, per unit flux entering) of the rows' total spectrum on `grid`.
pub fn rgb_totals(spectral: &SpectralSkin, grid: &WavelengthGrid) -> Result<[f64; 3], ExportError> {
    let totals = spectral.rows.iter().map(|r| r.total).collect();
    Ok(reflectance_to_xyz(&GridSpectrum::new(*grid, totals)?)
        .to_linear_srgb()
        .0)
}

/// Per channel, the skin's layers with one extinction σt per layer for all channels (the skin's at
/// the green wavelength) and per-channel albedos: both layers' σa at the channel's [`CHANNEL_NM`]
/// times one factor k, solved (bisection on the adding-doubling total) so that the two layers
/// return `targets` (per unit flux entering). A grey σt keeps Mitsuba's RGB `volpath` from
/// weighting the other channels by ratios of transmittances, whose variance grows without bound
/// over the hundreds of events a path takes in skin.
pub fn channel_layers(
    skin: &SkinParams,
    targets: [f64; 3],
) -> Result<[ChannelLayers; 3], ExportError> {
    let layers_at = |nm: f64| -> Result<Vec<LayerOptics>, ExportError> {
        let stack = LayeredMedium::skin(skin, Wavelength::new(nm)?, DEFAULT_G)?;
        Ok(SpectralSkin::layers_of(&stack))
    };
    let grey = layers_at(CHANNEL_NM[1])?;
    let one = |c: usize| -> Result<ChannelLayers, ExportError> {
        let own = layers_at(CHANNEL_NM[c])?;
        // The largest k keeps every σa below its layer's σt.
        let k_max = (0..2)
            .map(|i| grey[i].sigma_t_per_mm() / own[i].sigma_a_per_mm)
            .fold(f64::INFINITY, f64::min)
            * (1.0 - 1e-9);
        let with = |k: f64| {
            let mut l = grey.clone();
            for i in 0..2 {
                let sigma_a = k * own[i].sigma_a_per_mm;
                l[i].sigma_a_per_mm = sigma_a;
                l[i].sigma_s_per_mm = grey[i].sigma_t_per_mm() - sigma_a;
            }
            l
        };
        let k = solve_decreasing(targets[c], 1e-9 * k_max, k_max, |k| {
            two_layer_total(&with(k))
        })?;
        let layers = with(k);
        Ok(ChannelLayers {
            lambda_nm: CHANNEL_NM[c],
            absorption_factor: k,
            total: two_layer_total(&layers)?,
            layers,
            target: targets[c],
        })
    };
    Ok([one(0)?, one(1)?, one(2)?])
}

/// The scene XML and its notes. `spectral` must span [`SPECTRAL_RANGE_NM`] for the spectral and
/// RGB variants and hold the one wavelength of the mono variant.
pub fn write(
    spectral: &SpectralSkin,
    skin: &SkinParams,
    surface: Surface,
    opts: &ExportOptions,
) -> Result<(String, Vec<String>), ExportError> {
    let variant = opts.mitsuba_variant;
    let rows = &spectral.rows;
    let (first_nm, last_nm) = (rows[0].lambda_nm, rows[rows.len() - 1].lambda_nm);
    if variant != Variant::Mono {
        check(
            "first wavelength of the Mitsuba spectra (nm)",
            first_nm,
            0.0,
            SPECTRAL_RANGE_NM.0,
            "≤ 360 nm (Mitsuba's spectral variants sample 360–830 nm)",
        )?;
        check(
            "last wavelength of the Mitsuba spectra (nm)",
            last_nm,
            SPECTRAL_RANGE_NM.1,
            f64::INFINITY,
            "≥ 830 nm (Mitsuba's spectral variants sample 360–830 nm)",
        )?;
    }
    let first = &rows[0].layers;
    let epidermis_mm = first[0].thickness_mm.unwrap_or(0.0);
    let unit = opts.scene_unit_mm;
    let (w, total, epi) = (
        HALF_WIDTH_MM / unit,
        (epidermis_mm + opts.dermis_thickness_mm) / unit,
        epidermis_mm / unit,
    );
    let channels = match variant {
        Variant::Rgb => {
            let grid = WavelengthGrid::new(first_nm, last_nm, rows[1].lambda_nm - first_nm)?;
            Some(channel_layers(skin, rgb_totals(spectral, &grid)?)?)
        }
        _ => None,
    };
    let mut x = String::new();
    let _ = writeln!(x, r#"<?xml version="1.0" encoding="utf-8"?>"#);
    let _ = writeln!(x, r#"<scene version="3.0.0">"#);
    let integrator = match variant {
        Variant::Spectral => "volpathmis",
        Variant::Rgb | Variant::Mono => "volpath",
    };
    let _ = writeln!(
        x,
        r#"    <integrator type="{integrator}"><integer name="max_depth" value="-1"/><integer name="rr_depth" value="{RR_DEPTH}"/></integrator>"#
    );
    for (i, id) in ["epidermis", "dermis"].iter().enumerate() {
        let _ = writeln!(x, r#"    <medium type="homogeneous" id="{id}">"#);
        let mut scale = unit;
        match (&channels, variant) {
            (Some(ch), _) => {
                let sigma_t = [0, 1, 2].map(|c| ch[c].layers[i].sigma_t_per_mm());
                let max = sigma_t.iter().copied().fold(0.0, f64::max);
                scale *= max;
                let albedo = [0, 1, 2].map(|c| ch[c].layers[i].albedo());
                let _ = writeln!(
                    x,
                    r#"        <rgb name="albedo" value="{:.7}, {:.7}, {:.7}"/>"#,
                    albedo[0], albedo[1], albedo[2]
                );
                let _ = writeln!(
                    x,
                    r#"        <rgb name="sigma_t" value="{:.7}, {:.7}, {:.7}"/>"#,
                    sigma_t[0] / max,
                    sigma_t[1] / max,
                    sigma_t[2] / max
                );
            }
            (None, Variant::Mono) => {
                let l = &rows[0].layers[i];
                let _ = writeln!(
                    x,
                    r#"        <float name="albedo" value="{:.9}"/>"#,
                    l.albedo()
                );
                let _ = writeln!(
                    x,
                    r#"        <float name="sigma_t" value="{:.9e}"/>"#,
                    l.sigma_t_per_mm()
                );
            }
            (None, _) => {
                let spectrum = |f: &dyn Fn(&LayerOptics) -> f64| -> String {
                    rows.iter()
                        .map(|r| format!("{}:{:.6e}", r.lambda_nm, f(&r.layers[i])))
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                let _ = writeln!(
                    x,
                    r#"        <spectrum name="albedo" value="{}"/>"#,
                    spectrum(&LayerOptics::albedo)
                );
                let _ = writeln!(
                    x,
                    r#"        <spectrum name="sigma_t" value="{}"/>"#,
                    spectrum(&LayerOptics::sigma_t_per_mm)
                );
            }
        }
        let _ = writeln!(x, r#"        <float name="scale" value="{scale:.9e}"/>"#);
        let _ = writeln!(
            x,
            r#"        <phase type="hg"><float name="g" value="{}"/></phase>"#,
            first[i].g
        );
        let _ = writeln!(x, "    </medium>");
    }
    // The cube spans [−1, 1]³: scale by the half extents, translate the top face to z = 0.
    let block = |x: &mut String, id: &str, half_z: f64, centre_z: f64, half_w: f64| {
        let _ = writeln!(x, r#"    <shape type="cube" id="{id}">"#);
        let _ = writeln!(
            x,
            r#"        <transform name="to_world"><scale x="{half_w}" y="{half_w}" z="{half_z}"/><translate z="{centre_z}"/></transform>"#
        );
    };
    block(&mut x, "skin_epidermis", total / 2.0, -total / 2.0, w);
    let _ = writeln!(
        x,
        r#"        <bsdf type="dielectric"><float name="int_ior" value="{}"/><float name="ext_ior" value="{}"/></bsdf>"#,
        surface.eta, spectral.n_above
    );
    let _ = writeln!(x, r#"        <ref name="interior" id="epidermis"/>"#);
    let _ = writeln!(x, "    </shape>");
    // The dermis block sits inside the epidermis block, its top at −d, inset by 0.1% so that no two
    // faces coincide.
    let inset = 1e-3 * total;
    let dermis_half = (total - epi - inset) / 2.0;
    block(
        &mut x,
        "skin_dermis",
        dermis_half,
        -epi - dermis_half,
        w - inset,
    );
    let _ = writeln!(x, r#"        <bsdf type="null"/>"#);
    let _ = writeln!(x, r#"        <ref name="interior" id="dermis"/>"#);
    let _ = writeln!(x, r#"        <ref name="exterior" id="epidermis"/>"#);
    let _ = writeln!(x, "    </shape>");
    if opts.scene {
        write_scene(&mut x, unit);
    }
    let _ = writeln!(x, "</scene>");
    let mut notes = vec![
        format!(
            "units: scene unit = {unit} mm (media \"scale\" carries mm per scene unit, so sigma_t is per mm); epidermis {epidermis_mm} mm, dermis {} mm thick (finite for the renderer), block {} mm wide",
            opts.dermis_thickness_mm,
            2.0 * HALF_WIDTH_MM
        ),
        format!(
            "engine model: Mitsuba 3 {integrator} (rr_depth {RR_DEPTH}, max_depth -1), homogeneous media, HG phase, smooth dielectric face (the oily lobe is not written); conventions: albedo = σs/σt (single scattering), sigma_t = σa + σs (not reduced)"
        ),
    ];
    notes.push(match (&channels, variant) {
        (Some(ch), _) => format!(
            "variant rgb (scalar_rgb, llvm_ad_rgb): colour space lin_rec709; one sigma_t per layer (the skin's at 549.1 nm) carried by \"scale\" with sigma_t = 1 (RGB variants clamp colours to [0, 1]); albedos per channel from both layers' σa at {}/{}/{} nm times {:.4}/{:.4}/{:.4}, solved for our RGB totals (per entering photon) {:.5}/{:.5}/{:.5}, returned {:.5}/{:.5}/{:.5}",
            ch[0].lambda_nm,
            ch[1].lambda_nm,
            ch[2].lambda_nm,
            ch[0].absorption_factor,
            ch[1].absorption_factor,
            ch[2].absorption_factor,
            ch[0].target,
            ch[1].target,
            ch[2].target,
            ch[0].total,
            ch[1].total,
            ch[2].total
        ),
        (None, Variant::Mono) => format!(
            "variant mono (llvm_ad_mono): the skin at {} nm only",
            rows[0].lambda_nm
        ),
        (None, _) => format!(
            "variant spectral (scalar_spectral, llvm_ad_spectral): spectra over {first_nm}–{last_nm} nm, step {} nm, the range the variants sample",
            rows.get(1).map_or(0.0, |r| r.lambda_nm - first_nm)
        ),
    });
    notes.push(if opts.scene {
        format!(
            "scene: orthographic camera straight down on a {0}×{0} px film over the centre, uniform sky of radiance 1 (white; D65 in spectral variants), {SCENE_SPP} spp; normalisation: a pixel = F(0) + skin spectrum's diffuse_reflectance (per incident photon), F(0) = {1:.5}",
            SCENE_FILM_PX,
            surface.f0()
        )
    } else {
        "normalisation: our totals are per photon entering; per incident photon multiply by 1 − F(0); add a sensor and emitter to render (or export with --scene)".to_string()
    });
    notes.push(
        "accuracy: the layers are ours, so volpath solves our transport (only the finite dermis and block differ from the semi-infinite model)".to_string(),
    );
    Ok((x, notes))
}

/// A camera looking straight down on the block's centre and a uniform white sky.
fn write_scene(x: &mut String, unit: f64) {
    // A 1-mm patch at the centre, the camera 10 mm above the face.
    let (patch, height) = (1.0 / unit, 10.0 / unit);
    let _ = writeln!(
        x,
        r#"    <sensor type="orthographic">
        <transform name="to_world"><scale x="{h}" y="{h}"/><lookat origin="0, 0, {height}" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="{SCENE_SPP}"/></sampler>
        <film type="hdrfilm"><integer name="width" value="{SCENE_FILM_PX}"/><integer name="height" value="{SCENE_FILM_PX}"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="1, 1, 1"/></emitter>"#,
        h = patch / 2.0
    );
}
