//! What a skin material with chromophore maps holds (docs/physics.md §19, "Heterogeneous skin"):
//! the maps, both layers' absorption at any parameters (for the volumetric walk) and the profile
//! grid (for the BSSRDF; a second one under a thin epidermis where texels have it), with the rule
//! that combines the profiles of the two ends of a path.

use super::maps::ChromophoreMaps;
use crate::bssrdf::{Corners, GainCorners, IncidenceGrid, ProfileGrid};
use crate::media::{MediaError, SkinMedia};
use crate::spectrum::{N_WAVELENGTHS, SampledSpectrum, SampledWavelengths, SpectrumTable};
use glam::Vec2;
use skin_optics::SkinParams;
use std::fmt;
use std::str::FromStr;

/// How the BSSRDF combines the profiles at the point where light enters (p_i) and where it
/// leaves (p_o) when they lie in different skin (docs/physics.md §19.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ProfileBlend {
    /// R(r; p_o): the profile of the point the light leaves from (not reciprocal).
    Exit,
    /// R(r; p_i): the profile of the point the light entered at (not reciprocal).
    Entry,
    /// ½ (R(r; p_i) + R(r; p_o)) (reciprocal).
    Mean,
    /// √(R(r; p_i) R(r; p_o)) (reciprocal): the product of the two ends' epidermal filters when
    /// the profile is a filter T_epi² times the dermis' (§19.3).
    #[default]
    Geometric,
}

impl ProfileBlend {
    /// Every rule, in the order `explain` lists them.
    pub const ALL: [ProfileBlend; 4] = [Self::Exit, Self::Entry, Self::Mean, Self::Geometric];

    /// Whether swapping p_i and p_o leaves the profile unchanged.
    #[must_use]
    pub fn is_reciprocal(self) -> bool {
        matches!(self, Self::Mean | Self::Geometric)
    }

    /// The combined profile from the two ends' values `at_entry` and `at_exit`.
    #[must_use]
    #[inline]
    pub fn combine(self, at_entry: f32, at_exit: f32) -> f32 {
        match self {
            Self::Exit => at_exit,
            Self::Entry => at_entry,
            Self::Mean => 0.5 * (at_entry + at_exit),
            Self::Geometric => (at_entry * at_exit).max(0.0).sqrt(),
        }
    }
}

impl fmt::Display for ProfileBlend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Exit => "exit",
            Self::Entry => "entry",
            Self::Mean => "mean",
            Self::Geometric => "geometric",
        })
    }
}

/// A profile rule name that is none of `exit`, `entry`, `mean`, `geometric`.
#[derive(Debug, Clone, thiserror::Error)]
#[error("unknown profile rule '{0}' (valid: exit, entry, mean, geometric)")]
pub struct UnknownProfileBlend(pub String);

impl FromStr for ProfileBlend {
    type Err = UnknownProfileBlend;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|b| b.to_string().eq_ignore_ascii_case(s))
            .ok_or_else(|| UnknownProfileBlend(s.to_string()))
    }
}

/// Both layers' σa at the eight corners of the unit cube of (C_m, β_m, C_h), mm⁻¹, corner c
/// at (c & 1, c >> 1 & 1, c >> 2 & 1). The model's σa is multilinear in the three ([DJ06] eqs 1
/// and 5: C_m β_m, C_m and C_h appear in products of at most one of each), so the trilinear
/// interpolation of the corners is σa itself at any parameters.
#[derive(Debug, Clone)]
pub struct CornerAbsorption {
    epidermis: Vec<SpectrumTable>,
    dermis: Vec<SpectrumTable>,
}

/// [`CornerAbsorption`] read at one wavelength.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CornersAt {
    /// The epidermis' σa at the corners, mm⁻¹.
    pub epidermis: [f32; 8],
    /// The dermis' σa at the corners, mm⁻¹.
    pub dermis: [f32; 8],
}

