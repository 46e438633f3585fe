//! BSSRDF or volumetric walk, per hit (docs/physics.md §16.6). The separable BSSRDF takes the
//! skin under a hit for a half-space (§8); where the body is thin, light that the half-space would
//! send back instead crosses to the far face, and light entering the far face crosses to the
//! viewer: the BSSRDF returns 50–60% too little of a backlit slab 1–4 mm thick
//! (docs/accuracy_evidence.md §4). The criterion: a probe ray from the hit along the inward normal
//! meets the same material's surface at a distance d; the light the BSSRDF omits there is, from
//! the slab's exact totals ([`SlabTable`]: R(d), T(d), R∞ by adding-doubling),
//!
//! omitted / returned = (T(d) E_far + (R∞ − R(d)) E_near) / (R∞ E_near),
//!
//! with E_near and E_far the direct light of the two faces (the path tracer's light-selection
//! proxies where a shadow ray to each light's centre is clear). Where that share reaches
//! [`OMISSION_SHARE`] the path takes the volumetric walk (`crate::volumetric`, §15) through the
//! mesh instead of the BSSRDF. The probe is as long as the thickest slab whose T could still
//! matter under a far face [`MAX_FAR_TO_NEAR`] times brighter than the near one. A thin part lit
//! only from the front (an eyelid over the eye's cavity) keeps the BSSRDF: there the walk would
//! add a heavy-tailed estimate for light the BSSRDF misses by little.
//!
//! A skin with chromophore maps walks through its maps, each collision's absorption from the
//! texel of its nearest surface point as in the volumetric reference (§19.1); the criterion reads
//! the material's scalar skin, so where the maps reach much darker or lighter skin than the
//! scalars it judges that skin's slab, not the texel's.
//!
//! The walk needs each material's epidermis region, a distance grid over its triangles that takes
//! seconds for a head: it is built at the first thin hit of that material (`OnceLock`), so a scene
//! without thin parts pays one short probe ray per subsurface hit and nothing else.
//!
//! A pixel whose footprint exceeds `walk_below_mm` (k r₉₉, `--thin-walk K`) does not resolve the
//! thin part: its light is summed with that of the thick skin around it, thin hits are a small
//! share of the pixel (1.3% of light-skin hits in `builtin:three-heads-far`), and the walk costs
//! about fifty BSSRDF paths. There the hit keeps the BSSRDF and no probe ray is traced, as the
//! level of detail (`crate::fidelity::lod`) keeps no profile the footprint cannot resolve.

use super::hetero::MapMedium;
use super::slab_table::SlabTable;
use super::{LayerTables, SkinVolume};
use crate::geometry::{SurfaceHit, offset_origin};
use crate::light::{Light, QuadLight};
use crate::material::Material;
use crate::material::hetero::SkinMaps;
use crate::scene::Scene;
use glam::Vec3;
use std::fmt::Write;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};

/// One skin material's thin-part walk: its threshold, its medium (built at first use) and the
/// counts of the hits tested and walked.
#[derive(Debug)]
pub struct ThinPart {
    /// Pixel footprint above which a hit keeps the BSSRDF, mm (k r₉₉).
    pub walk_below_mm: f32,
    /// The slab's totals over its thickness; its range is the probe's length.
    pub slab: SlabTable,
    epidermis: LayerTables,
    dermis: LayerTables,
    phase_g: f64,
    eta: f32,
    d_epi_mm: f32,
    /// The material's chromophore maps: the walk takes each collision's absorption from them,
    /// as the volumetric reference does (docs/physics.md §19.1).
    maps: Option<Arc<SkinMaps>>,
    volume: OnceLock<SkinVolume>,
    tested: AtomicU64,
    walked: AtomicU64,
    front_lit: AtomicU64,
}

/// The thin-part walks of a scene, one slot per material (`None`: not skin, or the walk off).
#[derive(Debug, Default)]
pub struct ThinParts {
    parts: Vec<Option<ThinPart>>,
}

