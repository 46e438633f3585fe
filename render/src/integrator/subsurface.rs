//! The BSSRDF branch of the path at a skin hit (`crate::bssrdf`): light leaving here entered at an
//! exit point sampled with a probe ([`super::probe`]); light at the exit point is gathered by
//! next-event estimation with S_ω, and the path may continue from there. With
//! `split_subsurface` the light at the exit point is gathered at every skin hit (weight 1) and
//! only the continuation is chosen between the two branches (weight 1/q); without it the whole
//! branch is chosen (weight 1/q). Both are unbiased; splitting removes the variance of skipping
//! the exit's light whenever the surface branch is taken.

use super::lights::{
    LightProbabilities, PrevVertex, Receiver, direct_light, light_probabilities,
    split_direct_light, split_rates,
};
use super::{ExitLights, Path, PathTracer, Random, Shading, Step, dims, probe, russian_roulette};
use crate::bssrdf::{
    Directional, Exit, GainCorners, ProbeFrame, Subsurface, curvature, texture_modulation,
};
use crate::material::hetero::{ExitTexel, LaneCurvature, ProfileBlend};
use crate::material::{Material, SkinMaterial};
use crate::sampler::PathSampler;
use crate::sampling::cosine_hemisphere;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use brdf::Frame;
use glam::Vec3;
use std::f32::consts::FRAC_1_PI;

/// Where the light a BSSRDF sample carries leaves toward the viewer, for the azimuthal lobe
/// (`bssrdf::azimuth`): the cosine at the point it leaves from and its horizontal direction of
/// travel (unit, in that point's tangent plane). On curved skin the lobe compares it with the
/// incident light's horizontal direction in the entry point's tangent plane: the two planes are
/// taken as parallel, as the profile takes the surface between them as flat.
#[derive(Debug, Clone, Copy)]
pub(super) struct Outgoing {
    mu: f32,
    along: Vec3,
}

impl Outgoing {
    /// The direction `wo` leaving a point of outward shading normal `n` (None along the normal,
    /// where the lobe is 1, or below the surface).
    pub(super) fn new(wo: Vec3, n: Vec3) -> Option<Self> {
        let mu = wo.dot(n);
        let h = wo - mu * n;
        let len = h.length();
        (mu > 0.0 && len > 1e-6).then(|| Self {
            mu: mu.min(1.0),
            along: h / len,
        })
    }

    /// M at the incident direction `wi` (toward the light) at a point of normal `n`, cosine
    /// `cos_i` there, per lane (1 without a lobe or along the normal).
    fn lobe(
        self,
        ss: &Subsurface,
        wi: Vec3,
        n: Vec3,
        cos_i: f32,
        wl: &SampledWavelengths,
    ) -> Option<SampledSpectrum> {
        let lobe = ss.azimuth.as_ref()?;
        // The incident light travels along −wi: its horizontal direction of travel.
        let h = cos_i * n - wi;
        let len = h.length();
        (len > 1e-6).then(|| lobe.modulations(cos_i, self.mu, h.dot(self.along) / len, wl))
    }
}

/// What the BSSRDF reads of the skin light leaves at, once per hit for every probe: the maps'
/// texel, its curvature gains at the path's wavelengths, the angular factor T(θ_o) a(θ_o, λ)
/// toward the viewer and, with a gain per texel, the texel's normalisation c(λ).
#[derive(Clone, Copy)]
struct ExitSkin<'t, 'm> {
    texel: Option<&'t ExitTexel<'m>>,
    curvature: Option<&'t LaneCurvature>,
    t_o: SampledSpectrum,
    c_o: Option<SampledSpectrum>,
}

/// The angular factor where light enters skin, S_ω π = T a / c: the material's, or the entry
/// texel's gain over the normalisation the two ends' rule gives (docs/physics.md §19.3).
#[derive(Clone, Copy)]
pub(super) enum EntryAngle<'a> {
    /// The material's angular factor.
    Material(&'a Directional),
    /// The entry texel's gain `gain` and the path's normalisation `c` per lane.
    Texel {
        gain: GainCorners<'a>,
        c: SampledSpectrum,
    },
}

