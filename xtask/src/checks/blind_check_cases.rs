//! The cases of `cargo xtask blind-check`: one class per kind of hidden truth, each drawn with
//! what the diagnosis's candidates do not parameterise exactly.
//!
//! Classes, in the order case `i` takes them (position `i mod 11` of a round of eleven: the ten
//! below in their order, then `deflection`; so any eleven consecutive cases hold one of each and
//! the CI's first six hold the hardest). A case of the ten is drawn exactly as case
//! `10 · (i / 11) + i mod 11` was before the deflection class existed (its seed and data the
//! same), so the ten classes' cases are those of earlier reports:
//! `none`; `gear` (1–4 harmonics of orders 1–40, random phases and weights, any joint, joint 1
//! included); `compliance` (one or two of joints 2–6); `coupling` (joint 2–5's error a product of
//! harmonics of two *other* joints' angles: no candidate models it, the truth is `unknown`);
//! `seven_axis` (a real iiwa 7 campaign's shape: joints 1 and 2 moving, four payload runs with a
//! remounted probe each, measured torques, every joint compliant, full pose); `two_effects` (two
//! of compliance, backlash, gear at once); `backlash` (one or two of joints 2–6); `joint_one`
//! (compliance or backlash on joint 1 of a base tilted 30–90°, so that gravity loads joint 1; the
//! diagnosis is told the mounting, not the masses); `thermal`; `drift`; `deflection`
//! (`column_ur10.ron`, a UR10 on a 2.5 m lifting column, whose column bends under the arm's
//! gravity moment by `1/EI` of 1e-7 1/(N·m²) times weights 0.3–1 about its two horizontal axes,
//! the masses 50 kg per metre of link times 0.5–1.5 link by link; the diagnosis gets the robot
//! without masses, so its stand-in masses are not the truth).
//!
//! Each effect's size is what a geometric calibration leaves of it on noise-free positions (what
//! any diagnosis could possibly see), drawn log-uniformly from 1.2× the noise floor to 4 mm, the
//! parameters scaled to reach it (joint-space amplitudes capped at 5 mrad).

use crate::simulation::{mean_distance_mm, perturbed_robot, ranges, simulate, tracker_placement};
use anyhow::{Context, Result, bail};
use campaign::{Perturbation, Remount, campaign_cell, payload_run_campaign};
use diagnose::{DiagnoseOptions, Diagnosis, Effect, StructureOptions, diagnose};
use loadsim::{
    BacklashModel, BentLink, CouplingFactor, CouplingModel, CouplingTerm, Effects, GearPeriodicModel, GeneratorConfig,
    Harmonic, JointBacklash, JointComplianceModel, JointRange, LinkDeflectionModel, RobotDynamics, SimulatedCell,
    ThermalModel, TimeDriftModel, TrackerNoiseModel,
};
use measurements::MeasurementSet;
use model::Method;
use pipeline::FitOptions;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robot::RobotDescription;

/// The kind of hidden truth.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    None,
    Gear,
    Compliance,
    Coupling,
    SevenAxis,
    TwoEffects,
    Backlash,
    JointOne,
    Thermal,
    Drift,
    Deflection,
}

impl Class {
    /// Every class, in the order the cases cycle through them.
    pub const ALL: [Class; 11] = [
        Class::None,
        Class::Gear,
        Class::Compliance,
        Class::Coupling,
        Class::SevenAxis,
        Class::TwoEffects,
        Class::Backlash,
        Class::JointOne,
        Class::Thermal,
        Class::Drift,
        Class::Deflection,
    ];

