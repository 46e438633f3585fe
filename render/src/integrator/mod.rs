//! Spectral unidirectional path tracing with next-event estimation and multiple importance
//! sampling (power heuristic, [Veach 1997]), Russian roulette after a few bounces.
//!
//! One light (or the environment) is picked per shading point with probability proportional to a
//! rough estimate of the irradiance it delivers there, and sampled; at a subsurface exit point
//! every light that holds a share of that estimate is sampled instead ([`ExitLights`]). BSDF-sampled
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
//! Skin's body is rendered by one of two sibling integrators, each holding its own state
//! ([`BodyIntegrator`], built once per scene): the BSSRDF branch (`subsurface`: the BSSRDF
//! samples a probe segment, [`probe`] intersects it) with the volumetric walk at thin parts, or
//! the volumetric reference walk at every skin hit (`walk`, `crate::volumetric`).

mod lights;
pub mod probe;
mod subsurface;
mod walk;
pub mod widest;

use crate::bssrdf::{ProbeAxes, RadiusWavelength};
use crate::geometry::{SurfaceHit, offset_origin};
use crate::material::{Bsdf, Material};
use crate::sampler::{PathSampler, SamplerKind};
use crate::scene::{Hit, Scene};
use crate::spectrum::{SampledSpectrum, SampledWavelengths, WavelengthSampling};
use crate::volumetric::{SkinVolume, ThinParts, Volumetric};
use glam::Vec3;
use lights::{LightProbabilities, PrevVertex, Receiver, direct_light, light_probabilities};

/// Where each decision of a bounce reads its uniforms in the bounce's region of
/// [`PathSampler`] (sets of four dimensions: light choice and position at the hit with the
/// subsurface decision; the probe, or the BSDF sample and roulette; light at the exit point (two
/// sets: two dimensions for each of the first four lights under splitting, or up to two light
/// samples stratified by choice); the continuation from the exit point and roulette).
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
    /// has travelled, the footprint of skin's level of detail (`Material::collapses`; 0: off).
    pub pixel_angle_rad: f32,
    /// Where the path's uniforms come from.
    pub sampler: SamplerKind,
    /// How the path's wavelengths are drawn.
    pub wavelengths: WavelengthSampling,
    /// How subsurface probe axes are chosen (default [`ProbeAxes::DEFAULT`]).
    pub probe_axes: ProbeAxes,
    /// How the light at a subsurface exit point is sampled (default [`ExitLights::DEFAULT`]).
    pub exit_lights: ExitLights,
    /// Gather the light at a subsurface exit point at every skin hit, not only when the
    /// subsurface branch is chosen for the continuation.
    pub split_subsurface: bool,
    /// Probes (exit points, each with its light samples) at each skin hit whose exit light is
    /// gathered, ≥ 1; only the first continues the path (only with `split_subsurface`; default 2:
    /// BENCHMARKS.md, "Image noise").
    pub subsurface_probes: u32,
    /// How the wavelength whose profile draws a probe's radius is chosen (default
    /// [`RadiusWavelength::RENDER`]: mostly by the lanes' luminance).
    pub radius_wavelength: RadiusWavelength,
    /// How light leaves a thin part walked under the BSSRDF integrator (default
    /// [`ThinExit::LightSampled`]; the volumetric reference always refracts).
    pub thin_exit: ThinExit,
}

/// How the light at a subsurface exit point is sampled by next-event estimation (docs/physics.md
/// §8, "The light at an exit point").
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ExitLights {
    /// `samples` estimates, each choosing one light by its selection probability, averaged; with
    /// `stratified` the j-th of n chooses at u₀ + j/n instead of from its own uniform.
    Choose {
        /// Estimates per exit point, in [1, 64].
        samples: u32,
        /// Stratify the choices of one exit point.
        stratified: bool,
    },
    /// Every light whose selection probability p is at least 1/`budget` sampled once, each
    /// weaker one with probability `budget` · p (and its estimate divided by it): no
    /// light-choice variance among the lights that matter, such as a fill light in the key
    /// light's shadow.
    Split {
        /// The inverse of the least share sampled at every exit point, in [1, 10⁶].
        budget: f32,
    },
}

impl ExitLights {
    /// What renders use: splitting with budget 8. On the default scene budgets 8 and 16 give the
    /// same noise at equal CPU time, 4 and every light 1–2% more, two chosen samples 10% more
    /// (BENCHMARKS.md, "The default image: noise in 60 s").
    pub const DEFAULT: Self = Self::Split { budget: 8.0 };
}

