//! The Cholesky factorisation of a kernel matrix by halves on faer, with explicit parallelism.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt;
use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::linalg::triangular_solve;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, MatMut, Par, Spec};
use serde::{Deserialize, Serialize};

/// Block sizes of the dense Cholesky factorisation of a kernel matrix.
///
/// Above [`FactorOptions::recursion_leaf`] the matrix is split in halves: factor the top-left
/// half, solve for the bottom-left block, subtract its product from the bottom-right half (one
/// large product, faer's lower-triangular matrix product) and factor that half the same way. faer's
/// own factorisation updates the trailing matrix by 128 columns at a time, which on this 2-core
/// machine ran at 1.5× the time of faer's matrix product for the same flops on the rayon pool
/// (1.14× serially) at n = 3,000; the halving with leaves of 512 rows factored by faer with blocks
/// of 256 ran at 1.08× on both (the throwaway profile behind `bench-gp --lml-floor`, recorded in
/// docs/results/lml-floor.md). Results depend on these sizes in the last bits, never on the thread
/// count.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default)]
pub struct FactorOptions {
    /// Largest order factored by faer's blocked factorisation directly (at least 1).
    pub recursion_leaf: usize,
    /// faer's block size inside a leaf (at least 1).
    pub leaf_block: usize,
}

impl Default for FactorOptions {
    fn default() -> Self {
        // Leaves of 512–1,024 with blocks of 256 measured alike (1.08–1.09×); blocks of 128, faer's
        // default, 1.34× on the rayon pool.
        Self { recursion_leaf: 512, leaf_block: 256 }
    }
}

impl FactorOptions {
    /// Refuses a zero size, naming its field.
    pub fn validate(&self) -> Result<(), &'static str> {
        for (field, value) in [("recursion_leaf", self.recursion_leaf), ("leaf_block", self.leaf_block)] {
            if value == 0 {
                return Err(field);
            }
        }
        Ok(())
    }
}

/// `A = L Lᵀ` in place on the lower triangle of `a` (the strict upper triangle is neither read nor
/// written), by halves down to [`FactorOptions::recursion_leaf`]; on failure the index of the first
/// pivot that was not positive.
pub fn cholesky_lower_in_place(mut a: MatMut<'_, f64>, options: &FactorOptions, par: Par) -> Result<(), usize> {
    let n = a.nrows();
    if n <= options.recursion_leaf.max(1) {
        let mut params: Spec<llt::factor::LltParams, f64> = Default::default();
        params.config.block_size = options.leaf_block.max(1);
        let mut mem = MemBuffer::new(llt::factor::cholesky_in_place_scratch::<f64>(n, par, params));
        return llt::factor::cholesky_in_place(a, Default::default(), par, MemStack::new(&mut mem), params)
            .map(|_| ())
            .map_err(|llt::factor::LltError::NonPositivePivot { index }| index);
    }
    let half = n / 2;
    let (mut a00, _, mut a10, mut a11) = a.rb_mut().split_at_mut(half, half);
    cholesky_lower_in_place(a00.rb_mut(), options, par)?;
    // L₁₀ = A₁₀ L₀₀⁻ᵀ, then A₁₁ − L₁₀ L₁₀ᵀ (lower triangle only) is the Schur complement to factor.
    triangular_solve::solve_lower_triangular_in_place(a00.rb(), a10.rb_mut().transpose_mut(), par);
    triangular::matmul(
        a11.rb_mut(),
        BlockStructure::TriangularLower,
        Accum::Add,
        a10.rb(),
        BlockStructure::Rectangular,
        a10.rb().transpose(),
        BlockStructure::Rectangular,
        -1.0,
        par,
    );
    cholesky_lower_in_place(a11, options, par).map_err(|index| half + index)
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    /// A well-conditioned symmetric positive definite matrix: `B Bᵀ + n I` from a fixed pattern.
    fn spd(n: usize) -> Mat<f64> {
        let b = Mat::from_fn(n, n, |i, j| (((i * 7 + j * 13) % 17) as f64 - 8.0) / 8.0);
        let mut a = Mat::from_fn(n, n, |i, j| (0..n).map(|k| b[(i, k)] * b[(j, k)]).sum::<f64>());
        for i in 0..n {
            a[(i, i)] += n as f64;
        }
        a
    }

    #[test]
    fn the_factor_by_halves_reproduces_the_matrix_for_every_leaf_size() {
        let n = 37;
        let a = spd(n);
        for (recursion_leaf, leaf_block) in [(1, 1), (3, 2), (8, 4), (20, 128), (512, 256)] {
            let options = FactorOptions { recursion_leaf, leaf_block };
            for par in [Par::Seq, Par::rayon(2)] {
                let mut l = a.clone();
                cholesky_lower_in_place(l.as_mut(), &options, par).expect("positive definite");
                for j in 0..n {
                    for i in j..n {
                        let llt: f64 = (0..=j).map(|k| l[(i, k)] * l[(j, k)]).sum();
                        assert!((llt - a[(i, j)]).abs() < 1e-12 * n as f64, "{options:?} ({i}, {j})");
                    }
                }
            }
        }
    }

    #[test]
    fn a_negative_pivot_in_the_second_half_is_reported_at_its_own_index() {
        let n = 37;
        for bad in [0, 5, 18, 19, 30, 36] {
            for (recursion_leaf, leaf_block) in [(1, 1), (4, 2), (512, 256)] {
                // A negative diagonal entry: the pivot at `bad` goes negative while every earlier
                // one is untouched.
                let mut a = spd(n);
                a[(bad, bad)] = -1.0;
                let options = FactorOptions { recursion_leaf, leaf_block };
                let found = cholesky_lower_in_place(a.as_mut(), &options, Par::Seq).err();
                assert_eq!(found, Some(bad), "{options:?}");
            }
        }
    }

    #[test]
    fn zero_block_sizes_are_refused() {
        let zero_leaf = FactorOptions { recursion_leaf: 0, ..FactorOptions::default() };
        assert_eq!(zero_leaf.validate(), Err("recursion_leaf"));
        let zero_block = FactorOptions { leaf_block: 0, ..FactorOptions::default() };
        assert_eq!(zero_block.validate(), Err("leaf_block"));
        assert_eq!(FactorOptions::default().validate(), Ok(()));
    }
}