    /// The class of case `index` and the index its seed and data are drawn from: the ten classes
    /// as before the deflection class (case `10 · round + position`), the deflection class on
    /// seeds of its own.
    fn of_case(index: usize) -> (Class, u64) {
        let (round, position) = (index / Self::ALL.len(), index % Self::ALL.len());
        match Self::ALL[position] {
            Class::Deflection => (Class::Deflection, (1 << 32) + round as u64),
            class => (class, (10 * round + position) as u64),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Class::None => "none",
            Class::Gear => "gear (orders ≤ 40, any joint)",
            Class::Compliance => "compliance",
            Class::Coupling => "coupling (truth unknown)",
            Class::SevenAxis => "7-axis, joints 1–2 moving",
            Class::TwoEffects => "two effects",
            Class::Backlash => "backlash",
            Class::JointOne => "joint 1, tilted base",
            Class::Thermal => "thermal",
            Class::Drift => "drift",
            Class::Deflection => "deflection (lifting column)",
        }
    }
}

/// One hidden effect at a reference scale; `scale` multiplies its size.
#[derive(Debug, Clone)]
enum Hidden {
    /// The stiffness of these 0-based joints divided by the scale, every other joint rigid.
    Compliance(Vec<usize>),
    /// Every joint compliant as the robot file says, the stiffness divided by the scale.
    ComplianceAll,
    /// Half band 0.1 mrad × scale on these joints.
    Backlash(Vec<usize>),
    /// Harmonics `(order, weight, phase)` of one joint, amplitude 0.1 mrad × weight × scale.
    Gear(usize, Vec<(f64, f64, f64)>),
    Thermal,
    Drift,
    /// Joint `j`'s error 0.1 mrad × scale × Π cos(h q_s + φ) over the factors `(s, h, φ)`.
    Coupling(usize, Vec<(usize, f64, f64)>),
    /// Joint `j`'s link bends with `1/EI` of 1e-7 1/(N·m²) × scale × the weights about the x and
    /// y axes of its frame.
    Deflection(usize, [f64; 2]),
}

impl Hidden {
    /// What the verdict should say, and the 1-based joints.
    fn truth(&self) -> (Effect, Vec<usize>) {
        let one = |joints: &[usize]| joints.iter().map(|j| j + 1).collect();
        match self {
            Hidden::Compliance(joints) => (Effect::JointCompliance, one(joints)),
            Hidden::ComplianceAll => (Effect::JointCompliance, vec![]),
            Hidden::Backlash(joints) => (Effect::Backlash, one(joints)),
            Hidden::Gear(joint, _) => (Effect::GearPeriodic, vec![joint + 1]),
            Hidden::Thermal => (Effect::Thermal, vec![]),
            Hidden::Drift => (Effect::TimeDrift, vec![]),
            Hidden::Coupling(..) => (Effect::Unknown, vec![]),
            Hidden::Deflection(joint, _) => (Effect::LinkDeflection, vec![joint + 1]),
        }
    }

    /// The largest scale: joint-space errors stay within 5 mrad (beyond that neither the effect
    /// models nor a first-order identification hold).
    fn cap(&self) -> f64 {
        match self {
            Hidden::Backlash(_) | Hidden::Coupling(..) => 50.0,
            Hidden::Gear(_, harmonics) => 50.0 / harmonics.iter().map(|h| h.1).sum::<f64>().max(1e-9),
            // The column's moment times its length reaches about 1.2e3 N·m² (the UR10 stretched
            // out at full lift, 50 kg per metre): 4e-6 1/(N·m²) turns its top by 5 mrad.
            Hidden::Deflection(_, weights) => 40.0 / weights[0].max(weights[1]).max(1e-9),
            _ => f64::INFINITY,
        }
    }

    /// Adds the effect at `scale` to `effects` (and to the stiffness of `dynamics`).
    fn apply(&self, scale: f64, effects: &mut Effects, dynamics: &mut Option<RobotDynamics>) {
        match self {
            Hidden::Compliance(joints) => {
                if let Some(d) = dynamics.as_mut() {
                    for (j, k) in d.stiffness_nm_per_rad.iter_mut().enumerate() {
                        *k = if joints.contains(&j) { *k / scale } else { 1e15 };
                    }
                }
                effects.joint_compliance = Some(JointComplianceModel::default());
            }
            Hidden::ComplianceAll => {
                if let Some(d) = dynamics.as_mut() {
                    d.stiffness_nm_per_rad.iter_mut().for_each(|k| *k /= scale);
                }
                effects.joint_compliance = Some(JointComplianceModel::default());
            }
            _ => self.add_model(scale, effects),
        }
    }