impl Default for ExitLights {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// How the path leaves a thin part of skin after its volumetric walk (docs/physics.md §16.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ThinExit {
    /// The walk gives the exit point and the energy that leaves there; the direction follows the
    /// BSSRDF's S_ω, so the light at the exit is gathered by next-event estimation (MIS against
    /// the cosine-weighted continuation), as at a BSSRDF exit.
    #[default]
    LightSampled,
    /// The walk's own refracted direction, with no light sampling at the exit (the reference's
    /// estimator: unbiased, heavy-tailed where a small light is seen through the part).
    Refracted,
}

impl Default for PathSettings {
    fn default() -> Self {
        Self {
            max_depth: 16,
            rr_depth: 3,
            pixel_angle_rad: 0.0,
            sampler: SamplerKind::default(),
            wavelengths: WavelengthSampling::default(),
            probe_axes: ProbeAxes::DEFAULT,
            exit_lights: ExitLights::DEFAULT,
            split_subsurface: true,
            subsurface_probes: 2,
            radius_wavelength: RadiusWavelength::RENDER,
            thin_exit: ThinExit::LightSampled,
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

/// How skin's body is rendered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum IntegratorKind {
    /// The separable BSSRDF (with the volumetric walk at thin parts where the fidelity asks).
    #[default]
    Bssrdf,
    /// The volumetric random walk through the two layers at every skin hit: the reference.
    Volumetric,
}

/// The state of the integrator that renders skin's body, built once per scene.
#[derive(Debug)]
pub enum BodyIntegrator {
    /// The BSSRDF, with the thin-part walks of the materials whose choices ask for them and the
    /// wider profile each triangle of a skin with maps mixes into its radii.
    Bssrdf(Option<ThinParts>, widest::NearbyWidest),
    /// The volumetric walk through each skin material's meshes.
    Volumetric(Volumetric),
}

impl BodyIntegrator {
    /// The `kind` integrator's state for `scene`.
    #[must_use]
    pub fn build(scene: &Scene, kind: IntegratorKind) -> Self {
        match kind {
            IntegratorKind::Bssrdf => {
                Self::Bssrdf(ThinParts::build(scene), widest::NearbyWidest::build(scene))
            }
            IntegratorKind::Volumetric => Self::Volumetric(Volumetric::build(scene)),
        }
    }

    /// The node of the wider profile that triangle `triangle`'s BSSRDF mixes into its radii
    /// ([`widest::NearbyWidest`]).
    #[must_use]
    #[inline]
    pub fn widest_node(&self, triangle: u32) -> Option<usize> {
        match self {
            Self::Bssrdf(_, widest) => widest.node(triangle),
            Self::Volumetric(_) => None,
        }
    }

    /// The thin-part walks, if any skin takes them.
    #[must_use]
    pub fn thin_parts(&self) -> Option<&ThinParts> {
        match self {
            Self::Bssrdf(thin, _) => thin.as_ref(),
            Self::Volumetric(_) => None,
        }
    }

    /// The body to walk at this subsurface hit (`q_sss` > 0 there), if it is walked: every skin
    /// hit under the volumetric reference; a thin part of skin under the BSSRDF.
    fn volume_at(
        &self,
        scene: &Scene,
        si: &SurfaceHit,
        (ng, footprint_mm, q_sss): (Vec3, f32, f32),
        rays: &mut u64,
    ) -> Option<&SkinVolume> {
        match self {
            Self::Volumetric(v) => v.medium(si.material),
            Self::Bssrdf(Some(thin), _) if q_sss > 0.0 => {
                thin.walk_at(scene, si, ng, footprint_mm, rays)
            }
            Self::Bssrdf(..) => None,
        }
    }
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

/// The path tracer over one scene: the scene, the body integrator's state and the knobs.
#[derive(Clone, Copy)]
pub struct PathTracer<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// How skin's body is rendered, with its state.
    pub body: &'a BodyIntegrator,
    /// The knobs.
    pub settings: &'a PathSettings,
}

/// One path's running state.
struct Path {
    /// Radiance gathered so far.
    l: SampledSpectrum,
    /// Throughput.
    beta: SampledSpectrum,
    /// The next ray.
    o: Vec3,
    d: Vec3,
    prev: Option<PrevVertex>,
    /// Light probabilities at the current vertex and at a subsurface exit point.
    pick: LightProbabilities,
    exit_pick: LightProbabilities,
    /// Distance travelled from the camera, mm (the pixel footprint's scale).
    travelled_mm: f32,
    depth: u32,
    n_lights: usize,
    /// Whether a walk has already kept the hero wavelength alone (its lane then carries all N
    /// shares, so a later walk on the same path must not scale it again).
    hero_alone: bool,
}

impl Path {
    /// Continue along `d` from `p` (offset off the surface of normal `ng`).
    fn go(&mut self, p: Vec3, ng: Vec3, d: Vec3) {
        self.o = offset_origin(p, ng, d);
        self.d = d;
    }
}

/// A surface hit being shaded: the hit, its normals facing the viewer and its BSDF.
struct Shading<'s> {
    si: SurfaceHit,
    wo: Vec3,
    ng: Vec3,
    ns: Vec3,
    material: &'s Material,
    bsdf: Bsdf<'s>,
    /// Probability of the subsurface branch, and whether it was taken.
    q_sss: f32,
    take_sss: bool,
    /// Whether a light can reach the point (its light probabilities are in `Path::pick`).
    lit: bool,
    /// The maps' texel at the hit, for a skin with maps not collapsed to its diffuse body.
    texel: Option<crate::material::hetero::ExitTexel<'s>>,
}

/// What a branch did with the path.
enum Step {
    /// The path goes on from `Path::o` along `Path::d`.
    Continue,
    /// The path ends.
    Stop,
    /// The path goes on by sampling the surface's BSDF.
    Surface,
}

/// The random state of a path: its sampler and its count of traced rays.
type Random<'r> = (&'r mut PathSampler, &'r mut u64);

impl PathTracer<'_> {
    /// Radiance arriving at `origin` from direction `-dir` (i.e. along the ray), at the path's
    /// wavelengths; `rays` counts the rays traced (closest hit and shadow).
    pub fn radiance(
        &self,
        origin: Vec3,
        dir: Vec3,
        wl: &SampledWavelengths,
        sampler: &mut PathSampler,
        rays: &mut u64,
    ) -> SampledSpectrum {
        let scene = self.scene;
        let n_lights = scene.lights.len() + usize::from(scene.environment.is_some());
        let mut path = Path {
            l: SampledSpectrum::zero(),
            beta: SampledSpectrum::splat(1.0),
            o: origin,
            d: dir,
            prev: None,
            pick: LightProbabilities::new(),
            exit_pick: LightProbabilities::new(),
            travelled_mm: 0.0,
            depth: 0,
            n_lights,
            hero_alone: false,
        };
        for depth in 0..self.settings.max_depth {
            path.depth = depth;
            sampler.start_bounce(depth);
            *rays += 1;
            let si = match scene.intersect(path.o, path.d, 0.0, f32::INFINITY) {
                None => {
                    self.add_environment(&mut path, wl);
                    break;
                }
                Some(Hit::Light { index, t }) => {
                    self.add_emission(&mut path, index, t, wl);
                    break;
                }
                Some(Hit::Surface(si)) => si,
            };
            if !self.scatter(&mut path, si, wl, (sampler, rays)) {
                break;
            }
        }
        debug_assert!(path.l.is_finite(), "non-finite radiance {:?}", path.l);
        path.l
    }

