//! The render loop: passes of one sample per pixel, each split into tiles rendered in parallel with
//! rayon, until the sample count or the time limit is reached (stopping at the last finished pass).
//! With a noise target, each pass samples only the pixels whose estimated noise is still above it
//! (see [`crate::adaptive`]); the decision is taken between passes from the film alone, so it
//! does not depend on the thread count either.
//!
//! Every pixel sample draws its uniforms from a [`PathSampler`] seeded from (seed, pixel, sample
//! index), and passes are added
//! to the film in order, so the image for a given seed and sample count does not depend on the
//! number of threads or on the tile schedule.

use crate::adaptive::{Accumulator, ErrorEstimate, MIN_SPP};
use crate::error::RenderError;
pub use crate::error::SettingError;
use crate::film::Film;
use crate::integrator::{BodyIntegrator, ExitLights, IntegratorKind, PathSettings, PathTracer};
use crate::sampler::{PathSampler, SamplerKind};
use crate::scene::Scene;
use crate::spectrum::{LAMBDA_MAX_NM, LAMBDA_MIN_NM, SampledWavelengths};
use glam::Vec2;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Tile edge, pixels.
pub const TILE: usize = 16;

/// Largest image side, pixels (a 16384² film of XYZ sums is 3 GiB).
pub const MAX_SIDE: usize = 16384;
/// z of the stopping rule's one-sided upper confidence bound: 1.645, 95% (docs/physics.md §17).
pub const STOP_CONFIDENCE_Z: f64 = 1.645;

/// Most worker threads accepted.
pub const MAX_THREADS: usize = 1024;
/// Longest path accepted, scattering events.
pub const MAX_DEPTH: u32 = 1024;
/// Most light samples per subsurface exit point, and most probes per skin hit, accepted.
pub const MAX_EXIT_LIGHT_SAMPLES: u32 = 64;
/// Largest light-splitting budget accepted at an exit point (`ExitLights::Split`).
pub const MAX_SPLIT_BUDGET: f32 = 1e6;

/// What to render and how long, as requested; [`RenderOptions::validate`] checks it once and
/// gives the [`RenderSettings`] that [`render`] takes.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderOptions {
    /// Image width, pixels, in [1, [`MAX_SIDE`]].
    pub width: usize,
    /// Image height, pixels, in [1, [`MAX_SIDE`]].
    pub height: usize,
    /// Samples (paths) per pixel, ≥ 1; with a noise target, the most any pixel takes.
    pub spp: u32,
    /// Per-pixel relative noise target in (0, 1) (0.02 = 2%): a pixel stops once its estimated
    /// noise is below it (None = every pixel takes `spp` samples).
    pub noise: Option<f64>,
    /// Fewest samples a pixel takes before the noise target may stop it, ≥ 2.
    pub min_spp: u32,
    /// z of the one-sided upper confidence bound a pixel's estimated error must bring within the
    /// noise target, in [0, 10] ([`STOP_CONFIDENCE_Z`]: 95%; 0 stops on the estimate itself;
    /// docs/physics.md §17).
    pub stop_confidence_z: f64,
    /// How each pixel's error is estimated for the noise target and the reported noise (None:
    /// [`ErrorEstimate::for_sampler`]); the half-based ones need a sampler whose even and odd
    /// samples are independent (not [`SamplerKind::Sobol`]).
    pub error_estimate: Option<ErrorEstimate>,
    /// Wall-clock budget: no pass is started that would end past it (None = no limit; at least
    /// one pass is always rendered).
    pub time_limit: Option<Duration>,
    /// Seed of every random number.
    pub seed: u64,
    /// Worker threads in [1, [`MAX_THREADS`]] (None = rayon's default, all cores).
    pub threads: Option<usize>,
    /// Path tracer knobs (`max_depth` in [1, [`MAX_DEPTH`]]).
    pub path: PathSettings,
    /// How skin's body is rendered (default the BSSRDF).
    pub integrator: IntegratorKind,
    /// Render one wavelength, nm, in [380, 780]: each pixel holds the spectral radiance there
    /// as a grey (R = G = B) instead of the colour of the visible spectrum (None = colour).
    pub wavelength_nm: Option<f32>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            width: 512,
            height: 512,
            spp: 64,
            noise: None,
            min_spp: MIN_SPP,
            stop_confidence_z: STOP_CONFIDENCE_Z,
            error_estimate: None,
            time_limit: None,
            seed: 1,
            threads: None,
            path: PathSettings::default(),
            integrator: IntegratorKind::Bssrdf,
            wavelength_nm: None,
        }
    }
}

