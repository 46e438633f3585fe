//! Spectral unidirectional path tracing with next-event estimation and multiple importance
//! sampling (power heuristic, [Veach 1997]), Russian roulette after a few bounces.
//!
//! One light (or the environment) is picked per shading point with probability proportional to a
//! rough estimate of the irradiance it delivers there, and sampled; BSDF-sampled
//! rays that reach an area light or the environment add its emission with the MIS weight of the
//! same strategy pair. Delta lights (point, spot, distant) are only reached by light sampling.

use crate::geometry::offset_origin;
use crate::scene::{Hit, Scene};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};
use rand::Rng;

/// Knobs of the path tracer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathSettings {
    /// Maximum number of scattering events per path.
    pub max_depth: u32,
    /// Bounces before Russian roulette starts.
    pub rr_depth: u32,
}

impl Default for PathSettings {
    fn default() -> Self {
        Self {
            max_depth: 16,
            rr_depth: 3,
        }
    }
}

/// Power heuristic with β = 2 for one sample from each of two strategies.
#[must_use]
pub fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    let (a, b) = (pdf_a * pdf_a, pdf_b * pdf_b);
    if a == 0.0 { 0.0 } else { a / (a + b) }
}

/// Probability of picking each light (the environment last) at `p` with shading normal `n`,
/// ∝ its selection weight;
/// written into `probs`, returns false when nothing can light `p`.
fn light_probabilities(scene: &Scene, p: Vec3, n: Vec3, probs: &mut Vec<f32>) -> bool {
    probs.clear();
    probs.extend(scene.lights.iter().map(|l| l.selection_weight(p, n)));
    if let Some(env) = &scene.environment {
        probs.push(env.selection_weight());
    }
    let total: f32 = probs.iter().sum();
    if !(total > 0.0 && total.is_finite()) {
        return false;
    }
    probs.iter_mut().for_each(|w| *w /= total);
    true
}

/// Where the previous scattering event was, for MIS of emission found by BSDF sampling.
struct PrevVertex {
    ns: Vec3,
    bsdf_pdf: f32,
    /// Light selection probabilities there (environment last).
    pick: Vec<f32>,
    p: Vec3,
}

/// Radiance arriving at `origin` from direction `-dir` (i.e. along the ray), at the path's
/// wavelengths; `rays` counts the rays traced (closest hit and shadow).
pub fn radiance<R: Rng>(
    scene: &Scene,
    settings: &PathSettings,
    origin: Vec3,
    dir: Vec3,
    wl: &SampledWavelengths,
    rng: &mut R,
    rays: &mut u64,
) -> SampledSpectrum {
    let n_lights = scene.lights.len() + usize::from(scene.environment.is_some());
    let mut pick = Vec::with_capacity(n_lights);
    let mut l = SampledSpectrum::zero();
    let mut beta = SampledSpectrum::splat(1.0);
    let (mut o, mut d) = (origin, dir);
    let mut prev: Option<PrevVertex> = None;

    for depth in 0..settings.max_depth {
        *rays += 1;
        let hit = scene.intersect(o, d, 0.0, f32::INFINITY);
        let si = match hit {
            None => {
                if let Some(env) = &scene.environment {
                    let w = prev.as_ref().map_or(1.0, |v| {
                        let pick_pdf = v.pick.last().copied().unwrap_or(0.0);
                        power_heuristic(v.bsdf_pdf, pick_pdf * env.pdf(v.ns, d))
                    });
                    l += beta * env.radiance(d, wl) * w;
                }
                break;
            }
            Some(Hit::Light { index, t }) => {
                let light = &scene.lights[index];
                let w = prev.as_ref().map_or(1.0, |v| {
                    let pick_pdf = v.pick.get(index).copied().unwrap_or(0.0);
                    power_heuristic(v.bsdf_pdf, pick_pdf * light.pdf(v.p, d, t))
                });
                l += beta * light.radiance(wl) * w;
                break;
            }
            Some(Hit::Surface(si)) => si,
        };

        let wo = -d;
        // Two-sided shading: face both normals towards the viewer.
        let (ng, ns) = if si.ng.dot(wo) < 0.0 {
            (-si.ng, -si.ns)
        } else {
            (si.ng, si.ns)
        };
        let material = &scene.materials[si.material as usize];
        let bsdf = material.bsdf(ns, si.uv, wl, &scene.textures);

        // Next-event estimation.
        let lit = n_lights > 0 && light_probabilities(scene, si.p, ns, &mut pick);
        if lit {
            // Pick a light by its selection probability (inverse CDF over a handful of lights).
            let u_pick: f32 = rng.random();
            let mut k = 0;
            let mut cdf = pick[0];
            while u_pick >= cdf && k + 1 < n_lights {
                k += 1;
                cdf += pick[k];
            }
            let pick_pdf = pick[k];
            let u = Vec2::new(rng.random(), rng.random());
            let sample = if k < scene.lights.len() {
                scene.lights[k].sample(si.p, u, wl)
            } else {
                scene.environment.as_ref().and_then(|e| e.sample(ns, u, wl))
            };
            if let Some(ls) = sample
                && pick_pdf > 0.0
                && ls.pdf > 0.0
                && ls.wi.dot(ng) > 0.0
                && !ls.li.is_black()
            {
                let f = bsdf.eval(wo, ls.wi) * ls.wi.dot(ns).abs();
                if !f.is_black() {
                    let origin = offset_origin(si.p, ng, ls.wi);
                    let tmax = if ls.distance_mm.is_finite() {
                        (ls.distance_mm - (origin - si.p).length()) * (1.0 - 1e-4)
                    } else {
                        f32::INFINITY
                    };
                    *rays += 1;
                    if !scene.geometry.occluded(origin, ls.wi, tmax) {
                        let light_pdf = pick_pdf * ls.pdf;
                        let w = if ls.is_delta {
                            1.0
                        } else {
                            power_heuristic(light_pdf, bsdf.pdf(wo, ls.wi))
                        };
                        l += beta * f * ls.li * (w / light_pdf);
                    }
                }
            }
        }

        // Continue the path by sampling the BSDF.
        let u_lobe: f32 = rng.random();
        let u = Vec2::new(rng.random(), rng.random());
        let Some(bs) = bsdf.sample(wo, u_lobe, u) else {
            break;
        };
        if bs.wi.dot(ng) <= 0.0 || bs.f.is_black() {
            break;
        }
        beta *= bs.f * (bs.wi.dot(ns).abs() / bs.pdf);
        if !lit {
            pick.clear();
            pick.resize(n_lights, 0.0);
        }
        let mut prev_pick = prev.take().map(|v| v.pick).unwrap_or_default();
        std::mem::swap(&mut prev_pick, &mut pick);
        prev = Some(PrevVertex {
            p: si.p,
            ns,
            bsdf_pdf: bs.pdf,
            pick: prev_pick,
        });
        if depth + 1 >= settings.rr_depth {
            let survive = beta.max_value().min(1.0);
            if survive <= 0.0 || rng.random::<f32>() >= survive {
                break;
            }
            beta = beta / survive;
        }
        o = offset_origin(si.p, ng, bs.wi);
        d = bs.wi;
    }
    debug_assert!(l.is_finite(), "non-finite radiance {l:?}");
    l
}
