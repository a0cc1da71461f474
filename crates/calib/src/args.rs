//! The argument groups the subcommands share, each with one help text and the one call that reads
//! what it names: `--data` with `--columns` (every subcommand that reads measurements), with
//! `--robot` before it (`fit`, `diagnose`) or `--model` (`eval`, `predict`, `register`), `--columns`
//! alone (where the file has another flag: `compensate --targets`, `plan --candidates`), `--model`
//! and `--json`. `--robot` and its chain's ends are in `robot_args`.

use crate::robot_args::RobotArgs;
use errors::Error;
use measurements::{ColumnMap, MeasurementSet, ReadOptions};
use model::CalibratedModel;
use robot::RobotDescription;
use std::path::{Path, PathBuf};

/// `--columns`: the column map every reader of a measurement CSV takes.
#[derive(Debug, clap::Args)]
pub struct ColumnsArg {
    /// Other headers mapped onto the SPEC's column names: NAME=HEADER,… (e.g. x_mm="X [mm]",qw=Q0).
    #[arg(long)]
    columns: Option<ColumnMap>,
}

impl ColumnsArg {
    /// The map as given (empty without `--columns`).
    pub fn map(&self) -> ColumnMap {
        self.columns.clone().unwrap_or_default()
    }

    /// Reads the measurements of `path` (`--data`, or another file of the command read as it is,
    /// such as `report --train`) with the headers mapped.
    pub fn read(&self, path: &Path, options: ReadOptions) -> Result<MeasurementSet, Error> {
        measurements::read_measurements(path, &options.with_columns(self.map()))
    }
}

/// `--data` and `--columns`: the measurements a command reads.
#[derive(Debug, clap::Args)]
pub struct DataArgs {
    /// Measurements (SPEC CSV; `;` and decimal commas are detected).
    #[arg(long)]
    pub data: PathBuf,
    #[command(flatten)]
    pub columns: ColumnsArg,
}

impl DataArgs {
    /// Reads `--data` as measurements: `options` say the joints (and inputs) they are read
    /// against, `--columns` maps the headers.
    pub fn read(&self, options: ReadOptions) -> Result<MeasurementSet, Error> {
        self.columns.read(&self.data, options)
    }

    /// Reads `--data` as joint configurations: the position columns may be left out.
    pub fn read_configurations(&self, options: ReadOptions) -> Result<MeasurementSet, Error> {
        measurements::read_configurations(&self.data, &options.with_columns(self.columns.map()))
    }

    /// The path of `--data`, for messages.
    pub fn display(&self) -> std::path::Display<'_> {
        self.data.display()
    }
}

/// `--model`: the calibrated model a command applies.
#[derive(Debug, clap::Args)]
pub struct ModelArg {
    /// Calibrated model (RON, from `calib fit`).
    #[arg(long)]
    pub model: PathBuf,
}

impl ModelArg {
    /// Reads and checks the model file.
    pub fn read(&self) -> Result<CalibratedModel, Error> {
        model::read_model(&self.model)
    }
}

/// `--robot` (with its chain's ends), `--data` and `--columns`: measurements of a robot, read
/// against its joints.
#[derive(Debug, clap::Args)]
pub struct RobotDataArgs {
    #[command(flatten)]
    pub robot: RobotArgs,
    #[command(flatten)]
    pub data: DataArgs,
}

impl RobotDataArgs {
    /// Reads the robot, then the measurements against its joints, keeping the columns `inputs`
    /// as measured signals.
    pub fn read(&self, inputs: Vec<String>) -> Result<(RobotDescription, MeasurementSet), Error> {
        let robot = self.robot.read()?;
        let data = self.data.read(ReadOptions::for_joints(robot.joint_kinds()).with_inputs(inputs))?;
        Ok((robot, data))
    }

    /// The path of `--data`, for messages.
    pub fn display(&self) -> std::path::Display<'_> {
        self.data.display()
    }
}

/// `--model`, `--data` and `--columns`: measurements a model is applied to, read against its
/// joints and the inputs it takes.
#[derive(Debug, clap::Args)]
pub struct ModelDataArgs {
    #[command(flatten)]
    pub model: ModelArg,
    #[command(flatten)]
    pub data: DataArgs,
}

impl ModelDataArgs {
    /// Reads the model, then the measurements.
    pub fn read(&self) -> Result<(CalibratedModel, MeasurementSet), Error> {
        let model = self.model.read()?;
        let data = self.data.read(model.read_options(ColumnMap::default()))?;
        Ok((model, data))
    }

    /// Reads the model, then the joint configurations (the position columns may be left out).
    pub fn read_configurations(&self) -> Result<(CalibratedModel, MeasurementSet), Error> {
        let model = self.model.read()?;
        let data = self.data.read_configurations(model.read_options(ColumnMap::default()))?;
        Ok((model, data))
    }

    /// The path of `--data`, for messages.
    pub fn display(&self) -> std::path::Display<'_> {
        self.data.display()
    }

    /// The path of `--model`.
    pub fn model_file(&self) -> &Path {
        &self.model.model
    }
}

/// `--json`: the command's report as one JSON object on stdout.
#[derive(Debug, clap::Args)]
pub struct JsonFlag {
    /// Print the report as one JSON object on stdout (what else the command says goes to stderr).
    #[arg(long)]
    pub json: bool,
}
