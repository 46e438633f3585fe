//! Small dense square matrices (n ≤ 64) for adding-doubling, on nalgebra: the operations the
//! adding and doubling formulas (docs/physics.md §10) and the eigenmode layer (`modes`) are written
//! in, with the singular cases (a numerically zero pivot, a matrix that is not positive definite)
//! reported as [`Singular`] so the caller can fall back.

use nalgebra::{Cholesky, DMatrix, LU, SymmetricEigen};

/// A dense square matrix of f64.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Mat(DMatrix<f64>);

/// The matrix of a linear solve had a (numerically) zero pivot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Singular;

/// Pivots below this fraction of the matrix's largest entry count as zero.
const RELATIVE_PIVOT: f64 = 1e-14;

impl Mat {
    /// The n × n zero matrix.
    pub(crate) fn zeros(n: usize) -> Self {
        Self(DMatrix::zeros(n, n))
    }

    /// The n × n identity.
    pub(crate) fn identity(n: usize) -> Self {
        Self(DMatrix::identity(n, n))
    }

    /// The diagonal matrix with `d` on its diagonal.
    pub(crate) fn diagonal(d: &[f64]) -> Self {
        Self(DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(d)))
    }

    /// Build from a function of (row, column).
    pub(crate) fn from_fn(n: usize, f: impl Fn(usize, usize) -> f64) -> Self {
        Self(DMatrix::from_fn(n, n, f))
    }

    /// Order of the matrix.
    pub(crate) fn n(&self) -> usize {
        self.0.nrows()
    }

    /// Matrix product self · rhs.
    pub(crate) fn mul(&self, rhs: &Mat) -> Mat {
        Self(&self.0 * &rhs.0)
    }

    /// Matrix-vector product self · v.
    pub(crate) fn mul_vec(&self, v: &[f64]) -> Vec<f64> {
        (&self.0 * nalgebra::DVector::from_column_slice(v))
            .as_slice()
            .to_vec()
    }

    /// Sum self + rhs.
    pub(crate) fn add(&self, rhs: &Mat) -> Mat {
        Self(&self.0 + &rhs.0)
    }

    /// I + self.
    pub(crate) fn identity_plus(&self) -> Mat {
        let mut out = self.0.clone();
        for i in 0..out.nrows() {
            out[(i, i)] += 1.0;
        }
        Self(out)
    }

    /// I − self.
    pub(crate) fn identity_minus(&self) -> Mat {
        let mut out = -&self.0;
        for i in 0..out.nrows() {
            out[(i, i)] += 1.0;
        }
        Self(out)
    }

    /// Scale row i by `left[i]` and column j by `right[j]`: diag(left) · self · diag(right).
    pub(crate) fn scale_rows_cols(&self, left: &[f64], right: &[f64]) -> Mat {
        Mat::from_fn(self.n(), |i, j| left[i] * self.0[(i, j)] * right[j])
    }

    /// Sum of column j.
    pub(crate) fn column_sum(&self, j: usize) -> f64 {
        self.0.column(j).sum()
    }

    /// Column j as a vector.
    pub(crate) fn column(&self, j: usize) -> Vec<f64> {
        self.0.column(j).iter().copied().collect()
    }

    /// Largest absolute entry.
    pub(crate) fn max_abs(&self) -> f64 {
        self.0.amax()
    }

    /// Whether every entry is finite.
    pub(crate) fn is_finite(&self) -> bool {
        self.0.iter().all(|v| v.is_finite())
    }

    /// LU factors with partial pivoting, or `Singular` if a pivot is below [`RELATIVE_PIVOT`] of
    /// the largest entry (or NaN).
    fn lu(&self) -> Result<LU<f64, nalgebra::Dyn, nalgebra::Dyn>, Singular> {
        let threshold = RELATIVE_PIVOT * self.max_abs().max(f64::MIN_POSITIVE);
        let lu = LU::new(self.0.clone());
        // The pivots are U's diagonal, which LU stores on the packed factor's diagonal.
        if lu.u().diagonal().iter().all(|p| p.abs() > threshold) {
            Ok(lu)
        } else {
            Err(Singular)
        }
    }

    /// Solve self · X = rhs for X (LU with partial pivoting).
    pub(crate) fn solve(&self, rhs: &Mat) -> Result<Mat, Singular> {
        self.lu()?.solve(&rhs.0).map(Self).ok_or(Singular)
    }

    /// Solve self · x = rhs for a vector x.
    pub(crate) fn solve_vec(&self, rhs: &[f64]) -> Result<Vec<f64>, Singular> {
        let x = self.lu()?.solve(&nalgebra::DVector::from_column_slice(rhs));
        x.map(|x| x.as_slice().to_vec()).ok_or(Singular)
    }

    /// Solve self · X = B and self · Y = C with one factorisation.
    pub(crate) fn solve_two(&self, b: &Mat, c: &Mat) -> Result<(Mat, Mat), Singular> {
        let lu = self.lu()?;
        let x = lu.solve(&b.0).ok_or(Singular)?;
        let y = lu.solve(&c.0).ok_or(Singular)?;
        Ok((Self(x), Self(y)))
    }

    #[cfg(test)]
    /// self · self for a symmetric self.
    pub(crate) fn symmetric_square(&self) -> Mat {
        self.mul(self)
    }

    /// Cholesky factor L (lower triangular, self = L Lᵀ) of a symmetric positive definite matrix.
    pub(crate) fn cholesky(&self) -> Result<Mat, Singular> {
        Cholesky::new(self.0.clone())
            .map(|c| Self(c.unpack()))
            .ok_or(Singular)
    }

    /// L⁻¹ B for lower-triangular self = L.
    pub(crate) fn forward_substitute(&self, b: &Mat) -> Mat {
        let mut x = b.0.clone();
        // L comes from `cholesky`, whose diagonal is positive: the solve cannot fail.
        let solved = self.0.solve_lower_triangular_mut(&mut x);
        debug_assert!(solved, "Cholesky factor with a zero diagonal");
        Self(x)
    }

    /// selfᵀ · b (used where the result is known to be symmetric).
    pub(crate) fn transpose_mul_symmetric(&self, b: &Mat) -> Mat {
        Self(self.0.tr_mul(&b.0))
    }

    /// Lᵀ⁻¹ B for lower-triangular self = L.
    pub(crate) fn back_substitute_transpose(&self, b: &Mat) -> Mat {
        let mut x = b.0.clone();
        let solved = self.0.tr_solve_lower_triangular_mut(&mut x);
        debug_assert!(solved, "Cholesky factor with a zero diagonal");
        Self(x)
    }

    /// The transpose.
    pub(crate) fn transpose(&self) -> Mat {
        Self(self.0.transpose())
    }

    /// (self + selfᵀ)/2: removes rounding asymmetry from a matrix that is symmetric in exact arithmetic.
    pub(crate) fn symmetrised(&self) -> Mat {
        Self((&self.0 + self.0.transpose()) * 0.5)
    }

    /// Eigenvalues (in no promised order) and orthonormal eigenvectors (the columns of the returned
    /// matrix) of the symmetric self. `Singular` if the iteration does not converge (a NaN input).
    pub(crate) fn symmetric_eigen(&self) -> Result<(Vec<f64>, Mat), Singular> {
        // 30 QR sweeps per eigenvalue, as EISPACK allows: converging takes 2–3, and a bound is needed
        // because nalgebra reads 0 as "iterate until converged".
        let max_iterations = 30 * self.n().max(1);
        let eigen = SymmetricEigen::try_new(self.0.clone(), f64::EPSILON, max_iterations)
            .ok_or(Singular)?;
        if !eigen.eigenvalues.iter().all(|v| v.is_finite()) {
            return Err(Singular);
        }
        Ok((eigen.eigenvalues.as_slice().to_vec(), Self(eigen.eigenvectors)))
    }
}