impl RenderOptions {
    /// Check every option against its range.
    pub fn validate(self) -> Result<RenderSettings, SettingError> {
        let bad = |name, value: String, range| SettingError { name, value, range };
        if !(1..=MAX_SIDE).contains(&self.width) {
            return Err(bad("width", self.width.to_string(), "[1, 16384] pixels"));
        }
        if !(1..=MAX_SIDE).contains(&self.height) {
            return Err(bad("height", self.height.to_string(), "[1, 16384] pixels"));
        }
        if self.spp == 0 {
            return Err(bad("spp", "0".into(), "[1, 2^32)"));
        }
        if let Some(n) = self.noise
            && !(n > 0.0 && n < 1.0)
        {
            return Err(bad("noise", n.to_string(), "(0, 1) relative"));
        }
        if self.min_spp < 2 {
            return Err(bad("min_spp", self.min_spp.to_string(), "[2, 2^32)"));
        }
        if !(0.0..=10.0).contains(&self.stop_confidence_z) {
            return Err(bad(
                "stop_confidence_z",
                self.stop_confidence_z.to_string(),
                "[0, 10]",
            ));
        }
        if let Some(e) = self.error_estimate
            && e.needs_independent_halves()
            && self.path.sampler == SamplerKind::Sobol
        {
            return Err(bad(
                "error_estimate",
                format!("{e:?}"),
                "SampleVariance with the one-sequence Sobol sampler (its halves are not independent)",
            ));
        }
        if let Some(t) = self.threads
            && !(1..=MAX_THREADS).contains(&t)
        {
            return Err(bad("threads", t.to_string(), "[1, 1024]"));
        }
        match self.path.exit_lights {
            ExitLights::Choose { samples, .. }
                if !(1..=MAX_EXIT_LIGHT_SAMPLES).contains(&samples) =>
            {
                return Err(bad(
                    "path.exit_lights.samples",
                    samples.to_string(),
                    "[1, 64]",
                ));
            }
            ExitLights::Split { budget } if !(1.0..=MAX_SPLIT_BUDGET).contains(&budget) => {
                return Err(bad(
                    "path.exit_lights.budget",
                    budget.to_string(),
                    "[1, 1e6]",
                ));
            }
            _ => {}
        }
        if !(1..=MAX_EXIT_LIGHT_SAMPLES).contains(&self.path.subsurface_probes) {
            return Err(bad(
                "path.subsurface_probes",
                self.path.subsurface_probes.to_string(),
                "[1, 64]",
            ));
        }
        if let Some(nm) = self.wavelength_nm
            && !(LAMBDA_MIN_NM..=LAMBDA_MAX_NM).contains(&nm)
        {
            return Err(bad("wavelength_nm", nm.to_string(), "[380, 780] nm"));
        }
        if !(1..=MAX_DEPTH).contains(&self.path.max_depth) {
            return Err(bad(
                "path.max_depth",
                self.path.max_depth.to_string(),
                "[1, 1024]",
            ));
        }
        Ok(RenderSettings(self))
    }
}

/// Render options that passed [`RenderOptions::validate`]: only these reach [`render`] (the
/// default options are valid).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RenderSettings(RenderOptions);

impl std::ops::Deref for RenderSettings {
    type Target = RenderOptions;
    fn deref(&self) -> &RenderOptions {
        &self.0
    }
}

