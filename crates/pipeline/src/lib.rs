//! The two-step calibration of the paper: geometric identification of a local POE model, then a
//! Gaussian process on the remaining pose error. Also the measurement CSV and robot RON readers.
#![deny(missing_docs)]