impl ThinParts {
    /// The thin-part walks of every skin material of `scene` whose choices ask for one; `None`
    /// when none does.
    #[must_use]
    pub fn build(scene: &Scene) -> Option<Self> {
        let mut parts = Vec::with_capacity(scene.materials.len());
        for m in &scene.materials {
            let below = match m {
                Material::Skin(s) if s.subsurface.is_some() => {
                    s.choices.as_ref().and_then(|c| c.transport.walk_below_mm())
                }
                _ => None,
            };
            let (Some(walk_below_mm), Material::Skin(skin)) = (below, m) else {
                parts.push(None);
                continue;
            };
            // Cached beside the material's tables, unless they were not (`--no-cache`).
            let cached = skin
                .choices
                .as_ref()
                .is_some_and(|c| !matches!(c.cache, skin_io::cache::CacheOutcome::Off));
            let dir = cached
                .then(skin_io::cache::cache_dir)
                .flatten()
                .map(|d| d.join("tables"));
            let slab = match SlabTable::cached(
                &skin.media,
                f64::from(OMISSION_SHARE / MAX_FAR_TO_NEAR),
                MAX_PROBE_MM,
                dir.as_deref(),
            ) {
                Ok(t) => t,
                Err(e) => {
                    log::warn!("thin parts keep the BSSRDF: the slab totals failed: {e}");
                    parts.push(None);
                    continue;
                }
            };
            parts.push(Some(ThinPart {
                walk_below_mm,
                slab,
                epidermis: skin.media.epidermis.clone(),
                dermis: skin.media.dermis.clone(),
                phase_g: skin.media.phase_g,
                eta: skin.params.eta() as f32,
                d_epi_mm: skin
                    .maps
                    .as_ref()
                    .map_or(skin.params.epidermis_thickness_mm() as f32, |m| {
                        m.deepest_epidermis_mm()
                    }),
                maps: skin.maps.clone(),
                volume: OnceLock::new(),
                tested: AtomicU64::new(0),
                walked: AtomicU64::new(0),
                front_lit: AtomicU64::new(0),
            }));
        }
        parts.iter().any(Option::is_some).then_some(Self { parts })
    }

    /// The thin-part walk of material `material`, if it has one.
    #[must_use]
    pub fn part(&self, material: u32) -> Option<&ThinPart> {
        self.parts.get(material as usize).and_then(Option::as_ref)
    }

    /// The medium to walk at `si` (geometric normal `ng` facing the viewer) when the pixel
    /// footprint `footprint_mm` (mm) resolves the part and the BSSRDF would omit at least
    /// [`OMISSION_SHARE`] of the light there ([`omitted_share`]); `None` to keep the BSSRDF.
    /// Counts the rays in `rays`.
    pub fn walk_at(
        &self,
        scene: &Scene,
        si: &SurfaceHit,
        ng: Vec3,
        footprint_mm: f32,
        rays: &mut u64,
    ) -> Option<&SkinVolume> {
        let part = self.part(si.material)?;
        if footprint_mm > part.walk_below_mm {
            return None;
        }
        part.tested.fetch_add(1, Ordering::Relaxed);
        *rays += 1;
        let inward = -ng;
        let geometry = &scene.geometry;
        let far = geometry.intersect(
            offset_origin(si.p, ng, inward),
            inward,
            0.0,
            part.slab.max_mm(),
        )?;
        if far.material != si.material {
            return None;
        }
        let far_out = if far.ng.dot(inward) > 0.0 {
            far.ng
        } else {
            -far.ng
        };
        let e_near = direct_proxy(scene, (si.p, ng), rays);
        let e_far = direct_proxy(scene, (far.p, far_out), rays);
        if omitted_share(&part.slab, far.t, e_near, e_far) < OMISSION_SHARE {
            part.front_lit.fetch_add(1, Ordering::Relaxed);
            return None;
        }
        part.walked.fetch_add(1, Ordering::Relaxed);
        Some(part.volume.get_or_init(|| {
            let mut volume = SkinVolume::new(
                part.epidermis.clone(),
                part.dermis.clone(),
                part.phase_g,
                part.eta,
                part.d_epi_mm,
                geometry.triangles_of(si.material),
            );
            volume.maps = part.maps.as_ref().map(|maps| {
                MapMedium::new(
                    maps.clone(),
                    &geometry.triangles_with_uvs_of(si.material),
                    f64::from(part.d_epi_mm),
                    super::majorant::DEFAULT_CELL_MM,
                )
            });
            volume
        }))
    }
}

