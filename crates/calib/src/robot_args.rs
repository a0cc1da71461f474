//! `--robot` with `--base-link` and `--tip-link`, shared by every subcommand that reads a robot.

use errors::Error;
use robot::{ChainEnds, RobotDescription};
use std::path::PathBuf;

/// The robot description and, for a URDF, the chain's ends.
#[derive(Debug, clap::Args)]
pub struct RobotArgs {
    /// Robot description: RON (axes or DH table, e.g. fixtures/robots/irb4400.ron) or URDF (.urdf).
    #[arg(long)]
    pub robot: PathBuf,
    /// URDF only: the link whose frame is the robot base [default: the root link].
    #[arg(long)]
    pub base_link: Option<String>,
    /// URDF only: the link whose frame is the flange [default: the leaf with the most movable joints].
    #[arg(long)]
    pub tip_link: Option<String>,
}

impl RobotArgs {
    /// Reads and checks the robot description.
    pub fn read(&self) -> Result<RobotDescription, Error> {
        RobotDescription::read_with(&self.robot, &self.ends())
    }

    /// The chain's ends as given.
    pub fn ends(&self) -> ChainEnds {
        ChainEnds { base_link: self.base_link.clone(), tip_link: self.tip_link.clone() }
    }
}

/// `--robot` with `--base-link` and `--tip-link` where the robot may be left out: the model
/// keeps the description it was fitted with (models written before it was kept need `--robot`).
#[derive(Debug, clap::Args)]
pub struct KeptRobotArgs {
    /// Robot description (RON or URDF) [default: the one the model keeps; models written before
    /// it was kept need this].
    #[arg(long)]
    pub robot: Option<PathBuf>,
    /// URDF only: the link whose frame is the robot base [default: the root link].
    #[arg(long)]
    pub base_link: Option<String>,
    /// URDF only: the link whose frame is the flange [default: the leaf with the most movable joints].
    #[arg(long)]
    pub tip_link: Option<String>,
}

impl KeptRobotArgs {
    /// The chain's ends as given.
    pub fn ends(&self) -> ChainEnds {
        ChainEnds { base_link: self.base_link.clone(), tip_link: self.tip_link.clone() }
    }

    /// The robot of `--robot`, else the one `model` (read from `model_path`) keeps, with the words
    /// that name where it came from; `None` when neither is there. `--base-link`/`--tip-link`
    /// without `--robot` are refused (the kept description is already one chain).
    pub fn read_or_kept(
        &self,
        model: &model::CalibratedModel,
        model_path: &std::path::Path,
    ) -> Result<Option<(RobotDescription, String)>, Box<dyn std::error::Error>> {
        match &self.robot {
            Some(path) => Ok(Some((RobotDescription::read_with(path, &self.ends())?, path.display().to_string()))),
            None if self.ends() != ChainEnds::default() => Err("--base-link and --tip-link need --robot".into()),
            None => Ok(model
                .robot_description
                .clone()
                .map(|robot| (robot, format!("{} (as the model keeps it)", model_path.display())))),
        }
    }
}
