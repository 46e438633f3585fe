//! Spectral unidirectional path tracing with next-event estimation and multiple importance
//! sampling (power heuristic, [Veach 1997]), Russian roulette after a few bounces.
//!
//! One light (or the environment) is picked per shading point with probability proportional to a
//! rough estimate of the irradiance it delivers there, and sampled; BSDF-sampled
//! rays that reach an area light or the environment add its emission with the MIS weight of the
//! same strategy pair. Delta lights (point, spot, distant) are only reached by light sampling.
//!
//! Skin with a BSSRDF (`crate::bssrdf`): at a skin hit the surface lobe is handled as any
//! BSDF (NEE + sampling); with the probability `Bsdf::subsurface_probability` the path instead
//! takes the subsurface branch: an exit point is sampled with probe rays, the throughput gets
//! T(θ_o) · R(r) · N / pdf (spectral MIS) · √(m_o m_i) / q, light at the exit point is gathered by
//! next-event estimation with S_ω (MIS against the cosine-weighted continuation), and the path
//! continues from the exit point with a cosine-weighted direction (weight T(θ_i) / c).

use crate::bssrdf::{ProbeFrame, texture_modulation};
use crate::geometry::offset_origin;
use crate::material::Material;
use crate::sampling::cosine_hemisphere;
use crate::scene::{Hit, Scene};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::volumetric;
use brdf::Frame;
use glam::{Vec2, Vec3};
use rand::Rng;
use std::f32::consts::FRAC_1_PI;

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
    if pdf_a == f32::INFINITY {
        return 1.0; // a delta strategy: the other cannot sample it
    }
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

/// Russian roulette after `settings.rr_depth` bounces: false when the path ends, else `beta`
/// is rescaled by the survival probability.
fn russian_roulette<R: Rng>(
    beta: &mut SampledSpectrum,
    depth: u32,
    settings: &PathSettings,
    rng: &mut R,
) -> bool {
    if depth + 1 >= settings.rr_depth {
        let survive = beta.max_value().min(1.0);
        if survive <= 0.0 || rng.random::<f32>() >= survive {
            return false;
        }
        *beta = *beta / survive;
    }
    true
}

