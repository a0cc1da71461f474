//! Every parameter of the simulation study (the JSON's `params`), and the report's account of
//! each with its source and of what differs from the paper.

use anyhow::Context;
use campaign::{Perturbation, paper_effects};
use loadsim::{Effects, GeneratorConfig, JointComplianceModel, RobotDynamics, SimulatedCell};
use model::Method;
use pipeline::FitOptions;
use robot::RobotDescription;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::Path;

/// How many poses and folds.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Sizes {
    /// Training poses.
    pub training: usize,
    /// Cross-validation folds.
    pub folds: usize,
    /// Poses per test set (there are three).
    pub test: usize,
}

impl Sizes {
    /// The paper's study: 300 training poses, 10 folds, three test sets of 100.
    pub const PAPER: Sizes = Sizes { training: 300, folds: 10, test: 100 };
    /// For CI: the same pipeline on a fifth of the poses.
    pub const QUICK: Sizes = Sizes { training: 60, folds: 3, test: 20 };
}

/// Every seed, drawn from the study's seed.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Seeds {
    /// The `--seed` given.
    pub study: u64,
    /// The true robot's perturbation and the tracker placement.
    pub cell: u64,
    /// The training poses, payloads and noise.
    pub training: u64,
    /// The three test sets.
    pub tests: [u64; 3],
    /// The shuffle that assigns training poses to folds.
    pub folds: u64,
}

/// Where the tracker stands.
#[derive(Debug, Clone, Serialize)]
pub struct TrackerPlacement {
    /// Distance from the robot base, m.
    pub distance_m: f64,
    /// `tracker_from_base` translation, m.
    pub translation_m: [f64; 3],
    /// `tracker_from_base` rotation vector, rad.
    pub rotation_vector_rad: [f64; 3],
}

/// Every parameter of the simulation, as written to the JSON's `params`.
#[derive(Debug, Clone, Serialize)]
pub struct Params {
    /// Stiffness preset.
    pub preset: Preset,
    /// Factor the robot file's stiffness was divided by.
    pub stiffness_softening: f64,
    /// Whether this was the reduced `--quick` run.
    pub quick: bool,
    /// The robot file.
    pub robot_file: String,
    /// Its name.
    pub robot_name: String,
    /// Seeds.
    pub seeds: Seeds,
    /// Poses and folds.
    pub sizes: Sizes,
    /// Full-pose (6-DOF) measurements.
    pub full_pose: bool,
    /// The true robot's offsets from nominal.
    pub perturbation: Perturbation,
    /// The tracker.
    pub tracker: TrackerPlacement,
    /// Masses, centres of mass, stiffness (after the preset) and balancer.
    pub dynamics: RobotDynamics,
    /// The simulated effects.
    pub effects: Effects,
    /// The training set's generator (the test sets differ only in seed and count).
    pub generator: GeneratorConfig,
    /// Fit options per variant (`paper:` prefix for the paper-faithful rows).
    pub fit_options: BTreeMap<String, FitOptions>,
}

/// What the study needs to describe itself.
#[derive(Debug)]
pub struct Setup<'a> {
    /// The robot file.
    pub robot_file: &'a Path,
    /// The robot with the preset's stiffness.
    pub robot: &'a RobotDescription,
    /// The preset.
    pub preset: Preset,
    /// `--quick`.
    pub quick: bool,
    /// Poses and folds.
    pub sizes: Sizes,
    /// Seeds.
    pub seeds: Seeds,
    /// The truth.
    pub cell: &'a SimulatedCell,
    /// The perturbation the truth was drawn with.
    pub perturbation: Perturbation,
    /// The effects.
    pub effects: &'a Effects,
    /// The training generator.
    pub generator: &'a GeneratorConfig,
    /// Full pose.
    pub full_pose: bool,
    /// The rows compared.
    pub variants: &'a [Variant],
}

impl Params {
    /// The parameters of a study.
    pub fn new(s: &Setup<'_>) -> anyhow::Result<Self> {
        let base_in_tracker = s.cell.tracker_from_base;
        Ok(Params {
            preset: s.preset,
            stiffness_softening: s.preset.softening(),
            quick: s.quick,
            robot_file: s.robot_file.display().to_string(),
            robot_name: s.robot.name.clone(),
            seeds: s.seeds,
            sizes: s.sizes,
            full_pose: s.full_pose,
            perturbation: s.perturbation,
            tracker: TrackerPlacement {
                distance_m: base_in_tracker.translation().norm(),
                translation_m: base_in_tracker.translation().into(),
                rotation_vector_rad: base_in_tracker.rotation().log().into(),
            },
            dynamics: s.robot.dynamics.clone().context("the robot has no dynamics block")?,
            effects: s.effects.clone(),
            generator: s.generator.clone(),
            fit_options: s
                .variants
                .iter()
                .map(|v| (format!("{}{}", if v.paper_faithful { "paper:" } else { "" }, v.key), v.options.clone()))
                .collect(),
        })
    }
}

