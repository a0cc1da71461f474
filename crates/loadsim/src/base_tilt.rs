//! A base that tilts under the arm's own weight, read by an inclinometer on it: the
//! cause of the error is a signal the cell measures. A robot on a mobile platform, a column on a
//! soft floor or a light stand turns as a whole under the gravity moment of the arm and its
//! payload about the base, `M = Σ_k m_k c_k × g` (links and payload, base frame), as a rotational
//! spring: the base turns by `θ = C M_h`, `M_h` the horizontal part of `M` (the moment about the
//! vertical turns nothing) and `C` the mount's compliance, rad/(N·m). Every pose then moves by the
//! rotation `exp(θ̂)` about the base origin: `T' = exp(θ̂) · T` in the base frame. The inclinometer
//! reads `θ`'s two horizontal components plus its own white noise.
//!
//! Not an effect of [`crate::Effects`]: its part of the forward model is a motion of the base like
//! [`crate::TimeDriftModel`]'s, but the signal it is read by is a column of the data set, which the
//! generator's samples do not carry; `cargo xtask inputs-check` adds both to simulated data.

use crate::gravity::{link_centres_of_mass, payload_centre_of_mass};
use crate::{Error, Payload, RobotDynamics};
use lie::{SO3, Vector3};
use poe::LocalPoe;
use serde::{Deserialize, Serialize};

/// The mount's compliance and the inclinometer that reads it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct BaseTilt {
    /// Rotational compliance of the base mount about the horizontal axes, rad/(N·m). Default
    /// 1e-7: a 6-axis arm of ~1,000 N·m gravity moment tilts by ~0.1 mrad, which at 2 m reach
    /// moves the tool by ~0.2 mm, several times a tracker's noise (ENGINEERING ESTIMATE for a
    /// light mobile platform; a foundation-bolted arm is 10–100 times stiffer).
    pub compliance_rad_per_nm: f64,
    /// Standard deviation of the inclinometer's reading of each tilt component, rad. Default
    /// 2e-6 (2 µrad, a precision two-axis inclinometer's repeatability, ENGINEERING ESTIMATE: at
    /// 2.5 m reach it moves the tool by 5 µm, below a tracker's noise).
    pub inclinometer_noise_rad: f64,
}

impl Default for BaseTilt {
    fn default() -> Self {
        Self { compliance_rad_per_nm: 1e-7, inclinometer_noise_rad: 2e-6 }
    }
}

impl BaseTilt {
    /// Checks that both values are finite and not negative.
    pub fn validate(&self) -> Result<(), Error> {
        let fields = [
            ("base_tilt.compliance_rad_per_nm", self.compliance_rad_per_nm),
            ("base_tilt.inclinometer_noise_rad", self.inclinometer_noise_rad),
        ];
        match fields.into_iter().find(|(_, v)| !(v.is_finite() && *v >= 0.0)) {
            Some((field, value)) => Err(Error::from(dynamics::Error::InvalidParameter { field, value })),
            None => Ok(()),
        }
    }

    /// The gravity moment of the links and the payload about the base origin at `q`, base frame,
    /// N·m: `Σ m_k c_k × g`.
    pub fn moment(
        model: &LocalPoe,
        dynamics: &RobotDynamics,
        q: &[f64],
        tool: usize,
        payload: &Payload,
    ) -> Result<Vector3, Error> {
        let g = Vector3::from(dynamics.gravity_m_per_s2);
        let links: Vector3 = link_centres_of_mass(model, dynamics, q)?
            .iter()
            .zip(&dynamics.links)
            .map(|(c, link)| link.mass_kg * c.cross(&g))
            .sum();
        Ok(links + payload.mass_kg * payload_centre_of_mass(model, q, tool, payload)?.cross(&g))
    }