impl CornerAbsorption {
    /// The corners of skin `params` (its other constants kept) at anisotropy `g`.
    pub fn new(params: &SkinParams, g: f64) -> Result<Self, MediaError> {
        let mut epidermis = Vec::with_capacity(8);
        let mut dermis = Vec::with_capacity(8);
        for c in 0..8 {
            let bit = |k: usize| f64::from(((c >> k) & 1) as u8);
            let p = params
                .with_melanin(bit(0))
                .and_then(|p| p.with_eumelanin_blend(bit(1)))
                .and_then(|p| p.with_hemoglobin(bit(2)))
                .expect("0 and 1 are valid fractions");
            let media = SkinMedia::new(&p, g)?;
            epidermis.push(media.epidermis.sigma_a);
            dermis.push(media.dermis.sigma_a);
        }
        Ok(Self { epidermis, dermis })
    }

    /// The corners at wavelength `nm`.
    #[must_use]
    pub fn at_nm(&self, nm: f32) -> CornersAt {
        CornersAt {
            epidermis: std::array::from_fn(|c| self.epidermis[c].at_nm(nm)),
            dermis: std::array::from_fn(|c| self.dermis[c].at_nm(nm)),
        }
    }

    /// The dermis' σa at wavelength `nm` and parameters `p` = (C_m, β_m, C_h), mm⁻¹.
    #[must_use]
    #[inline]
    pub fn dermis_sigma_a(&self, nm: f32, p: [f32; 3]) -> f32 {
        trilinear(&self.dermis_at_nm(nm), p)
    }

    /// The dermis' σa at the corners at wavelength `nm`, mm⁻¹.
    #[inline]
    fn dermis_at_nm(&self, nm: f32) -> [f32; 8] {
        std::array::from_fn(|c| self.dermis[c].at_nm(nm))
    }
}

/// The trilinear interpolation of the corner values `v` (corner c at (c & 1, c >> 1 & 1,
/// c >> 2 & 1)) at `p`, at least 0.
#[inline]
fn trilinear(v: &[f32; 8], p: [f32; 3]) -> f32 {
    let lerp = |a: f32, b: f32, t: f32| a + t * (b - a);
    let x00 = lerp(v[0], v[1], p[0]);
    let x10 = lerp(v[2], v[3], p[0]);
    let x01 = lerp(v[4], v[5], p[0]);
    let x11 = lerp(v[6], v[7], p[0]);
    let y0 = lerp(x00, x10, p[1]);
    let y1 = lerp(x01, x11, p[1]);
    lerp(y0, y1, p[2]).max(0.0)
}

impl CornersAt {
    /// σa of the epidermis (`epidermis`) or dermis at parameters `p` = (C_m, β_m, C_h), mm⁻¹.
    #[must_use]
    #[inline]
    pub fn sigma_a(&self, epidermis: bool, p: [f32; 3]) -> f32 {
        trilinear(
            if epidermis {
                &self.epidermis
            } else {
                &self.dermis
            },
            p,
        )
    }

    /// The largest σa of each layer (epidermis, dermis) over the box `range` of parameters: a
    /// multilinear function's largest value over a box is at one of its corners.
    #[must_use]
    pub fn largest(&self, range: [[f32; 2]; 3]) -> (f32, f32) {
        let mut out = (0.0f32, 0.0f32);
        for c in 0..8 {
            let p = std::array::from_fn(|k| range[k][(c >> k) & 1]);
            out.0 = out.0.max(self.sigma_a(true, p));
            out.1 = out.1.max(self.sigma_a(false, p));
        }
        out
    }
}

/// The texel light leaves at, as the BSSRDF reads it ([`SkinMaps::exit_texel`]).
#[derive(Debug, Clone, Copy)]
pub struct ExitTexel<'a> {
    /// The texel's parameters (C_m, β_m, C_h).
    pub params: [f32; 3],
    /// The profile grid's corners at the texel's parameters.
    pub corners: Corners<'a>,
    /// The BSSRDF that samples radii there (`None`: the material's, from the grid's widest
    /// profile).
    pub sampling: Option<&'a crate::bssrdf::Subsurface>,
    /// The incidence gain's corners at the texel (`None`: the material's angular factor).
    pub gain: Option<GainCorners<'a>>,
}

/// The texel light enters at, as the BSSRDF reads it ([`SkinMaps::entry_texel`]).
#[derive(Debug, Clone, Copy)]
pub struct EntryTexel<'a> {
    /// The texel's parameters (C_m, β_m, C_h).
    pub params: [f32; 3],
    /// The profile grid's corners at the texel's parameters.
    pub corners: Corners<'a>,
    /// The incidence gain's corners at the texel (`None`: the material's angular factor).
    pub gain: Option<GainCorners<'a>>,
}