    /// Adds the effect's model at `scale` to `effects`: every kind but compliance, which `apply`
    /// adds with the stiffness it changes.
    fn add_model(&self, scale: f64, effects: &mut Effects) {
        match self {
            Hidden::Compliance(_) | Hidden::ComplianceAll => {}
            Hidden::Backlash(joints) => {
                effects.backlash = Some(BacklashModel {
                    joints: joints
                        .iter()
                        .map(|&joint_index| JointBacklash { joint_index, half_band_rad: 1e-4 * scale })
                        .collect(),
                });
            }
            Hidden::Gear(joint, harmonics) => {
                effects.gear_periodic = Some(GearPeriodicModel {
                    harmonics: harmonics
                        .iter()
                        .map(|&(order, weight, phase_rad)| Harmonic {
                            joint_index: *joint,
                            order,
                            amplitude_rad: 1e-4 * weight * scale,
                            phase_rad,
                        })
                        .collect(),
                });
            }
            Hidden::Thermal => {
                effects.thermal = Some(ThermalModel { expansion_per_k: 12e-6 * scale, ..ThermalModel::default() })
            }
            Hidden::Drift => {
                let per_hour = scale * 1e-4 / 3600.0;
                effects.time_drift = Some(TimeDriftModel {
                    twist_per_s: [per_hour, -0.5 * per_hour, 0.7 * per_hour, 0.0, 0.0, 0.3 * per_hour],
                });
            }
            Hidden::Coupling(joint, factors) => {
                effects.coupling = Some(CouplingModel {
                    terms: vec![CouplingTerm {
                        joint_index: *joint,
                        amplitude_rad: 1e-4 * scale,
                        factors: factors
                            .iter()
                            .map(|&(source_joint_index, order, phase_rad)| CouplingFactor {
                                source_joint_index,
                                order,
                                phase_rad,
                            })
                            .collect(),
                    }],
                });
            }
            Hidden::Deflection(joint, weights) => {
                effects.link_deflection = Some(LinkDeflectionModel {
                    links: vec![BentLink {
                        joint_index: *joint,
                        flexibility_per_nm2: weights.map(|w| 1e-7 * w * scale),
                    }],
                });
            }
        }
    }
}

/// One case's truth and what the diagnosis said.
#[derive(Debug, Clone)]
pub struct Case {
    pub class: Class,
    /// What the verdict should say: one effect, or either of two.
    pub truths: Vec<Effect>,
    /// Their 1-based joints (empty where the class does not fix them).
    pub joints: Vec<usize>,
    pub full_pose: bool,
    /// The size of the smallest hidden effect (what a geometric fit leaves of it), mm.
    pub magnitude_mm: f64,
    pub floor_mm: f64,
    pub verdict: Effect,
    pub verdict_joints: Vec<usize>,
    /// Whether every hidden effect was selected (two-effect cases).
    pub all_selected: bool,
    pub before_mm: f64,
    pub after_mm: f64,
    /// The geometric model's held-out error on the same poses and noise without the effects.
    pub oracle_mm: f64,
}

impl Case {
    pub fn right(&self) -> bool {
        self.truths.contains(&self.verdict)
    }

    pub fn predicted_shrink(&self) -> f64 {
        1.0 - self.after_mm / self.before_mm
    }

    pub fn true_shrink(&self) -> f64 {
        1.0 - self.oracle_mm / self.before_mm
    }
}

/// What every case shares.
pub struct Robots {
    pub irb4400: RobotDescription,
    pub iiwa7: RobotDescription,
    /// A UR10 on a lifting column, without masses (`column_ur10.ron`).
    pub column: RobotDescription,
}

fn draw_joints(rng: &mut ChaCha8Rng, from: &[usize], at_most: usize) -> Vec<usize> {
    let mut joints = vec![from[rng.random_range(0..from.len())]];
    if at_most > 1 && rng.random_bool(0.3) {
        let second = from[rng.random_range(0..from.len())];
        if !joints.contains(&second) {
            joints.push(second);
        }
    }
    joints.sort_unstable();
    joints
}

