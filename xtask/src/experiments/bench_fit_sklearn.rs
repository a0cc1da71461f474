//! The scikit-learn side of `cargo xtask bench-fit`: scikit-learn's GP per output
//! (`bench_gp_sklearn.py`) on the residuals our own `poe` fit leaves on the same rows, so that
//! both GPs learn the same residuals; optionally the local POE identification with SciPy
//! (`identify_scipy.py`, from the same closed-form registration) timed beside it; and the Python
//! environment they run in.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

use faer::Mat;
use lie::{SE3, Twist, Vector3, Vector6};
use measurements::MeasurementSet;
use model::{ErrorSummary, PoseError, pose_error};
use robot::RobotDescription;

use super::bench_gp_sklearn::{SklearnOptions, fit_predict_with};

/// SciPy's identification beside ours (`--scipy-identify`).
#[derive(Debug, Clone, PartialEq)]
pub struct Identification {
    /// One `least_squares`, s.
    pub seconds: f64,
    /// Its RMS position error on the training rows, mm.
    pub rms_mm: f64,
    /// Our `poe` fit's on the same rows, mm.
    pub calib_poe_rms_mm: f64,
}

/// scikit-learn's kernel, as the existing comparisons run it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SklearnKernel {
    /// `C·RBF(ARD) + C + White`, one restart: `bench-gp --paper`'s for the UR10.
    Ard,
    /// The paper's Eq. 5, `C·RBF + C + DotProduct + White` with one length scale, two restarts:
    /// `bench-gp --paper`'s for the paper's setting.
    Eq5,
}

impl SklearnKernel {
    /// `n_restarts_optimizer`, as `bench-gp --paper` sets it; `--quick` takes none.
    pub fn restarts(self, quick: bool) -> usize {
        match (quick, self) {
            (true, _) => 0,
            (false, SklearnKernel::Ard) => 1,
            (false, SklearnKernel::Eq5) => 2,
        }
    }

    /// The kernel in words.
    pub fn text(self, restarts: usize) -> String {
        let plural = if restarts == 1 { "" } else { "s" };
        match self {
            SklearnKernel::Ard => format!("C·RBF(ARD) + C + White, {restarts} restart{plural}"),
            SklearnKernel::Eq5 => format!("Eq. 5: C·RBF + C + DotProduct + White, {restarts} restart{plural}"),
        }
    }
}

/// What the scikit-learn pipeline did.
#[derive(Debug, Clone, PartialEq)]
pub enum SklearnSide {
    /// Not run, and why.
    Skipped(String),
    /// Finished.
    Done {
        /// SciPy's identification, where it ran.
        scipy: Option<Identification>,
        /// scikit-learn's GP fit (its process, without the prediction), s.
        gp_s: f64,
        /// Peak resident memory of the GP's process and its workers, MiB.
        peak_mib: f64,
        /// Mean held-out position error of our `poe` geometry corrected by its GP, mm.
        heldout_mm: f64,
        /// And rotation error, mrad, for full-pose data.
        heldout_mrad: Option<f64>,
    },
    /// Its GP was stopped at the time limit.
    TimedOut {
        /// SciPy's identification, where it ran.
        scipy: Option<Identification>,
        /// The limit, s.
        limit_s: f64,
    },
}

impl SklearnSide {
    /// scikit-learn's GP fit (the limit where it was stopped); NaN where it did not run. SciPy's
    /// identification is not in it: how long it takes depends on how a user sets it up (ours
    /// fits every local frame with a finite-difference Jacobian, slow where position-only data
    /// leave parameters unobservable), and leaving it out can only understate a speed-up.
    pub fn seconds(&self) -> f64 {
        match self {
            SklearnSide::Skipped(_) => f64::NAN,
            SklearnSide::Done { gp_s, .. } => *gp_s,
            SklearnSide::TimedOut { limit_s, .. } => *limit_s,
        }
    }

    /// [`SklearnSide::seconds`] for the table: `> …` where it was stopped.
    pub fn seconds_text(&self) -> String {
        match self {
            SklearnSide::Skipped(_) => "–".into(),
            SklearnSide::Done { .. } => format!("{:.1}", self.seconds()),
            SklearnSide::TimedOut { .. } => format!("> {:.0}", self.seconds()),
        }
    }

    /// The parts, in words.
    pub fn note(&self) -> String {
        let identified = |i: &Option<Identification>| {
            i.as_ref().map_or(String::new(), |i| {
                format!(
                    "; SciPy `least_squares` on the same rows {:.2} s, not in the ratio (training RMS {:.4} mm; calib's \
                     `poe` {:.4} mm)",
                    i.seconds, i.rms_mm, i.calib_poe_rms_mm
                )
            })
        };
        match self {
            SklearnSide::Skipped(why) => format!("not run: {why}"),
            SklearnSide::Done { scipy, gp_s, peak_mib, .. } => {
                format!("GP fit {gp_s:.1} s (peak {peak_mib:.0} MiB){}", identified(scipy))
            }
            SklearnSide::TimedOut { scipy, limit_s } => {
                format!("GP fit stopped after {limit_s:.0} s{}", identified(scipy))
            }
        }
    }
}