/// The curvature gains of a skin with maps at one path's wavelengths
/// ([`SkinMaps::lane_curvature`]).
#[derive(Debug, Clone, Copy)]
pub struct LaneCurvature {
    /// The dermis' σa at the parameter corners, per lane, mm⁻¹.
    dermis: [[f32; 8]; N_WAVELENGTHS],
    /// The dermis' σs per lane, mm⁻¹.
    sigma_s: [f32; N_WAVELENGTHS],
    g: f32,
    /// κ of the exit texel per lane, mm⁻¹.
    pub exit: [f32; N_WAVELENGTHS],
}

impl LaneCurvature {
    /// κ at lane `k` of skin with parameters `p` = (C_m, β_m, C_h), mm⁻¹: the dermis' σ_tr.
    #[must_use]
    #[inline]
    pub fn kappa_per_mm(&self, k: usize, p: [f32; 3]) -> f32 {
        crate::bssrdf::curvature::sigma_tr_per_mm(
            trilinear(&self.dermis[k], p),
            self.sigma_s[k],
            self.g,
        )
    }
}

/// A skin material's maps and what is built from them.
#[derive(Debug, Clone)]
pub struct SkinMaps {
    /// Per-texel (C_m, β_m, C_h).
    pub maps: ChromophoreMaps,
    /// Both layers' σa at any parameters (the volumetric walk).
    pub absorption: CornerAbsorption,
    /// Profiles over the maps' parameter box (the BSSRDF and the diffuse body).
    pub grid: ProfileGrid,
    /// Profiles under the thin epidermis over the box its texels use (`None` when no texel has
    /// it): the second node of the thickness axis.
    pub thin_grid: Option<ProfileGrid>,
    /// How the BSSRDF combines the two ends' profiles.
    pub blend: ProfileBlend,
    /// Per node of `grid` and of `thin_grid` (in that order), the material's BSSRDF sampling
    /// radii from that node's profile; empty where the radii come from the grid's widest
    /// profile (`SkinMaps::sampling_at`).
    sampling: Vec<crate::bssrdf::Subsurface>,
    /// The material's epidermis thickness (texels without a thin epidermis), mm.
    pub epidermis_mm: f32,
    /// The curvature term at each texel (`None`: the planar profile, `Curvature::Planar`).
    curvature: Option<TexelCurvature>,
    /// The angular factor's incidence gain at each texel: over the maps' box, and over the thin
    /// epidermis' where texels have it (`None` without the gain, `Incidence::Normal`).
    pub incidence: Option<(IncidenceGrid, Option<IncidenceGrid>)>,
}

/// What the first-order curvature term needs at a texel (docs/physics.md §8.2, §19.3): its gain
/// κ is the dermis' σ_tr, whose σa follows the texel's blood (the corners) while σs and g are the
/// material's.
#[derive(Debug, Clone)]
struct TexelCurvature {
    /// The dermis' σs, mm⁻¹.
    dermis_sigma_s: SpectrumTable,
    /// Henyey–Greenstein g of the layers.
    g: f32,
}

