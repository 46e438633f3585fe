//! Small dense square matrices (n ≤ 64) for adding-doubling: products, sums, row and column
//! scaling, LU solves with partial pivoting, and the Cholesky factorisation with its triangular
//! solves that `modes` uses (the symmetric eigensolver is in `eigen`).
//!
//! Hand-written rather than nalgebra, on measurement: the same solver on nalgebra 0.34 took more
//! CPU time at every quadrature point count, although it executed fewer instructions
//! (docs/benchmarks-archive.md, "Layout change", has the table and the commands).

/// A dense square matrix of f64, row-major.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Mat {
    n: usize,
    data: Vec<f64>,
}

/// The matrix of a linear solve had a (numerically) zero pivot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Singular;

impl Mat {
    /// The n × n zero matrix.
    pub(crate) fn zeros(n: usize) -> Self {
        Self {
            n,
            data: vec![0.0; n * n],
        }
    }

    /// The n × n identity.
    pub(crate) fn identity(n: usize) -> Self {
        Self::diagonal(&vec![1.0; n])
    }

    /// The diagonal matrix with `d` on its diagonal.
    pub(crate) fn diagonal(d: &[f64]) -> Self {
        let mut m = Self::zeros(d.len());
        for (i, &v) in d.iter().enumerate() {
            m[(i, i)] = v;
        }
        m
    }

    /// Build from a function of (row, column).
    pub(crate) fn from_fn(n: usize, f: impl Fn(usize, usize) -> f64) -> Self {
        let mut m = Self::zeros(n);
        for i in 0..n {
            for j in 0..n {
                m[(i, j)] = f(i, j);
            }
        }
        m
    }

    /// Order of the matrix.
    pub(crate) fn n(&self) -> usize {
        self.n
    }

    /// Matrix product self · rhs.
    pub(crate) fn mul(&self, rhs: &Mat) -> Mat {
        debug_assert_eq!(self.n, rhs.n);
        let n = self.n;
        let mut out = Mat::zeros(n);
        // i-k-j order: the inner loop runs over contiguous rows of rhs and out, so it vectorises.
        for i in 0..n {
            let out_row = &mut out.data[i * n..(i + 1) * n];
            for k in 0..n {
                let a = self.data[i * n + k];
                if a == 0.0 {
                    continue;
                }
                let rhs_row = &rhs.data[k * n..(k + 1) * n];
                for (o, &b) in out_row.iter_mut().zip(rhs_row) {
                    *o += a * b;
                }
            }
        }
        out
    }

    /// Matrix-vector product self · v.
    pub(crate) fn mul_vec(&self, v: &[f64]) -> Vec<f64> {
        let n = self.n;
        (0..n)
            .map(|i| {
                self.data[i * n..(i + 1) * n]
                    .iter()
                    .zip(v)
                    .map(|(a, b)| a * b)
                    .sum()
            })
            .collect()
    }

    /// Sum self + rhs.
    pub(crate) fn add(&self, rhs: &Mat) -> Mat {
        let mut out = self.clone();
        for (o, r) in out.data.iter_mut().zip(&rhs.data) {
            *o += r;
        }
        out
    }

    /// I + self.
    pub(crate) fn identity_plus(&self) -> Mat {
        let mut out = self.clone();
        for i in 0..self.n {
            out[(i, i)] += 1.0;
        }
        out
    }

    /// I − self.
    pub(crate) fn identity_minus(&self) -> Mat {
        let mut out = self.clone();
        for v in &mut out.data {
            *v = -*v;
        }
        for i in 0..self.n {
            out[(i, i)] += 1.0;
        }
        out
    }

    /// Scale row i by `left[i]` and column j by `right[j]`: diag(left) · self · diag(right).
    pub(crate) fn scale_rows_cols(&self, left: &[f64], right: &[f64]) -> Mat {
        let n = self.n;
        Mat::from_fn(n, |i, j| left[i] * self[(i, j)] * right[j])
    }

    /// Sum of column j.
    pub(crate) fn column_sum(&self, j: usize) -> f64 {
        (0..self.n).map(|i| self[(i, j)]).sum()
    }

    /// Column j as a vector.
    pub(crate) fn column(&self, j: usize) -> Vec<f64> {
        (0..self.n).map(|i| self[(i, j)]).collect()
    }

    /// Largest absolute entry.
    pub(crate) fn max_abs(&self) -> f64 {
        self.data.iter().fold(0.0, |m, v| m.max(v.abs()))
    }