    /// The environment seen by the path's ray, MIS-weighted against its light sampling.
    fn add_environment(&self, path: &mut Path, wl: &SampledWavelengths) {
        if let Some(env) = &self.scene.environment {
            let w = path.prev.as_ref().map_or(1.0, |v| {
                let pick_pdf = v.pick.last().copied().unwrap_or(0.0);
                power_heuristic(v.bsdf_pdf, pick_pdf * env.pdf(v.ns, path.d))
            });
            path.l += path.beta * env.radiance(path.d, wl) * w;
        }
    }

    /// Area light `index` hit at distance `t`, MIS-weighted against its light sampling.
    fn add_emission(&self, path: &mut Path, index: usize, t: f32, wl: &SampledWavelengths) {
        let light = &self.scene.lights[index];
        let w = path.prev.as_ref().map_or(1.0, |v| {
            let pick_pdf = v.pick.get(index).copied().unwrap_or(0.0);
            power_heuristic(v.bsdf_pdf, pick_pdf * light.pdf(v.p, path.d, t))
        });
        path.l += path.beta * light.radiance(wl) * w;
    }

    /// Shade the surface hit `si`: light by next-event estimation, then the subsurface branch
    /// (the volumetric walk or the BSSRDF) or the BSDF continuation; false when the path ends.
    fn scatter(
        &self,
        path: &mut Path,
        si: SurfaceHit,
        wl: &SampledWavelengths,
        (sampler, rays): Random<'_>,
    ) -> bool {
        let scene = self.scene;
        let wo = -path.d;
        // Two-sided shading: face both normals towards the viewer.
        let (ng, ns) = if si.ng.dot(wo) < 0.0 {
            (-si.ng, -si.ns)
        } else {
            (si.ng, si.ns)
        };
        let material = &scene.materials[si.material as usize];
        path.travelled_mm += si.t;
        let footprint_mm = self.settings.pixel_angle_rad * path.travelled_mm;
        let collapse = material.collapses(footprint_mm, sampler.independent_1d());
        // A skin with maps reads the texel once for the branch choice and every probe.
        let texel = match material {
            Material::Skin(s) if !collapse => s.maps.as_ref().map(|m| m.exit_texel(si.uv)),
            _ => None,
        };
        let bsdf = material.bsdf_lod(ns, si.uv, wl, &scene.textures, collapse, texel.as_ref());

        // Next-event estimation.
        let lit = path.n_lights > 0 && light_probabilities(scene, si.p, ns, &mut path.pick);
        if lit {
            let u_pick = sampler.get_1d();
            path.l += path.beta
                * direct_light(
                    scene,
                    Receiver { p: si.p, ng, ns },
                    wl,
                    (&path.pick, u_pick),
                    (&mut *sampler, &mut *rays),
                    |wi| (bsdf.eval(wo, wi) * wi.dot(ns).abs(), bsdf.pdf(wo, wi)),
                );
        }

        let q_sss = bsdf.subsurface_probability(wo);
        sampler.seek(dims::SUBSURFACE_CHOICE);
        let take_sss = q_sss > 0.0 && sampler.get_1d() < q_sss;
        let volume = self
            .body
            .volume_at(scene, &si, (ng, footprint_mm, q_sss), rays);
        let hit = Shading {
            si,
            wo,
            ng,
            ns,
            material,
            bsdf,
            q_sss,
            take_sss,
            lit,
            texel,
        };
        let step = match (volume, material) {
            // A skin rendered by the volumetric walk takes no BSSRDF exit: its body is walked.
            (Some(vol), Material::Skin(skin)) if take_sss && skin.subsurface.is_some() => {
                self.walk_body(path, &hit, vol, wl, (sampler, rays))
            }
            (None, Material::Skin(skin))
                if skin.subsurface.is_some()
                    && (take_sss || (q_sss > 0.0 && self.settings.split_subsurface)) =>
            {
                self.bssrdf_branch(path, &hit, wl, (sampler, rays))
            }
            _ if take_sss => Step::Stop,
            _ => Step::Surface,
        };
        match step {
            Step::Continue => true,
            Step::Stop => false,
            Step::Surface => self.continue_by_bsdf(path, &hit, (sampler, rays)),
        }
    }