fn draw_gear(rng: &mut ChaCha8Rng, joints: usize) -> Hidden {
    let joint = rng.random_range(0..joints);
    let count = rng.random_range(1..=4);
    let harmonics = (0..count)
        .map(|_| {
            (
                f64::from(rng.random_range(1..=40_u32)),
                rng.random_range(0.3..1.0),
                rng.random_range(0.0..std::f64::consts::TAU),
            )
        })
        .collect();
    Hidden::Gear(joint, harmonics)
}

fn draw_kind(rng: &mut ChaCha8Rng, kind: usize, loaded: &[usize], joints: usize) -> Hidden {
    match kind {
        0 => Hidden::Compliance(draw_joints(rng, loaded, 2)),
        1 => Hidden::Backlash(draw_joints(rng, loaded, 2)),
        _ => draw_gear(rng, joints),
    }
}

/// The robot as the diagnosis gets it: the mounting (gravity) it is told, no masses (a uniform
/// 10 kg per link at the file's centres of mass stands in where the mounting must be stated), no
/// stiffness.
fn blind(robot: &RobotDescription, gravity: Option<[f64; 3]>) -> RobotDescription {
    let dynamics = gravity.and_then(|g| {
        robot.dynamics.as_ref().map(|d| RobotDynamics {
            links: d.links.iter().map(|l| loadsim::LinkInertia { mass_kg: 10.0, com_m: l.com_m }).collect(),
            stiffness_nm_per_rad: vec![1.0; d.links.len()],
            counterbalance: None,
            gravity_m_per_s2: g,
        })
    });
    RobotDescription { dynamics, ..robot.clone() }
}

/// Draws and diagnoses case `index` of the check seeded `seed`.
pub fn run_case(robots: &Robots, index: usize, seed: u64, rows: usize, dump: Option<&std::path::Path>) -> Result<Case> {
    let (class, drawn) = Class::of_case(index);
    let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ drawn);
    // Position only and full pose alternate within each round of ten and between rounds; the
    // deflection cases alternate from round to round.
    let mut full_pose =
        if class == Class::Deflection { index / Class::ALL.len() % 2 == 1 } else { (drawn + drawn / 10) % 2 == 1 };
    let robot = match class {
        Class::SevenAxis => &robots.iiwa7,
        Class::Deflection => &robots.column,
        _ => &robots.irb4400,
    };
    let hidden = draw_hidden(class, &mut rng, robot.joint_count());
    if class == Class::SevenAxis {
        full_pose = true;
    }
    let gravity = (class == Class::JointOne).then(|| {
        loadsim::tilted_base_gravity(rng.random_range(0.5..1.6), rng.random_range(0.0..std::f64::consts::TAU))
    });
    let (mut cell, config) = truth_cell(class, robot, rows, &mut rng)?;
    if let (Some(g), Some(d)) = (gravity, cell.dynamics.as_mut()) {
        d.gravity_m_per_s2 = g;
    }
    let sim = Simulator { robot, ranges: ranges(robot), config };
    let clean_none = sim.run(&cell, &Effects::default(), full_pose)?;
    let noisy_none = sim.run(&cell, &with_noise(&Effects::default()), full_pose)?;
    let floor_mm = mean_distance_mm(&clean_none, &noisy_none);
    let (effects, dynamics, magnitude_mm) = hide(&sim, &cell, &hidden, floor_mm, &mut rng, index)?;
    cell.dynamics = dynamics;
    let data = sim.run(&cell, &with_noise(&effects), full_pose)?;
    if let Some(folder) = dump {
        let path = folder.join(format!("case{index}.csv"));
        let file = std::fs::File::create(&path).with_context(|| path.display().to_string())?;
        data.write_csv(std::io::BufWriter::new(file)).with_context(|| path.display().to_string())?;
    }
    let (diagnosis, oracle) = diagnose_blind(&blind(robot, gravity), &data, &noisy_none, index)?;
    let truths: Vec<(Effect, Vec<usize>)> = hidden.iter().map(Hidden::truth).collect();
    let selected_effects: Vec<Effect> = diagnosis.selected.iter().map(|s| s.effect).collect();
    Ok(Case {
        class,
        truths: if truths.is_empty() { vec![Effect::None] } else { truths.iter().map(|t| t.0).collect() },
        joints: if truths.len() == 1 { truths[0].1.clone() } else { vec![] },
        full_pose,
        magnitude_mm,
        floor_mm,
        verdict: diagnosis.verdict.effect,
        verdict_joints: diagnosis.verdict.joints.clone(),
        all_selected: truths.iter().all(|t| t.0 == Effect::Unknown || selected_effects.contains(&t.0)),
        before_mm: diagnosis.heldout_before_mm,
        after_mm: diagnosis.heldout_after_selected_mm,
        oracle_mm: oracle.heldout_before_mm,
    })
}