fn round(values: impl IntoIterator<Item = f64>, scale: f64, digits: usize) -> String {
    values.into_iter().map(|v| format!("{:.digits$}", v * scale)).collect::<Vec<_>>().join(", ")
}

/// The "Parameters and their sources" and "Differences from the paper" sections.
pub fn parameters_section(p: &Params) -> String {
    let mut out =
        String::from("## Parameters and their sources\n\n| parameter | value | source |\n| --- | --- | --- |\n");
    cell_rows(&mut out, p);
    dynamics_rows(&mut out, &p.dynamics, p.preset);
    effect_rows(&mut out, p);
    sampling_rows(&mut out, p);
    fit_rows(&mut out, &p.fit_options);
    out.push_str(DIFFERENCES);
    out
}

/// One row of the parameters table.
fn row(out: &mut String, name: &str, value: String, source: &str) {
    let _ = writeln!(out, "| {name} | {value} | {source} |");
}

/// The robot, its perturbation, the tool, the tracker and what it measures.
fn cell_rows(out: &mut String, p: &Params) {
    let pert = &p.perturbation;
    row(
        out,
        "robot",
        format!("{} (`{}`), nominal local POE from its zero-configuration axes", p.robot_name, p.robot_file),
        "ABB IRB 4400 product specification, tabulated in the project SPEC",
    );
    row(
        out,
        "true robot",
        format!(
            "every local frame (6 joints and the tool) moved by exp(ξ), each component of ξ uniform in ±{} mm / ±{} mrad",
            pert.translation_m * 1e3,
            pert.rotation_rad * 1e3
        ),
        "engineering estimate: machining and assembly tolerances of a 1-tonne arm are tenths of a mm to a mm and \
tenths of a mrad to a mrad; the uncalibrated arm then misses by millimetres, the range tracker studies report \
before calibration (e.g. Nubiola & Bonev 2013, IRB 1600: 0.97 mm mean, 2.2 mm max). The paper says only \
\"slightly perturbed\"; the base-tool row scales with this choice",
    );
    row(
        out,
        "tool",
        format!("{} m along the flange's z axis", pert.tool_m),
        "a T-Mac probe on a short adapter (estimate)",
    );
    row(
        out,
        "tracker placement",
        format!(
            "{:.2} m from the base, levelled, random bearing and yaw; tracker_from_base translation ({}) m",
            p.tracker.distance_m,
            round(p.tracker.translation_m, 1.0, 3)
        ),
        "drawn 3–5 m from the base, within the AT901's accurate range (estimate)",
    );
    row(
        out,
        "measurements",
        if p.full_pose { "full pose (position and orientation)".into() } else { "position only".into() },
        "paper: Leica AT901 with a T-Mac 6-DOF probe",
    );
}

/// Masses, centres of mass, stiffness and balancer.
fn dynamics_rows(out: &mut String, d: &RobotDynamics, preset: Preset) {
    row(
        out,
        "link masses",
        format!("{} kg (links 1–6)", round(d.links.iter().map(|l| l.mass_kg), 1.0, 0)),
        "fixture comments: ABB spec 3HAC9117-1 gives about 1 t for the manipulator; the split is an ENGINEERING ESTIMATE",
    );
    row(
        out,
        "centres of mass",
        d.links.iter().map(|l| format!("({})", round(l.com_m, 1.0, 2))).collect::<Vec<_>>().join(", ")
            + " m, zero configuration",
        "fixture comments: ENGINEERING ESTIMATES from the link geometry",
    );
    let stiffness = round(d.stiffness_nm_per_rad.iter().copied(), 1.0, 0);
    row(
        out,
        "joint stiffness",
        match preset {
            Preset::Physical => format!("{stiffness} N·m/rad"),
            Preset::PaperLike => format!("{stiffness} N·m/rad (the fixture's divided by {PAPER_LIKE_SOFTENING})"),
        },
        match preset {
            Preset::Physical => {
                "fixture comments: identified 6R arms (Dumas et al., Robotica 2011, KUKA KR240-2) are of order 1e6 on \
joints 1–3 and 1e5–1e6 on the wrist; round values taken, ENGINEERING ESTIMATE"
            }
            Preset::PaperLike => {
                "PAPER-LIKE PRESET, not physical: softened so that the payload sag reaches the size the paper's Table I implies"
            }
        },
    );
    row(
        out,
        "balancer",
        d.counterbalance.as_ref().map_or("none".into(), |c| {
            format!(
                "joint {}: spring {} N at zero, {} N/m, anchor {} m, attachment {} m",
                c.joint_index + 1,
                c.force_at_zero_n,
                c.stiffness_n_per_m,
                c.anchor_radius_m,
                c.attachment_radius_m
            )
        }),
        "fixture comments: the IRB 4400 has a spring balancer on axis 2 (product manual 3HAC022032-001); 85 % balanced, ENGINEERING ESTIMATE",
    );
}

