//! One random walk through a skin volume (docs/physics.md §15): delta (Woodcock) tracking against
//! the majorant σ̄ = max(σt_epidermis, σt_dermis) at the hero wavelength (with chromophore maps,
//! by default each cell's own σ̄, [`super::majorant`], §19.1), so the layer boundary
//! (a distance from the surface, not a plane) is crossed exactly without ever being intersected;
//! at a real collision the weight keeps σs/σt (implicit capture; with maps by default of the
//! cell's least σa, the band above it ratio-tracked, [`Absorption`]) and the direction turns by
//! Henyey–Greenstein — both from `multipole::exact::montecarlo`, the photon physics of the layered Monte
//! Carlo; under isotropic scattering part of the steps are drawn towards the surface instead, with
//! exact MIS weights ([`super::guide`], §15.6); below weight `SkinVolume::roulette_below`
//! ([`ROULETTE_BELOW`] by default) the walk plays Russian roulette. At the surface the
//! walk meets the skin's boundary: total internal reflection beyond the critical angle, else it
//! leaves with probability T(θ_out) (the same energy split as the BSSRDF's, `Directional`:
//! 1 − F for the smooth surface, 1 − ρ_dr for the oily lobe), refracted by Snell's law, or is
//! reflected back in.
//!
//! Where it may go without asking the mesh (§15.5): the walk keeps an anchor point with bounds
//! lo ≤ D ≤ hi on its distance D to the surface ([`super::distance`]). Within |x − anchor| = δ,
//! D(x) ≥ lo − δ and D(x) ≤ hi + δ (D is 1-Lipschitz), which settles the layer of most tentative
//! collisions (dermis when lo − δ > d_epi, epidermis when hi + δ ≤ d_epi), and a flight of length
//! s with s < lo − δ cannot reach the surface, so no ray is cast for it. Otherwise the bounds are
//! taken afresh at x, and the flight is tested against the surface only when it may still reach
//! it: against the faces listed in x's grid cell when they hold every face within reach, else by a
//! ray. Every
//! decision is the one the exact distance and ray would give: the walk is unchanged in law, only
//! cheaper.
//!
//! Precision: the walk's position and direction are f64 in world mm. A ray is cast in the f32 BVH
//! from a point pulled back along the direction beyond the f32 rounding of the position, and each
//! hit is refined in f64 against its triangle's plane; hits behind the position (or on the face
//! the walk is leaving) are passed over. So the walk neither skips medium near the surface nor
//! loses light through it, whatever the mesh's distance from the origin (§15.5). At the surface the
//! walk uses the triangle's geometric normal: the volume it tracks is the mesh's polyhedron, and a
//! smooth normal there would refract into directions the flat face does not allow.

use super::SkinVolume;
use super::distance::{SegmentHit, SurfaceDistance};
use super::guide::{Guide, Layer, Segment};
use super::majorant::Majorant;
use crate::accel::BVH_MIN_T_MM;
use crate::bssrdf::Directional;
use crate::geometry::{Geometry, SurfaceHit};
use glam::{DVec3, Vec3};
use multipole::exact::montecarlo::scatter_direction;
use rand::{Rng, RngCore};
use std::fmt;

/// Most real collisions per walk (a bound on the cost; a walk reaching it is dropped, a bias
/// below 1e-6 of the energy for skin — BENCHMARKS.md).
pub const MAX_COLLISIONS: u32 = 1_000_000;

/// Default weight below which a walk plays Russian roulette (`SkinVolume::roulette_below`): it goes
/// on with probability w / this, at weight this, else ends (unbiased [AK90]); light skin's walks
/// fall below it after about twenty collisions, and ending most of their tails costs less than the
/// variance it adds (BENCHMARKS.md, "Volumetric reference").
pub const ROULETTE_BELOW: f64 = 0.1;

/// How a real collision in skin with chromophore maps accounts for absorption (docs/physics.md
/// §19.1). Both are unbiased; they differ in variance and in how often σa(x), and so the
/// nearest surface point, is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Absorption {
    /// Every real collision keeps σs/σt(x) in the weight (implicit capture): σa is read at each.
    Implicit,
    /// With the local majorant, a collision with ξσ̄ < σs + σa,min (the cell's least σa) is real
    /// and keeps σs/(σs + σa,min); one in the band up to σs + the cell's largest σa is null with
    /// weight (σa,max − σa(x))/(σa,max − σa,min) (ratio tracking of the excess over σa,min):
    /// σa is read only in that band. Elsewhere (global majorant, guided walk), as
    /// [`Absorption::Implicit`].
    #[default]
    Excess,
}