    /// Whether every entry is finite.
    pub(crate) fn is_finite(&self) -> bool {
        self.data.iter().all(|v| v.is_finite())
    }

    /// Solve self · X = rhs for X (Gaussian elimination with partial pivoting).
    pub(crate) fn solve(&self, rhs: &Mat) -> Result<Mat, Singular> {
        let n = self.n;
        let mut x = rhs.clone();
        self.solve_in_place(n, &mut x.data)?;
        Ok(x)
    }

    /// Solve self · x = rhs for a vector x.
    pub(crate) fn solve_vec(&self, rhs: &[f64]) -> Result<Vec<f64>, Singular> {
        let mut x = rhs.to_vec();
        self.solve_in_place(1, &mut x)?;
        Ok(x)
    }

    /// Overwrite `b` (n rows of `cols` entries, row-major) with self⁻¹ b.
    fn solve_in_place(&self, cols: usize, b: &mut [f64]) -> Result<(), Singular> {
        let n = self.n;
        let mut a = self.data.clone();
        let scale = self.max_abs().max(f64::MIN_POSITIVE);
        for k in 0..n {
            let (p, pivot_abs) = (k..n)
                .map(|i| (i, a[i * n + k].abs()))
                .fold((k, -1.0), |best, c| if c.1 > best.1 { c } else { best });
            if pivot_abs.is_nan() || pivot_abs <= 1e-14 * scale {
                return Err(Singular);
            }
            if p != k {
                swap_rows(&mut a, n, k, p);
                swap_rows(b, cols, k, p);
            }
            let inv = 1.0 / a[k * n + k];
            // Row slices let the eliminations below vectorise (no aliasing, no bounds checks).
            let (a_top, a_rest) = a.split_at_mut((k + 1) * n);
            let a_k = &a_top[k * n + k + 1..(k + 1) * n];
            let (b_top, b_rest) = b.split_at_mut((k + 1) * cols);
            let b_k = &b_top[k * cols..];
            for (a_i, b_i) in a_rest
                .chunks_exact_mut(n)
                .zip(b_rest.chunks_exact_mut(cols))
            {
                let f = a_i[k] * inv;
                if f == 0.0 {
                    continue;
                }
                axpy(&mut a_i[k + 1..], -f, a_k);
                axpy(b_i, -f, b_k);
            }
        }
        for k in (0..n).rev() {
            let inv = 1.0 / a[k * n + k];
            let (b_top, b_rest) = b.split_at_mut((k + 1) * cols);
            let b_k = &mut b_top[k * cols..];
            for (m, b_m) in (k + 1..n).zip(b_rest.chunks_exact(cols)) {
                axpy(b_k, -a[k * n + m], b_m);
            }
            for v in b_k.iter_mut() {
                *v *= inv;
            }
        }
        Ok(())
    }
}

/// y ← y + α x.
fn axpy(y: &mut [f64], alpha: f64, x: &[f64]) {
    for (y, x) in y.iter_mut().zip(x) {
        *y += alpha * x;
    }
}

fn swap_rows(m: &mut [f64], cols: usize, i: usize, j: usize) {
    let (lo, hi) = (i.min(j), i.max(j));
    let (top, bottom) = m.split_at_mut(hi * cols);
    top[lo * cols..(lo + 1) * cols].swap_with_slice(&mut bottom[..cols]);
}

impl Mat {
    #[cfg(test)]
    /// self · self for a symmetric self (the result is symmetric: upper triangle by row dot products,
    /// mirrored).
    pub(crate) fn symmetric_square(&self) -> Mat {
        let n = self.n;
        let mut out = Mat::zeros(n);
        for i in 0..n {
            let row_i = &self.data[i * n..(i + 1) * n];
            for j in i..n {
                let v = dot(row_i, &self.data[j * n..(j + 1) * n]);
                out.data[i * n + j] = v;
                out.data[j * n + i] = v;
            }
        }
        out
    }

    /// Cholesky factor L (lower triangular, self = L Lᵀ) of a symmetric positive definite matrix.
    pub(crate) fn cholesky(&self) -> Result<Mat, Singular> {
        let n = self.n;
        let mut l = Mat::zeros(n);
        for i in 0..n {
            for j in 0..=i {
                let s = self.data[i * n + j]
                    - dot(&l.data[i * n..i * n + j], &l.data[j * n..j * n + j]);
                if i == j {
                    if s.is_nan() || s <= 1e-300 {
                        return Err(Singular);
                    }
                    l.data[i * n + i] = s.sqrt();
                } else {
                    l.data[i * n + j] = s / l.data[j * n + j];
                }
            }
        }
        Ok(l)
    }

