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
//! continues from the exit point with a cosine-weighted direction (weight T(θ_i) / c). With
//! `split_subsurface` the exit light is gathered at every skin hit, from `subsurface_probes`
//! probes (each from its own scrambled sequence, [`PathSampler::fork`]) whose mean is the
//! estimate; most of the image's variance is this first-hit subsurface light (BENCHMARKS.md).
//!
//! The sampler's dimension table and the knobs are plain lists of named constants and documented
//! fields; their shape repeats other such lists (the surface lobe's parameters) by nature.

use crate::bssrdf::{
    Exit, ProbeAxes, ProbeFrame, RadiusWavelength, Subsurface, texture_modulation,
};
use crate::geometry::SurfaceHit;

use crate::geometry::offset_origin;
use crate::material::{Material, SkinMaterial};
use crate::sampler::{PathSampler, SamplerKind};
use crate::sampling::cosine_hemisphere;
use crate::scene::{Hit, Scene};
use crate::spectrum::{SampledSpectrum, SampledWavelengths, WavelengthSampling};
use crate::volumetric;
use brdf::Frame;
use glam::Vec3;
use std::f32::consts::FRAC_1_PI;

/// Where each decision of a bounce reads its uniforms in the bounce's region of
/// [`PathSampler`] (sets of four dimensions: light choice and position at the hit with the
/// subsurface decision; the probe, or the BSDF sample and roulette; light at the exit point (two
/// sets: up to two light samples stratified); the continuation from the exit point and roulette).
mod dims {
    pub const SUBSURFACE_CHOICE: u32 = 3;
    pub const PROBE: u32 = 4;
    pub const CONTINUATION: u32 = 4;
    pub const EXIT_LIGHT: u32 = 8;
    pub const EXIT_CONTINUATION: u32 = 16;
}

/// Knobs of the path tracer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathSettings {
    /// Maximum number of scattering events per path.
    pub max_depth: u32,
    /// Bounces before Russian roulette starts.
    pub rr_depth: u32,
    /// Angle one pixel subtends, radians (`Camera::pixel_angle_rad`): times the distance a path
    /// has travelled, the footprint of skin's level of detail (`crate::fidelity::lod`; 0: off).
    pub pixel_angle_rad: f32,
    /// Where the path's uniforms come from.
    pub sampler: SamplerKind,
    /// How the path's wavelengths are drawn.
    pub wavelengths: WavelengthSampling,
    /// How subsurface probe axes are chosen (default [`ProbeAxes::RENDER`]).
    pub probe_axes: ProbeAxes,
    /// Light samples (next-event estimates, averaged) at each subsurface exit point, ≥ 1
    /// (default 2: BENCHMARKS.md, "Image noise").
    pub exit_light_samples: u32,
    /// Gather the light at a subsurface exit point at every skin hit, not only when the
    /// subsurface branch is chosen for the continuation.
    pub split_subsurface: bool,
    /// Probes (exit points, each with its light samples) at each skin hit whose exit light is
    /// gathered, ≥ 1; only the first continues the path (only with `split_subsurface`; default 2:
    /// BENCHMARKS.md, "Image noise").
    pub subsurface_probes: u32,
    /// Stratify the light choice of the light samples at one exit point (u₀ + j/n) instead of
    /// drawing each from its own uniform.
    pub stratified_exit_lights: bool,
    /// How the wavelength whose profile draws a probe's radius is chosen (default
    /// [`RadiusWavelength::RENDER`]: mostly by the lanes' luminance).
    pub radius_wavelength: RadiusWavelength,
}