impl fmt::Display for Absorption {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Implicit => "implicit",
            Self::Excess => "excess",
        })
    }
}

/// Most BVH hits one surface query passes over (behind the walk, or its own face) before the
/// light is counted lost.
const MAX_PASSED_HITS: usize = 16;

/// Where and how a walk left the skin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exit {
    /// Exit point on the surface, mm.
    pub p: Vec3,
    /// Geometric normal there, pointing out of the skin.
    pub ng: Vec3,
    /// Direction of the light leaving, outside the skin (unit).
    pub dir: Vec3,
    /// Throughput of the walk at its wavelength (σs/σt per real collision, roulette gains).
    pub weight: f32,
}

/// What happened to a walk, with its event counts (for the statistics).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Walk {
    /// The exit, or `None` when the light was absorbed (or lost).
    pub exit: Option<Exit>,
    /// Real collisions.
    pub collisions: u32,
    /// Tentative collisions (real + null).
    pub tentative: u32,
}

/// Refraction of unit `d` through a face of unit normal `n` (n · d < 0, n on the incident side)
/// with relative index `eta` = n_incident / n_transmitted; `None` under total internal reflection.
#[must_use]
pub fn refract(d: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = -n.dot(d);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((d * eta + n * (eta * cos_i - cos_t)).normalize())
}