impl ThinParts {
    /// Per skin material with a walk, the share of its subsurface hits that took it, one line
    /// each (`names`: the scene's material names).
    #[must_use]
    pub fn report(&self, names: &[String]) -> String {
        let mut s = String::new();
        for (index, name) in names.iter().enumerate() {
            let Some(part) = self.part(index as u32) else {
                continue;
            };
            let (tested, walked) = part.counts();
            let front_lit = part.front_lit.load(Ordering::Relaxed);
            let share = |n: u64| 100.0 * n as f64 / tested.max(1) as f64;
            let _ = writeln!(
                s,
                "skin '{name}': volumetric walk at {:.2}% of {tested} subsurface hits (the BSSRDF \
                 would omit ≥ {:.0}% of their light), the BSSRDF at the rest ({:.2}% within {:.1} mm \
                 of a far face but below that share)",
                share(walked),
                100.0 * OMISSION_SHARE,
                share(front_lit),
                part.slab.max_mm()
            );
        }
        s
    }
}

impl ThinPart {
    /// (hits tested, hits walked) so far.
    #[must_use]
    pub fn counts(&self) -> (u64, u64) {
        (
            self.tested.load(Ordering::Relaxed),
            self.walked.load(Ordering::Relaxed),
        )
    }
}

pub use crate::fidelity::THIN_OMISSION_SHARE as OMISSION_SHARE;

/// The brightest far face, against the near one, that the probe's length allows for: beyond the
/// thickness where T(d) < [`OMISSION_SHARE`] R∞ / this, no lighting makes the part thin (the
/// backlit ear's far face receives about 100 times its near face's light).
pub const MAX_FAR_TO_NEAR: f32 = 1000.0;

/// Longest probe, mm, whatever the skin's transmission.
const MAX_PROBE_MM: f64 = 60.0;

/// The share of the returned light R∞ E_near that the BSSRDF omits at a part `d_mm` thick whose
/// faces receive `e_near` and `e_far` (any common unit): the light crossing from the far face,
/// T(d) E_far, and the reflection the half-space adds over the slab's, (R∞ − R(d)) E_near
/// (docs/physics.md §16.6). Infinite where only the far face is lit, 0 where neither is.
#[must_use]
pub fn omitted_share(slab: &SlabTable, d_mm: f32, e_near: f32, e_far: f32) -> f32 {
    let (r, t) = slab.totals(d_mm);
    let r_inf = slab.half_space_reflectance();
    let omitted = t * e_far + (r_inf - r).max(0.0) * e_near;
    let returned = r_inf * e_near;
    if returned > 0.0 {
        omitted / returned
    } else if omitted > 0.0 {
        f32::INFINITY
    } else {
        0.0
    }
}

/// Irradiance at `p` (normal `n`) from quad light `q`, its mean radiance times the projected
/// solid angle of the quad (Lambert's polygon formula, ½ Σ γ_i n · (r_i × r_(i+1))/|…|, the
/// quad taken whole above the horizon). The light-selection proxy takes a near quad for a point
/// source, which underestimates a 200-mm quad 60 mm behind a slab sevenfold; the criterion
/// compares the two faces' light, so it needs the irradiance itself.
fn quad_irradiance(q: &QuadLight, p: Vec3, n: Vec3) -> f32 {
    let normal = q.edge_u_mm.cross(q.edge_v_mm);
    if (p - q.corner_mm).dot(normal) <= 0.0 {
        return 0.0;
    }
    let corners = [
        q.corner_mm,
        q.corner_mm + q.edge_u_mm,
        q.corner_mm + q.edge_u_mm + q.edge_v_mm,
        q.corner_mm + q.edge_v_mm,
    ]
    .map(|c| (c - p).normalize_or_zero());
    let mut projected = 0.0f32;
    for i in 0..4 {
        let (a, b) = (corners[i], corners[(i + 1) % 4]);
        let gamma = a.dot(b).clamp(-1.0, 1.0).acos();
        projected += gamma * n.dot(a.cross(b).normalize_or_zero());
    }
    q.radiance.mean() * (0.5 * projected).abs()
}