/// Next-event estimation at `p` (geometric normal `ng`, shading normal `ns`): pick a light with
/// the probabilities `pick`, sample it, and return f · L_i · w / pdf with the power heuristic
/// against the scattering density; `scatter(wi)` gives (f(wi) · |cos θ_i| per wavelength, its
/// sampling density sr⁻¹).
#[allow(clippy::too_many_arguments)] // the shading point and its random state, nothing to group
fn direct_light<R: Rng>(
    scene: &Scene,
    p: Vec3,
    ng: Vec3,
    ns: Vec3,
    wl: &SampledWavelengths,
    pick: &[f32],
    rng: &mut R,
    rays: &mut u64,
    scatter: impl Fn(Vec3) -> (SampledSpectrum, f32),
) -> SampledSpectrum {
    let n_lights = pick.len();
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
        scene.lights[k].sample(p, u, wl)
    } else {
        scene.environment.as_ref().and_then(|e| e.sample(ns, u, wl))
    };
    let Some(ls) = sample else {
        return SampledSpectrum::zero();
    };
    if pick_pdf <= 0.0 || ls.pdf <= 0.0 || ls.wi.dot(ng) <= 0.0 || ls.li.is_black() {
        return SampledSpectrum::zero();
    }
    let (f, scatter_pdf) = scatter(ls.wi);
    if f.is_black() {
        return SampledSpectrum::zero();
    }
    let origin = offset_origin(p, ng, ls.wi);
    let tmax = if ls.distance_mm.is_finite() {
        (ls.distance_mm - (origin - p).length()) * (1.0 - 1e-4)
    } else {
        f32::INFINITY
    };
    *rays += 1;
    if scene.geometry.occluded(origin, ls.wi, tmax) {
        return SampledSpectrum::zero();
    }
    let light_pdf = pick_pdf * ls.pdf;
    let w = if ls.is_delta {
        1.0
    } else {
        power_heuristic(light_pdf, scatter_pdf)
    };
    f * ls.li * (w / light_pdf)
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
            l += beta
                * direct_light(scene, si.p, ng, ns, wl, &pick, rng, rays, |wi| {
                    (bsdf.eval(wo, wi) * wi.dot(ns).abs(), bsdf.pdf(wo, wi))
                });
        }

        // Subsurface branch (skin rendered with the BSSRDF, crate::bssrdf): light leaving here
        // entered at an exit point sampled with probe rays; continue from there.
        let q_sss = bsdf.subsurface_probability(wo);
        if q_sss > 0.0 && rng.random::<f32>() < q_sss {
            let Material::Skin(skin) = material else {
                break;
            };
            let Some(ss) = &skin.subsurface else { break };
            if let Some(vol) = scene
                .volumetric
                .as_ref()
                .and_then(|v| v.medium(si.material))
            {
                // The volumetric reference (crate::volumetric): refract in, walk, leave.
                // T at the shading normal, as the surface lobe's split (energy: ρ + T = 1).
                let t_o = ss.directional.transmittance(wo.dot(ns));
                let Some(d_in) = volumetric::walk::refract(-wo, ng, 1.0 / vol.eta) else {
                    break;
                };
                let walk = volumetric::walk(
                    scene,
                    vol,
                    &ss.directional,
                    si.p,
                    ng,
                    d_in,
                    wl.nm(0),
                    rng,
                    rays,
                );
                let Some(exit) = walk.exit else { break };
                beta = volumetric::hero_only(beta) * (exit.weight * t_o / q_sss);
                // No light was sampled at the exit: emission found next takes MIS weight 1.
                prev = None;
                if beta.is_black() || !russian_roulette(&mut beta, depth, settings, rng) {
                    break;
                }
                o = offset_origin(exit.p, exit.ng, exit.dir);
                d = exit.dir;
                continue;
            }
            let frame = ProbeFrame {
                x: bsdf.frame.x,
                y: bsdf.frame.y,
                n: bsdf.frame.z,
            };
            let u = [rng.random(), rng.random(), rng.random(), rng.random()];
            let flipped = ns.dot(si.ns) < 0.0;
            let Some(exit) = ss.sample_exit(
                &scene.geometry,
                si.material,
                si.p,
                &frame,
                flipped,
                wl,
                u,
                rays,
            ) else {
                break;
            };
            // S = T(θ_o) · R(r) · S_ω(ω_i) with the texture's √(m_o m_i) (bssrdf::separable); the
            // modulation is capped so that no wavelength's R_tot · m exceeds 1.
            let m_o = skin.texture_factor(si.uv, &scene.textures);
            let m_i = exit
                .hit
                .map_or(m_o, |h| skin.texture_factor(h.uv, &scene.textures));
            let m = texture_modulation(m_o, m_i);
            let t_o = ss.directional.transmittance(wo.dot(ns));
            let cap = SampledSpectrum(std::array::from_fn(|k| {
                m.min(1.0 / ss.table.total(wl.nm(k)).max(1e-6))
            }));
            beta *= exit.weight * cap * (t_o / q_sss);
            if beta.is_black() || !beta.is_finite() {
                break;
            }
            // At the exit point: next-event estimation with S_ω, then a cosine-weighted
            // continuation (weight S_ω cos / (cos / π) = T / c).
            let (eng, ens) = (exit.ng, exit.ns);
            let lit = n_lights > 0 && light_probabilities(scene, exit.p, ens, &mut pick);
            if lit {
                l += beta
                    * direct_light(scene, exit.p, eng, ens, wl, &pick, rng, rays, |wi| {
                        let c = wi.dot(ens);
                        (
                            SampledSpectrum::splat(ss.directional.s_omega(c) * c.max(0.0)),
                            c.max(0.0) * FRAC_1_PI,
                        )
                    });
            }
            let local = cosine_hemisphere(Vec2::new(rng.random(), rng.random()));
            let wi = Frame::from_normal(ens).to_world(local);
            if local.z <= 0.0 || wi.dot(eng) <= 0.0 {
                break;
            }
            beta *= ss.directional.cosine_sample_weight(local.z);
            if !lit {
                pick.clear();
                pick.resize(n_lights, 0.0);
            }
            let mut prev_pick = prev.take().map(|v| v.pick).unwrap_or_default();
            std::mem::swap(&mut prev_pick, &mut pick);
            prev = Some(PrevVertex {
                p: exit.p,
                ns: ens,
                bsdf_pdf: local.z * FRAC_1_PI,
                pick: prev_pick,
            });
            if !russian_roulette(&mut beta, depth, settings, rng) {
                break;
            }
            o = offset_origin(exit.p, eng, wi);
            d = wi;
            continue;
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
            bsdf_pdf: if bs.delta { f32::INFINITY } else { bs.pdf },
            pick: prev_pick,
        });
        if !russian_roulette(&mut beta, depth, settings, rng) {
            break;
        }
        o = offset_origin(si.p, ng, bs.wi);
        d = bs.wi;
    }
    debug_assert!(l.is_finite(), "non-finite radiance {l:?}");
    l
}