impl EntryAngle<'_> {
    /// T a s / c at each of the path's wavelengths (the texel's).
    fn texel_factors(
        gain: &GainCorners<'_>,
        c: &SampledSpectrum,
        s: f32,
        cos_theta: f32,
        wl: &SampledWavelengths,
    ) -> SampledSpectrum {
        let f = gain.factors(cos_theta, wl);
        SampledSpectrum(std::array::from_fn(|k| {
            if c.0[k] > 0.0 {
                f.0[k] * s / c.0[k]
            } else {
                0.0
            }
        }))
    }

    /// T a / c at each of the path's wavelengths: the cosine-weighted continuation's weight.
    fn cosine_sample_weights(&self, cos_theta: f32, wl: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Self::Material(d) => d.cosine_sample_weights(cos_theta, wl),
            Self::Texel { gain, c } => Self::texel_factors(gain, c, 1.0, cos_theta, wl),
        }
    }

    /// S_ω = T a / (c π) at each of the path's wavelengths, sr⁻¹.
    fn s_omegas(&self, cos_theta: f32, wl: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Self::Material(d) => d.s_omegas(cos_theta, wl),
            Self::Texel { gain, c } => Self::texel_factors(gain, c, FRAC_1_PI, cos_theta, wl),
        }
    }
}