/// Walk light that has just entered the skin volume `vol` through the surface point `entry` (of
/// the volume's material) along the refracted direction `dir` (pointing in), at wavelength `nm`;
/// `rays` counts the rays cast.
#[allow(clippy::too_many_arguments)] // the walk's medium, start and random state
pub fn walk<R: RngCore>(
    geometry: &Geometry,
    vol: &SkinVolume,
    directional: &Directional,
    entry: &SurfaceHit,
    dir: Vec3,
    nm: f32,
    rng: &mut R,
    rays: &mut u64,
) -> Walk {
    let mut epidermis = (
        vol.epidermis.sigma_a.at_nm(nm),
        vol.epidermis.sigma_s.at_nm(nm),
    );
    let mut dermis = (vol.dermis.sigma_a.at_nm(nm), vol.dermis.sigma_s.at_nm(nm));
    // With maps σa varies per point: the majorant (and the guide) take each layer's largest.
    let maps = vol.maps.as_ref().map(|m| m.at_nm(nm));
    if let Some(m) = &maps {
        (epidermis.0, dermis.0) = m.largest;
    }
    let majorant = (epidermis.0 + epidermis.1).max(dermis.0 + dermis.1);
    let mut out = Walk {
        exit: None,
        collisions: 0,
        tentative: 0,
    };
    debug_assert!(
        dir.dot(entry.ng) <= 1e-4,
        "the walk starts with light going in"
    );
    let region = &vol.epidermis_region;
    let d_epi = region.radius_mm();
    let one_layer = epidermis == dermis && maps.is_none();
    let material = entry.material;
    // The walk starts on the entry face itself (its f32 hit point put back on the face's plane):
    // an origin offset into the skin would skip medium.
    let entry_face = geometry.triangle(entry.triangle);
    let mut x = onto_face(&entry_face, entry.p.as_dvec3());
    let mut d = dir.as_dvec3();
    let mut on_face = Some(entry_face);
    let mut anchor = Anchor::surface(x);
    let mut ahead: Option<Boundary> = None;
    let mut w = 1.0f64;
    let majorant = f64::from(majorant);
    let nu0 = vol.dwivedi_nu0.each_ref().map(|t| f64::from(t.at_nm(nm)));
    let guide = Guide::new(
        majorant,
        [epidermis, dermis],
        nu0,
        vol.g,
        vol.guided_fraction,
    );
    // The guide's outward normal: the last face the walk touched.
    let mut normal = entry.ng.as_dvec3();
    let mut segment = match &guide {
        Some(guide) => guide.along(d, normal, rng),
        None => Segment::classic(majorant),
    };
    // With maps and no guide, each cell of the local majorant's grid is tracked with its own σ̄
    // ([`super::majorant`]); the guide's weights assume one σ̄ along a segment.
    let sigma_s = (epidermis.1, dermis.1);
    let local = match (&maps, vol.majorant, &guide) {
        (Some(m), Majorant::Local, None) => Some(m),
        _ => None,
    };
    let mut cell = local.map(|m| m.cell_at(x, sigma_s));
    while out.collisions < MAX_COLLISIONS {
        let rate = cell.map_or(segment.rate, |c| f64::from(c.sigma_t));
        // A clear medium (σ̄ = 0) flies straight to the surface.
        let s = if rate > 0.0 {
            -(1.0 - rng.random::<f64>()).ln() / rate
        } else {
            f64::INFINITY
        };
        // The flight ends at the cell's face when it would pass it. The surface is looked for
        // over the whole flight, and kept across the cells it passes: a surface lying on a
        // cell's face (a slab's top on the grid's plane) is then met from the side it was
        // found from, not missed from a point within rounding of it.
        // A flight shorter than the distance to the cell's nearest face stays in the cell.
        let exit = local
            .zip(cell.as_ref())
            .filter(|(m, c)| s >= m.inside_mm(c, x))
            .map(|(m, c)| m.exit(c, x, d));
        let flight = exit.map_or(s, |(t, _)| s.min(t));
        if ahead.is_none() {
            let f = Flight { x, d, s, on_face };
            match look_ahead(geometry, material, region, &mut anchor, f, rays) {
                Ahead::Surface(b) => ahead = Some(b),
                Ahead::Clear => {}
                Ahead::Lost => return out,
            }
        }
        if let Some(b) = ahead.filter(|b| flight >= b.t) {
            if let Some(guide) = &guide {
                segment.reach(b.t);
                w *= guide.weight(&segment);
            }
            match meet_surface(&b, d, vol, directional, w, rng) {
                Ok(exit) => {
                    out.exit = Some(exit);
                    return out;
                }
                Err((reflected, n_out)) => {
                    d = reflected;
                    normal = n_out;
                }
            }
            // The surface point lies in the cell (b.t ≤ the flight to its face).
            x = b.p;
            on_face = Some(b.face);
            anchor = Anchor::surface(x);
            ahead = None;
            if let Some(guide) = &guide {
                segment = guide.along(d, normal, rng);
            }
            continue;
        }
        if let (Some(m), Some((t, key))) = (local, exit)
            && s >= t
        {
            // Into the next cell, no collision: the rest of the flight is drawn afresh there
            // (the exponential forgets the distance flown).
            x += d * t;
            if t > 0.0 {
                on_face = None;
            }
            if let Some(b) = &mut ahead {
                b.t -= t;
            }
            cell = Some(m.cell(key, sigma_s));
            continue;
        }
        x += d * s;
        on_face = None;
        if let Some(b) = &mut ahead {
            b.t -= s;
        }
        out.tentative += 1;
        segment.collide(s);
        // With a thin epidermis in the maps, d_epi is the deepest boundary; a point above it is
        // in the epidermis when it also lies above its nearest texel's.
        let layer = if !one_layer
            && in_epidermis(region, &mut anchor, x, d_epi)
            && maps.as_ref().is_none_or(|m| {
                // A cell whose texels are all thin or all not names the thickness unread.
                !m.has_thin() || {
                    let d = cell
                        .and_then(|c| c.epidermis_mm)
                        .unwrap_or_else(|| m.epidermis_mm(x));
                    in_epidermis(region, &mut anchor, x, f64::from(d))
                }
            }) {
            Layer::Epidermis
        } else {
            Layer::Dermis
        };
        let (sa, ss) = match layer {
            Layer::Epidermis => epidermis,
            Layer::Dermis => dermis,
        };
        let xi = rng.random::<f32>() * cell.map_or(majorant as f32, |c| c.sigma_t);
        // Above the layer's largest σt in the cell the collision is null whatever the texel:
        // no nearest-point query.
        if let Some(c) = &cell {
            let largest = match layer {
                Layer::Epidermis => c.sigma_a.0,
                Layer::Dermis => c.sigma_a.1,
            };
            if xi >= largest + ss {
                continue;
            }
        }
        let excess = local
            .zip(cell.as_ref())
            .filter(|_| vol.absorption == Absorption::Excess);
        let sa = if let Some((m, c)) = excess {
            let (least, largest) = match layer {
                Layer::Epidermis => (c.least_sigma_a.0, c.sigma_a.0),
                Layer::Dermis => (c.least_sigma_a.1, c.sigma_a.1),
            };
            let least = least.min(largest);
            if xi >= least + ss {
                // Between the cell's least and largest σt: null, weighted by the share of that
                // band σt(x) leaves free (ratio tracking of the excess σa(x) − σa,min).
                let sa = m.sigma_a(layer == Layer::Epidermis, x);
                w *= f64::from(((largest - sa) / (largest - least)).clamp(0.0, 1.0));
                if w == 0.0 {
                    return out;
                }
                continue;
            }
            least
        } else {
            let sa = maps
                .as_ref()
                .map_or(sa, |m| m.sigma_a(layer == Layer::Epidermis, x));
            if xi >= sa + ss {
                continue; // null collision
            }
            sa
        };
        out.collisions += 1;
        if let Some(guide) = &guide {
            w *= guide.weight(&segment);
        }
        match after_collision(w, sa, ss, vol.roulette_below, rng) {
            Some(kept) => w = kept,
            None => return out,
        }
        match &guide {
            Some(guide) => (d, segment) = guide.scatter(layer, d, normal, &vol.hg, rng),
            None => {
                d = DVec3::from_array(scatter_direction(d.to_array(), &vol.hg, rng)).normalize();
            }
        }
        ahead = None;
    }
    out
}