/// The load model, the payloads, the tracker noise and the effects left out.
fn effect_rows(out: &mut String, p: &Params) {
    let g = &p.generator;
    row(
        out,
        "load model",
        match p.effects.joint_compliance {
            Some(c) if c.payload_only => "δq = C τ, payload weight only".into(),
            Some(_) => "δq = C τ(q, m): gravity of the arm, the balancer and the payload, first order".into(),
            None => "off".into(),
        },
        match p.preset {
            Preset::Physical => {
                "the paper's ref. [15] (Tao, Yang & Tomizuka 2013): lumped joint compliance, rigid links (loadsim)"
            }
            Preset::PaperLike => {
                "ref. [15]'s joint compliance under the payload alone (PAPER-LIKE: the paper simulates \"adding different \
payloads\"; the arm's own weight on joints this soft would leave POE 5 mm)"
            }
        },
    );
    row(
        out,
        "payloads",
        format!("{} kg, one drawn uniformly per pose, at the tool point", list(&g.payloads_kg)),
        "paper, Section IV-A",
    );
    if let Some(n) = p.effects.tracker_noise {
        row(
            out,
            "tracker noise (σ)",
            format!(
                "radial {} µm, transverse {} µm + {} µm/m, orientation {:.4}° per axis",
                n.radial_sigma_m * 1e6,
                n.transverse_sigma_m * 1e6,
                n.transverse_sigma_per_m * 1e6,
                n.orientation_sigma_rad.to_degrees()
            ),
            "loadsim `TrackerNoiseModel` docs: Leica AT901 MPE ±(15 µm + 6 µm/m), ADM ±10 µm, T-Mac ≈ 0.01°; σ = MPE/2 \
(Leica: typical errors are half the MPE)",
        );
    }
    row(
        out,
        "other effects",
        "none (no backlash, gear error, thermal growth, drift)".into(),
        "the paper simulates loading only",
    );
}

/// How the poses are drawn, how many, and the seeds.
fn sampling_rows(out: &mut String, p: &Params) {
    let g = &p.generator;
    row(
        out,
        "joint sampling",
        format!(
            "uniform within the limits less {:.0}°, poses with a tool-point Jacobian singular value below {} rejected",
            g.limit_margin_rad.to_degrees(),
            g.min_singular_value
        ),
        "paper: \"randomly generated within the workspace\"; margin and rejection are loadsim's defaults",
    );
    row(
        out,
        "poses",
        format!("{} training, {} folds, 3 test sets of {}", p.sizes.training, p.sizes.folds, p.sizes.test),
        if p.quick { "`--quick` (the paper: 300, 10, 3 × 100)" } else { "paper, Section IV-A" },
    );
    let s = &p.seeds;
    row(
        out,
        "seeds",
        format!(
            "study {}; cell {}, training {}, tests {}, folds {}",
            s.study,
            s.cell,
            s.training,
            s.tests.map(|t| t.to_string()).join(", "),
            s.folds
        ),
        "ChaCha8 streams drawn from the study seed",
    );
}

/// The fit options of the POE and GP rows.
fn fit_rows(out: &mut String, fit_options: &BTreeMap<String, FitOptions>) {
    if let Some(o) = fit_options.get("poe") {
        let id = &o.identification;
        row(
            out,
            "identification",
            format!(
                "{:?}, ≤ {} iterations, residuals weighted by σ = {} mm and {} mrad",
                id.solver,
                id.max_iterations,
                id.position_sigma_m * 1e3,
                id.rotation_sigma_rad * 1e3
            ),
            "poe `IdentificationOptions::default()` (paper Section III-A: iterative least squares)",
        );
    }
    if let Some(o) = fit_options.get("poe-gp") {
        row(
            out,
            "GP (our rows)",
            format!("{}, inputs standardised: {}", gp_choice(o), o.residual_gp.gp.standardise_inputs),
            "pipeline `ResidualGpOptions::default()` (no random restart, as `calib fit`), but one thread per fit: the \
fits themselves run in parallel",
        );
    }
    if let Some(o) = fit_options.get("paper:poe-gp") {
        row(
            out,
            "GP (Eq. 5, Eq. 8 rows)",
            gp_choice(o),
            "paper Eq. 5 (Bishop PRML 6.63) and Eq. 8; one kernel for the six components because Eq. 11 uses one K \
for all (and scikit-learn's regressor shares its kernel across the columns of a multi-output target)",
        );
    }
}