    /// Continue the path by sampling the BSDF; false when the path ends.
    fn continue_by_bsdf(
        &self,
        path: &mut Path,
        hit: &Shading<'_>,
        (sampler, _rays): Random<'_>,
    ) -> bool {
        sampler.seek(dims::CONTINUATION);
        let u_lobe = sampler.get_1d();
        let u = sampler.get_2d();
        let Some(bs) = hit.bsdf.sample(hit.wo, u_lobe, u) else {
            return false;
        };
        if bs.wi.dot(hit.ng) <= 0.0 || bs.f.is_black() {
            return false;
        }
        path.beta *= bs.f * (bs.wi.dot(hit.ns).abs() / bs.pdf);
        let bsdf_pdf = if bs.delta { f32::INFINITY } else { bs.pdf };
        let vertex = (hit.si.p, hit.ns, bsdf_pdf);
        PrevVertex::record(
            &mut path.prev,
            &mut path.pick,
            hit.lit,
            path.n_lights,
            vertex,
        );
        if !russian_roulette(&mut path.beta, path.depth, self.settings, sampler) {
            return false;
        }
        path.go(hit.si.p, hit.ng, bs.wi);
        true
    }
}

/// Radiance arriving at `origin` from direction `-dir` in `scene` with skin's body rendered by
/// `body` ([`PathTracer::radiance`]).
#[allow(clippy::too_many_arguments)] // the tracer's three parts, the ray and the random state
pub fn radiance(
    scene: &Scene,
    body: &BodyIntegrator,
    settings: &PathSettings,
    origin: Vec3,
    dir: Vec3,
    wl: &SampledWavelengths,
    sampler: &mut PathSampler,
    rays: &mut u64,
) -> SampledSpectrum {
    PathTracer {
        scene,
        body,
        settings,
    }
    .radiance(origin, dir, wl, sampler, rays)
}
