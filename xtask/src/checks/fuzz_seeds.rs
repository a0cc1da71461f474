//! The valid files `cargo xtask fuzz` starts from, made the way a user's files are made: measurement
//! CSV written by `calib simulate`'s writer (SPEC files, full pose, tools and torques, a Leica-style
//! export with its column map, a prismatic joint), the robot fixtures (RON axes, DH tables, URDF),
//! model files written by `calib fit`'s writer for every kind of part, and effects files.

use anyhow::{Context, Result};
use campaign::{Effects, GeneratorConfig, JointCoupling, Perturbation, Remount};
use effects::{EffectKind, EffectSelection, EffectSpec};
use measurements::MeasurementSet;
use model::Method;
use pipeline::FitOptions;
use poe::JointKind;
use robot::RobotDescription;
use std::path::{Path, PathBuf};

/// Which reader a seed feeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Reader {
    /// The measurement CSV (`read_measurements`, with `--columns`).
    Csv,
    /// Robot descriptions: RON axes, RON DH tables, URDF.
    Robot,
    /// Calibrated model files.
    Model,
    /// The effects RON of `calib simulate --effects`.
    Effects,
    /// The `--effects LIST` argument of `calib fit`.
    EffectsList,
    /// The `--options FIT.ron` file of `calib fit`.
    Options,
}

impl Reader {
    /// Every reader, in the order `--reader all` runs them.
    pub const ALL: [Reader; 6] =
        [Reader::Csv, Reader::Robot, Reader::Model, Reader::Effects, Reader::EffectsList, Reader::Options];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Reader::Csv => "csv",
            Reader::Robot => "robot",
            Reader::Model => "model",
            Reader::Effects => "effects",
            Reader::EffectsList => "effects-list",
            Reader::Options => "options",
        }
    }
}

/// One valid file and how it is read.
#[derive(Debug, Clone)]
pub struct Seed {
    /// What it is, for reports.
    pub name: String,
    /// The file name's extension (the robot reader chooses RON or URDF by it).
    pub extension: &'static str,
    /// The file's bytes.
    pub bytes: Vec<u8>,
    /// The robot's joints a CSV is read against (`None`: any number of joints).
    pub joints: Option<Vec<JointKind>>,
    /// The `--columns` argument a CSV is read with.
    pub columns: Option<String>,
}

impl Seed {
    fn file(name: &str, extension: &'static str, bytes: Vec<u8>) -> Self {
        Self { name: name.to_owned(), extension, bytes, joints: None, columns: None }
    }
}

/// The fixture folder of the workspace.
pub fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../fixtures/robots")
}

/// A fixture robot.
pub fn fixture_robot(name: &str) -> Result<RobotDescription> {
    let path = fixtures().join(name);
    RobotDescription::read(&path).with_context(|| format!("reading the fixture {}", path.display()))
}

fn csv_bytes(set: &MeasurementSet) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    set.write_csv(&mut bytes).context("writing a seed CSV")?;
    Ok(bytes)
}

/// A simulated set of `rows` rows of `robot` from `config`'s seed.
fn simulated_set(robot: &RobotDescription, config: &GeneratorConfig, full_pose: bool) -> Result<MeasurementSet> {
    let effects = campaign::paper_effects();
    let (_, set) =
        campaign::simulate_campaign(robot, &effects, &Perturbation::default(), &Remount::default(), config, full_pose)
            .context("simulating a seed data set")?;
    Ok(set)
}

fn rows(count: usize, seed: u64) -> GeneratorConfig {
    GeneratorConfig { sample_count: count, seed, ..GeneratorConfig::default() }
}

/// `value` as a tracker export writes it: a decimal comma.
fn comma(value: f64) -> String {
    format!("{value}").replace('.', ",")
}