    /// The base's tilt at `q` as a rotation vector, base frame, rad: `C` times the moment's part
    /// across gravity.
    pub fn tilt(
        &self,
        model: &LocalPoe,
        dynamics: &RobotDynamics,
        q: &[f64],
        tool: usize,
        payload: &Payload,
    ) -> Result<Vector3, Error> {
        self.validate()?;
        let moment = Self::moment(model, dynamics, q, tool, payload)?;
        let g = Vector3::from(dynamics.gravity_m_per_s2);
        let up = if g.norm() > 0.0 { -g.normalize() } else { Vector3::z() };
        Ok(self.compliance_rad_per_nm * (moment - up * up.dot(&moment)))
    }

    /// The base's rotation for a tilt of [`BaseTilt::tilt`], to put before every base-frame pose.
    pub fn rotation(tilt: &Vector3) -> SO3 {
        SO3::exp(tilt)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::LinkInertia;
    use poe::{JointAxis, JointKind, LocalPoe};

    /// A two-joint arm: a vertical joint 1 at the base, a horizontal joint 2 above it, a 1 m link.
    fn arm() -> (LocalPoe, RobotDynamics) {
        let axis =
            |d: [f64; 3], p: [f64; 3]| JointAxis { kind: JointKind::Revolute, direction: d.into(), point: p.into() };
        let model = LocalPoe::from_zero_configuration(
            &[axis([0.0, 0.0, 1.0], [0.0; 3]), axis([0.0, 1.0, 0.0], [0.0, 0.0, 0.5])],
            lie::SE3::from_translation(Vector3::new(1.0, 0.0, 0.5)),
        )
        .unwrap();
        let dynamics = RobotDynamics {
            links: vec![
                LinkInertia { mass_kg: 10.0, com_m: [0.0, 0.0, 0.25] },
                LinkInertia { mass_kg: 20.0, com_m: [0.5, 0.0, 0.5] },
            ],
            stiffness_nm_per_rad: Vec::new(),
            counterbalance: None,
            gravity_m_per_s2: crate::FLOOR_GRAVITY_M_PER_S2,
        };
        (model, dynamics)
    }

    #[test]
    fn the_base_tilts_about_the_horizontal_axis_across_the_arms_reach_in_proportion_to_its_moment() {
        let (model, dynamics) = arm();
        let tilt = BaseTilt { compliance_rad_per_nm: 1e-6, inclinometer_noise_rad: 0.0 };
        // Reaching along +x, the link's 20 kg at 0.5 m and the 5 kg at 1 m tip the base forward:
        // c × g with c along +x and g along −z is (0, c g, 0), a turn about +y (x towards −z).
        let payload = Payload::at_tool(5.0);
        let theta = tilt.tilt(&model, &dynamics, &[0.0, 0.0], 0, &payload).unwrap();
        let expected = 1e-6 * 9.81 * (20.0 * 0.5 + 5.0 * 1.0);
        assert!((theta.y - expected).abs() < 1e-12 && theta.x.abs() < 1e-12 && theta.z.abs() < 1e-12, "{theta:?}");
        // Turned a quarter about joint 1, the arm reaches along +y and tips the base about −x.
        let turned = tilt.tilt(&model, &dynamics, &[std::f64::consts::FRAC_PI_2, 0.0], 0, &payload).unwrap();
        assert!((turned.x + expected).abs() < 1e-12 && turned.y.abs() < 1e-12, "{turned:?}");
        // Twice the compliance, twice the tilt.
        let double = BaseTilt { compliance_rad_per_nm: 2e-6, ..tilt };
        assert!((double.tilt(&model, &dynamics, &[0.0, 0.0], 0, &payload).unwrap().y - 2.0 * expected).abs() < 1e-12);
    }

    #[test]
    fn a_negative_or_non_finite_compliance_is_refused_by_name() {
        let (model, dynamics) = arm();
        let bad = BaseTilt { compliance_rad_per_nm: f64::NAN, ..BaseTilt::default() };
        let error = bad.tilt(&model, &dynamics, &[0.0, 0.0], 0, &Payload::default()).unwrap_err();
        assert!(error.to_string().contains("base_tilt.compliance_rad_per_nm"), "{error}");
    }
}