/// What the comparisons import.
const IMPORTS: &str = "import numpy, scipy, sklearn";

/// `true` when `python` imports NumPy, SciPy and scikit-learn.
fn imports(python: &Path) -> bool {
    Command::new(python)
        .args(["-c", IMPORTS])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// The interpreter the scikit-learn side runs: `given` (`--python`), else the comparisons' usual
/// one ([`super::bench_gp_sklearn::python`]: `$CALIB_PYTHON`, `target/pyenv`, `python3`) where it
/// imports scikit-learn, else `target/pyenv` made for it with pip from
/// `xtask/scripts/requirements.txt`. `Err` says why there is none.
pub fn python_env(given: Option<&Path>) -> Result<PathBuf, String> {
    if let Some(python) = given {
        return if imports(python) {
            Ok(python.to_owned())
        } else {
            Err(format!("--python {}: does not import NumPy, SciPy and scikit-learn", python.display()))
        };
    }
    let usual = super::bench_gp_sklearn::python();
    if imports(&usual) {
        return Ok(usual);
    }
    let root = crate::workspace_root();
    let venv = root.join("target/pyenv");
    let python = venv.join("bin/python3");
    eprintln!("bench-fit: making {} with pip (xtask/scripts/requirements.txt) …", venv.display());
    let made = Command::new("python3").arg("-m").arg("venv").arg(&venv).status().is_ok_and(|s| s.success());
    let installed = made
        && Command::new(venv.join("bin/pip"))
            .args(["install", "--quiet", "-r"])
            .arg(root.join("xtask/scripts/requirements.txt"))
            .status()
            .is_ok_and(|s| s.success());
    if installed && imports(&python) {
        Ok(python)
    } else {
        Err(format!("no Python with scikit-learn, and pip could not install it into {}", venv.display()))
    }
}

/// The interpreter and the versions of what it imports, for the table's head.
pub fn versions(python: &Path) -> String {
    let script = "import platform, numpy, scipy, sklearn; \
                  print(f'Python {platform.python_version()}, NumPy {numpy.__version__}, SciPy {scipy.__version__}, \
                  scikit-learn {sklearn.__version__}')";
    match Command::new(python).args(["-c", script]).output() {
        Ok(out) if out.status.success() => {
            format!("{} ({})", String::from_utf8_lossy(&out.stdout).trim(), python.display())
        }
        _ => format!("{}: scikit-learn or SciPy not importable", python.display()),
    }
}

/// The position error a residual row stands for, m: the vector itself (position only) or the
/// translation of the tool-point twist's exponential (full pose), which is the measured position
/// minus the model's exactly.
fn position_error_m(y: &Mat<f64>, i: usize) -> f64 {
    if y.ncols() == 3 {
        return Vector3::new(y[(i, 0)], y[(i, 1)], y[(i, 2)]).norm();
    }
    let g = Vector6::from_fn(|c, _| y[(i, c)]);
    Twist::from_vector(&g).exp().translation().norm()
}

/// The errors on `test` of the geometric poses `poses` corrected by predicted residuals `mean`
/// (one row per pose: the position error, or the error twist at the tool point, as
/// `ResidualFrame::ToolPoint` defines it and `ResidualGp` applies it).
pub fn corrected(poses: &[SE3], test: &MeasurementSet, mean: &Mat<f64>) -> anyhow::Result<ErrorSummary> {
    if poses.len() != test.rows.len() || mean.nrows() != poses.len() || !matches!(mean.ncols(), 3 | 6) {
        anyhow::bail!(
            "{} poses, {} test rows, a {} × {} prediction: they do not match",
            poses.len(),
            test.rows.len(),
            mean.nrows(),
            mean.ncols()
        );
    }
    let errors: Vec<PoseError> = poses
        .iter()
        .zip(&test.rows)
        .enumerate()
        .map(|(i, (pose, row))| {
            let corrected = if mean.ncols() == 3 {
                SE3::new(pose.rotation(), pose.translation() + Vector3::new(mean[(i, 0)], mean[(i, 1)], mean[(i, 2)]))
            } else {
                let p = SE3::from_translation(pose.translation());
                let g = Vector6::from_fn(|c, _| mean[(i, c)]);
                p * Twist::from_vector(&g).exp() * p.inverse() * *pose
            };
            let error = pose_error(&corrected, row);
            if test.full_pose { error } else { PoseError { rotation_mrad: None, ..error } }
        })
        .collect();
    Ok(ErrorSummary::from_errors(&errors))
}

/// How the pipeline runs.
#[derive(Debug, Clone)]
pub struct PipelineOptions {
    /// The interpreter ([`python_env`]).
    pub python: PathBuf,
    /// scikit-learn's kernel.
    pub kernel: SklearnKernel,
    /// Its `n_restarts_optimizer`.
    pub restarts: usize,
    /// The payload as a GP input, as `poe-gp-load` has it.
    pub with_payload: bool,
    /// scikit-learn's GP is stopped after this.
    pub timeout: Duration,
    /// Also time SciPy's identification of the same rows.
    pub scipy_identify: bool,
}

/// Runs the pipeline on `train` and tests it on `test`: our `poe`'s residuals, scikit-learn's GP
/// on them, one per output in 2 worker processes; where asked, SciPy's identification first
/// (timed; its model is not used further).
pub fn sklearn_pipeline(
    robot: &RobotDescription,
    train: &MeasurementSet,
    test: &MeasurementSet,
    options: &PipelineOptions,
) -> anyhow::Result<SklearnSide> {
    let set = super::bench_gp_residuals::residuals(String::new(), robot, train, test, options.with_payload)?;
    let y = &set.train.outputs;
    let scipy = if options.scipy_identify {
        let observations = model::geometric::observations(train);
        let start = poe::identify::register(&robot.nominal_model()?, &observations)?;
        let weights = pipeline::FitOptions::default().identification;
        let scipy = super::bench_identify::scipy_identify(
            &options.python,
            &start,
            &observations,
            weights.position_sigma_m,
            weights.rotation_sigma_rad,
            1,
        )?;
        let calib_poe_rms_mm = 1e3
            * ((0..y.nrows()).map(|i| position_error_m(y, i).powi(2)).sum::<f64>() / y.nrows().max(1) as f64).sqrt();
        Some(Identification { seconds: scipy.seconds, rms_mm: scipy.rms_position_m * 1e3, calib_poe_rms_mm })
    } else {
        None
    };
    let sklearn = SklearnOptions {
        linear: false,
        isotropic: options.kernel == SklearnKernel::Eq5,
        restarts: options.restarts,
        independent: true,
        processes: 2,
        timeout: options.timeout,
    };
    // Its convergence warnings (a length scale at its bound) would bury the progress lines.
    let quiet = true;
    Ok(match fit_predict_with(&options.python, quiet, &set.train.inputs, y, &set.test.inputs, &sklearn)? {
        None => SklearnSide::TimedOut { scipy, limit_s: options.timeout.as_secs_f64() },
        Some(result) => {
            let summary = corrected(&set.test_poses, test, &result.mean)?;
            SklearnSide::Done {
                scipy,
                gp_s: result.fit_s,
                peak_mib: result.peak_bytes / (1024.0 * 1024.0),
                heldout_mm: summary.mean_position_error_mm,
                heldout_mrad: summary.mean_rotation_error_mrad,
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use lie::SO3;
    use measurements::Measurement;
    use model::{ResidualFrame, ResidualSet};

    /// A pose away from the origin and a measurement off it by millimetres and milliradians,
    /// where the tool-point frame and the tracker frame differ by far more than the tolerance.
    fn case(full_pose: bool) -> (Vec<SE3>, MeasurementSet) {
        let pose = SE3::new(SO3::exp(&Vector3::new(0.3, -0.2, 1.1)), Vector3::new(1.2, -0.4, 0.9));
        let measured = SE3::new(SO3::exp(&Vector3::new(2e-3, -1e-3, 3e-3)), Vector3::new(1e-3, 2e-3, -3e-3)) * pose;
        let row = Measurement {
            line: 2,
            q: vec![0.0; 6],
            position: measured.translation(),
            orientation: full_pose.then(|| measured.rotation()),
            payload_kg: 0.0,
            tool: 0,
            temp_c: None,
            t_s: None,
            torques_nm: None,
            inputs: measurements::Inputs::default(),
            std: None,
        };
        (vec![pose], MeasurementSet::from_rows("mem", vec![row], vec![]))
    }

    #[test]
    fn a_prediction_of_the_exact_residual_corrects_the_pose_onto_the_measurement() {
        for full_pose in [true, false] {
            let (poses, test) = case(full_pose);
            let residual = ResidualSet::new(&poses, &test, false, ResidualFrame::ToolPoint).outputs;
            let before = corrected(&poses, &test, &Mat::zeros(1, residual.ncols())).unwrap();
            let after = corrected(&poses, &test, &residual).unwrap();
            assert!(before.mean_position_error_mm > 3.0, "{before:?}");
            assert!(after.mean_position_error_mm < 1e-9, "full pose {full_pose}: {after:?}");
            assert_eq!(after.mean_rotation_error_mrad.is_some(), full_pose);
            assert!(after.mean_rotation_error_mrad.unwrap_or(0.0) < 1e-9, "{after:?}");
            let error_m = position_error_m(&residual, 0);
            assert!((error_m * 1e3 - before.mean_position_error_mm).abs() < 1e-12, "{error_m} m");
        }
    }

    #[test]
    fn a_prediction_of_the_wrong_shape_is_refused() {
        let (poses, test) = case(true);
        assert!(corrected(&poses, &test, &Mat::zeros(2, 6)).is_err());
        assert!(corrected(&poses, &test, &Mat::zeros(1, 4)).is_err());
    }
}
