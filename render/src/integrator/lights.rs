//! Light at a shading point: the light choice, next-event estimation with the power heuristic
//! ([Veach 1997]) and the previous vertex that weights emission found by scattering.

use super::power_heuristic;
use crate::geometry::offset_origin;
use crate::sampler::PathSampler;
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};
use smallvec::SmallVec;

/// Lights whose probabilities a path keeps without allocating (a scene with more spills to the
/// heap, still correct).
const INLINE_LIGHTS: usize = 8;

/// Light selection probabilities at a vertex, the environment last.
pub(super) type LightProbabilities = SmallVec<[f32; INLINE_LIGHTS]>;

/// Probability of picking each light (the environment last) at `p` with shading normal `n`,
/// ∝ its selection weight; written into `probs`, returns false when nothing can light `p`.
pub(super) fn light_probabilities(
    scene: &Scene,
    p: Vec3,
    n: Vec3,
    probs: &mut LightProbabilities,
) -> bool {
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

/// A shading point for next-event estimation: position, geometric normal `ng` and shading
/// normal `ns` (both facing the side light is gathered on).
#[derive(Debug, Clone, Copy)]
pub(super) struct Receiver {
    pub p: Vec3,
    pub ng: Vec3,
    pub ns: Vec3,
}

/// Next-event estimation at `at`: pick a light with the probabilities `pick` by the uniform
/// `u_pick`, sample it, and return f · L_i · w / pdf with the power heuristic against the
/// scattering density; `scatter(wi)` gives (f(wi) · |cos θ_i| per wavelength, its sampling
/// density sr⁻¹).
pub(super) fn direct_light(
    scene: &Scene,
    at: Receiver,
    wl: &SampledWavelengths,
    (pick, u_pick): (&[f32], f32),
    (sampler, rays): (&mut PathSampler, &mut u64),
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
    let u = sampler.get_2d();
    light_estimate(scene, at, wl, (k, pick[k]), (u, rays), scatter)
}

/// Uniforms of the first [`SPLIT_STRATIFIED`] lights under splitting come from the sampler's
/// region (two dimensions each); further lights draw independent numbers.
pub(super) const SPLIT_STRATIFIED: usize = 4;

/// Each light's expected number of samples under splitting with `budget` ≥ 1, written over its
/// selection probability in `probs`: min(1, budget · p). A light holding at least 1/`budget` of
/// the selection weight is sampled at every point; a weaker one with that probability.
pub(super) fn split_rates(probs: &mut LightProbabilities, budget: f32) {
    for p in probs.iter_mut() {
        *p = (budget * *p).min(1.0);
    }
}

/// Next-event estimation at `at` by splitting (docs/physics.md §8, "The light at an exit point"):
/// light k is sampled with probability `rates[k]` (from [`split_rates`]) and its estimate divided
/// by it, so the sum over lights is unbiased with no light-choice variance among the lights whose
/// rate is 1. Light k < [`SPLIT_STRATIFIED`] reads its two uniforms at offset `first_dim` + 2k of
/// the sampler's region; the rate's coin is independent.
pub(super) fn split_direct_light(
    scene: &Scene,
    at: Receiver,
    wl: &SampledWavelengths,
    (rates, first_dim): (&[f32], u32),
    (sampler, rays): (&mut PathSampler, &mut u64),
    scatter: impl Fn(Vec3) -> (SampledSpectrum, f32),
) -> SampledSpectrum {
    let mut sum = SampledSpectrum::zero();
    for (k, &rate) in rates.iter().enumerate() {
        if rate <= 0.0 || (rate < 1.0 && sampler.independent_1d() >= rate) {
            continue;
        }
        let u = if k < SPLIT_STRATIFIED {
            sampler.seek(first_dim + 2 * k as u32);
            sampler.get_2d()
        } else {
            Vec2::new(sampler.independent_1d(), sampler.independent_1d())
        };
        sum += light_estimate(scene, at, wl, (k, rate), (u, &mut *rays), &scatter);
    }
    sum
}

/// One sample of light `k` (the environment after the scene's lights) from the uniforms `u`,
/// taken with strategy weight `chosen` (its selection probability, or its expected number of
/// samples): f · L_i · w / (chosen · pdf), the power heuristic w against the scattering density
/// of `scatter`; one shadow ray, counted in `rays`.
fn light_estimate(
    scene: &Scene,
    at: Receiver,
    wl: &SampledWavelengths,
    (k, chosen): (usize, f32),
    (u, rays): (Vec2, &mut u64),
    scatter: impl Fn(Vec3) -> (SampledSpectrum, f32),
) -> SampledSpectrum {
    let Receiver { p, ng, ns } = at;
    let sample = if k < scene.lights.len() {
        scene.lights[k].sample(p, u, wl)
    } else {
        scene.environment.as_ref().and_then(|e| e.sample(ns, u, wl))
    };
    let Some(ls) = sample else {
        return SampledSpectrum::zero();
    };
    if chosen <= 0.0 || ls.pdf <= 0.0 || ls.wi.dot(ng) <= 0.0 || ls.li.is_black() {
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
    let light_pdf = chosen * ls.pdf;
    let w = if ls.is_delta {
        1.0
    } else {
        power_heuristic(light_pdf, scatter_pdf)
    };
    f * ls.li * (w / light_pdf)
}

/// Where the previous scattering event was, for MIS of emission found by BSDF sampling.
pub(super) struct PrevVertex {
    pub ns: Vec3,
    pub bsdf_pdf: f32,
    /// Each light's strategy weight there, environment last: its selection probability, or
    /// its expected number of samples under splitting ([`split_rates`]).
    pub pick: LightProbabilities,
    pub p: Vec3,
}

impl PrevVertex {
    /// Make the vertex (position, shading normal, density of the direction sampled there, sr⁻¹)
    /// the previous one: it takes over `pick` (zeroed first when nothing lit it), and `pick`
    /// gets the old vertex's buffer back.
    pub fn record(
        prev: &mut Option<PrevVertex>,
        pick: &mut LightProbabilities,
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
