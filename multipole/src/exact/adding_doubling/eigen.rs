//! Symmetric eigendecomposition of a small dense matrix: Householder reduction to tridiagonal form,
//! then the implicit QL algorithm with shifts (the EISPACK `tred2`/`tql2` pair, as in JAMA), eigenvectors
//! accumulated. Backward stable: eigenvalues to about ε‖A‖, eigenvectors orthonormal to rounding.

use super::matrix::{Mat, Singular};

/// Eigenvalues (ascending is not promised) and orthonormal eigenvectors (as the columns of the
/// returned matrix) of the symmetric matrix `a`. Only the lower triangle of `a` is read.
/// Fails only if the QL iteration has not converged after 30 sweeps per eigenvalue (a NaN input).
pub(crate) fn symmetric_eigen(a: &Mat) -> Result<(Vec<f64>, Mat), Singular> {
    let n = a.n();
    let mut v = a.clone();
    let mut d = vec![0.0; n];
    let mut e = vec![0.0; n];
    tridiagonalise(&mut v, &mut d, &mut e);
    // The QL rotations combine pairs of eigenvectors: keep them as rows so each update is contiguous.
    let mut vt = v.transpose();
    ql_implicit(&mut vt, &mut d, &mut e)?;
    Ok((d, vt.transpose()))
}

/// Householder reduction of the symmetric `v` to tridiagonal form: on return `d` holds the diagonal,
/// `e[1..]` the subdiagonal, and `v` the orthogonal transformation.
fn tridiagonalise(v: &mut Mat, d: &mut [f64], e: &mut [f64]) {
    let n = v.n();
    for j in 0..n {
        d[j] = v[(n - 1, j)];
    }
    for i in (1..n).rev() {
        // Scale the row to avoid under- and overflow in the Householder vector.
        let scale: f64 = d[..i].iter().map(|x| x.abs()).sum();
        let mut h = 0.0;
        if scale == 0.0 {
            e[i] = d[i - 1];
            for j in 0..i {
                d[j] = v[(i - 1, j)];
                v[(i, j)] = 0.0;
                v[(j, i)] = 0.0;
            }
        } else {
            for dk in &mut d[..i] {
                *dk /= scale;
                h += *dk * *dk;
            }
            let mut f = d[i - 1];
            let mut g = if f > 0.0 { -h.sqrt() } else { h.sqrt() };
            e[i] = scale * g;
            h -= f * g;
            d[i - 1] = f - g;
            for ej in &mut e[..i] {
                *ej = 0.0;
            }
            // Apply the similarity transformation to the remaining columns.
            for j in 0..i {
                f = d[j];
                v[(j, i)] = f;
                g = e[j] + v[(j, j)] * f;
                for k in j + 1..i {
                    g += v[(k, j)] * d[k];
                    e[k] += v[(k, j)] * f;
                }
                e[j] = g;
            }
            f = 0.0;
            for j in 0..i {
                e[j] /= h;
                f += e[j] * d[j];
            }
            let hh = f / (h + h);
            for j in 0..i {
                e[j] -= hh * d[j];
            }
            for j in 0..i {
                f = d[j];
                g = e[j];
                for k in j..i {
                    v[(k, j)] -= f * e[k] + g * d[k];
                }
                d[j] = v[(i - 1, j)];
                v[(i, j)] = 0.0;
            }
        }
        d[i] = h;
    }
    // Accumulate the transformations.
    for i in 0..n - 1 {
        v[(n - 1, i)] = v[(i, i)];
        v[(i, i)] = 1.0;
        let h = d[i + 1];
        if h != 0.0 {
            for k in 0..=i {
                d[k] = v[(k, i + 1)] / h;
            }
            for j in 0..=i {
                let g: f64 = (0..=i).map(|k| v[(k, i + 1)] * v[(k, j)]).sum();
                for k in 0..=i {
                    v[(k, j)] -= g * d[k];
                }
            }
        }
        for k in 0..=i {
            v[(k, i + 1)] = 0.0;
        }
    }
    for j in 0..n {
        d[j] = v[(n - 1, j)];
        v[(n - 1, j)] = 0.0;
    }
    v[(n - 1, n - 1)] = 1.0;
    e[0] = 0.0;
}