/// The hidden effects of a case of `class` on a robot of `n` joints, drawn from `rng`.
fn draw_hidden(class: Class, rng: &mut ChaCha8Rng, n: usize) -> Vec<Hidden> {
    let loaded: Vec<usize> = (1..n).collect();
    match class {
        Class::None => vec![],
        Class::Gear => vec![draw_gear(rng, n)],
        Class::Compliance => vec![Hidden::Compliance(draw_joints(rng, &loaded, 2))],
        Class::Backlash => vec![Hidden::Backlash(draw_joints(rng, &loaded, 2))],
        Class::Thermal => vec![Hidden::Thermal],
        Class::Drift => vec![Hidden::Drift],
        Class::JointOne => {
            if rng.random_bool(0.5) {
                vec![Hidden::Compliance(vec![0])]
            } else {
                vec![Hidden::Backlash(vec![0])]
            }
        }
        Class::TwoEffects => {
            let first = rng.random_range(0..3);
            let second = (first + rng.random_range(1..3)) % 3;
            vec![draw_kind(rng, first, &loaded, n), draw_kind(rng, second, &loaded, n)]
        }
        Class::Coupling => {
            let joint = rng.random_range(1..5);
            let mut sources: Vec<usize> = (0..n).filter(|&s| s != joint).collect();
            let a = sources.remove(rng.random_range(0..sources.len()));
            let b = sources[rng.random_range(0..sources.len())];
            let factor = |rng: &mut ChaCha8Rng, s: usize| {
                (s, f64::from(rng.random_range(1..=3_u32)), rng.random_range(0.0..std::f64::consts::TAU))
            };
            vec![Hidden::Coupling(joint, vec![factor(rng, a), factor(rng, b)])]
        }
        Class::SevenAxis => vec![Hidden::ComplianceAll],
        Class::Deflection => vec![Hidden::Deflection(0, [rng.random_range(0.3..1.0), rng.random_range(0.3..1.0)])],
    }
}

/// The true cell of a case (perturbed geometry, tool, tracker and masses drawn from `rng`) and the
/// generator of its poses.
fn truth_cell(
    class: Class,
    robot: &RobotDescription,
    rows: usize,
    rng: &mut ChaCha8Rng,
) -> Result<(SimulatedCell, GeneratorConfig)> {
    if class == Class::SevenAxis {
        let config = payload_run_campaign(rows, rng.random());
        let cell = campaign_cell(robot, &Perturbation::default(), &Remount::default(), &config)?;
        return Ok((cell, config));
    }
    let tool_m = rng.random_range(0.1..0.3);
    let geometry = perturbed_robot(robot, rng, 0.002, 0.002, tool_m)?;
    let dynamics = match class {
        // The truth's masses: the stand-in's bars, each 0.5–1.5 times as heavy.
        Class::Deflection => {
            let mut truth = effects::stand_in_dynamics(robot);
            truth.links.iter_mut().for_each(|l| l.mass_kg *= rng.random_range(0.5..1.5));
            Some(truth)
        }
        _ => robot.dynamics.clone(),
    };
    let mut cell = SimulatedCell::new(geometry, dynamics);
    cell.tracker_from_base = tracker_placement(rng);
    Ok((cell, GeneratorConfig { sample_count: rows, seed: rng.random(), ..GeneratorConfig::default() }))
}

