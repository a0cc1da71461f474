//! A set of input points stored row by row, so that each point is one contiguous slice.
//!
//! faer matrices are column-major; kernels read one point at a time, so the inputs are copied once
//! into this layout.

use faer::MatRef;
use serde::{Deserialize, Serialize};

use crate::Error;

/// `len` points of dimension `dim`, row-major.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Points {
    dim: usize,
    data: Vec<f64>,
}

impl Points {
    /// Copies the rows of `x`, refusing NaN and infinities.
    pub fn from_rows(x: MatRef<'_, f64>) -> Result<Self, Error> {
        let (n, dim) = (x.nrows(), x.ncols());
        let mut data = Vec::with_capacity(n * dim);
        for i in 0..n {
            for j in 0..dim {
                let v = x[(i, j)];
                if !v.is_finite() {
                    return Err(Error::NonFiniteData { row: i, column: j, in_outputs: false });
                }
                data.push(v);
            }
        }
        Ok(Self { dim, data })
    }

    /// Builds from row-major data; `data.len()` must be a multiple of `dim`.
    pub fn from_row_major(dim: usize, data: Vec<f64>) -> Self {
        debug_assert!(dim > 0 && data.len().is_multiple_of(dim));
        Self { dim, data }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.data.len().checked_div(self.dim).unwrap_or(0)
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Dimension of each point.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Point `i`.
    #[inline]
    pub fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.dim..(i + 1) * self.dim]
    }

    /// All coordinates, row-major.
    pub fn as_slice(&self) -> &[f64] {
        &self.data
    }

    /// Every coordinate `j` multiplied by `factor[j]`.
    pub(crate) fn scaled_columns(&self, factor: &[f64]) -> Self {
        let data =
            self.data.chunks_exact(self.dim).flat_map(|row| row.iter().zip(factor).map(|(x, f)| x * f)).collect();
        Self { dim: self.dim, data }
    }

    /// The points in `range`, in order.
    pub fn rows(&self, range: std::ops::Range<usize>) -> Self {
        Self { dim: self.dim, data: self.data[range.start * self.dim..range.end * self.dim].to_vec() }
    }

    /// The points at `indices`, in that order.
    pub fn select(&self, indices: &[usize]) -> Self {
        let mut data = Vec::with_capacity(indices.len() * self.dim);
        for &i in indices {
            data.extend_from_slice(self.row(i));
        }
        Self { dim: self.dim, data }
    }
}