    /// L⁻¹ B for lower-triangular self = L (forward substitution on whole rows of B).
    pub(crate) fn forward_substitute(&self, b: &Mat) -> Mat {
        let n = self.n;
        let mut x = b.clone();
        for i in 0..n {
            let (done, rest) = x.data.split_at_mut(i * n);
            let x_i = &mut rest[..n];
            for (k, x_k) in done.chunks_exact(n).enumerate() {
                axpy(x_i, -self.data[i * n + k], x_k);
            }
            let inv = 1.0 / self.data[i * n + i];
            for v in x_i.iter_mut() {
                *v *= inv;
            }
        }
        x
    }

    /// selfᵀ · b when the result is known to be symmetric: upper triangle accumulated row by row,
    /// mirrored (half the work of a full product).
    pub(crate) fn transpose_mul_symmetric(&self, b: &Mat) -> Mat {
        let n = self.n;
        let mut out = Mat::zeros(n);
        for k in 0..n {
            let b_k = &b.data[k * n..(k + 1) * n];
            for i in 0..n {
                let a = self.data[k * n + i];
                axpy(&mut out.data[i * n + i..(i + 1) * n], a, &b_k[i..]);
            }
        }
        for i in 0..n {
            for j in 0..i {
                out.data[i * n + j] = out.data[j * n + i];
            }
        }
        out
    }

    /// Lᵀ⁻¹ B for lower-triangular self = L (back substitution with the transpose, on whole rows of B).
    pub(crate) fn back_substitute_transpose(&self, b: &Mat) -> Mat {
        let n = self.n;
        let mut x = b.clone();
        for i in (0..n).rev() {
            let (head, rest) = x.data.split_at_mut((i + 1) * n);
            let x_i = &mut head[i * n..];
            for (k, x_k) in (i + 1..n).zip(rest.chunks_exact(n)) {
                axpy(x_i, -self.data[k * n + i], x_k);
            }
            let inv = 1.0 / self.data[i * n + i];
            for v in x_i.iter_mut() {
                *v *= inv;
            }
        }
        x
    }

    /// Rows i and i + 1, mutably.
    pub(crate) fn rows_pair_mut(&mut self, i: usize) -> (&mut [f64], &mut [f64]) {
        let n = self.n;
        let (a, b) = self.data[i * n..(i + 2) * n].split_at_mut(n);
        (a, b)
    }

    /// Solve self · X = B and self · Y = C with one factorisation.
    pub(crate) fn solve_two(&self, b: &Mat, c: &Mat) -> Result<(Mat, Mat), Singular> {
        let n = self.n;
        // Side by side: n rows of 2n entries.
        let mut bc = Vec::with_capacity(2 * n * n);
        for i in 0..n {
            bc.extend_from_slice(&b.data[i * n..(i + 1) * n]);
            bc.extend_from_slice(&c.data[i * n..(i + 1) * n]);
        }
        self.solve_in_place(2 * n, &mut bc)?;
        let x = Mat::from_fn(n, |i, j| bc[i * 2 * n + j]);
        let y = Mat::from_fn(n, |i, j| bc[i * 2 * n + n + j]);
        Ok((x, y))
    }

    /// The transpose.
    pub(crate) fn transpose(&self) -> Mat {
        Mat::from_fn(self.n, |i, j| self[(j, i)])
    }

    /// (self + selfᵀ)/2: removes rounding asymmetry from a matrix that is symmetric in exact arithmetic.
    pub(crate) fn symmetrised(&self) -> Mat {
        Mat::from_fn(self.n, |i, j| 0.5 * (self[(i, j)] + self[(j, i)]))
    }
}

/// Σ a_k b_k with four partial sums, so the loop vectorises without reassociating a single sum.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let chunks = a.len() / 4;
    for c in 0..chunks {
        for l in 0..4 {
            acc[l] += a[4 * c + l] * b[4 * c + l];
        }
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for k in 4 * chunks..a.len() {
        s += a[k] * b[k];
    }
    s
}

impl std::ops::Index<(usize, usize)> for Mat {
    type Output = f64;
    fn index(&self, (i, j): (usize, usize)) -> &f64 {
        &self.data[i * self.n + j]
    }
}

impl std::ops::IndexMut<(usize, usize)> for Mat {
    fn index_mut(&mut self, (i, j): (usize, usize)) -> &mut f64 {
        &mut self.data[i * self.n + j]
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
}