/// The GP's kernel, residual frame, outputs and restarts, as both GP rows state them.
fn gp_choice(o: &FitOptions) -> String {
    let gp = &o.residual_gp.gp;
    format!(
        "{:?} kernel, {:?} residual frame, {:?} outputs, random restarts: {}",
        gp.kernel, o.residual_gp.residual_frame, gp.outputs, gp.optimiser.restarts
    )
}

const DIFFERENCES: &str = "
## Differences from the paper

- **The GP.** Our default rows use an ARD squared-exponential kernel (one length scale per input) on the error
  twist taken at the tool point, so that its translation part is the position error and not the orientation
  error times the lever arm to the tracker. The paper uses its Eq. 5 kernel (one length scale for all inputs,
  plus a bias and a linear term) on the twist of its Eq. 8, in the tracker frame. The rows marked (Eq. 5, Eq. 8)
  are that choice, with one kernel shared by the six components as Eq. 11 has it. Both fit their
  hyperparameters by maximising the log marginal likelihood with bounded L-BFGS, scikit-learn's method (the
  paper's implementation), here from the default start and one random start.
- **Unstated quantities.** The paper gives neither the size of its kinematic perturbation, nor the stiffness,
  masses or balancer of its load model, nor its measurement noise. Ours are listed above with their sources;
  the base-tool row scales with the perturbation, the POE and POE + GP rows with the compliance.
- **Error measure.** The paper reports a \"norm pose error\"; we report the mean tool-point position error,
  the SPEC's measure.
- **Base-tool.** Ours identifies the base placement and the tool transform (12 parameters) by the same
  least squares as POE; the paper takes its base-tool method from its ref. [11].
- **Folds.** The paper does not say how it drew its folds; ours are slices of a seeded shuffle.
";

/// How stiff the simulated joints are, and what loads them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Preset {
    /// The robot file's stiffness (engineering estimates of an arm of this class), loaded by the
    /// arm's own weight, its balancer and the payload.
    Physical,
    /// Every joint [`PAPER_LIKE_SOFTENING`] times softer than the robot file's, loaded by the payload
    /// alone. Not a physical robot: see [`PAPER_LIKE_SOFTENING`].
    PaperLike,
}

/// How much softer the paper-like preset makes every joint. The paper's Table I has POE leave
/// 0.81–0.90 mm and POE+GP 0.62–0.71 mm, which the payload input takes down to 0.23–0.25 mm: the
/// error left after POE is mostly the payload's, and of the order of a millimetre. With the
/// fixture's stiffness the payload moves the tool by about 0.1 mm and the arm's own weight by
/// about 1 mm (physical preset); softening every joint tenfold under the arm's weight as well
/// leaves POE 5 mm, another regime than the paper's. So the paper-like preset lets the payload
/// alone load joints ten times softer (a round factor; 20 overshoots: POE then leaves over 1 mm).
pub const PAPER_LIKE_SOFTENING: f64 = 10.0;

impl Preset {
    /// The name used on the command line and in the reports.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Physical => "physical",
            Preset::PaperLike => "paper-like",
        }
    }

    /// The factor the robot file's stiffness is divided by.
    pub fn softening(self) -> f64 {
        match self {
            Preset::Physical => 1.0,
            Preset::PaperLike => PAPER_LIKE_SOFTENING,
        }
    }

    /// The simulated effects: compliance (under everything, or the payload alone) and tracker noise.
    pub fn effects(self) -> Effects {
        let payload_only = self == Preset::PaperLike;
        Effects {
            joint_compliance: Some(JointComplianceModel { payload_only, ..JointComplianceModel::default() }),
            ..paper_effects()
        }
    }
}

/// One row of the comparison: a method with its fit options.
#[derive(Debug, Clone)]
pub struct Variant {
    /// Key in the JSON (`base-tool`, …) and, for the paper-faithful rows, in `paper_faithful`.
    pub key: &'static str,
    /// Label in the table and the plot.
    pub label: &'static str,
    /// The method.
    pub method: Method,
    /// Its options.
    pub options: FitOptions,
    /// Whether this is one of the paper-faithful extra rows (Eq. 5 kernel, Eq. 8 frame).
    pub paper_faithful: bool,
    /// Whether this row goes beyond the paper (not one of its four methods).
    pub beyond: bool,
}

/// `a, b, c` with trailing zeros trimmed.
pub fn list(values: &[f64]) -> String {
    values.iter().map(|v| format!("{v}")).collect::<Vec<_>>().join(", ")
}