impl SkinMaps {
    /// The profile tables at the texel of `uv` and their weights: the corners at its parameters
    /// of the thin epidermis' grid where the texel is thin ([`ThinEpidermisMap::is_thin`]), else of
    /// the material's (§19.2).
    ///
    /// [`ThinEpidermisMap::is_thin`]: super::maps::ThinEpidermisMap::is_thin
    #[must_use]
    #[inline]
    pub fn corners(&self, uv: Vec2) -> Corners<'_> {
        self.corners_at(uv, self.maps.at(uv))
    }

    /// Whether the texel of `uv` reads the thin epidermis' grids.
    #[inline]
    fn reads_thin(&self, uv: Vec2) -> bool {
        self.thin_grid.is_some() && self.maps.thin().is_some_and(|t| t.is_thin(uv))
    }

    /// The incidence gain's corners at parameters `p` of a texel under the thin epidermis
    /// (`thin`) or the material's.
    #[inline]
    fn gain_at(&self, thin: bool, p: [f32; 3]) -> Option<GainCorners<'_>> {
        let (thick_grid, thin_grid) = self.incidence.as_ref()?;
        Some(match thin_grid {
            Some(g) if thin => g.corners(p),
            _ => thick_grid.corners(p),
        })
    }

    /// The incidence gain's corners at the texel of `uv` (`None` without a gain per texel).
    #[must_use]
    pub fn gain(&self, uv: Vec2) -> Option<GainCorners<'_>> {
        self.incidence.as_ref()?;
        self.gain_at(self.reads_thin(uv), self.maps.at(uv))
    }

    /// What the BSSRDF reads of the texel of `uv` where light enters: its parameters, its
    /// profile's corners and its incidence gain's, from one look-up of the maps.
    #[must_use]
    #[inline]
    pub fn entry_texel(&self, uv: Vec2) -> EntryTexel<'_> {
        let p = self.maps.at(uv);
        let thin = self.reads_thin(uv);
        EntryTexel {
            params: p,
            corners: match &self.thin_grid {
                Some(grid) if thin => grid.corners(p),
                _ => self.grid.corners(p),
            },
            gain: self.gain_at(thin, p),
        }
    }

    /// [`SkinMaps::corners`] with the texel's parameters `p` already read.
    #[inline]
    fn corners_at(&self, uv: Vec2, p: [f32; 3]) -> Corners<'_> {
        match &self.thin_grid {
            Some(grid) if self.reads_thin(uv) => grid.corners(p),
            _ => self.grid.corners(p),
        }
    }

    /// The BSSRDF that samples radii for light leaving at the texel of `uv`: the material's
    /// with the profile of the low corner of that texel's cell (`ProfileGrid::low_corner`), which
    /// follows the texel's own profile and so every combined profile the rules `exit` and
    /// `geometric` give (both vanish where the exit's does); the integrator mixes it with a wider
    /// profile ([`SkinMaps::widest_node`], [`crate::bssrdf::WIDE_SHARE`]). `None` to sample from
    /// the grid's widest profile (the rules `entry` and `mean`, or a grid over β_m). A radius
    /// weight R_het / R_sample near 1 keeps strongly absorbing texels as quiet as uniform skin
    /// (docs/physics.md §19.3).
    #[must_use]
    #[inline]
    pub fn sampling_at(&self, uv: Vec2) -> Option<&crate::bssrdf::Subsurface> {
        self.exit_texel(uv).sampling
    }

    /// What the BSSRDF reads of the texel of `uv` where light leaves: its profile's corners
    /// ([`SkinMaps::corners`]) and the BSSRDF that samples its radii ([`SkinMaps::sampling_at`]),
    /// from one look-up of the maps.
    #[must_use]
    #[inline]
    pub fn exit_texel(&self, uv: Vec2) -> ExitTexel<'_> {
        let p = self.maps.at(uv);
        let thin = self.reads_thin(uv);
        let (grid, offset) = match &self.thin_grid {
            Some(grid) if thin => (grid, self.grid.tables().len()),
            _ => (&self.grid, 0),
        };
        let sampling = if self.sampling.is_empty() {
            None
        } else {
            grid.low_corner(p)
                .and_then(|i| self.sampling.get(offset + i))
        };
        ExitTexel {
            params: p,
            corners: grid.corners(p),
            sampling,
            gain: self.gain_at(thin, p),
        }
    }

    /// The node (an index over `grid`'s nodes, then `thin_grid`'s) whose profile is at least as
    /// wide as that of any skin with parameters at or above `lo` = (C_m, β_m, C_h): the low
    /// corner of `lo`'s cell, in the thin epidermis' grid where `thin` skin is among it, in the
    /// material's where `thick` skin is, the farther reaching of the two where both are. R(r)
    /// falls with σa at every r (every path's weight does), so that profile bounds theirs.
    /// `None` when the BSSRDF samples from the grid's widest profile ([`SkinMaps::sampling_at`]).
    #[must_use]
    pub fn widest_node(&self, lo: [f32; 3], thin: bool, thick: bool) -> Option<usize> {
        if self.sampling.is_empty() {
            return None;
        }
        let thick_node = thick.then(|| self.grid.low_corner(lo)).flatten();
        let thin_node = match &self.thin_grid {
            Some(g) if thin => g.low_corner(lo).map(|i| self.grid.tables().len() + i),
            _ => None,
        };
        let reach = |i: usize| self.sampling[i].table.largest_radius_for_energy_mm(1.0);
        match (thick_node, thin_node) {
            (Some(a), Some(b)) => Some(if reach(b) > reach(a) { b } else { a }),
            (a, b) => a.or(b),
        }
    }

    /// Whether the BSSRDF draws radii from each texel's node ([`SkinMaps::sampling_at`]).
    #[must_use]
    pub fn samples_per_node(&self) -> bool {
        !self.sampling.is_empty()
    }

    /// The profile of node `node` ([`SkinMaps::widest_node`]).
    #[must_use]
    #[inline]
    pub fn node_table(&self, node: usize) -> Option<&crate::bssrdf::ProfileTable> {
        self.sampling.get(node).map(|s| &*s.table)
    }

    /// The epidermis thickness at the texel of `uv`, mm: the thin one where the texel is thin,
    /// else the material's.
    #[must_use]
    #[inline]
    pub fn epidermis_at_mm(&self, uv: Vec2) -> f32 {
        match self.maps.thin() {
            Some(t) if t.is_thin(uv) => t.thickness_mm,
            _ => self.epidermis_mm,
        }
    }

    /// The deepest epidermis/dermis boundary under any texel, mm.
    #[must_use]
    pub fn deepest_epidermis_mm(&self) -> f32 {
        let d = self.epidermis_mm;
        self.maps.thin().map_or(d, |t| t.thickness_mm.max(d))
    }

    /// The curvature gain κ at wavelength `nm` of skin with parameters `p` = (C_m, β_m, C_h),
    /// mm⁻¹: the dermis' σ_tr there (`None` without the curvature term).
    #[must_use]
    pub fn kappa_per_mm(&self, nm: f32, p: [f32; 3]) -> Option<f32> {
        let c = self.curvature.as_ref()?;
        Some(crate::bssrdf::curvature::sigma_tr_per_mm(
            self.absorption.dermis_sigma_a(nm, p),
            c.dermis_sigma_s.at_nm(nm),
            c.g,
        ))
    }

    /// The curvature gains at the path's wavelengths `wl` for light leaving at the texel
    /// `exit`, and what any entry's needs (`None` without the curvature term): read once per
    /// hit for every probe.
    #[must_use]
    pub fn lane_curvature(
        &self,
        wl: &SampledWavelengths,
        exit: &ExitTexel<'_>,
    ) -> Option<LaneCurvature> {
        let c = self.curvature.as_ref()?;
        let dermis: [[f32; 8]; N_WAVELENGTHS] =
            std::array::from_fn(|k| self.absorption.dermis_at_nm(wl.nm(k)));
        let sigma_s: [f32; N_WAVELENGTHS] =
            std::array::from_fn(|k| c.dermis_sigma_s.at_nm(wl.nm(k)));
        let mut lanes = LaneCurvature {
            dermis,
            sigma_s,
            g: c.g,
            exit: [0.0; N_WAVELENGTHS],
        };
        lanes.exit = std::array::from_fn(|k| lanes.kappa_per_mm(k, exit.params));
        Some(lanes)
    }

    /// R(r) per lane of a path through skin from the texel `entry` to the texel `exit` at distance
    /// `r_mm`, combined by the material's rule, mm⁻². Where the exit lies `depth_mm` below the
    /// entry's tangent plane (`crate::bssrdf::curvature::depth_below_tangent_mm`; `None` for
    /// none, as for the local fallback) each end's profile carries its own skin's curvature
    /// term 1 + κ h before the rule combines them (docs/physics.md §19.3).
    #[must_use]
    pub fn profile(
        &self,
        wl: &SampledWavelengths,
        entry: &EntryTexel<'_>,
        exit: &ExitTexel<'_>,
        r_mm: f32,
        (depth_mm, curvature): (Option<f32>, Option<&LaneCurvature>),
    ) -> SampledSpectrum {
        let p_i = entry.params;
        let [mut at_o, mut at_i] = exit.corners.eval_pair(&entry.corners, wl, r_mm);
        if let (Some(h), Some(c)) = (depth_mm, curvature) {
            for k in 0..N_WAVELENGTHS {
                if wl.pdf()[k] > 0.0 {
                    at_i.0[k] *= crate::bssrdf::curvature::factor(c.kappa_per_mm(k, p_i), h);
                    at_o.0[k] *= crate::bssrdf::curvature::factor(c.exit[k], h);
                }
            }
        }
        SampledSpectrum(std::array::from_fn(|k| {
            self.blend.combine(at_i.0[k], at_o.0[k])
        }))
    }

    /// The total diffuse reflectance R_tot per lane at the texel of `uv`.
    #[must_use]
    pub fn totals(&self, wl: &SampledWavelengths, uv: Vec2) -> SampledSpectrum {
        self.corners(uv).totals(wl)
    }
}

