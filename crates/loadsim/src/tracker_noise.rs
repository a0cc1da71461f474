//! Laser-tracker measurement noise. A tracker measures a distance (interferometer or absolute
//! distance meter) and two angles, so its position error is anisotropic: a radial part along the
//! line of sight, roughly constant, and a transverse part that grows with the distance. Leica
//! states the AT901 accuracy as a maximum permissible error (MPE) of ±(15 µm + 6 µm/m) for a
//! point and ±10 µm for the absolute distance meter, and notes that typical errors are half the
//! MPE; the T-Mac 6-DOF probe adds an orientation MPE of about 0.01°. The defaults take σ = MPE/2.

use crate::Error;
use crate::{EntryFault, RobotFacts, SimulatedCell, SimulatedEffect, beyond};
use lie::{Matrix3, SE3, SO3, Vector3};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// Gaussian tracker noise, radial and transverse in position, isotropic in orientation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TrackerNoiseModel {
    /// Standard deviation along the line of sight, m. Default 5 µm (AT901 ADM, MPE 10 µm).
    pub radial_sigma_m: f64,
    /// Standard deviation across the line of sight at zero distance, m. Default 7.5 µm.
    pub transverse_sigma_m: f64,
    /// Growth of the transverse standard deviation with distance, m per m. Default 3 µm/m.
    pub transverse_sigma_per_m: f64,
    /// Standard deviation of each rotation-vector component of the orientation, rad (T-Mac).
    /// Default 0.005° (MPE 0.01°).
    pub orientation_sigma_rad: f64,
}

impl Default for TrackerNoiseModel {
    fn default() -> Self {
        Self {
            radial_sigma_m: 5e-6,
            transverse_sigma_m: 7.5e-6,
            transverse_sigma_per_m: 3e-6,
            orientation_sigma_rad: 0.005_f64.to_radians(),
        }
    }
}

impl TrackerNoiseModel {
    /// Checks that every standard deviation is finite and non-negative.
    pub fn validate(&self) -> Result<(), Error> {
        for (field, value) in [
            ("tracker_noise.radial_sigma_m", self.radial_sigma_m),
            ("tracker_noise.transverse_sigma_m", self.transverse_sigma_m),
            ("tracker_noise.transverse_sigma_per_m", self.transverse_sigma_per_m),
            ("tracker_noise.orientation_sigma_rad", self.orientation_sigma_rad),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(Error::from(dynamics::Error::InvalidParameter { field, value }));
            }
        }
        Ok(())
    }

    /// The line of sight to `point` and two unit vectors across it (tracker at the origin).
    fn sight_basis(point: &Vector3) -> [Vector3; 3] {
        let radial = if point.norm() > 1e-9 { point.normalize() } else { Vector3::z() };
        let helper = if radial.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
        let first = radial.cross(&helper).normalize();
        [radial, first, radial.cross(&first)]
    }

    /// The transverse standard deviation at `distance_m`, m.
    pub fn transverse_sigma_at(&self, distance_m: f64) -> f64 {
        self.transverse_sigma_m + self.transverse_sigma_per_m * distance_m
    }

    /// The covariance of a measured point at `point` (tracker frame), m².
    pub fn position_covariance(&self, point: &Vector3) -> Matrix3 {
        let [radial, first, second] = Self::sight_basis(point);
        let t2 = self.transverse_sigma_at(point.norm()).powi(2);
        radial * radial.transpose() * self.radial_sigma_m.powi(2)
            + (first * first.transpose() + second * second.transpose()) * t2
    }

    /// A noisy measurement of the true pose `tracker_from_tool`: the position moved along and
    /// across the line of sight, the orientation perturbed on the left by a small rotation.
    pub fn measure<R: Rng + ?Sized>(&self, tracker_from_tool: &SE3, rng: &mut R) -> SE3 {
        let mut normal = || -> f64 { StandardNormal.sample(rng) };
        let p = tracker_from_tool.translation();
        let [radial, first, second] = Self::sight_basis(&p);
        let t = self.transverse_sigma_at(p.norm());
        let moved = p + radial * (self.radial_sigma_m * normal()) + first * (t * normal()) + second * (t * normal());
        let tilt = Vector3::new(normal(), normal(), normal()) * self.orientation_sigma_rad;
        SE3::new(SO3::exp(&tilt) * tracker_from_tool.rotation(), moved)
    }
}

/// Largest tracker noise an effects file may give, m (and m per m of range for the transverse
/// part, rad for the orientation): trackers and photogrammetry err by micrometres to a
/// millimetre, a metre is none.
pub const MAX_NOISE: f64 = 1.0;

/// The noise acts where the tracker measures (`Effects::measured_pose`), not on the robot.
impl SimulatedEffect for TrackerNoiseModel {
    fn validate(&self, _cell: &SimulatedCell) -> Result<(), Error> {
        TrackerNoiseModel::validate(self)
    }

    fn check_entries(&self, _robot: &RobotFacts<'_>) -> Result<(), EntryFault> {
        TrackerNoiseModel::validate(self).map_err(|e| EntryFault::of_section(&e))?;
        let bounds = [
            ("radial_sigma_m", self.radial_sigma_m, MAX_NOISE),
            ("transverse_sigma_m", self.transverse_sigma_m, MAX_NOISE),
            ("transverse_sigma_per_m", self.transverse_sigma_per_m, MAX_NOISE),
            ("orientation_sigma_rad", self.orientation_sigma_rad, MAX_NOISE),
        ];
        match bounds.iter().find_map(|b| beyond(&[*b]).map(|f| (b.0, f))) {
            Some((field, message)) => Err(EntryFault { field: field.into(), index: 0, message }),
            None => Ok(()),
        }
    }
}
