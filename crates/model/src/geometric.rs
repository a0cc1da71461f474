//! Step 1 of the paper: the geometric calibration (`base-tool` and `poe`).

use errors::Error;
use lie::SE3;
use measurements::MeasurementSet;
use poe::LocalPoe;
use poe::identify::{IdentificationOptions, IdentificationReport, Observation, Scope, Target};

/// The measurements as identification observations (SI units, tracker frame).
pub fn observations(data: &MeasurementSet) -> Vec<Observation> {
    data.rows
        .iter()
        .map(|row| Observation {
            q: row.q.clone(),
            tool: row.tool,
            target: match row.orientation {
                Some(rotation) => Target::Pose(SE3::new(rotation, row.position)),
                None => Target::Point(row.position),
            },
            stated_sigma: row.std,
        })
        .collect()
}

/// The result of the geometric step.
#[derive(Debug, Clone)]
pub struct GeometricFit {
    /// The identified kinematics, reference frame = tracker.
    pub model: LocalPoe,
    /// The nominal model placed in the tracker frame by the base-tool fit (the "before" of the
    /// report).
    pub registered: LocalPoe,
    /// How the identification went.
    pub report: IdentificationReport,
}

/// Fits the kinematics to the data: closed-form registration, then the base-tool or the full
/// local POE identification.
pub fn fit_geometry(
    nominal: &LocalPoe,
    data: &MeasurementSet,
    scope: Scope,
    options: &IdentificationOptions,
) -> Result<GeometricFit, Error> {
    let observations = observations(data);
    // The "before" is the nominal model at its base-tool fit, not the closed-form registration
    // that starts it (UR10 series B: 24 m off against 0.87 mm).
    let (registered, identification) =
        poe::identify::calibrate_placed(nominal, &observations, scope, options).map_err(Error::kinematics)?;
    Ok(GeometricFit { model: identification.model, registered, report: identification.report })
}

/// [`fit_geometry`] with the full identification under a prior toward the placed nominal model:
/// `prior` is the standard deviation of a link's translation (m) and rotation (rad)
/// about it; `None` is [`fit_geometry`].
pub fn fit_geometry_with_prior(
    nominal: &LocalPoe,
    data: &MeasurementSet,
    scope: Scope,
    prior: Option<(f64, f64)>,
    options: &IdentificationOptions,
) -> Result<GeometricFit, Error> {
    let observations = observations(data);
    let (registered, identification) =
        poe::identify::calibrate_placed_with_prior(nominal, &observations, scope, prior, options)
            .map_err(Error::kinematics)?;
    Ok(GeometricFit { model: identification.model, registered, report: identification.report })
}