impl super::SkinMaterial {
    /// The same skin with chromophore maps `maps`: the corners of its absorption, the profile
    /// grid over the maps' parameter box (error target `grid_error`,
    /// `crate::fidelity::grid::DEFAULT_GRID_ERROR` by default) and the rule `blend`. The BSSRDF
    /// samples radii from the grid's widest profile (least melanin and blood) and weights each
    /// sample by the combined profile of its two ends (§19.3). Where the material has the
    /// incidence gain, each texel's comes from a grid of its own (error target
    /// `incidence_error`, `crate::fidelity::incidence::DEFAULT_INCIDENCE_ERROR` by default).
    pub fn with_maps(
        mut self,
        maps: ChromophoreMaps,
        blend: ProfileBlend,
        knobs: &super::SkinKnobs,
        (grid_error, incidence_error): (f32, f32),
    ) -> Result<Self, super::SkinBuildError> {
        let g = self.media.phase_g;
        let absorption = CornerAbsorption::new(&self.params, g)?;
        // Every node on the scalar table's wavelength rows: interpolating between tables of
        // different rows would add their wavelength interpolations' difference to the error.
        let mut fidelity = knobs.fidelity;
        fidelity.wavelength_step_nm = Some(
            self.choices
                .as_ref()
                .map_or(crate::fidelity::SKIN_TABLE_STEP_NM, |c| {
                    c.wavelengths.step_nm
                }),
        );
        let settings = crate::fidelity::grid::GridSettings {
            params: &self.params,
            phase_g: g,
            surface: self.media.surface,
            method: knobs.method,
            shape_escapes: knobs.shape_escapes,
            fidelity: &fidelity,
            target: grid_error,
        };
        let grid = crate::fidelity::grid::profile_grid(&settings, maps.range())
            .map_err(super::SkinBuildError::Profiles)?;
        // The skin under the thin epidermis, with the box of the texels that read it.
        let thin_skin = match maps.thin() {
            Some(thin) => Some((
                self.params
                    .with_epidermis_thickness_mm(f64::from(thin.thickness_mm))
                    .map_err(|e| super::SkinBuildError::Profiles(e.into()))?,
                thin.range(),
            )),
            None => None,
        };
        let thin_grid = match &thin_skin {
            Some((params, range)) => {
                let settings = crate::fidelity::grid::GridSettings { params, ..settings };
                Some(
                    crate::fidelity::grid::profile_grid(&settings, *range)
                        .map_err(super::SkinBuildError::Profiles)?,
                )
            }
            None => None,
        };
        let incidence = match self.directional.incidence() {
            Some(_) => {
                let settings = crate::fidelity::incidence::IncidenceSettings {
                    params: &self.params,
                    phase_g: g,
                    surface: self.media.surface,
                    directional: &self.directional,
                    fidelity: &fidelity,
                    target: incidence_error,
                };
                let thick = crate::fidelity::incidence::incidence_grid(&settings, maps.range())
                    .map_err(super::SkinBuildError::Profiles)?;
                let thin = match &thin_skin {
                    Some((params, range)) => {
                        let settings =
                            crate::fidelity::incidence::IncidenceSettings { params, ..settings };
                        Some(
                            crate::fidelity::incidence::incidence_grid(&settings, *range)
                                .map_err(super::SkinBuildError::Profiles)?,
                        )
                    }
                    None => None,
                };
                Some((thick, thin))
            }
            None => None,
        };
        // The curvature term moves from the probe (one κ for the material) to each end's texel.
        let curvature = self
            .subsurface
            .as_mut()
            .and_then(|ss| ss.curvature.take())
            .map(|_| TexelCurvature {
                dermis_sigma_s: self.media.dermis.sigma_s.clone(),
                g: g as f32,
            });
        if let Some(ss) = &mut self.subsurface {
            // Radii are drawn from the widest profile: the least absorbing node of either
            // thickness, whichever reaches farther (a sample's weight is 0 beyond its table).
            let reach = |t: &crate::bssrdf::ProfileTable| t.largest_radius_for_energy_mm(1.0);
            ss.table = match &thin_grid {
                Some(t) if reach(t.lowest()) > reach(grid.lowest()) => t.lowest().clone(),
                _ => grid.lowest().clone(),
            };
        }
        if let Some(c) = &mut self.choices {
            c.maps = Some(crate::fidelity::explain::MapChoice {
                texels: maps.size(),
                range: maps.range(),
                nodes: grid.axes().clone().map(|a| a.len()),
                max_error: grid.max_error,
                target: grid_error,
                blend: blend.to_string(),
                thin: maps.thin().zip(thin_grid.as_ref()).map(|(t, g)| {
                    (
                        t.thickness_mm,
                        g.axes().clone().map(|a| a.len()),
                        g.max_error,
                    )
                }),
                incidence: incidence.as_ref().map(|(thick, thin)| {
                    let of = |g: &IncidenceGrid| (g.axes().clone().map(|a| a.len()), g.max_error);
                    (
                        std::iter::once(thick).chain(thin).map(of).collect(),
                        incidence_error,
                    )
                }),
            });
        }
        let per_node = matches!(blend, ProfileBlend::Exit | ProfileBlend::Geometric)
            && grid.axes()[1].len() == 1
            && thin_grid.as_ref().is_none_or(|t| t.axes()[1].len() == 1);
        let sampling = match &self.subsurface {
            Some(ss) if per_node => grid
                .tables()
                .iter()
                .chain(thin_grid.iter().flat_map(ProfileGrid::tables))
                .map(|t| crate::bssrdf::Subsurface {
                    table: t.clone(),
                    ..ss.clone()
                })
                .collect(),
            _ => Vec::new(),
        };
        self.maps = Some(std::sync::Arc::new(SkinMaps {
            maps,
            absorption,
            grid,
            thin_grid,
            blend,
            sampling,
            epidermis_mm: self.params.epidermis_thickness_mm() as f32,
            curvature,
            incidence,
        }));
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// The trilinear interpolation of the corners is the model's σa at random parameters (the
    /// model is multilinear; only f32 rounding, 1e-5 relative, separates them), in both layers
    /// and across the visible range; the largest over a box bounds every value inside it.
    #[test]
    fn corners_give_the_models_absorption_anywhere() {
        let base = SkinParams::preset(skin_optics::Preset::Medium);
        let corners = CornerAbsorption::new(&base, 0.9).unwrap();
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        for _ in 0..40 {
            let p: [f32; 3] = std::array::from_fn(|_| rng.random_range(0.0..1.0));
            let q = base
                .with_melanin(f64::from(p[0]))
                .unwrap()
                .with_eumelanin_blend(f64::from(p[1]))
                .unwrap()
                .with_hemoglobin(f64::from(p[2]))
                .unwrap();
            let media = SkinMedia::new(&q, 0.9).unwrap();
            for nm in [380.0, 455.0, 560.0, 700.0] {
                let at = corners.at_nm(nm);
                let (e, d) = (
                    media.epidermis.sigma_a.at_nm(nm),
                    media.dermis.sigma_a.at_nm(nm),
                );
                assert!((at.sigma_a(true, p) / e - 1.0).abs() < 1e-5, "{p:?} {nm}");
                assert!((at.sigma_a(false, p) / d - 1.0).abs() < 1e-5, "{p:?} {nm}");
                let (me, md) = at.largest([[0.0, 1.0]; 3]);
                assert!(me >= e * (1.0 - 1e-6) && md >= d * (1.0 - 1e-6));
            }
        }
    }

    /// The reciprocal rules are symmetric in the two ends; the others are not.
    #[test]
    fn reciprocal_rules_are_symmetric() {
        for b in ProfileBlend::ALL {
            let same = b.combine(0.2, 0.8) == b.combine(0.8, 0.2);
            assert_eq!(same, b.is_reciprocal(), "{b}");
            assert_eq!(b.to_string().parse::<ProfileBlend>().unwrap(), b);
        }
        assert!((ProfileBlend::Geometric.combine(0.2, 0.8) - 0.4).abs() < 1e-6);
        assert!("median".parse::<ProfileBlend>().is_err());
    }
}