/// A free flight: from `x` along unit `d` for `s` mm, starting on face `on_face` if any.
#[derive(Debug, Clone, Copy)]
struct Flight {
    x: DVec3,
    d: DVec3,
    s: f64,
    on_face: Option<[Vec3; 3]>,
}

/// The surface the flight could reach, found only when the anchor's bounds (refreshed when they
/// could decide) do not clear the whole flight: `Clear` when the flight stays inside the body,
/// `Lost` when the mesh is not closed around the point.
fn look_ahead(
    geometry: &Geometry,
    material: u32,
    region: &SurfaceDistance,
    anchor: &mut Anchor,
    f: Flight,
    rays: &mut u64,
) -> Ahead {
    let delta = anchor.x0.distance(f.x);
    if f.s < anchor.lo - delta {
        return Ahead::Clear;
    }
    // D(x) ≤ hi + δ: when the flight is longer, fresh bounds could not clear it.
    let lo = if f.s < anchor.hi + delta {
        *anchor = Anchor::at(region, f.x);
        anchor.lo
    } else {
        anchor.lo - delta
    };
    if f.s < lo {
        return Ahead::Clear;
    }
    // Only as far as the flight goes: a short ray visits few BVH nodes.
    *rays += 1;
    let ahead_min = ahead_min(f.x);
    let found = match region.segment_hit(f.x, f.d, f.s, f.on_face.as_ref(), ahead_min) {
        SegmentHit::Face { t, face } => Ahead::Surface(Boundary {
            t,
            p: f.x + f.d * t,
            face,
        }),
        SegmentHit::Clear => Ahead::Clear,
        SegmentHit::Unknown => surface_ahead(geometry, material, f, ahead_min),
    };
    match found {
        Ahead::Clear if !region.encloses(f.x + f.d * f.s) => Ahead::Lost,
        found => found,
    }
}

/// At the surface `b` from inside along `d`: the light leaves with probability T of its refracted
/// direction (the exit, carrying weight `w`), or is reflected (the new direction, and the face's
/// outward normal).
fn meet_surface<R: RngCore>(
    b: &Boundary,
    d: DVec3,
    vol: &SkinVolume,
    directional: &Directional,
    w: f64,
    rng: &mut R,
) -> Result<Exit, (DVec3, DVec3)> {
    let dir32 = d.as_vec3();
    let [a, b1, c] = b.face;
    let ng = (b1 - a).cross(c - a).normalize_or_zero();
    let n_out = if ng.dot(dir32) > 0.0 { ng } else { -ng };
    if let Some(t) = refract(dir32, -n_out, vol.eta)
        && rng.random::<f32>() < directional.transmittance(t.dot(n_out))
    {
        return Ok(Exit {
            p: b.p.as_vec3(),
            ng: n_out,
            dir: t,
            weight: w as f32,
        });
    }
    let n = n_out.as_dvec3();
    Err(((d - n * (2.0 * d.dot(n))).normalize(), n))
}

/// Whether `x` lies within `d_epi` of the surface (the epidermis), from the anchor's bounds where
/// they decide and from fresh bounds at `x` (which become the anchor) where they do not.
fn in_epidermis(region: &SurfaceDistance, anchor: &mut Anchor, x: DVec3, d_epi: f64) -> bool {
    let delta = anchor.x0.distance(x);
    if anchor.lo - delta > d_epi {
        false
    } else if anchor.hi + delta <= d_epi {
        true
    } else {
        *anchor = Anchor::at(region, x);
        anchor.hi <= d_epi
    }
}

/// The path's weight after a real collision of single-scattering albedo σs/(σa + σs), with Russian
/// roulette below `below` ([AK90]); `None` when the path ends.
fn after_collision<R: RngCore>(w: f64, sa: f32, ss: f32, below: f64, rng: &mut R) -> Option<f64> {
    let w = w * f64::from(ss / (sa + ss));
    if w == 0.0 {
        return None;
    }
    if w < below {
        if rng.random::<f64>() * below >= w {
            return None;
        }
        return Some(below);
    }
    Some(w)
}

