//! The volumetric branch of the path at a skin hit (`crate::volumetric`, docs/physics.md §15,
//! §16.6): refract into the body, random-walk through its two layers, leave where the walk does.
//! Under the volumetric reference the path leaves along the walk's refracted direction; at a thin
//! part under the BSSRDF integrator ([`ThinExit::LightSampled`]) the walk gives the exit point and
//! the energy leaving there, and the exit is shaded as a BSSRDF exit: light sampled with S_ω, the
//! path continued cosine-weighted.

use super::subsurface::EntryAngle;
use super::{BodyIntegrator, Path, PathTracer, Random, Shading, Step, ThinExit, russian_roulette};
use crate::bssrdf::Exit;
use crate::material::Material;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::volumetric::{self, SkinVolume};

impl PathTracer<'_> {
    /// Walk the body `vol` under `hit` (the subsurface branch was taken) and continue from where
    /// the walk leaves, at the hero wavelength only.
    pub(super) fn walk_body(
        &self,
        path: &mut Path,
        hit: &Shading<'_>,
        vol: &SkinVolume,
        wl: &SampledWavelengths,
        (sampler, rays): Random<'_>,
    ) -> Step {
        let Material::Skin(skin) = hit.material else {
            return Step::Stop;
        };
        let Some(ss) = &skin.subsurface else {
            return Step::Stop;
        };
        // T at the shading normal, as the surface lobe's split (energy: ρ + T = 1).
        let t_o = ss.directional.transmittance(hit.wo.dot(hit.ns));
        let Some(d_in) = volumetric::walk::refract(-hit.wo, hit.ng, 1.0 / vol.eta) else {
            return Step::Stop;
        };
        let walk = volumetric::walk(
            &self.scene.geometry,
            vol,
            &ss.directional,
            &hit.si,
            d_in,
            wl.nm(0),
            sampler.rng(),
            rays,
        );
        let Some(exit) = walk.exit else {
            return Step::Stop;
        };
        // The hero takes the other lanes' shares once per path: a second walk (light that left
        // one stretch of skin and entered another) finds them already ended.
        let beta_hero = if path.hero_alone {
            path.beta
        } else {
            path.hero_alone = true;
            volumetric::hero_only(path.beta)
        };
        let beta_exit = beta_hero * (exit.weight * t_o);
        let thin = matches!(self.body, BodyIntegrator::Bssrdf(..));
        if thin && self.settings.thin_exit == ThinExit::LightSampled {
            // The walk chose to leave here (with probability T(θ) at its own direction): its
            // weight is the energy leaving, which S_ω spreads over the outgoing directions.
            let at = Exit {
                p: exit.p,
                ng: exit.ng,
                ns: exit.ng,
                hit: None,
                weight: SampledSpectrum::splat(1.0),
                per_profile: SampledSpectrum::splat(1.0),
                r_mm: (exit.p - hit.si.p).length(),
            };
            let angle = EntryAngle::Material(&ss.directional);
            let (direct, lit) = self.exit_light(
                (ss, angle),
                &at,
                wl,
                (&mut *sampler, &mut *rays),
                &mut path.exit_pick,
                None,
            );
            path.l += beta_exit * direct / hit.q_sss;
            return self.continue_from_exit(
                path,
                hit,
                (ss, angle),
                &at,
                (beta_exit, lit, None),
                (wl, sampler),
            );
        }
        path.beta = beta_exit / hit.q_sss;
        // No light was sampled at the exit: emission found next takes MIS weight 1.
        path.prev = None;
        if path.beta.is_black()
            || !russian_roulette(&mut path.beta, path.depth, self.settings, sampler)
        {
            return Step::Stop;
        }
        path.go(exit.p, exit.ng, exit.dir);
        Step::Continue
    }
}