/// A full-pose set as a Leica/T-Mac export: `;`, decimal commas, joints in degrees, Euler angles
/// (R = Rx·Ry·Rz), its own header names; with the column map that reads it.
fn leica_export(set: &MeasurementSet) -> (Vec<u8>, String) {
    let n = set.joint_count;
    let mut header: Vec<String> = vec!["Timestamp".into()];
    header.extend((1..=n).map(|k| format!("A{k} [deg]")));
    header.extend(["X [mm]", "Y [mm]", "Z [mm]", "Rx [deg]", "Ry [deg]", "Rz [deg]", "Load [kg]"].map(String::from));
    let mut text = header.join(";") + "\n";
    for (i, row) in set.rows.iter().enumerate() {
        let mut cells = vec![format!("2,02011E+13{i}")];
        cells.extend(row.q.iter().map(|q| comma(q.to_degrees())));
        cells.extend(row.position.iter().map(|p| comma(p * 1e3)));
        let r = row.orientation.map(|o| o.matrix()).unwrap_or_else(lie::Matrix3::identity);
        let euler = [(-r[(1, 2)]).atan2(r[(2, 2)]), r[(0, 2)].clamp(-1.0, 1.0).asin(), (-r[(0, 1)]).atan2(r[(0, 0)])];
        cells.extend(euler.iter().map(|a| comma(a.to_degrees())));
        cells.push(comma(row.payload_kg));
        text.push_str(&(cells.join(";") + "\n"));
    }
    let mut map: Vec<String> = (1..=n).map(|k| format!("q{k}_deg=A{k} [deg]")).collect();
    for (name, header) in [("x_mm", "X [mm]"), ("y_mm", "Y [mm]"), ("z_mm", "Z [mm]")] {
        map.push(format!("{name}={header}"));
    }
    for (name, header) in [("rx_deg", "Rx [deg]"), ("ry_deg", "Ry [deg]"), ("rz_deg", "Rz [deg]")] {
        map.push(format!("{name}=\"{header}\""));
    }
    map.push("payload_kg=Load [kg]".into());
    (text.into_bytes(), map.join(","))
}

fn csv_seeds() -> Result<Vec<Seed>> {
    let irb = fixture_robot("irb4400.ron")?;
    let iiwa = fixture_robot("iiwa7.ron")?;
    let six = irb.joint_kinds();
    let position = simulated_set(&irb, &rows(8, 1), false)?;
    let full = simulated_set(&irb, &rows(8, 2), true)?;
    let campaign = simulated_set(&iiwa, &campaign::payload_run_campaign(8, 3), true)?;
    let with = |name: &str, bytes: Vec<u8>, joints: Option<Vec<JointKind>>, columns: Option<String>| Seed {
        name: name.to_owned(),
        extension: "csv",
        bytes,
        joints,
        columns,
    };
    let position_text = String::from_utf8(csv_bytes(&position)?).context("a seed CSV is UTF-8")?;
    let mut prismatic = six.clone();
    prismatic[1] = JointKind::Prismatic;
    let (leica, map) = leica_export(&full);
    Ok(vec![
        with("position only (6R)", position_text.clone().into_bytes(), Some(six.clone()), None),
        with("full pose (6R)", csv_bytes(&full)?, Some(six.clone()), None),
        with("payload runs, a tool each, torques (7R)", csv_bytes(&campaign)?, Some(iiwa.joint_kinds()), None),
        with("Leica-style export with --columns", leica, Some(six), Some(map)),
        with(
            "a prismatic joint in mm",
            position_text.replacen("q2_rad", "q2_mm", 1).into_bytes(),
            Some(prismatic),
            None,
        ),
        with("any joint count", position_text.into_bytes(), None, None),
    ])
}

fn robot_seeds() -> Result<Vec<Seed>> {
    let names = [
        "irb4400.ron",
        "ur10.ron",
        "iiwa7.ron",
        "ur10_dh.ron",
        "iiwa7_dh.ron",
        "irb4400_dh.ron",
        "ur10.urdf",
        "iiwa7.urdf",
        "irb4400.urdf",
    ];
    names
        .iter()
        .map(|name| {
            let path = fixtures().join(name);
            let bytes = std::fs::read(&path).with_context(|| format!("reading {}", path.display()))?;
            let extension = if name.ends_with(".urdf") { "urdf" } else { "ron" };
            Ok(Seed::file(name, extension, bytes))
        })
        .collect()
}

fn model_text(model: &model::CalibratedModel, folder: &Path) -> Result<Vec<u8>> {
    let path = folder.join("seed-model.ron");
    model::write_model(&path, model).context("writing a seed model")?;
    std::fs::read(&path).with_context(|| format!("reading {}", path.display()))
}

