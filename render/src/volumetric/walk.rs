//! One random walk through a skin volume (docs/physics.md §15): delta (Woodcock) tracking against
//! the majorant σ̄ = max(σt_epidermis, σt_dermis) at the hero wavelength, so the layer boundary
//! (a distance from the surface, not a plane) is crossed exactly without ever being intersected;
//! at a real collision the weight keeps σs/σt (implicit capture) and the direction turns by
//! Henyey–Greenstein — both from `multipole::exact::montecarlo`, the photon physics of the layered Monte
//! Carlo; below its roulette threshold the walk plays its Russian roulette. At the surface the
//! walk meets the skin's boundary: total internal reflection beyond the critical angle, else it
//! leaves with probability T(θ_out) (the same energy split as the BSSRDF's, `Directional`:
//! 1 − F for the smooth surface, 1 − ρ_dr for the oily lobe), refracted by Snell's law, or is
//! reflected back in.

use super::SkinVolume;
use crate::bssrdf::Directional;
use crate::geometry::Geometry;
use glam::{DVec3, Vec3};
use multipole::exact::montecarlo::{ROULETTE_SURVIVAL, ROULETTE_THRESHOLD, scatter_direction};
use rand::{Rng, RngCore};

/// Most real collisions per walk (a bound on the cost; a walk reaching it is dropped, a bias
/// below 1e-6 of the energy for skin — BENCHMARKS.md).
pub const MAX_COLLISIONS: u32 = 1_000_000;

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

/// Walk light that has just entered the skin volume `vol` (material `material`) at `p` along the
/// refracted direction `dir` (pointing in), at wavelength `nm`; `rays` counts the rays cast.
#[allow(clippy::too_many_arguments)] // the walk's medium, start and random state
pub fn walk<R: RngCore>(
    geometry: &Geometry,
    vol: &SkinVolume,
    directional: &Directional,
    p: Vec3,
    ng_out: Vec3,
    dir: Vec3,
    nm: f32,
    rng: &mut R,
    rays: &mut u64,
) -> Walk {
    let epidermis = (
        vol.epidermis.sigma_a.at_nm(nm),
        vol.epidermis.sigma_s.at_nm(nm),
    );
    let dermis = (vol.dermis.sigma_a.at_nm(nm), vol.dermis.sigma_s.at_nm(nm));
    let media = Media {
        epidermis,
        dermis,
        majorant: (epidermis.0 + epidermis.1).max(dermis.0 + dermis.1),
    };
    let mut out = Walk {
        exit: None,
        collisions: 0,
        tentative: 0,
    };
    debug_assert!(
        dir.dot(ng_out) <= 1e-4,
        "the walk starts with light going in"
    );
    // The walk starts on the surface itself: an origin offset into the skin would skip medium,
    // and the offset that clears a triangle grows with the coordinates (2·10⁻⁵ of them: 0.02 mm,
    // two mean free paths in the blue, on a 1 m mesh). Leaving the surface, the ray ignores hits
    // closer than that instead. The position is kept in f64: f32 steps of 0.01 mm would round by
    // 10% at 10 m from the origin.
    let mut x = p.as_dvec3();
    let mut t_min = surface_clearance(p);
    let mut d = dir;
    let mut w = 1.0f64;
    while out.collisions < MAX_COLLISIONS {
        *rays += 1;
        let Some(hit) = geometry.intersect(x.as_vec3(), d, t_min, f32::INFINITY) else {
            // Not a closed mesh around x: the light is lost.
            return out;
        };
        t_min = 0.0;
        match fly(&mut x, &mut d, &mut w, hit.t, vol, &media, &mut out, rng) {
            Flight::Absorbed => return out,
            Flight::Scattered => continue,
            Flight::Surface => {}
        }
        // At the surface, from inside.
        let n_out = if hit.ng.dot(d) > 0.0 { hit.ng } else { -hit.ng };
        let leaving = refract(d, -n_out, vol.eta);
        if let Some(t) = leaving {
            let cos_out = t.dot(n_out);
            if rng.random::<f32>() < directional.transmittance(cos_out) {
                out.exit = Some(Exit {
                    p: hit.p,
                    ng: n_out,
                    dir: t,
                    weight: w as f32,
                });
                return out;
            }
        }
        d -= n_out * (2.0 * d.dot(n_out));
        x = hit.p.as_dvec3();
        t_min = surface_clearance(hit.p);
    }
    out
}

/// The walk's two media at its wavelength, (σa, σs) in mm⁻¹, and the majorant σ̄ of σt.
struct Media {
    epidermis: (f32, f32),
    dermis: (f32, f32),
    majorant: f32,
}

/// How a flight towards the surface ended.
enum Flight {
    /// It reached the surface `left` mm ahead.
    Surface,
    /// It scattered at a real collision (`x`, `d` and `w` updated).
    Scattered,
    /// The light was absorbed (weight 0, or lost at roulette).
    Absorbed,
}

/// Delta-track from `x` along `d` towards the surface `left` mm ahead: null collisions pass, the
/// first real one scatters (implicit capture in `w`, roulette below its threshold).
#[allow(clippy::too_many_arguments)] // the walk's state, its media and its random state
fn fly<R: RngCore>(
    x: &mut DVec3,
    d: &mut Vec3,
    w: &mut f64,
    mut left: f32,
    vol: &SkinVolume,
    media: &Media,
    out: &mut Walk,
    rng: &mut R,
) -> Flight {
    loop {
        // A clear medium (σ̄ = 0) flies straight to the surface.
        let step = if media.majorant > 0.0 {
            -(1.0 - rng.random::<f32>()).ln() / media.majorant
        } else {
            f32::INFINITY
        };
        if step >= left {
            return Flight::Surface;
        }
        left -= step;
        *x += d.as_dvec3() * f64::from(step);
        out.tentative += 1;
        let (sa, ss) = if vol.epidermis_region.within(x.as_vec3()) {
            media.epidermis
        } else {
            media.dermis
        };
        if rng.random::<f32>() * media.majorant >= sa + ss {
            continue; // null collision
        }
        out.collisions += 1;
        *w *= f64::from(ss / (sa + ss));
        if *w == 0.0 {
            return Flight::Absorbed;
        }
        if *w < ROULETTE_THRESHOLD {
            if rng.random::<f64>() >= ROULETTE_SURVIVAL {
                return Flight::Absorbed;
            }
            *w /= ROULETTE_SURVIVAL;
        }
        let u = scatter_direction(d.as_dvec3().to_array(), &vol.hg, rng);
        *d = DVec3::from_array(u).normalize().as_vec3();
        return Flight::Scattered;
    }
}

/// Distance along a ray leaving the surface at `p` within which hits are its own triangle's:
/// a few hundred f32 ulps of the coordinates (the scale of `geometry::offset_origin`).
fn surface_clearance(p: Vec3) -> f32 {
    2e-5 * (1.0 + p.abs().max_element())
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
