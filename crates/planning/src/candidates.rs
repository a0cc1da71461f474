//! The candidates of `calib plan`: read from a measurement-like CSV (every cell kept, so that the
//! chosen rows are written unchanged), or generated within the robot's joint limits.

use crate::information::Candidate;
use errors::Error;
use measurements::{Cells, MeasurementSet};
use model::CalibratedModel;
use poe::{JointKind, LocalPoe};
use robot::RobotDescription;
use std::io::Write;

/// The model a plan is made for and the candidates in its tool indices.
#[derive(Debug, Clone)]
pub struct CandidateSet {
    /// The kinematics the identification Jacobian is taken of (one tool per tool of the candidates).
    pub model: LocalPoe,
    /// The candidates.
    pub candidates: Vec<Candidate>,
    /// Tools of the candidates that the calibrated model does not have (planned with its first tool).
    pub unknown_tools: Vec<String>,
}

/// Candidates read from a file, for a calibrated `model` (its geometry and tools) or else the
/// robot's nominal model (one tool per distinct tool identifier, all its nominal tool).
pub fn file_candidates(
    set: &MeasurementSet,
    robot: &RobotDescription,
    model: Option<&CalibratedModel>,
) -> Result<CandidateSet, Error> {
    let mut unknown_tools = Vec::new();
    let (kinematics, tool_of): (LocalPoe, Vec<usize>) = match model {
        Some(m) => {
            let mut kinematics = m.kinematics.clone();
            let mut tools = kinematics.tools().to_vec();
            let tool_of = set
                .tools
                .iter()
                .map(|name| match m.tools.iter().position(|t| t == name) {
                    Some(i) => i,
                    None => {
                        unknown_tools.push(name.clone());
                        tools.push(tools[0]);
                        tools.len() - 1
                    }
                })
                .collect();
            kinematics.set_tools(tools);
            (kinematics, tool_of)
        }
        None => {
            let mut nominal = robot.nominal_model()?;
            let tool = nominal.tools()[0];
            nominal.set_tools(vec![tool; set.tools.len().max(1)]);
            (nominal, (0..set.tools.len()).collect())
        }
    };
    let candidates = set
        .rows
        .iter()
        .map(|r| Candidate {
            q: r.q.clone(),
            tool: tool_of.get(r.tool).copied().unwrap_or(0),
            payload_kg: r.payload_kg,
        })
        .collect();
    Ok(CandidateSet { model: kinematics, candidates, unknown_tools })
}

/// `count` configurations drawn within the robot's joint limits (away from them and from
/// singular poses, as `calib simulate` draws them), seeded.
pub fn generated_candidates(
    robot: &RobotDescription,
    model: Option<&CalibratedModel>,
    count: usize,
    seed: u64,
) -> Result<CandidateSet, Error> {
    let nominal = robot.nominal_model()?;
    let config = loadsim::GeneratorConfig { sample_count: count, seed, ..loadsim::GeneratorConfig::default() };
    let ranges = campaign::joint_ranges(robot);
    let configurations = loadsim::sample_configurations(&nominal, 0, &ranges, &config).map_err(Error::generator)?;
    let candidates = configurations.into_iter().map(|q| Candidate { q, tool: 0, payload_kg: 0.0 }).collect();
    let kinematics = model.map_or(nominal, |m| m.kinematics.clone());
    Ok(CandidateSet { model: kinematics, candidates, unknown_tools: Vec::new() })
}

/// Writes the chosen rows of a candidates file unchanged (its header, its cells, its field
/// separator), in `order`.
pub fn write_chosen_rows<W: Write>(writer: W, cells: &Cells, delimiter: u8, order: &[usize]) -> std::io::Result<()> {
    let mut out = csv::WriterBuilder::new().delimiter(delimiter).from_writer(writer);
    out.write_record(&cells.header)?;
    for &i in order {
        out.write_record(&cells.rows[i])?;
    }
    out.flush()
}

/// Writes generated candidates: `q1_rad …` (`qK_m` for a prismatic joint), in `order`.
pub fn write_generated_rows<W: Write>(
    writer: W,
    kinds: &[JointKind],
    candidates: &[Candidate],
    order: &[usize],
) -> std::io::Result<()> {
    let mut out = csv::Writer::from_writer(writer);
    let header: Vec<String> = kinds
        .iter()
        .enumerate()
        .map(|(k, kind)| format!("q{}_{}", k + 1, if *kind == JointKind::Prismatic { "m" } else { "rad" }))
        .collect();
    out.write_record(&header)?;
    for &i in order {
        out.write_record(candidates[i].q.iter().map(|v| v.to_string()))?;
    }
    out.flush()
}
