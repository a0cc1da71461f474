//! faer's products and triangular solves wrapped so that results are the same to the bit whatever
//! the thread count.
//!
//! faer splits the sums of a product or a triangular solve with a single right-hand column (a
//! matrix–vector product) by the number of threads: at n = 1,387, `L⁻¹ y` and `A y` differed in the
//! last bits between one and two threads, and with them the likelihood's gradient and the optimum
//! a hyperparameter search reached (UR10 C: a log marginal likelihood 0.24 nats apart). With two
//! or more columns faer splits by column and agreed to the bit (measured for 2–64 columns, n =
//! 700–1,387, square and triangular products, the factorisation and the inverse). A single column
//! costs `O(n²)`, so it runs serially here.

use faer::linalg::matmul;
use faer::linalg::triangular_solve;
use faer::{Accum, MatMut, MatRef, Par};

/// `par`, or serial for a single right-hand column.
fn for_columns(columns: usize, par: Par) -> Par {
    if columns <= 1 { Par::Seq } else { par }
}

/// `rhs ← L⁻¹ rhs`.
pub fn solve_lower(l: MatRef<'_, f64>, rhs: MatMut<'_, f64>, par: Par) {
    let par = for_columns(rhs.ncols(), par);
    triangular_solve::solve_lower_triangular_in_place(l, rhs, par);
}

/// `rhs ← L⁻ᵀ rhs`.
pub fn solve_upper_transposed(l: MatRef<'_, f64>, rhs: MatMut<'_, f64>, par: Par) {
    let par = for_columns(rhs.ncols(), par);
    triangular_solve::solve_upper_triangular_in_place(l.transpose(), rhs, par);
}

/// `dst ← accum(dst) + alpha · a b`.
pub fn product(dst: MatMut<'_, f64>, accum: Accum, a: MatRef<'_, f64>, b: MatRef<'_, f64>, alpha: f64, par: Par) {
    let par = for_columns(dst.ncols(), par);
    matmul::matmul(dst, accum, a, b, alpha, par);
}
