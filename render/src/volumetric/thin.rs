//! BSSRDF or volumetric walk, per hit (docs/physics.md §16.6). The separable BSSRDF takes the skin
//! under a hit for a half-space (§8); where the body is thinner than the distance its light
//! travels, light that the half-space would send back instead crosses to the far face, and light
//! entering the far face crosses to the viewer: the BSSRDF returns 50–60% too little of a backlit
//! slab 1–4 mm thick (BENCHMARKS.md, "BSSRDF against the volumetric reference"). The criterion: a
//! probe ray from the hit along the inward normal; when it meets the same material's surface
//! within `walk_below_mm` — the skin's largest 99% energy radius r₉₉ (over the table's
//! wavelengths) times a factor (`crate::fidelity::DEFAULT_THIN_WALK_R99`, `--thin-walk`) — and
//! that far face receives direct light ([`FAR_LIGHT_SHARE`]), the hit is thin and the path takes
//! the volumetric walk (`crate::volumetric`, §15) through the mesh instead of the BSSRDF. r₉₉ is
//! the profile's own reach: a slab thicker than it holds 99% of the half-space's light within its
//! depth, so the BSSRDF's answer stands. A thin part lit only from the front (an eyelid over the
//! eye's cavity) keeps the BSSRDF: there the walk would add a heavy-tailed estimate for light the
//! BSSRDF misses by little.
//!
//! The walk needs each material's epidermis region, a distance grid over its triangles that takes
//! seconds for a head: it is built at the first thin hit of that material (`OnceLock`), so a scene
//! without thin parts pays one short probe ray per subsurface hit and nothing else.
//!
//! A pixel whose footprint exceeds `walk_below_mm` does not resolve the thin part: its light is
//! summed with that of the thick skin around it, thin hits are a small share of the pixel
//! (1.3% of light-skin hits in `builtin:three-heads-far`), and the walk costs about fifty BSSRDF
//! paths. There the hit keeps the BSSRDF and no probe ray is traced, as the level of detail
//! (`crate::fidelity::lod`) keeps no profile the footprint cannot resolve.

use super::{LayerTables, SkinVolume};
use crate::geometry::{SurfaceHit, offset_origin};
use crate::light::Light;
use crate::material::Material;
use crate::scene::Scene;
use glam::Vec3;
use std::fmt::Write;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};

/// One skin material's thin-part walk: its threshold, its medium (built at first use) and the
/// counts of the hits tested and walked.
#[derive(Debug)]
pub struct ThinPart {
    /// Local thickness below which a hit walks, mm.
    pub walk_below_mm: f32,
    epidermis: LayerTables,
    dermis: LayerTables,
    phase_g: f64,
    eta: f32,
    d_epi_mm: f32,
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
            parts.push(Some(ThinPart {
                walk_below_mm,
                epidermis: skin.media.epidermis.clone(),
                dermis: skin.media.dermis.clone(),
                phase_g: skin.media.phase_g,
                eta: skin.params.eta() as f32,
                d_epi_mm: skin.params.epidermis_thickness_mm() as f32,
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

    /// The medium to walk at `si` (geometric normal `ng` facing the viewer) when the body under it
    /// is thinner than its material's threshold, the pixel footprint `footprint_mm` (mm) resolves
    /// it and its far face is lit (`far_face_lit`); `None` to keep the BSSRDF. Counts the rays in
    /// `rays`.
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
            part.walk_below_mm,
        )?;
        if far.material != si.material {
            return None;
        }
        let far_out = if far.ng.dot(inward) > 0.0 {
            far.ng
        } else {
            -far.ng
        };
        if !far_face_lit(scene, (si.p, ng), (far.p, far_out), rays) {
            part.front_lit.fetch_add(1, Ordering::Relaxed);
            return None;
        }
        part.walked.fetch_add(1, Ordering::Relaxed);
        Some(part.volume.get_or_init(|| {
            SkinVolume::new(
                part.epidermis.clone(),
                part.dermis.clone(),
                part.phase_g,
                part.eta,
                part.d_epi_mm,
                geometry.triangles_of(si.material),
            )
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
                "skin '{name}': volumetric walk at {:.2}% of {tested} subsurface hits (thinner than \
                 {:.2} mm, far face lit), the BSSRDF at the rest ({:.2}% thin with an unlit far face)",
                share(walked),
                part.walk_below_mm,
                share(front_lit)
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

/// Share of the near face's direct light (irradiance proxy) below which a thin part's far face
/// counts as unlit. The light the BSSRDF omits there is what crosses from the far face, T·E_far,
/// against the R·E_near it returns: below this share the omission is under 5% of the pixel
/// wherever the part transmits no more than it reflects (T ≤ R). The error of the choice, with
/// the light lost through the far face, is measured on front-lit slabs (docs/accuracy_evidence.md
/// §4).
pub const FAR_LIGHT_SHARE: f32 = 0.05;

/// Whether the far face of a thin part (point and outward normal `far`) receives at least
/// [`FAR_LIGHT_SHARE`] of the direct light of its near face (`near`): per light, the selection
/// proxy (radiance × solid angle × widened cosine, `Light::selection_weight`) where a shadow ray
/// to the light's centre (the environment: along the normal) is clear. A part lit only from the
/// front (an eyelid over the eye's cavity) keeps the BSSRDF: what it misses there is the light
/// that crosses the part instead of returning (docs/physics.md §16.6), while the walk would add a
/// heavy-tailed estimate for little light. Deterministic in the hit, so the technique chosen at a
/// point never depends on random numbers.
fn far_face_lit(scene: &Scene, near: (Vec3, Vec3), far: (Vec3, Vec3), rays: &mut u64) -> bool {
    let e_near = direct_proxy(scene, near, rays);
    let e_far = direct_proxy(scene, far, rays);
    e_far > 0.0 && e_far >= FAR_LIGHT_SHARE * e_near
}

/// Sum over the lights (and the environment) visible from `p` along their centre ray of their
/// selection proxies at `(p, n)`; counts the shadow rays in `rays`.
fn direct_proxy(scene: &Scene, (p, n): (Vec3, Vec3), rays: &mut u64) -> f32 {
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
        let w = light.selection_weight(p, n);
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
