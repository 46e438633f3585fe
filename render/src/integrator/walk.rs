//! The volumetric branch of the path at a skin hit (`crate::volumetric`, docs/physics.md §15):
//! refract into the body, random-walk through its two layers, leave where the walk does.

use super::{Path, PathTracer, Random, Shading, Step, russian_roulette};
use crate::material::Material;
use crate::spectrum::SampledWavelengths;
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
        path.beta = volumetric::hero_only(path.beta) * (exit.weight * t_o / hit.q_sss);
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
