//! The local product-of-exponentials (POE) kinematic model of a serial robot and its
//! identification Jacobian (Jing, Tao, Yang, Shimada, Eq. 1–4).
#![deny(missing_docs)]
