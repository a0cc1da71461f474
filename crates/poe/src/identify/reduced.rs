//! The stacked least-squares problem of one iteration, `min ‖y − A δ‖`, folded block of rows by
//! block into the triangle of its QR factorisation (Golub & Van Loan, *Matrix Computations*, 4th
//! ed., §5.3.3, the least-squares solution by QR; updating by rows, §6.5.3): `[A y] = Q [R z; 0 ρ]`.
//! `R` (p × p) has the singular values and right singular vectors of `A`, `A⁺y = R⁺z`,
//! `AᵀA = RᵀR` and `Aᵀy = Rᵀz`, so every solver step, the gradient criterion and the report's
//! singular values come from it alone; the whole `A` (six rows per pose, 1.45 million rows × 42
//! columns, 490 MB for a 68 MB measurement file) is never held, and neither is the SVD's `U`.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::qr::no_pivoting::factor;
use faer::{Mat, MatRef, Par};

/// `R`, `z` and `‖y‖²` of the rows folded so far.
pub(super) struct Reduced {
    /// Upper triangular, at most `p` rows (fewer while fewer rows than columns were folded).
    pub r: Mat<f64>,
    /// `Qᵀy` restricted to the rows of `r`.
    pub z: Vec<f64>,
    /// `‖y‖²` over every folded row (the cost; `z` holds only its part in the range of `A`).
    pub residual_sq: f64,
}

impl Reduced {
    /// No rows yet, `columns` parameters.
    pub(super) fn new(columns: usize) -> Self {
        Self { r: Mat::zeros(0, columns), z: Vec::new(), residual_sq: 0.0 }
    }

    /// The reduced form of one block `A`, `y` (tests, and the solver's small problems).
    #[cfg(test)]
    pub(super) fn of(a: MatRef<'_, f64>, y: &[f64]) -> Self {
        let mut reduced = Self::new(a.ncols());
        reduced.fold(a, y);
        reduced
    }

    /// Adds the rows `a`, `y`: the QR factorisation of `[R z; a y]`, whose triangle replaces
    /// `[R z]`.
    pub(super) fn fold(&mut self, a: MatRef<'_, f64>, y: &[f64]) {
        let p = self.r.ncols();
        debug_assert_eq!(a.ncols(), p);
        debug_assert_eq!(a.nrows(), y.len());
        // Row by row, in the order `solver::cost` sums a whole residual, so that the two agree to
        // the bit and the line search compares like with like.
        for v in y {
            self.residual_sq += v * v;
        }
        if a.nrows() == 0 {
            return;
        }
        let held = self.r.nrows();
        let mut triangle = Mat::<f64>::from_fn(held + a.nrows(), p + 1, |i, j| match (i < held, j < p) {
            (true, true) => self.r[(i, j)],
            (true, false) => self.z[i],
            (false, true) => a[(i - held, j)],
            (false, false) => y[i - held],
        });
        // Householder QR in place, serially: faer's global parallelism would split the sums by
        // the thread count and change the last bits (the identification must give the same
        // answer on any machine, and a borderline line search must not flip with the load).
        let (m, n) = triangle.shape();
        let block = factor::recommended_block_size::<f64>(m, n);
        let mut coefficients = Mat::<f64>::zeros(block, m.min(n));
        let mut memory = MemBuffer::new(factor::qr_in_place_scratch::<f64>(m, n, block, Par::Seq, Default::default()));
        factor::qr_in_place(
            triangle.as_mut(),
            coefficients.as_mut(),
            Par::Seq,
            MemStack::new(&mut memory),
            Default::default(),
        );
        let rows = m.min(n).min(p);
        self.r = Mat::from_fn(rows, p, |i, j| if j >= i { triangle[(i, j)] } else { 0.0 });
        self.z = (0..rows).map(|i| triangle[(i, p)]).collect();
    }

    /// `Aᵀy = Rᵀz`.
    pub(super) fn gradient(&self) -> Vec<f64> {
        (0..self.r.ncols()).map(|j| (0..self.r.nrows()).map(|i| self.r[(i, j)] * self.z[i]).sum()).collect()
    }

    /// `‖a_j‖² = ‖r_j‖²` of every column.
    pub(super) fn column_norms_sq(&self) -> Vec<f64> {
        (0..self.r.ncols()).map(|j| (0..self.r.nrows()).map(|i| self.r[(i, j)].powi(2)).sum()).collect()
    }

    /// `AᵀA = RᵀR`.
    pub(super) fn gram(&self) -> Mat<f64> {
        self.r.transpose() * &self.r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tall matrix with a repeated column (rank deficient, as the unidentifiable directions
    /// make the identification's) and a residual with a part outside its range.
    fn problem() -> (Mat<f64>, Vec<f64>) {
        let a = Mat::<f64>::from_fn(37, 5, |i, j| {
            let x = i as f64 * 0.37 + 0.1;
            match j {
                0 => x.sin(),
                1 => (2.0 * x).cos(),
                2 => x * 0.1,
                3 => x.sin(),
                _ => (x * 1.7).sin() * (x * 0.3).cos(),
            }
        });
        let y = (0..37).map(|i| (i as f64 * 0.71).cos() + 0.05 * i as f64).collect();
        (a, y)
    }

    #[test]
    fn folding_in_blocks_keeps_the_normal_equations_and_the_cost_of_the_whole_matrix() {
        let (a, y) = problem();
        let whole_gram = a.transpose() * &a;
        let whole_gradient: Vec<f64> = (0..5).map(|j| (0..37).map(|i| a[(i, j)] * y[i]).sum()).collect();
        // One row at a time (fewer rows than columns at first), uneven blocks, one block.
        for block in [1, 4, 11, 37] {
            let mut reduced = Reduced::new(5);
            for start in (0..37).step_by(block) {
                let end = (start + block).min(37);
                reduced.fold(a.get(start..end, ..), &y[start..end]);
            }
            let gram = reduced.gram();
            for i in 0..5 {
                for j in 0..5 {
                    assert!((gram[(i, j)] - whole_gram[(i, j)]).abs() < 1e-10, "block {block}: AᵀA ({i}, {j})");
                }
            }
            for (g, w) in reduced.gradient().iter().zip(&whole_gradient) {
                assert!((g - w).abs() < 1e-10, "block {block}: Aᵀy {g} vs {w}");
            }
            let cost: f64 = y.iter().map(|v| v * v).sum();
            assert!((reduced.residual_sq - cost).abs() < 1e-10);
            assert_eq!((reduced.r.nrows(), reduced.z.len()), (5, 5));
        }
    }

    #[test]
    fn the_triangle_has_the_singular_values_of_the_whole_matrix() {
        let (a, y) = problem();
        let whole = a.thin_svd().unwrap();
        let reduced = Reduced::of(a.as_ref(), &y);
        let small = reduced.r.thin_svd().unwrap();
        let (s, t) = (whole.S().column_vector(), small.S().column_vector());
        for k in 0..5 {
            assert!((s[k] - t[k]).abs() < 1e-10 * s[0], "σ_{k}: {} vs {}", s[k], t[k]);
        }
        assert!(t[4] < 1e-12 * t[0], "the repeated column leaves a zero singular value");
    }
}
