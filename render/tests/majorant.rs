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
use render::volumetric::walk::Absorption;

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

/// `n` points in the slab: every fourth anywhere (half of those within 5 mm of its top face,
/// where the grid's cells are), the rest a step of at most 0.05 mm per axis from the last (as a
/// walk moves), which exercises the anchors.
fn slab_points(seed: u64, n: usize) -> Vec<glam::DVec3> {
    let (h, top) = (
        0.5 * f64::from(SLAB_SIDE_MM),
        0.5 * f64::from(SLAB_DEPTH_MM),
    );
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut x = glam::DVec3::new(0.0, 0.0, top - 0.1);
    (0..n)
        .map(|i| {
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
            x
        })
        .collect()
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
    let top = 0.5 * f64::from(SLAB_DEPTH_MM);
    let mut anchor = None;
    let mut light_cells = 0;
    for x in slab_points(11, 20_000) {
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

/// The walk's mean radiance at 550 nm on each side of the split slab of `dir` (half-width `half`
/// mm, `cols` columns; ≥ 1 mm from the split) at 384 spp with seed `seed`, each skin volume set
/// by `set`.
fn side_means(
    dir: &std::path::Path,
    (half, cols): (f32, usize),
    seed: u64,
    set: impl Fn(&mut render::volumetric::SkinVolume),
) -> [(f64, f64); 2] {
    let scene = slab(dir, half, cols);
    let BodyIntegrator::Volumetric(mut walked) =
        BodyIntegrator::build(&scene, IntegratorKind::Volumetric)
    else {
        unreachable!("the volumetric integrator");
    };
    walked.media.iter_mut().flatten().for_each(set);
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
    [
        region(&cols, half, -half, -1.0),
        region(&cols, half, 1.0, half),
    ]
}

/// The walk at 550 nm on the split slab under two settings of its skin volumes (`set(m, k)` for
/// setting k, named `names[k]`, rendered with seed `seeds[k]`): the mean radiance of each side
/// (≥ 1 mm from the split) agrees within 3σ of the two renders' difference.
fn assert_settings_agree(
    names: [&str; 2],
    seeds: [u64; 2],
    set: impl Fn(&mut render::volumetric::SkinVolume, usize),
) {
    let dir = tempfile::tempdir().unwrap();
    let [a, b] = [0, 1].map(|k| side_means(dir.path(), (3.0, 6), seeds[k], |m| set(m, k)));
    for (side, ((x, xs), (y, ys))) in a.into_iter().zip(b).enumerate() {
        eprintln!(
            "side {side}: {} {x:.5} ± {xs:.5}, {} {y:.5} ± {ys:.5}",
            names[0], names[1]
        );
        assert!(
            (x - y).abs() <= 3.0 * xs.hypot(ys),
            "side {side}: {} {x} ± {xs} vs {} {y} ± {ys}",
            names[0],
            names[1]
        );
    }
}

/// The walk at 550 nm on the split slab with the local and with the global majorant: the mean
/// radiance of each side (≥ 1 mm from the split) agrees within 3σ of the two renders' difference
/// (independent seeds; both are unbiased, nothing but noise may separate them).
#[test]
fn local_and_global_majorants_agree() {
    let majorants = [Majorant::Local, Majorant::Global];
    assert_settings_agree(["local", "global"], [33, 34], |m, k| {
        m.majorant = majorants[k];
    });
}

/// The split speckle's slab with the left half's epidermis thin (0.05 mm; the material's is
/// 0.25 mm): at 20,000 points ([`slab_points`]) at 550 nm, a cell that names its epidermis
/// thickness names the one the point's nearest texel reads (exact: both come from the same
/// flag, the cell's over every texel its points can read), and each layer's σa at the point is
/// at least its cell's least σa (the excess absorption's bound; a multilinear function's
/// smallest value on a box is at a corner). Cells far left name the thin epidermis, far right
/// the normal one, and those over the split name none.
#[test]
fn cells_bound_the_texels_thickness_and_least_absorption() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (128usize, 128usize);
    let side = f64::from(SLAB_SIDE_MM);
    let texel_x = |i: usize| -0.5 * side + (i as f64 + 0.5) * side / w as f64;
    let mut melanin = Vec::with_capacity(w * h);
    let mut thin = Vec::with_capacity(w * h);
    for j in 0..h {
        for i in 0..w {
            let y = 0.5 * side - (j as f64 + 0.5) * side / h as f64;
            melanin.push(split_speckle(texel_x(i) as f32, y as f32));
            thin.push(if texel_x(i) < 0.0 { 1.0 } else { 0.0 });
        }
    }
    let exr = render::texture::channels_exr_bytes_with(
        w,
        h,
        vec![("melanin", melanin), ("thin_epidermis", thin)],
        &[("thin_epidermis_mm", 0.05)],
    )
    .unwrap();
    std::fs::write(dir.path().join("maps.exr"), exr).unwrap();
    let scene = strip_scene(dir.path(), 4.0, 8, "maps = \"maps.exr\"");
    let vol = Volumetric::build(&scene);
    let medium = vol.media[0].as_ref().unwrap();
    let sigma_s = (
        medium.epidermis.sigma_s.at_nm(550.0),
        medium.dermis.sigma_s.at_nm(550.0),
    );
    let at = medium.maps.as_ref().unwrap().at_nm(550.0);
    let (mut named, mut varies) = ([0usize; 2], 0usize);
    for x in slab_points(12, 20_000) {
        let cell = at.cell_at(x, sigma_s);
        match cell.epidermis_mm {
            Some(d) => {
                let read = at.epidermis_mm(x);
                assert_eq!(d, read, "{x}: cell names {d} mm, the texel reads {read} mm");
                named[usize::from(d > 0.1)] += 1;
            }
            None => varies += 1,
        }
        for (epidermis, least) in [(true, cell.least_sigma_a.0), (false, cell.least_sigma_a.1)] {
            let sa = at.sigma_a(epidermis, x);
            assert!(
                least <= sa,
                "{x}: σa {sa} below its cell's least {least} (epidermis {epidermis})"
            );
        }
    }
    assert!(
        named[0] > 1000 && named[1] > 1000 && varies > 100,
        "thin {}, normal {}, varying {varies}",
        named[0],
        named[1]
    );
}

/// The walk at 550 nm on the split slab with each absorption rule: the mean radiance of each side
/// (≥ 1 mm from the split) agrees within 3σ of the two renders' difference (independent seeds;
/// both rules are unbiased, nothing but noise may separate them).
#[test]
fn excess_and_implicit_absorption_agree() {
    let rules = [Absorption::Implicit, Absorption::Excess];
    assert_settings_agree(["implicit", "excess"], [35, 36], |m, k| {
        m.absorption = rules[k];
    });
}
