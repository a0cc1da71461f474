//! `--robot` with `--base-link` and `--tip-link`, shared by every subcommand that reads a robot.

use pipeline::{ChainEnds, Error, RobotDescription};
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