/// Sum over the lights (and the environment) visible from `p` along their centre ray of their
/// direct light at `(p, n)`: a quad's irradiance, the other lights' selection proxies (radiance ×
/// solid angle × widened cosine); counts the shadow rays in `rays`.
pub fn direct_proxy(scene: &Scene, (p, n): (Vec3, Vec3), rays: &mut u64) -> f32 {
    let clear = |d: Vec3, t_max: f32, rays: &mut u64| {
        if d.dot(n) <= 0.0 {
            return false;
        }
        *rays += 1;
        !scene
            .geometry
            .occluded(offset_origin(p, n, d), d, t_max * (1.0 - 1e-4))
    };
    let towards = |target: Vec3, short_of_mm: f32, rays: &mut u64| {
        let to = target - p;
        let dist = to.length();
        dist > short_of_mm && clear(to / dist, dist - short_of_mm, rays)
    };
    let mut e = 0.0;
    for light in &scene.lights {
        let w = match light {
            Light::Quad(q) => quad_irradiance(q, p, n),
            _ => light.selection_weight(p, n),
        };
        if w <= 0.0 {
            continue;
        }
        let visible = match light {
            Light::Point(l) => towards(l.position_mm, 0.0, rays),
            Light::Spot(l) => towards(l.position_mm, 0.0, rays),
            Light::Distant(l) => clear(l.to_light, f32::INFINITY, rays),
            Light::Sphere(l) => towards(l.center_mm, l.radius_mm, rays),
            Light::Quad(l) => towards(l.corner_mm + 0.5 * (l.edge_u_mm + l.edge_v_mm), 0.0, rays),
        };
        if visible {
            e += w;
        }
    }
    if let Some(env) = &scene.environment
        && clear(n, f32::INFINITY, rays)
    {
        e += env.selection_weight();
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::media::SkinMedia;
    use crate::spectrum::SpectrumTable;
    use skin_optics::{Preset, SkinParams};

    /// A square light of half-side a centred h above a point facing it delivers E = L · 4 A/√(1 +
    /// A²) · atan(A/√(1 + A²)), A = a/h (the projected solid angle of four corner rectangles); π L
    /// as it fills the hemisphere (a = 10⁴ h); nothing behind its emitting side. Within 10⁻⁵ relative (f32).
    #[test]
    fn a_quads_irradiance_is_its_projected_solid_angle() {
        let quad = |a: f32, h: f32| {
            QuadLight::new(
                Vec3::new(-a, -a, h),
                Vec3::new(0.0, 2.0 * a, 0.0),
                Vec3::new(2.0 * a, 0.0, 0.0),
                SpectrumTable::constant(2.0),
            )
        };
        for (a, h) in [(100.0f32, 60.0f32), (10.0, 60.0), (1e4, 1.0)] {
            let big_a = f64::from(a / h);
            let s = big_a / (1.0 + big_a * big_a).sqrt();
            let want = 2.0 * 4.0 * s * s.atan();
            let got = f64::from(quad_irradiance(&quad(a, h), Vec3::ZERO, Vec3::Z));
            assert!(
                (got / want - 1.0).abs() < 1e-5,
                "a {a} h {h}: {got} vs {want}"
            );
        }
        // The light emits towards −z (edge_u × edge_v): a point above it is behind.
        let q = quad(100.0, 60.0);
        assert_eq!(
            quad_irradiance(&q, Vec3::new(0.0, 0.0, 100.0), -Vec3::Z),
            0.0
        );
    }

    /// The omitted share from the slab's totals: with the far face unlit it is (R∞ − R(d))/R∞,
    /// which falls below the 5% threshold for light skin within 2 mm (0.35% there); lit from
    /// behind it adds T(d) E_far / (R∞ E_near) and falls with the thickness; infinite with only
    /// the far face lit, 0 with neither.
    #[test]
    fn the_omitted_share_follows_the_slabs_totals() {
        let media =
            SkinMedia::new(&SkinParams::preset(Preset::Light), multipole::DEFAULT_G).unwrap();
        let slab = SlabTable::build(&media, 5e-5, 60.0).unwrap();
        let r_inf = slab.half_space_reflectance();
        for d in [0.5f32, 1.0, 2.0, 4.0] {
            let (r, t) = slab.totals(d);
            let front = omitted_share(&slab, d, 1.0, 0.0);
            assert!((front - (r_inf - r) / r_inf).abs() < 1e-6, "{d}: {front}");
            let back = omitted_share(&slab, d, 1.0, 100.0);
            assert!(
                (back - front - 100.0 * t / r_inf).abs() < 1e-5 * back,
                "{d}: {back}"
            );
        }
        assert!(omitted_share(&slab, 2.0, 1.0, 0.0) < OMISSION_SHARE);
        assert!(omitted_share(&slab, 1.0, 1.0, 100.0) > omitted_share(&slab, 2.0, 1.0, 100.0));
        assert_eq!(omitted_share(&slab, 1.0, 0.0, 1.0), f32::INFINITY);
        assert_eq!(omitted_share(&slab, 1.0, 0.0, 0.0), 0.0);
    }
}