impl std::ops::Index<(usize, usize)> for Mat {
    type Output = f64;
    fn index(&self, ij: (usize, usize)) -> &f64 {
        &self.0[ij]
    }
}

impl std::ops::IndexMut<(usize, usize)> for Mat {
    fn index_mut(&mut self, ij: (usize, usize)) -> &mut f64 {
        &mut self.0[ij]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve_inverts_a_product() {
        let a = Mat::from_fn(5, |i, j| {
            1.0 / (1.0 + i as f64 + j as f64) + if i == j { 2.0 } else { 0.0 }
        });
        let x = Mat::from_fn(5, |i, j| (i as f64 - 2.0 * j as f64).sin());
        let b = a.mul(&x);
        let x2 = a.solve(&b).expect("well conditioned");
        for i in 0..5 {
            for j in 0..5 {
                assert!((x[(i, j)] - x2[(i, j)]).abs() < 1e-12);
            }
        }
        let v = x.column(1);
        let bv = a.mul_vec(&v);
        let v2 = a.solve_vec(&bv).expect("well conditioned");
        for (p, q) in v.iter().zip(&v2) {
            assert!((p - q).abs() < 1e-12);
        }
    }

    #[test]
    fn symmetric_kernels_match_general_products() {
        let n = 7;
        let r = Mat::from_fn(n, |i, j| {
            0.05 / (1.0 + (i as f64 - j as f64).abs()) + 0.01 * (i + j) as f64 / n as f64
        });
        let t = Mat::from_fn(n, |i, j| {
            if i == j {
                0.6
            } else {
                0.02 * ((i * j) as f64).cos().abs()
            }
        })
        .symmetrised();
        let sq = r.symmetric_square();
        let sq_ref = r.mul(&r);
        let a = sq.identity_minus();
        let l = a.cholesky().expect("SPD");
        let f = l.forward_substitute(&t);
        // Fᵀ F = T (I − R²)⁻¹ T.
        let tt = f.transpose_mul_symmetric(&f);
        let tt_ref = t.mul(&a.solve(&t).expect("regular"));
        for i in 0..n {
            for j in 0..n {
                assert!((sq[(i, j)] - sq_ref[(i, j)]).abs() < 1e-15);
                assert!((tt[(i, j)] - tt_ref[(i, j)]).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn singular_is_reported() {
        let a = Mat::from_fn(3, |i, _| i as f64);
        assert_eq!(a.solve(&Mat::identity(3)), Err(Singular));
    }

    #[test]
    fn decomposition_reconstructs_the_matrix() {
        for n in [1, 2, 5, 12, 24] {
            let a = Mat::from_fn(n, |i, j| {
                let (i, j) = (i.min(j) as f64, i.max(j) as f64);
                (1.0 + i * 0.37 + j * 0.11).sin() + if i == j { 3.0 } else { 0.0 }
            });
            let (d, v) = a.symmetric_eigen().expect("converges");
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
        let (mut d, _) = a.symmetric_eigen().expect("converges");
        d.sort_by(f64::total_cmp);
        assert_eq!(d, vec![1.0, 2.0, 2.0, 3.0]);
    }
}
