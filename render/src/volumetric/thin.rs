//! BSSRDF or volumetric walk, per hit (docs/physics.md §16.6). The separable BSSRDF takes the skin
//! under a hit for a half-space (§8); where the body is thinner than the distance its light
//! travels, light that the half-space would send back instead crosses to the far face, and the
//! BSSRDF returns far too little of a backlit slab a few millimetres thick (BENCHMARKS.md, "BSSRDF
//! against the volumetric reference"). The criterion: a probe ray from the hit along the
//! inward normal; when it meets the same material's surface within `walk_below_mm` — the skin's
//! largest 99% energy radius r₉₉ (over the table's wavelengths) times a factor
//! (`crate::fidelity::DEFAULT_THIN_WALK_R99`, `--thin-walk`) — the hit is thin and the path takes the volumetric walk (`crate::volumetric`,
//! §15) through the mesh instead of the BSSRDF. r₉₉ is the profile's own reach: a slab thicker
//! than it holds 99% of the half-space's light within its depth, so the BSSRDF's answer stands;
//! measured, the dark preset's 3-mm slab (r₉₉ 2.2 mm) agrees with the walk within noise
//! (−0.3% ± 4.8%) and takes the BSSRDF, the light and medium slabs (r₉₉ 5.0 and 4.0 mm) take the
//! walk.
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

use super::{LayerTables, SkinVolume, VolumetricError};
use crate::geometry::{Geometry, SurfaceHit, offset_origin};
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
}

/// The thin-part walks of a scene, one slot per material (`None`: not skin, or the walk off).
#[derive(Debug, Default)]
pub struct ThinParts {
    parts: Vec<Option<ThinPart>>,
}

impl ThinParts {
    /// The thin-part walks of every skin material of `scene` whose choices ask for one; `None`
    /// when none does.
    pub fn build(scene: &Scene) -> Result<Option<Self>, VolumetricError> {
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
            }));
        }
        Ok(parts.iter().any(Option::is_some).then_some(Self { parts }))
    }

    /// The thin-part walk of material `material`, if it has one.
    #[must_use]
    pub fn part(&self, material: u32) -> Option<&ThinPart> {
        self.parts.get(material as usize).and_then(Option::as_ref)
    }

    /// The medium to walk at `si` (geometric normal `ng` facing the viewer) when the body under it
    /// is thinner than its material's threshold and the pixel footprint `footprint_mm` (mm)
    /// resolves it; `None` to keep the BSSRDF. Counts the probe ray in `rays`.
    pub fn walk_at(
        &self,
        geometry: &Geometry,
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
        let far = geometry.intersect(
            offset_origin(si.p, ng, inward),
            inward,
            0.0,
            part.walk_below_mm,
        )?;
        if far.material != si.material {
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
            let _ = writeln!(
                s,
                "skin '{name}': volumetric walk at {:.2}% of {tested} subsurface hits (thinner than \
                 {:.2} mm), the BSSRDF at the rest",
                100.0 * walked as f64 / tested.max(1) as f64,
                part.walk_below_mm
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
