//! The volumetric walk's local majorant with chromophore maps (docs/physics.md §19.1): every
//! point's σa lies under its cell's bound, the cells' nearest-point search is the hierarchy's,
//! and the walk renders the same image with either majorant.

use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use render::integrator::{BodyIntegrator, IntegratorKind};
use render::renderer::{RenderOptions, render_with};
use render::scene::Scene;
use render::testing::hetero::{
    SLAB_DEPTH_MM, SLAB_SIDE_MM, columns, melanin_exr, region, strip_scene,
};
use render::volumetric::Volumetric;
use render::volumetric::majorant::Majorant;

/// C_m of a texel at (x, y) mm: dark (0.3) left of x = 0, and right of it a speckle of C_m in
/// [0.01, 0.11] from a hash of the texel (so neighbouring texels differ).
fn split_speckle(x: f32, y: f32) -> f32 {
    if x < 0.0 {
        return 0.3;
    }
    let h = (x * 12.9898 + y * 78.233).sin() * 43_758.547;
    0.01 + 0.1 * (h - h.floor())
}

fn slab(dir: &std::path::Path, half_mm: f32, columns: usize) -> Scene {
    std::fs::write(dir.join("maps.exr"), melanin_exr(128, 128, split_speckle)).unwrap();
    strip_scene(dir, half_mm, columns, "maps = \"maps.exr\"")
}

/// At 20,000 random points in the slab (most within 5 mm of its top face, where the grid's
/// cells are), the parameters read at the nearest surface point (the hierarchy's search, tested
/// against brute force in `nearest`) lie in the box of the point's cell, and the point's layer
/// (distance to the surface against d_epi) is one its cell allows; the grid's own nearest-point
/// search (cell lists and anchors) returns the same texture coordinates (to f32 rounding). The
/// cells within 1 mm of the top face and 8–13 mm right of the split hold no dark texel (a cell
/// there reaches at most D(c) + 2r ≤ 1 + 3r = 6.2 mm, r the 2-mm cell's half-diagonal, plus a
/// texel; u wraps, so the right edge reads the dark left column): the bound is local.
#[test]
fn every_texel_lies_under_its_cells_majorant() {
    let dir = tempfile::tempdir().unwrap();
    let scene = slab(dir.path(), 4.0, 8);
    let vol = Volumetric::build(&scene);
    let medium = vol.media[0].as_ref().unwrap();
    let maps = medium.maps.as_ref().unwrap();
    let d_epi = medium.epidermis_region.radius_mm();
    let (h, top) = (
        0.5 * f64::from(SLAB_SIDE_MM),
        0.5 * f64::from(SLAB_DEPTH_MM),
    );
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    let mut anchor = None;
    let mut x = glam::DVec3::new(0.0, 0.0, top - 0.1);
    let mut light_cells = 0;
    for i in 0..20_000 {
        // Every fourth point anywhere; the rest a short step from the last (as a walk moves),
        // which exercises the anchors.
        x = if i % 4 == 0 {
            let depth = if i % 8 == 0 {
                rng.random_range(0.0..2.0 * top)
            } else {
                rng.random_range(0.0..5.0)
            };
            glam::DVec3::new(
                rng.random_range(-h..h),
                rng.random_range(-h..h),
                top - depth,
            )
        } else {
            let step = glam::DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            ) * 0.05;
            (x + step).clamp(
                glam::DVec3::splat(-h + 1e-6),
                glam::DVec3::new(h, h, top) - 1e-6,
            )
        };
        let uv = maps.nearest.uv(x).unwrap();
        let p = maps.maps.maps.at(uv);
        let (range, epidermis, dermis) = maps.grid.bound_at(&maps.nearest, x);
        // The bilinear weights' f32 rounding may move a value an ulp or two past its texels'.
        let ulps = |v: f32| 4.0 * f32::EPSILON * v.abs();
        for k in 0..3 {
            assert!(
                range[k][0] - ulps(range[k][0]) <= p[k] && p[k] <= range[k][1] + ulps(range[k][1]),
                "{x}: parameter {k} = {} outside its cell's [{}, {}]",
                p[k],
                range[k][0],
                range[k][1]
            );
        }
        let d = maps.nearest.distance(x).unwrap();
        assert!(
            if d <= d_epi { epidermis } else { dermis },
            "{x}: depth {d} mm, cell layers epidermis {epidermis} dermis {dermis}"
        );
        let listed = maps.grid.uv(&maps.nearest, x, &mut anchor).unwrap();
        assert!((listed - uv).length() < 1e-5, "{x}: {listed} vs {uv}");
        if (8.0..13.0).contains(&x.x) && top - x.z < 1.0 {
            light_cells += 1;
            assert!(
                range[0][1] <= 0.11 + 1e-6,
                "{x}: light cell reaches C_m {}",
                range[0][1]
            );
        }
    }
    assert!(light_cells > 50, "{light_cells} light points checked");
}

/// The walk at 550 nm on the split slab with the local and with the global majorant: the mean
/// radiance of each side (≥ 1 mm from the split) agrees within 3σ of the two renders' difference
/// (independent seeds; both are unbiased, nothing but noise may separate them).
#[test]
fn local_and_global_majorants_agree() {
    let dir = tempfile::tempdir().unwrap();
    let (half, cols) = (3.0, 6);
    let scene = slab(dir.path(), half, cols);
    let mut means = Vec::new();
    for (majorant, seed) in [(Majorant::Local, 33), (Majorant::Global, 34)] {
        let BodyIntegrator::Volumetric(mut walked) =
            BodyIntegrator::build(&scene, IntegratorKind::Volumetric)
        else {
            unreachable!("the volumetric integrator");
        };
        for m in walked.media.iter_mut().flatten() {
            m.majorant = majorant;
        }
        let body = BodyIntegrator::Volumetric(walked);
        let opts = RenderOptions {
            width: cols,
            height: 2,
            spp: 384,
            seed,
            wavelength_nm: Some(550.0),
            ..Default::default()
        };
        let film = render_with(&scene, &body, &opts.validate().unwrap(), None)
            .unwrap()
            .0;
        let cols = columns(&film);
        means.push([
            region(&cols, half, -half, -1.0),
            region(&cols, half, 1.0, half),
        ]);
    }
    for (side, (&(l, ls), &(g, gs))) in means[0].iter().zip(&means[1]).enumerate() {
        eprintln!("side {side}: local {l:.5} ± {ls:.5}, global {g:.5} ± {gs:.5}");
        assert!(
            (l - g).abs() <= 3.0 * ls.hypot(gs),
            "side {side}: local {l} ± {ls} vs global {g} ± {gs}"
        );
    }
}