/// √(a² + b²) without the cost of `hypot`, falling back to it where squaring could over- or underflow.
fn hyp(a: f64, b: f64) -> f64 {
    let m = a.abs().max(b.abs());
    if !(1e-150..=1e150).contains(&m) {
        a.hypot(b)
    } else {
        (a * a + b * b).sqrt()
    }
}

/// Implicit QL with Wilkinson-like shifts on the tridiagonal (`d`, `e`), rotating the eigenvector
/// rows of `vt` along.
fn ql_implicit(vt: &mut Mat, d: &mut [f64], e: &mut [f64]) -> Result<(), Singular> {
    let n = vt.n();
    for i in 1..n {
        e[i - 1] = e[i];
    }
    e[n - 1] = 0.0;
    let mut f = 0.0;
    let mut tst1: f64 = 0.0;
    let eps = f64::EPSILON;
    for l in 0..n {
        // Find a negligible subdiagonal element.
        tst1 = tst1.max(d[l].abs() + e[l].abs());
        let mut m = l;
        while m < n - 1 && e[m].abs() > eps * tst1 {
            m += 1;
        }
        let mut iterations = 0;
        if m > l {
            loop {
                iterations += 1;
                if iterations > 30 {
                    return Err(Singular);
                }
                // Implicit shift.
                let mut g = d[l];
                let mut p = (d[l + 1] - g) / (2.0 * e[l]);
                let mut r = hyp(p, 1.0);
                if p < 0.0 {
                    r = -r;
                }
                d[l] = e[l] / (p + r);
                d[l + 1] = e[l] * (p + r);
                let dl1 = d[l + 1];
                let mut h = g - d[l];
                for di in &mut d[l + 2..] {
                    *di -= h;
                }
                f += h;
                // QL transformation.
                p = d[m];
                let (mut c, mut c2, mut c3) = (1.0, 1.0, 1.0);
                let el1 = e[l + 1];
                let (mut s, mut s2) = (0.0, 0.0);
                for i in (l..m).rev() {
                    c3 = c2;
                    c2 = c;
                    s2 = s;
                    g = c * e[i];
                    h = c * p;
                    r = hyp(p, e[i]);
                    e[i + 1] = s * r;
                    s = e[i] / r;
                    c = p / r;
                    p = c * d[i] - s * g;
                    d[i + 1] = h + s * (c * g + s * d[i]);
                    let (row_i, row_next) = vt.rows_pair_mut(i);
                    for (vi, h) in row_i.iter_mut().zip(row_next.iter_mut()) {
                        let (a, b) = (*vi, *h);
                        *h = s * a + c * b;
                        *vi = c * a - s * b;
                    }
                }
                p = -s * s2 * c3 * el1 * e[l] / dl1;
                e[l] = s * p;
                d[l] = c * p;
                if e[l].abs() <= eps * tst1 || e[l].is_nan() {
                    break;
                }
            }
        }
        d[l] += f;
        e[l] = 0.0;
    }
    if d.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(Singular)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decomposition_reconstructs_the_matrix() {
        for n in [1, 2, 5, 12, 24] {
            let a = Mat::from_fn(n, |i, j| {
                let (i, j) = (i.min(j) as f64, i.max(j) as f64);
                (1.0 + i * 0.37 + j * 0.11).sin() + if i == j { 3.0 } else { 0.0 }
            });
            let (d, v) = symmetric_eigen(&a).expect("converges");
            for i in 0..n {
                for j in 0..n {
                    let av: f64 = (0..n).map(|k| a[(i, k)] * v[(k, j)]).sum();
                    assert!((av - v[(i, j)] * d[j]).abs() < 1e-12, "n {n} A v = λ v");
                    let vv: f64 = (0..n).map(|k| v[(k, i)] * v[(k, j)]).sum();
                    let id = if i == j { 1.0 } else { 0.0 };
                    assert!((vv - id).abs() < 1e-12, "n {n} orthonormal");
                }
            }
        }
    }

    #[test]
    fn diagonal_and_degenerate_matrices() {
        let a = Mat::diagonal(&[3.0, 1.0, 2.0, 2.0]);
        let (mut d, _) = symmetric_eigen(&a).expect("converges");
        d.sort_by(f64::total_cmp);
        assert_eq!(d, vec![1.0, 2.0, 2.0, 3.0]);
    }
}
