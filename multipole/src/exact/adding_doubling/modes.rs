//! A homogeneous layer's reflection and transmission from the eigenmodes of the discrete-ordinate
//! equations (the matrix-operator / eigenvalue method: Stamnes & Swanson 1981, [vdH80] ch. 4), in place
//! of a thin-layer start plus doubling: the same discretised transport (δ-M HG redistribution on the
//! same quadrature), solved in closed form for any thickness, and for a semi-infinite layer without
//! iterating to convergence.
//!
//! In the symmetric basis d = √(μw) D, u = √(μw) U (D, U the down- and upward radiances at the nodes),
//! with Ĥ± = (a/2) W^½ h± W^½ and M = diag(μ), the equations are d' = −A d + B u, u' = A u − B d with
//! A = M^−½ (I − Ĥ⁺) M^−½ and B = M^−½ Ĥ⁻ M^−½ (both symmetric; ' = d/dτ, τ down). Sum s = d + u and
//! difference δ = d − u obey s' = −P δ, δ' = −Q s with P = A + B, Q = A − B, so s'' = P Q s. With
//! P = L Lᵀ (Cholesky) the modes come from the symmetric problem Lᵀ Q L y = k² y: s = L y e^{−kτ},
//! δ = k L^−ᵀ y e^{−kτ}, i.e. the columns of G₊ = ½(L Y + L^−ᵀ Y K) (down) and G₋ = ½(L Y − L^−ᵀ Y K)
//! (up); the modes growing with depth are the same with G₊ and G₋ swapped. Then, with E = e^{−Kτ},
//! Γ = G₊⁻¹ G₋ and N = G₊ − G₋ E Γ E:
//! R̂ = (G₋ − G₊ E Γ E) N⁻¹, T̂ = (G₊ E − G₋ Γ E) N⁻¹, and for τ → ∞ simply R̂ = G₋ G₊⁻¹.
//! Every exponential is a decaying one, so thick layers are as stable as thin ones.
//!
//! [`layer_by_modes`] and the thin-layer start in `layer.rs` solve one homogeneous layer on the
//! same quadrature; the start is the fallback when the modes are `Singular`.

use super::eigen::symmetric_eigen;
use super::layer::Angles;
use super::matrix::{Mat, Singular};

/// Smallest k² (relative to the largest) accepted: below it a mode is conservative (albedo 1) and the
/// growing/decaying pair degenerates; the caller then doubles instead.
const MIN_RELATIVE_K2: f64 = 1e-12;

/// (R̂, T̂) of a layer of (δ-M scaled) albedo `a` < 1 and optical thickness `tau` (may be infinite),
/// in the symmetric basis X̂ = C^−½ X̃ C^½ (C = diag(2μw)) that the doubling code uses; `h_plus`,
/// `h_minus` the HG redistribution h(μ_i, ±μ_j). `Err(Singular)` when the mode construction is
/// ill-posed (albedo too close to 1, or a singular matrix): fall back to doubling.
pub(crate) fn layer_by_modes(
    angles: &Angles,
    h_plus: &Mat,
    h_minus: &Mat,
    a: f64,
    tau: f64,
) -> Result<(Mat, Mat), Singular> {
    let n = angles.n();
    let sw: Vec<f64> = angles.w.iter().map(|w| w.sqrt()).collect();
    let sm: Vec<f64> = angles.mu.iter().map(|m| 1.0 / m.sqrt()).collect();
    let hat = |h: &Mat, i: usize, j: usize| 0.5 * a * sw[i] * h[(i, j)] * sw[j];
    let id = |i: usize, j: usize| if i == j { 1.0 } else { 0.0 };
    let p = Mat::from_fn(n, |i, j| {
        sm[i] * (id(i, j) - hat(h_plus, i, j) + hat(h_minus, i, j)) * sm[j]
    });
    let q = Mat::from_fn(n, |i, j| {
        sm[i] * (id(i, j) - hat(h_plus, i, j) - hat(h_minus, i, j)) * sm[j]
    });
    let l = p.cholesky()?;
    let s = l.transpose_mul_symmetric(&q.mul(&l));
    let (k2, y) = symmetric_eigen(&s)?;
    let k2_max = k2.iter().fold(0.0f64, |m, v| m.max(*v));
    if k2
        .iter()
        .any(|&v| v.is_nan() || v <= MIN_RELATIVE_K2 * k2_max)
    {
        return Err(Singular);
    }
    let k: Vec<f64> = k2.iter().map(|v| v.sqrt()).collect();
    let ly = l.mul(&y);
    let lty = l.back_substitute_transpose(&y);
    let g_down = Mat::from_fn(n, |i, j| 0.5 * (ly[(i, j)] + lty[(i, j)] * k[j]));
    let g_up = Mat::from_fn(n, |i, j| 0.5 * (ly[(i, j)] - lty[(i, j)] * k[j]));
    if tau.is_infinite() {
        // R̂ G₊ = G₋, i.e. G₊ᵀ R̂ᵀ = G₋ᵀ; R̂ is symmetric (reciprocity).
        let r = g_down.transpose().solve(&g_up.transpose())?;
        return Ok((r.symmetrised(), Mat::zeros(n)));
    }
    let e: Vec<f64> = k.iter().map(|kj| (-kj * tau).exp()).collect();
    let gamma = g_down.solve(&g_up)?;
    let ege = Mat::from_fn(n, |i, j| e[i] * gamma[(i, j)] * e[j]);
    let gamma_e = Mat::from_fn(n, |i, j| gamma[(i, j)] * e[j]);
    let g_down_e = Mat::from_fn(n, |i, j| g_down[(i, j)] * e[j]);
    let minus_ege = |g: &Mat, x: &Mat| {
        let gx = x.mul(&ege);
        Mat::from_fn(n, |i, j| g[(i, j)] - gx[(i, j)])
    };
    let nt = minus_ege(&g_down, &g_up).transpose();
    let xr = minus_ege(&g_up, &g_down);
    let gg = g_up.mul(&gamma_e);
    let xt = Mat::from_fn(n, |i, j| g_down_e[(i, j)] - gg[(i, j)]);
    // X N⁻¹ = (N⁻ᵀ Xᵀ)ᵀ; both results are symmetric, so the transpose is only rounding.
    let (r, t) = nt.solve_two(&xr.transpose(), &xt.transpose())?;
    Ok((r.symmetrised(), t.symmetrised()))
}