fn model_seeds(folder: &Path) -> Result<Vec<Seed>> {
    let irb = fixture_robot("irb4400.ron")?;
    let position = simulated_set(&irb, &rows(40, 4), false)?;
    let full = simulated_set(&irb, &rows(40, 5), true)?;
    let fit = |data: &MeasurementSet, method: Method, effects: &[EffectSpec]| {
        let options = FitOptions::default().with_effects(EffectSelection::List(effects.to_vec()));
        pipeline::fit(&irb, data, method, &options).map(|(model, _)| model).context("fitting a seed model")
    };
    let small = position.subset(&(0..30).collect::<Vec<_>>());
    let every_effect = [
        EffectSpec::new(EffectKind::JointCompliance),
        EffectSpec::gear_periodic(2, 3),
        EffectSpec::on_joint(EffectKind::Backlash, 3),
        EffectSpec::new(EffectKind::Thermal),
        EffectSpec::new(EffectKind::TimeDrift),
    ];
    Ok(vec![
        Seed::file("poe, position only", "ron", model_text(&fit(&position, Method::Poe, &[])?, folder)?),
        Seed::file("base-tool, full pose", "ron", model_text(&fit(&full, Method::BaseTool, &[])?, folder)?),
        Seed::file("poe with every effect", "ron", model_text(&fit(&full, Method::Poe, &every_effect)?, folder)?),
        Seed::file("poe-gp-load", "ron", model_text(&fit(&small, Method::PoeGpLoad, &[])?, folder)?),
    ])
}

fn effects_seeds() -> Result<Vec<Seed>> {
    let mut typical = Effects::typical(6);
    typical.coupling = Some(JointCoupling {
        terms: vec![campaign::CouplingTerm {
            joint_index: 2,
            amplitude_rad: 1e-3,
            factors: vec![campaign::CouplingFactor { source_joint_index: 1, order: 2.0, phase_rad: 0.3 }],
        }],
    });
    let pretty = ron::ser::PrettyConfig::default();
    let mut seeds = Vec::new();
    for (name, effects) in [("every effect", typical.clone()), ("the paper's", campaign::paper_effects())] {
        let text = ron::ser::to_string_pretty(&effects, pretty.clone()).context("writing a seed effects file")?;
        seeds.push(Seed::file(name, "ron", text.into_bytes()));
    }
    // As a user writes one by hand: `Some` left out, defaults left out.
    let by_hand = "// joint 2's gear, a little backlash\n(\n    periodic: (harmonics: [\n        (joint_index: 1, order: 2.0, amplitude_rad: 2e-5, phase_rad: 0.5),\n    ]),\n    backlash: (joints: [(joint_index: 0, half_band_rad: 1e-4)]),\n    thermal: (reference_temp_c: 20.0, expansion_per_k: 1.2e-5),\n    tracker_noise: (),\n)\n";
    seeds.push(Seed::file("written by hand", "ron", by_hand.as_bytes().to_vec()));
    Ok(seeds)
}

fn effects_list_seeds() -> Vec<Seed> {
    let lists = [
        "joint_compliance",
        "gear_periodic:2:3,backlash:2",
        "joint_compliance,gear_periodic:1:32,gear_periodic:2:24,backlash:3,thermal,time_drift",
        "auto",
    ];
    lists.iter().map(|list| Seed::file(list, "txt", list.as_bytes().to_vec())).collect()
}

fn options_seeds() -> Result<Vec<Seed>> {
    let pretty = ron::ser::PrettyConfig::default();
    let every = FitOptions::default().with_effects(EffectSelection::List(vec![
        EffectSpec::new(EffectKind::JointCompliance),
        EffectSpec::gear_periodic(1, 8),
    ]));
    let mut seeds = Vec::new();
    for (name, options) in [("the defaults", FitOptions::default()), ("with effects", every)] {
        let text = ron::ser::to_string_pretty(&options, pretty.clone()).context("writing a seed options file")?;
        seeds.push(Seed::file(name, "ron", text.into_bytes()));
    }
    let by_hand = "// fewer iterations, a looser prior\n(identification: (max_iterations: 20), effects: (prior_sigma: 0.01, selection: \"thermal\"))\n";
    seeds.push(Seed::file("written by hand", "ron", by_hand.as_bytes().to_vec()));
    Ok(seeds)
}

/// The seeds of `reader`; `folder` is scratch space.
pub fn seeds(reader: Reader, folder: &Path) -> Result<Vec<Seed>> {
    match reader {
        Reader::Csv => csv_seeds(),
        Reader::Robot => robot_seeds(),
        Reader::Model => model_seeds(folder),
        Reader::Effects => effects_seeds(),
        Reader::EffectsList => Ok(effects_list_seeds()),
        Reader::Options => options_seeds(),
    }
}