/// A case's poses: the robot, its joint ranges and the generator.
struct Simulator<'a> {
    robot: &'a RobotDescription,
    ranges: Vec<JointRange>,
    config: GeneratorConfig,
}

impl Simulator<'_> {
    fn run(&self, cell: &SimulatedCell, effects: &Effects, full_pose: bool) -> Result<MeasurementSet> {
        simulate(cell, effects, &self.ranges, &self.config, full_pose)
    }

    /// What a geometric fit leaves, on positions alone (with orientations, a fit weighted for a
    /// tracker's orientation noise can trade position for orientation error and overstate it).
    fn left_after_fit(&self, data: &MeasurementSet) -> Result<f64> {
        let mut positions = data.clone();
        positions.full_pose = false;
        positions.rows.iter_mut().for_each(|r| r.orientation = None);
        let (_, report) = pipeline::fit(self.robot, &positions, Method::Poe, &FitOptions::default())?;
        Ok(report.after.mean_position_error_mm)
    }
}

/// `effects` with the tracker's default noise.
fn with_noise(effects: &Effects) -> Effects {
    Effects { tracker_noise: Some(TrackerNoiseModel::default()), ..effects.clone() }
}

/// Scales each hidden effect so that a geometric fit leaves of it alone a size drawn from `rng`
/// between 1.2× the noise floor and 4 mm (within its cap), and adds them up: the effects, the
/// cell's dynamics with them, and the smallest size (0 without hidden effects).
fn hide(
    sim: &Simulator<'_>,
    cell: &SimulatedCell,
    hidden: &[Hidden],
    floor_mm: f64,
    rng: &mut ChaCha8Rng,
    index: usize,
) -> Result<(Effects, Option<RobotDynamics>, f64)> {
    let base_dynamics = &cell.dynamics;
    let mut effects = Effects::default();
    let mut dynamics = base_dynamics.clone();
    let mut magnitude_mm = f64::INFINITY;
    for h in hidden {
        let target_mm = floor_mm * 1.2 * (4.0 / (1.2 * floor_mm)).powf(rng.random_range(0.0..1.0));
        let alone = |scale: f64| -> Result<f64> {
            let mut e = Effects::default();
            let mut d = base_dynamics.clone();
            h.apply(scale, &mut e, &mut d);
            let mut c = cell.clone();
            c.dynamics = d;
            sim.left_after_fit(&sim.run(&c, &e, false)?)
        };
        let left = alone(1.0)?;
        if left <= 0.0 {
            bail!("case {index}: {h:?} leaves nothing after a geometric fit");
        }
        let scale = (target_mm / left).min(h.cap());
        magnitude_mm = magnitude_mm.min(alone(scale)?);
        h.apply(scale, &mut effects, &mut dynamics);
    }
    if hidden.is_empty() {
        magnitude_mm = 0.0;
    }
    Ok((effects, dynamics, magnitude_mm))
}

/// The diagnosis of a case's data by the blind robot, and the oracle's: the same poses and noise
/// without the effects, diagnosed without the structure search.
fn diagnose_blind(
    blind_robot: &RobotDescription,
    data: &MeasurementSet,
    noisy_none: &MeasurementSet,
    index: usize,
) -> Result<(Diagnosis, Diagnosis)> {
    let options = DiagnoseOptions::default();
    let diagnosis = diagnose(blind_robot, data, &options).with_context(|| format!("case {index}"))?;
    let oracle_options =
        DiagnoseOptions { structure: StructureOptions { enabled: false, ..StructureOptions::default() }, ..options };
    let oracle = diagnose(blind_robot, noisy_none, &oracle_options)?;
    Ok((diagnosis, oracle))
}