/// A point and bounds lo ≤ D ≤ hi on its distance D to the surface, mm.
#[derive(Debug, Clone, Copy)]
struct Anchor {
    x0: DVec3,
    lo: f64,
    hi: f64,
}

impl Anchor {
    /// A point on the surface.
    fn surface(x0: DVec3) -> Self {
        Self {
            x0,
            lo: 0.0,
            hi: 0.0,
        }
    }

    /// The bounds at `x0`.
    fn at(region: &SurfaceDistance, x0: DVec3) -> Self {
        let (lo, hi) = region.bounds(x0);
        Self { x0, lo, hi }
    }
}

/// The surface ahead of the walk: distance along its direction, point (f64, on the face's plane)
/// and the face.
#[derive(Debug, Clone, Copy)]
struct Boundary {
    t: f64,
    p: DVec3,
    face: [Vec3; 3],
}

/// What lies along a flight.
#[derive(Debug, Clone, Copy)]
enum Ahead {
    /// The surface, within the flight.
    Surface(Boundary),
    /// No surface within the flight.
    Clear,
    /// The query passed over too many hits (the walk is no longer inside a closed mesh).
    Lost,
}

/// `p` moved onto the plane of the triangle `face`.
fn onto_face(face: &[Vec3; 3], p: DVec3) -> DVec3 {
    let [a, b, c] = face.map(Vec3::as_dvec3);
    let n = (b - a).cross(c - a).normalize_or_zero();
    p - n * n.dot(p - a)
}

/// What f64 plane intersections from `x` can still confuse with "on the face", mm.
fn ahead_min(x: DVec3) -> f64 {
    64.0 * f64::EPSILON * (1.0 + x.abs().max_element())
}

/// The first surface of `material` along the flight `f` (from the BVH), refined in f64 against
/// its face, passing over faces at most `ahead_min` ahead and the face the flight starts on.
fn surface_ahead(geometry: &Geometry, material: u32, f: Flight, ahead_min: f64) -> Ahead {
    let Flight {
        x,
        d,
        s: reach_mm,
        on_face,
    } = f;
    let scale = 1.0 + x.abs().max_element();
    // Beyond the f32 rounding of x (half an ulp of the coordinates) with a wide margin, and far
    // enough that the BVH sees surfaces just ahead of x.
    let back = (16.0 * f64::from(f32::EPSILON) * scale).max(2.0 * f64::from(BVH_MIN_T_MM));
    let (o, d32) = ((x - d * back).as_vec3(), d.as_vec3());
    // Past the reach by the f32 rounding of the origin and of t.
    let t_max = (back + reach_mm + back) as f32;
    let mut t_min = 0.0f32;
    for _ in 0..MAX_PASSED_HITS {
        let Some(hit) = geometry.intersect_material(o, d32, t_min, t_max, material) else {
            return Ahead::Clear;
        };
        let face = geometry.triangle(hit.triangle);
        let [a, b, c] = face.map(Vec3::as_dvec3);
        let n = (b - a).cross(c - a);
        let nd = n.dot(d);
        let t = if nd.abs() > 1e-9 * n.length() {
            n.dot(a - x) / nd
        } else {
            f64::from(hit.t) - back
        };
        if t > reach_mm {
            return Ahead::Clear;
        }
        if t > ahead_min && Some(face) != on_face {
            return Ahead::Surface(Boundary {
                t,
                p: x + d * t,
                face,
            });
        }
        // Past this hit (its t may be −0 when the origin rounds onto its plane).
        let passed = hit.t.max(t_min);
        t_min = if passed > 0.0 {
            f32::from_bits(passed.to_bits() + 1)
        } else {
            f32::MIN_POSITIVE
        };
    }
    Ahead::Lost
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Snell's law: n₁ sin θ₁ = n₂ sin θ₂, and total internal reflection past the critical angle.
    #[test]
    fn refraction_obeys_snell() {
        let n = Vec3::Z;
        let d = Vec3::new(0.6, 0.0, -0.8);
        let t = refract(d, n, 1.0 / 1.4).unwrap();
        assert!((t.x - 0.6 / 1.4).abs() < 1e-6 && t.z < 0.0, "{t}");
        assert!(refract(Vec3::new(0.8, 0.0, -0.6), n, 1.4).is_none());
        let t = refract(Vec3::new(0.6, 0.0, -0.8), n, 1.4).unwrap();
        assert!((t.x - 0.84).abs() < 1e-6, "{t}");
    }
}
