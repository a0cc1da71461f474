//! The calibration methods of the paper's comparison.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// A calibration method, as named on the command line (`calib fit --method …`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Base placement and tool only (12 parameters; 9 with position-only data).
    BaseTool,
    /// The full local POE identification (paper step 1).
    Poe,
    /// POE, then a GP on the residual with the joint angles as inputs (paper step 2 without load).
    PoeGp,
    /// POE, then a GP on the residual with the joint angles and the payload as inputs (Eq. 12).
    PoeGpLoad,
}

impl Method {
    /// Every method, in the order of the paper's tables.
    pub const ALL: [Method; 4] = [Method::BaseTool, Method::Poe, Method::PoeGp, Method::PoeGpLoad];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Method::BaseTool => "base-tool",
            Method::Poe => "poe",
            Method::PoeGp => "poe-gp",
            Method::PoeGpLoad => "poe-gp-load",
        }
    }

    /// Whether a Gaussian process follows the geometric fit.
    pub fn uses_gp(self) -> bool {
        matches!(self, Method::PoeGp | Method::PoeGpLoad)
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A method name that is not one of [`Method::ALL`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownMethod {
    /// The name given.
    pub name: String,
}

impl fmt::Display for UnknownMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "unknown method '{}': expected one of base-tool, poe, poe-gp, poe-gp-load", self.name)
    }
}

impl std::error::Error for UnknownMethod {}

impl FromStr for Method {
    type Err = UnknownMethod;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Method::ALL.into_iter().find(|m| m.name() == s).ok_or_else(|| UnknownMethod { name: s.to_owned() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_names_round_trip_and_unknown_names_are_refused() {
        for method in Method::ALL {
            assert_eq!(method.name().parse::<Method>(), Ok(method));
        }
        assert_eq!("poe+gp".parse::<Method>(), Err(UnknownMethod { name: "poe+gp".into() }));
    }
}