/// How the render went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderStats {
    /// Most samples any pixel took.
    pub spp: u32,
    /// Mean samples per pixel.
    pub mean_spp: f64,
    /// Estimated RMS relative noise over the lit pixels (the two-seed metric, predicted).
    pub noise: f64,
    /// Pixels stopped by the noise target.
    pub converged: usize,
    /// Wall-clock time of the passes.
    pub elapsed: Duration,
    /// Rays traced (closest-hit and shadow).
    pub rays: u64,
}

impl RenderStats {
    /// Rays per second.
    #[must_use]
    pub fn rays_per_second(&self) -> f64 {
        self.rays as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }

    /// Seconds per mean sample per pixel (wall-clock time of one full-image pass).
    #[must_use]
    pub fn seconds_per_spp(&self) -> f64 {
        self.elapsed.as_secs_f64() / self.mean_spp.max(1e-9)
    }
}

/// A tile's sampled pixels (row-major index) and their XYZ.
type TileResult = Vec<(usize, [f32; 3])>;

/// Where a render stands after a pass, for a progress display.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Passes done (samples per pixel of the pixels still sampling).
    pub done: u32,
    /// Most passes the render takes.
    pub spp: u32,
    /// Pixels whose noise is below the target.
    pub converged: usize,
    /// Pixels of the image.
    pub pixels: usize,
    /// Image-wide noise estimate, relative (refreshed at most every 0.5 s; infinite before the
    /// second pass).
    pub noise: f64,
    /// Rays traced per second so far.
    pub rays_per_second: f64,
    /// The render stops after this pass because the next would end past the time limit.
    pub time_limit_reached: bool,
}

/// Render `scene` into a new film with validated `settings`, skin's body by
/// `settings.integrator`.
pub fn render(
    scene: &Scene,
    settings: &RenderSettings,
) -> Result<(Film, RenderStats), RenderError> {
    let body = BodyIntegrator::build(scene, settings.integrator);
    render_with(scene, &body, settings, None)
}

/// Render `scene` with skin's body by `body` (whose state, such as the thin-part walks' counts,
/// the caller keeps), calling `on_pass` after every pass.
pub fn render_with(
    scene: &Scene,
    body: &BodyIntegrator,
    settings: &RenderSettings,
    on_pass: Option<&mut (dyn FnMut(&Progress) + Send)>,
) -> Result<(Film, RenderStats), RenderError> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(t) = settings.threads {
        builder = builder.num_threads(t);
    }
    let pool = builder.build().map_err(|e| RenderError::Threads {
        threads: settings.threads,
        message: e.to_string(),
    })?;
    let tracer = PathTracer {
        scene,
        body,
        settings: &settings.path,
    };
    pool.install(|| render_passes(&tracer, settings, on_pass))
}

/// How often the image-wide noise estimate of [`Progress`] is refreshed.
const PROGRESS_NOISE_EVERY: Duration = Duration::from_millis(500);

/// One path through pixel (`x`, `y`) for pass `sample`: its colour, CIE XYZ (a grey at one
/// wavelength with `wavelength_nm`); counts its rays in `rays`.
fn sample_pixel(
    tracer: &PathTracer<'_>,
    s: &RenderSettings,
    (x, y): (usize, usize),
    sample: u32,
    rays: &mut u64,
) -> [f32; 3] {
    let (w, h) = (s.width, s.height);
    let aspect = w as f32 / h as f32;
    let i = y * w + x;
    let mut sampler = PathSampler::new(s.path.sampler, s.seed, i as u64, sample);
    sampler.start_camera();
    let u_wl = sampler.get_1d();
    let wl = s.wavelength_nm.map_or_else(
        || SampledWavelengths::sample(u_wl, s.path.wavelengths),
        SampledWavelengths::fixed,
    );
    let jitter = sampler.get_2d();
    let film_pos = Vec2::new(
        (x as f32 + jitter.x) / w as f32,
        (y as f32 + jitter.y) / h as f32,
    );
    // A pinhole reads no lens point: its two uniforms would cost a Sobol set of their own.
    let camera = &tracer.scene.camera;
    let lens = if camera.has_lens() {
        sampler.get_2d()
    } else {
        Vec2::ZERO
    };
    let (o, d) = camera.generate_ray(film_pos, aspect, lens);
    let l = tracer.radiance(o, d, &wl, &mut sampler, rays);
    // A non-finite sample is dropped and counted by the accumulator.
    if s.wavelength_nm.is_some() {
        wl.to_grey_xyz(&l)
    } else {
        wl.to_xyz(&l)
    }
}