impl PathTracer<'_> {
    /// The BSSRDF branch at `hit` (a skin with a BSSRDF): the first probe's exit, the light at
    /// the further probes' exits (splitting), the light at the first exit and, when the branch
    /// was taken, the cosine-weighted continuation from it.
    pub(super) fn bssrdf_branch(
        &self,
        path: &mut Path,
        hit: &Shading<'_>,
        wl: &SampledWavelengths,
        (sampler, rays): Random<'_>,
    ) -> Step {
        let Material::Skin(skin) = hit.material else {
            return Step::Surface;
        };
        let Some(ss) = &skin.subsurface else {
            return Step::Surface;
        };
        let texel = hit
            .texel
            .or_else(|| skin.maps.as_ref().map(|m| m.exit_texel(hit.si.uv)));
        let curvature = skin
            .maps
            .as_ref()
            .zip(texel.as_ref())
            .and_then(|(m, t)| m.lane_curvature(wl, t));
        let cos_o = hit.wo.dot(hit.ns);
        let gain_o = texel.as_ref().and_then(|t| t.gain);
        let exit_skin = ExitSkin {
            texel: texel.as_ref(),
            curvature: curvature.as_ref(),
            t_o: gain_o.map_or_else(
                || ss.directional.factors(cos_o, wl),
                |g| g.factors(cos_o, wl),
            ),
            c_o: gain_o.map(|g| g.normalisations(wl)),
        };
        let found =
            self.subsurface_exit(skin, (ss, exit_skin), hit, wl, (&mut *sampler, &mut *rays));
        let outgoing = Outgoing::new(hit.wo, hit.ns);
        // Further probes at the same skin hit (splitting): each gathers the light at its own exit
        // point from its own scrambled sequence; the mean over the probes is the estimate, and
        // the continuation keeps the first probe's exit.
        let probes = if self.settings.split_subsurface {
            self.settings.subsurface_probes.max(1)
        } else {
            1
        };
        let light_scale = if self.settings.split_subsurface {
            1.0
        } else {
            1.0 / hit.q_sss
        } / probes as f32;
        if probes > 1 && hit.q_sss > 0.0 {
            for k in 1..probes {
                let mut fork = sampler.fork(k);
                if let Some((exit, w, angle)) =
                    self.subsurface_exit(skin, (ss, exit_skin), hit, wl, (&mut fork, &mut *rays))
                {
                    let (direct, _) = self.exit_light(
                        (ss, angle),
                        &exit,
                        wl,
                        (&mut fork, &mut *rays),
                        &mut path.exit_pick,
                        outgoing,
                    );
                    path.l += path.beta * w * direct * light_scale;
                }
            }
        }
        let Some((exit, weight, angle)) = found else {
            return if hit.take_sss {
                Step::Stop
            } else {
                Step::Surface
            };
        };
        let beta_exit = path.beta * weight;
        // At the exit point: next-event estimation with S_ω, then the continuation.
        let (direct, lit_exit) = self.exit_light(
            (ss, angle),
            &exit,
            wl,
            (&mut *sampler, &mut *rays),
            &mut path.exit_pick,
            outgoing,
        );
        path.l += beta_exit * direct * light_scale;
        if !hit.take_sss {
            return Step::Surface;
        }
        self.continue_from_exit(
            path,
            hit,
            (ss, angle),
            &exit,
            (beta_exit, lit_exit, outgoing),
            (wl, sampler),
        )
    }

    /// The subsurface branch was taken: continue from `exit` in a cosine-weighted direction
    /// (weight S_ω cos / (cos / π) = T a / c of the entry's `angle`, times `beta_exit` / q,
    /// times the azimuthal lobe toward `outgoing`); `lit_exit` tells whether a light could reach
    /// the exit (its probabilities are in `Path::exit_pick`).
    pub(super) fn continue_from_exit(
        &self,
        path: &mut Path,
        hit: &Shading<'_>,
        (ss, angle): (&Subsurface, EntryAngle<'_>),
        exit: &Exit,
        (beta_exit, lit_exit, outgoing): (SampledSpectrum, bool, Option<Outgoing>),
        (wl, sampler): (&SampledWavelengths, &mut PathSampler),
    ) -> Step {
        let (eng, ens) = (exit.ng, exit.ns);
        sampler.seek(dims::EXIT_CONTINUATION);
        let local = cosine_hemisphere(sampler.get_2d());
        let wi = Frame::from_normal(ens).to_world(local);
        if local.z <= 0.0 || wi.dot(eng) <= 0.0 {
            return Step::Stop;
        }
        let mut w = angle.cosine_sample_weights(local.z, wl);
        if let Some(m) = outgoing.and_then(|o| o.lobe(ss, wi, ens, local.z, wl)) {
            w *= m;
        }
        path.beta = beta_exit * w / hit.q_sss;
        let vertex = (exit.p, ens, local.z * FRAC_1_PI);
        PrevVertex::record(
            &mut path.prev,
            &mut path.exit_pick,
            lit_exit,
            path.n_lights,
            vertex,
        );
        if !russian_roulette(&mut path.beta, path.depth, self.settings, sampler) {
            return Step::Stop;
        }
        path.go(exit.p, eng, wi);
        Step::Continue
    }

    /// Sample where the light leaving skin at `hit` entered (a probe, [`probe::sample_exit`]),
    /// and the throughput factor of the path through the skin: T(θ_o) · R(r) · N / pdf ·
    /// √(m_o m_i), the texture's modulation capped so that no wavelength's R_tot · m exceeds 1
    /// (`bssrdf::separable`), and the angular factor where the light entered. None when the
    /// probe found nothing or the factor is 0 or not finite.
    fn subsurface_exit<'s>(
        &self,
        skin: &'s SkinMaterial,
        (ss, exit_skin): (&'s Subsurface, ExitSkin<'_, 's>),
        hit: &Shading<'_>,
        wl: &SampledWavelengths,
        (sampler, rays): Random<'_>,
    ) -> Option<(Exit, SampledSpectrum, EntryAngle<'s>)> {
        let scene = self.scene;
        let f = &hit.bsdf.frame;
        let frame = ProbeFrame {
            x: f.x,
            y: f.y,
            n: f.z,
        };
        sampler.seek(dims::PROBE);
        let u = [
            sampler.get_1d(),
            sampler.get_1d(),
            sampler.get_1d(),
            sampler.get_1d(),
        ];
        let si = &hit.si;
        let flipped = hit.ns.dot(si.ns) < 0.0;
        // With maps, radii follow the profile of the skin the light leaves, mixed under the
        // geometric rule with the widest within the probe's reach (the grid's widest where that
        // is not known); under the exit rule the combined profile is the exit's own.
        let texel = exit_skin.texel;
        let (ss, wide) = match skin.maps.as_ref().zip(texel.and_then(|t| t.sampling)) {
            Some((maps, own)) if maps.blend == ProfileBlend::Exit => (own, None),
            Some((maps, own)) => {
                let near = self.body.widest_node(si.triangle);
                (
                    own,
                    Some(near.and_then(|n| maps.node_table(n)).unwrap_or(&*ss.table)),
                )
            }
            None => (ss, None),
        };
        let exit = probe::sample_exit(
            &scene.geometry,
            ss,
            wide,
            si.material,
            si.p,
            &frame,
            &self.settings.probe_axes,
            self.settings.radius_wavelength,
            flipped,
            wl,
            u,
            rays,
        )?;
        let t_o = exit_skin.t_o;
        if let (Some(maps), Some(texel)) = (&skin.maps, texel) {
            // The profile of the skin at both ends instead of the texture's modulation.
            let entry = maps.entry_texel(exit.hit.map_or(si.uv, |h| h.uv));
            // Each end's own curvature term (the probe carries none with maps); the local
            // fallback keeps the planar weight.
            let depth = exit
                .hit
                .and_then(|_| curvature::depth_below_tangent_mm(si.p, frame.n, exit.p, exit.ns));
            let weight = maps.profile(wl, &entry, texel, exit.r_mm, (depth, exit_skin.curvature))
                * exit.per_profile
                * t_o;
            let angle = match (entry.gain, exit_skin.c_o) {
                (Some(gain), Some(c_o)) => {
                    let c_i = gain.normalisations(wl);
                    EntryAngle::Texel {
                        gain,
                        c: SampledSpectrum(std::array::from_fn(|k| {
                            maps.blend.combine(c_i.0[k], c_o.0[k])
                        })),
                    }
                }
                _ => EntryAngle::Material(&ss.directional),
            };
            return (!weight.is_black() && weight.is_finite()).then_some((exit, weight, angle));
        }
        let m_o = skin.texture_factor(si.uv, &scene.textures);
        let m_i = exit
            .hit
            .map_or(m_o, |h| skin.texture_factor(h.uv, &scene.textures));
        let m = texture_modulation(m_o, m_i);
        let cap = SampledSpectrum(std::array::from_fn(|k| {
            m.min(1.0 / ss.table.at_lane(wl, k).total().max(1e-6))
        }));
        let weight = exit.weight * cap * t_o;
        (!weight.is_black() && weight.is_finite()).then_some((
            exit,
            weight,
            EntryAngle::Material(&ss.directional),
        ))
    }

    /// Next-event estimation at a subsurface exit point with S_ω of the entry's `angle` (MIS
    /// against the cosine-weighted continuation) by `settings.exit_lights`, and whether any
    /// light can reach the point (`pick` gets each light's strategy weight there).
    pub(super) fn exit_light(
        &self,
        (ss, angle): (&Subsurface, EntryAngle<'_>),
        exit: &Exit,
        wl: &SampledWavelengths,
        (sampler, rays): (&mut PathSampler, &mut u64),
        pick: &mut LightProbabilities,
        outgoing: Option<Outgoing>,
    ) -> (SampledSpectrum, bool) {
        let scene = self.scene;
        let n_lights = scene.lights.len() + usize::from(scene.environment.is_some());
        let (eng, ens) = (exit.ng, exit.ns);
        sampler.seek(dims::EXIT_LIGHT);
        let lit = n_lights > 0 && light_probabilities(scene, exit.p, ens, pick);
        if !lit {
            return (SampledSpectrum::zero(), false);
        }
        let at = Receiver {
            p: exit.p,
            ng: eng,
            ns: ens,
        };
        let scatter = |wi: Vec3| {
            let c = wi.dot(ens);
            let mut f = angle.s_omegas(c, wl) * c.max(0.0);
            if let Some(m) = outgoing.and_then(|o| o.lobe(ss, wi, ens, c, wl)) {
                f *= m;
            }
            (f, c.max(0.0) * FRAC_1_PI)
        };
        let (samples, stratified) = match self.settings.exit_lights {
            ExitLights::Split { budget } => {
                split_rates(pick, budget);
                let direct = split_direct_light(
                    scene,
                    at,
                    wl,
                    (pick, dims::EXIT_LIGHT),
                    (sampler, rays),
                    scatter,
                );
                return (direct, true);
            }
            ExitLights::Choose {
                samples,
                stratified,
            } => (samples.max(1), stratified),
        };
        let mut direct = SampledSpectrum::zero();
        let mut u_first = 0.0;
        for j in 0..samples {
            sampler.seek(dims::EXIT_LIGHT + 4 * j.min(1));
            let drawn = sampler.get_1d();
            // Stratified light choice: the j-th sample picks at u₀ + j/n (mod 1), each uniform, so
            // the n samples spread over the lights in proportion to their probabilities.
            let u_pick = if j == 0 {
                u_first = drawn;
                drawn
            } else if stratified {
                (u_first + j as f32 / samples as f32).fract()
            } else {
                drawn
            };
            direct += direct_light(
                scene,
                at,
                wl,
                (pick, u_pick),
                (&mut *sampler, &mut *rays),
                scatter,
            );
        }
        (direct / samples as f32, true)
    }
}