impl Default for PathSettings {
    fn default() -> Self {
        Self {
            max_depth: 16,
            rr_depth: 3,
            pixel_angle_rad: 0.0,
            sampler: SamplerKind::default(),
            wavelengths: WavelengthSampling::default(),
            probe_axes: ProbeAxes::RENDER,
            exit_light_samples: 2,
            split_subsurface: true,
            subsurface_probes: 2,
            stratified_exit_lights: false,
            radius_wavelength: RadiusWavelength::RENDER,
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
fn russian_roulette(
    beta: &mut SampledSpectrum,
    depth: u32,
    settings: &PathSettings,
    sampler: &mut PathSampler,
) -> bool {
    if depth + 1 >= settings.rr_depth {
        let survive = beta.max_value().min(1.0);
        if survive <= 0.0 || sampler.get_1d() >= survive {
            return false;
        }
        *beta = *beta / survive;
    }
    true
}

/// Next-event estimation at `p` (geometric normal `ng`, shading normal `ns`): pick a light with
/// the probabilities `pick` by the uniform `u_pick`, sample it, and return f · L_i · w / pdf with
/// the power heuristic against the scattering density; `scatter(wi)` gives (f(wi) · |cos θ_i| per
/// wavelength, its sampling density sr⁻¹).
#[allow(clippy::too_many_arguments)] // the shading point and its random state, nothing to group
fn direct_light(
    scene: &Scene,
    p: Vec3,
    ng: Vec3,
    ns: Vec3,
    wl: &SampledWavelengths,
    (pick, u_pick): (&[f32], f32),
    sampler: &mut PathSampler,
    rays: &mut u64,
    scatter: impl Fn(Vec3) -> (SampledSpectrum, f32),
) -> SampledSpectrum {
    let n_lights = pick.len();
    // Pick a light by its selection probability (inverse CDF over a handful of lights).
    let mut k = 0;
    let mut cdf = pick[0];
    while u_pick >= cdf && k + 1 < n_lights {
        k += 1;
        cdf += pick[k];
    }
    let pick_pdf = pick[k];
    let u = sampler.get_2d();
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

/// The shading point where a subsurface path leaves towards the viewer.
struct Entry<'a> {
    si: &'a SurfaceHit,
    /// Shading normal facing the viewer.
    ns: Vec3,
    wo: Vec3,
    frame: &'a Frame,
}

/// Sample where the light leaving skin at `entry` entered (probe rays, `crate::bssrdf`), and the
/// throughput factor of the path through the skin: T(θ_o) · R(r) · N / pdf · √(m_o m_i), the
/// texture's modulation capped so that no wavelength's R_tot · m exceeds 1
/// (`bssrdf::separable`). None when the probe found nothing or the factor is 0 or not finite.
#[allow(clippy::too_many_arguments)] // the entry, the skin and the random state
fn subsurface_exit(
    scene: &Scene,
    settings: &PathSettings,
    skin: &SkinMaterial,
    ss: &Subsurface,
    entry: &Entry<'_>,
    wl: &SampledWavelengths,
    sampler: &mut PathSampler,
    rays: &mut u64,
) -> Option<(Exit, SampledSpectrum)> {
    let frame = ProbeFrame {
        x: entry.frame.x,
        y: entry.frame.y,
        n: entry.frame.z,
    };
    sampler.seek(dims::PROBE);
    let u = [
        sampler.get_1d(),
        sampler.get_1d(),
        sampler.get_1d(),
        sampler.get_1d(),
    ];
    let si = entry.si;
    let flipped = entry.ns.dot(si.ns) < 0.0;
    let exit = ss.sample_exit(
        &scene.geometry,
        si.material,
        si.p,
        &frame,
        &settings.probe_axes,
        settings.radius_wavelength,
        flipped,
        wl,
        u,
        rays,
    )?;
    let m_o = skin.texture_factor(si.uv, &scene.textures);
    let m_i = exit
        .hit
        .map_or(m_o, |h| skin.texture_factor(h.uv, &scene.textures));
    let m = texture_modulation(m_o, m_i);
    let t_o = ss.directional.transmittance(entry.wo.dot(entry.ns));
    let cap = SampledSpectrum(std::array::from_fn(|k| {
        m.min(1.0 / ss.table.total(wl.nm(k)).max(1e-6))
    }));
    let weight = exit.weight * cap * t_o;
    (!weight.is_black() && weight.is_finite()).then_some((exit, weight))
}

/// Next-event estimation at a subsurface exit point with S_ω (MIS against the cosine-weighted
/// continuation): the mean of `settings.exit_light_samples` light samples sharing the exit
/// (splitting), and whether any light can reach the point (`pick` holds its light probabilities).
#[allow(clippy::too_many_arguments)] // the exit and its random state
fn exit_light(
    scene: &Scene,
    settings: &PathSettings,
    ss: &Subsurface,
    exit: &Exit,
    wl: &SampledWavelengths,
    sampler: &mut PathSampler,
    rays: &mut u64,
    pick: &mut Vec<f32>,
) -> (SampledSpectrum, bool) {
    let n_lights = scene.lights.len() + usize::from(scene.environment.is_some());
    let (eng, ens) = (exit.ng, exit.ns);
    sampler.seek(dims::EXIT_LIGHT);
    let lit = n_lights > 0 && light_probabilities(scene, exit.p, ens, pick);
    if !lit {
        return (SampledSpectrum::zero(), false);
    }
    let n = settings.exit_light_samples.max(1);
    let mut direct = SampledSpectrum::zero();
    let mut u_first = 0.0;
    for j in 0..n {
        sampler.seek(dims::EXIT_LIGHT + 4 * j.min(1));
        let drawn = sampler.get_1d();
        // Stratified light choice: the j-th sample picks at u₀ + j/n (mod 1), each uniform, so
        // the n samples spread over the lights in proportion to their probabilities.
        let u_pick = if j == 0 {
            u_first = drawn;
            drawn
        } else if settings.stratified_exit_lights {
            (u_first + j as f32 / n as f32).fract()
        } else {
            drawn
        };
        direct += direct_light(
            scene,
            exit.p,
            eng,
            ens,
            wl,
            (pick, u_pick),
            sampler,
            rays,
            |wi| {
                let c = wi.dot(ens);
                (
                    SampledSpectrum::splat(ss.directional.s_omega(c) * c.max(0.0)),
                    c.max(0.0) * FRAC_1_PI,
                )
            },
        );
    }
    (direct / n as f32, true)
}

/// Where the previous scattering event was, for MIS of emission found by BSDF sampling.
struct PrevVertex {
    ns: Vec3,
    bsdf_pdf: f32,
    /// Light selection probabilities there (environment last).
    pick: Vec<f32>,
    p: Vec3,
}

impl PrevVertex {
    /// Make the vertex (position, shading normal, density of the direction sampled there, sr⁻¹)
    /// the previous one: it takes over `pick` (zeroed first when nothing lit it), and `pick`
    /// gets the old vertex's buffer back, so no path allocates after its first bounce.
    fn record(
        prev: &mut Option<PrevVertex>,
        pick: &mut Vec<f32>,
        lit: bool,
        n_lights: usize,
        (p, ns, bsdf_pdf): (Vec3, Vec3, f32),
    ) {
        if !lit {
            pick.clear();
            pick.resize(n_lights, 0.0);
        }
        let mut prev_pick = prev.take().map(|v| v.pick).unwrap_or_default();
        std::mem::swap(&mut prev_pick, pick);
        *prev = Some(PrevVertex {
            p,
            ns,
            bsdf_pdf,
            pick: prev_pick,
        });
    }
}

/// Radiance arriving at `origin` from direction `-dir` (i.e. along the ray), at the path's
/// wavelengths; `rays` counts the rays traced (closest hit and shadow).
pub fn radiance(
    scene: &Scene,
    settings: &PathSettings,
    origin: Vec3,
    dir: Vec3,
    wl: &SampledWavelengths,
    sampler: &mut PathSampler,
    rays: &mut u64,
) -> SampledSpectrum {
    let n_lights = scene.lights.len() + usize::from(scene.environment.is_some());
    let mut pick = Vec::with_capacity(n_lights);
    let mut exit_pick = Vec::with_capacity(n_lights);
    let mut l = SampledSpectrum::zero();
    let mut beta = SampledSpectrum::splat(1.0);
    let (mut o, mut d) = (origin, dir);
    let mut prev: Option<PrevVertex> = None;
    let mut travelled_mm = 0.0f32;

    for depth in 0..settings.max_depth {
        sampler.start_bounce(depth);
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
        travelled_mm += si.t;
        let footprint_mm = settings.pixel_angle_rad * travelled_mm;
        let collapse =
            crate::fidelity::lod::collapse(material, footprint_mm, sampler.independent_1d());
        let bsdf = material.bsdf_lod(ns, si.uv, wl, &scene.textures, collapse);

        // Next-event estimation.
        let lit = n_lights > 0 && light_probabilities(scene, si.p, ns, &mut pick);
        if lit {
            let u_pick = sampler.get_1d();
            l += beta
                * direct_light(
                    scene,
                    si.p,
                    ng,
                    ns,
                    wl,
                    (&pick, u_pick),
                    sampler,
                    rays,
                    |wi| (bsdf.eval(wo, wi) * wi.dot(ns).abs(), bsdf.pdf(wo, wi)),
                );
        }

        // Subsurface branch (skin rendered with the BSSRDF, crate::bssrdf): light leaving here
        // entered at an exit point sampled with probe rays; continue from there. With
        // `split_subsurface` the light at the exit point is gathered at every skin hit (weight
        // 1) and only the continuation is chosen between the two branches (weight 1/q); without
        // it the whole branch is chosen (weight 1/q). Both are unbiased; splitting removes the
        // variance of skipping the exit's light whenever the surface branch is taken.
        let q_sss = bsdf.subsurface_probability(wo);
        sampler.seek(dims::SUBSURFACE_CHOICE);
        let take_sss = q_sss > 0.0 && sampler.get_1d() < q_sss;
        // The volumetric reference walks every skin hit; otherwise a thin part of skin is walked
        // (crate::fidelity::transport) and the rest takes the BSSRDF.
        let volume = match (&scene.volumetric, &scene.thin_parts) {
            (Some(v), _) => v.medium(si.material),
            (None, Some(thin)) if q_sss > 0.0 => thin.walk_at(scene, &si, ng, footprint_mm, rays),
            _ => None,
        };
        // A skin rendered by the volumetric walk takes no BSSRDF exit: its body is walked.
        if take_sss
            && let (Some(vol), Material::Skin(skin)) = (volume, material)
            && let Some(ss) = &skin.subsurface
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
                sampler.rng(),
                rays,
            );
            let Some(exit) = walk.exit else { break };
            beta = volumetric::hero_only(beta) * (exit.weight * t_o / q_sss);
            // No light was sampled at the exit: emission found next takes MIS weight 1.
            prev = None;
            if beta.is_black() || !russian_roulette(&mut beta, depth, settings, sampler) {
                break;
            }
            o = offset_origin(exit.p, exit.ng, exit.dir);
            d = exit.dir;
            continue;
        }
        let found = match material {
            Material::Skin(skin)
                if volume.is_none() && (take_sss || (q_sss > 0.0 && settings.split_subsurface)) =>
            {
                skin.subsurface.as_ref().and_then(|ss| {
                    let entry = Entry {
                        si: &si,
                        ns,
                        wo,
                        frame: &bsdf.frame,
                    };
                    subsurface_exit(scene, settings, skin, ss, &entry, wl, sampler, rays)
                        .map(|(exit, w)| (ss, exit, w))
                })
            }
            _ => None,
        };
        // Further probes at the same skin hit (splitting): each gathers the light at its own exit
        // point from its own scrambled sequence; the mean over the probes is the estimate, and
        // the continuation (below) keeps the first probe's exit.
        let probes = if settings.split_subsurface {
            settings.subsurface_probes.max(1)
        } else {
            1
        };
        let light_scale = if settings.split_subsurface {
            1.0
        } else {
            1.0 / q_sss
        } / probes as f32;
        if probes > 1
            && q_sss > 0.0
            && volume.is_none()
            && let Material::Skin(skin) = material
            && let Some(ss) = &skin.subsurface
        {
            let entry = Entry {
                si: &si,
                ns,
                wo,
                frame: &bsdf.frame,
            };
            for k in 1..probes {
                let mut fork = sampler.fork(k);
                if let Some((exit, w)) =
                    subsurface_exit(scene, settings, skin, ss, &entry, wl, &mut fork, rays)
                {
                    let (direct, _) = exit_light(
                        scene,
                        settings,
                        ss,
                        &exit,
                        wl,
                        &mut fork,
                        rays,
                        &mut exit_pick,
                    );
                    l += beta * w * direct * light_scale;
                }
            }
        }
        if let Some((ss, exit, weight)) = found {
            let beta_exit = beta * weight;
            // At the exit point: next-event estimation with S_ω, then a cosine-weighted
            // continuation (weight S_ω cos / (cos / π) = T / c).
            let (eng, ens) = (exit.ng, exit.ns);
            let (direct, lit_exit) = exit_light(
                scene,
                settings,
                ss,
                &exit,
                wl,
                sampler,
                rays,
                &mut exit_pick,
            );
            l += beta_exit * direct * light_scale;
            if take_sss {
                sampler.seek(dims::EXIT_CONTINUATION);
                let local = cosine_hemisphere(sampler.get_2d());
                let wi = Frame::from_normal(ens).to_world(local);
                if local.z <= 0.0 || wi.dot(eng) <= 0.0 {
                    break;
                }
                beta = beta_exit * (ss.directional.cosine_sample_weight(local.z) / q_sss);
                let vertex = (exit.p, ens, local.z * FRAC_1_PI);
                PrevVertex::record(&mut prev, &mut exit_pick, lit_exit, n_lights, vertex);
                if !russian_roulette(&mut beta, depth, settings, sampler) {
                    break;
                }
                o = offset_origin(exit.p, eng, wi);
                d = wi;
                continue;
            }
        } else if take_sss {
            break;
        }

        // Continue the path by sampling the BSDF.
        sampler.seek(dims::CONTINUATION);
        let u_lobe = sampler.get_1d();
        let u = sampler.get_2d();
        let Some(bs) = bsdf.sample(wo, u_lobe, u) else {
            break;
        };
        if bs.wi.dot(ng) <= 0.0 || bs.f.is_black() {
            break;
        }
        beta *= bs.f * (bs.wi.dot(ns).abs() / bs.pdf);
        let bsdf_pdf = if bs.delta { f32::INFINITY } else { bs.pdf };
        PrevVertex::record(&mut prev, &mut pick, lit, n_lights, (si.p, ns, bsdf_pdf));
        if !russian_roulette(&mut beta, depth, settings, sampler) {
            break;
        }
        o = offset_origin(si.p, ng, bs.wi);
        d = bs.wi;
    }
    debug_assert!(l.is_finite(), "non-finite radiance {l:?}");
    l
}