fn render_passes(
    tracer: &PathTracer<'_>,
    s: &RenderSettings,
    mut on_pass: Option<&mut (dyn FnMut(&Progress) + Send)>,
) -> Result<(Film, RenderStats), RenderError> {
    let (w, h) = (s.width, s.height);
    let estimate = s
        .error_estimate
        .unwrap_or_else(|| ErrorEstimate::for_sampler(s.path.sampler));
    let mut acc = Accumulator::new(w, h, estimate);
    let mut active = vec![true; w * h];
    let mut converged = 0usize;
    let tiles: Vec<(usize, usize)> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    let rays = AtomicU64::new(0);
    let start = Instant::now();
    let mut last = Duration::ZERO;
    let (mut noise, mut noise_at) = (f64::INFINITY, Duration::ZERO);
    for sample in 0..s.spp {
        let results: Vec<TileResult> = tiles
            .par_iter()
            .map(|&(x0, y0)| {
                let mut tile_rays = 0u64;
                let mut out = Vec::with_capacity(TILE * TILE);
                for y in y0..(y0 + TILE).min(h) {
                    for x in x0..(x0 + TILE).min(w) {
                        let i = y * w + x;
                        if !active[i] {
                            continue;
                        }
                        let xyz = sample_pixel(tracer, s, (x, y), sample, &mut tile_rays);
                        out.push((i, xyz));
                    }
                }
                rays.fetch_add(tile_rays, Ordering::Relaxed);
                out
            })
            .collect();
        for (i, v) in results.into_iter().flatten() {
            acc.add(i, sample, v);
        }
        let done = sample + 1;
        // Pixels stop after an even pass only, so both halves of a pixel hold equally many samples.
        if let Some(target) = s.noise
            && done >= s.min_spp
            && done % 2 == 0
        {
            converged = acc.update_active(&mut active, target, s.min_spp, s.stop_confidence_z);
        }
        let elapsed = start.elapsed();
        // The image-wide estimate costs a pass over every pixel and is only shown, so it is formed
        // for a progress callback and at most every PROGRESS_NOISE_EVERY: a pass late in a
        // noise-targeted render samples a few pixels, and work over the whole image at every
        // pass would then set the frame's time.
        if done >= 2 && on_pass.is_some() && elapsed >= noise_at + PROGRESS_NOISE_EVERY {
            noise = acc.noise_estimate();
            noise_at = elapsed;
        }
        // Stop when the next pass would end past the limit (passes shrink as pixels converge, so
        // the last one is a safe guess).
        let pass_time = elapsed.checked_sub(last).unwrap_or_default();
        last = elapsed;
        let all_converged = converged == w * h;
        let time_limit_reached = !all_converged
            && s.time_limit
                .is_some_and(|limit| elapsed + pass_time > limit && done < s.spp);
        if let Some(f) = on_pass.as_mut() {
            f(&Progress {
                done,
                spp: s.spp,
                converged,
                pixels: w * h,
                noise,
                rays_per_second: rays.load(Ordering::Relaxed) as f64
                    / elapsed.as_secs_f64().max(1e-9),
                time_limit_reached,
            });
        }
        if all_converged || time_limit_reached {
            break;
        }
    }
    let film = acc.to_film();
    let stats = RenderStats {
        spp: film.spp(),
        mean_spp: acc.mean_spp(),
        noise: acc.noise_estimate(),
        converged,
        elapsed: start.elapsed(),
        rays: rays.load(Ordering::Relaxed),
    };
    Ok((film, stats))
}
