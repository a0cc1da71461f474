//! `cargo xtask convert-ur10`: the IPA UR10 tracker dataset (Landgraf et al., CASE 2021, MIT
//! licence; <https://ieeexplore.ieee.org/document/9551684>) as SPEC measurement CSV.
//!
//! The dataset is not part of this repository: point `--input` at a copy (by default
//! `../shared/data/ipa-ur10` beside the project). Its measurement files are `;`-separated with a
//! decimal comma; joints in radians (UR's DH zero), the T-Mac position in millimetres and its
//! orientation as `rx, ry, rz` in degrees, and the cell temperature.

use super::ur10_placements::{self, NotPlacements, PlacementOptions, Placements};
use anyhow::Context;
use lie::{SO3, Vector3};
use measurements::{Measurement, MeasurementSet};
use std::path::{Path, PathBuf};

/// Where the IPA UR10 dataset is and which series to read.
#[derive(Debug, clap::Args)]
pub struct Dataset {
    /// Folder of the dataset (holding Series_A … Series_D).
    #[arg(long, default_value = "../shared/data/ipa-ur10")]
    pub input: PathBuf,
    /// Which series: A (grid), B (joint configurations), C (random poses), D (ISO cubes).
    #[arg(long, default_value = "C")]
    pub series: String,
}

/// Convert the IPA UR10 dataset (a Leica laser tracker with a T-Mac on a UR10) to SPEC CSV.
///
/// The series is checked for the tracker placements it holds first (each row's commanded goal
/// against its measured point): one placement is written as asked; two are written as
/// FILE.placement1.csv and FILE.placement2.csv beside --out, with their lines and row counts; rows
/// neither one nor two placements explain are refused, saying where.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    dataset: Dataset,
    /// Keep the T-Mac orientation (full-pose data); otherwise position only.
    #[arg(long)]
    full_pose: bool,
    /// Write all rows here.
    #[arg(long, conflicts_with_all = ["train", "test"])]
    out: Option<PathBuf>,
    /// Write the first half of the rows (in measurement order) here…
    #[arg(long, requires = "test")]
    train: Option<PathBuf>,
    /// …and the second half here.
    #[arg(long, requires = "train")]
    test: Option<PathBuf>,
}

const SERIES: [(&str, &str); 4] = [
    ("A", "Series_A/measurements_grid.csv"),
    ("B", "Series_B/measurements_joint_configurations.csv"),
    ("C", "Series_C/measurements_random_poses.csv"),
    ("D", "Series_D/measurements_iso_cubes.csv"),
];

const JOINTS: [&str; 6] =
    ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"];

fn number(text: &str, file: &Path, line: usize, column: usize) -> anyhow::Result<f64> {
    let value: f64 = text
        .trim()
        .replace(',', ".")
        .parse()
        .map_err(|_| anyhow::anyhow!("{}:{line}:{column}: '{text}' is not a number", file.display()))?;
    if value.is_finite() {
        Ok(value)
    } else {
        Err(anyhow::anyhow!("{}:{line}:{column}: '{text}' is not finite", file.display()))
    }
}

/// The tracker's orientation angles as a rotation: `R = Rx(rx) · Ry(ry) · Rz(rz)` (intrinsic
/// x-y'-z''), the convention that makes the T-Mac a rigid body on the flange in this dataset
/// (checked by `cargo xtask convert-ur10 --full-pose` followed by a `poe` fit: the orientation
/// residual is at the tracker's noise level only with this order).
fn rotation(rx: f64, ry: f64, rz: f64) -> SO3 {
    SO3::exp(&(Vector3::x() * rx.to_radians()))
        * SO3::exp(&(Vector3::y() * ry.to_radians()))
        * SO3::exp(&(Vector3::z() * rz.to_radians()))
}

/// `YYYYMMDDhhmmss` as seconds since the first row's day; `None` when the stamp lost its digits
/// (Series B and C store it as `2,02011E+13`).
fn seconds(stamp: &str) -> Option<f64> {
    let s = stamp.trim();
    if s.len() != 14 || !s.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let part = |a: usize, b: usize| s[a..b].parse::<f64>().ok();
    Some(part(6, 8)? * 86400.0 + part(8, 10)? * 3600.0 + part(10, 12)? * 60.0 + part(12, 14)?)
}

/// One series as read: its rows, and each row's commanded goal (the planned T-Mac point in the
/// robot's base frame, mm), which the placement check compares the measured points with.
pub struct Series {
    /// The rows.
    pub set: MeasurementSet,
    /// Each row's goal, mm.
    pub goals_mm: Vec<Vector3>,
}

impl Series {
    /// The tracker placements the rows hold (module `ur10_placements`).
    pub fn placements(&self) -> Result<Placements, Box<NotPlacements>> {
        let measured: Vec<Vector3> = self.set.rows.iter().map(|r| r.position * 1e3).collect();
        ur10_placements::placements(&self.goals_mm, &measured, &PlacementOptions::default())
    }

    /// The raw file's line of row `index`.
    fn line(&self, index: usize) -> u64 {
        self.set.rows.get(index).map_or(0, |r| r.line)
    }

    /// What the placement check found, in words; `Err` where it is neither one placement nor two.
    pub fn placement_text(&self) -> anyhow::Result<(Placements, String)> {
        let file = &self.set.source;
        match self.placements() {
            Ok(Placements::One(fit)) => {
                let text = format!(
                    "{file}: one tracker placement: one rigid transform maps the commanded goals onto the measured \
                     points, RMS {:.2} mm, largest {:.2} mm (line {}); a moved tracker leaves its move, metres",
                    fit.rms_mm,
                    fit.max_mm,
                    self.line(fit.max_row)
                );
                Ok((Placements::One(fit), text))
            }
            Ok(Placements::Two { first, second, together }) => {
                let text = format!(
                    "{file}: two tracker placements: one rigid transform maps the goals onto the measured points only \
                     to {:.1} mm (line {}); lines {}-{} ({} rows, largest {:.2} mm) and lines {}-{} ({} rows, largest \
                     {:.2} mm) each by their own",
                    together.max_mm,
                    self.line(together.max_row),
                    self.line(first.rows.0),
                    self.line(first.rows.1 - 1),
                    first.rows.1 - first.rows.0,
                    first.max_mm,
                    self.line(second.rows.0),
                    self.line(second.rows.1 - 1),
                    second.rows.1 - second.rows.0,
                    second.max_mm
                );
                Ok((Placements::Two { first, second, together }, text))
            }
            Err(not) => {
                let NotPlacements { together, best_split } = *not;
                let split = best_split.map_or(String::new(), |(a, b)| {
                    format!(
                        ", and the best split in two (at line {}) still {:.1} mm",
                        self.line(b.rows.0),
                        a.max_mm.max(b.max_mm)
                    )
                });
                Err(anyhow::anyhow!(
                    "{file}: neither one tracker placement nor two: one rigid transform of the commanded goals leaves \
                     {:.1} mm at line {}{split} (above {} mm): the series needs a look by hand",
                    together.max_mm,
                    self.line(together.max_row),
                    PlacementOptions::default().max_residual_mm
                ))
            }
        }
    }
}

/// Reads one series as measurements; a series of more than one tracker placement is refused
/// (`cargo xtask convert-ur10` writes each placement to its own file).
pub fn read_series(input: &Path, series: &str, full_pose: bool) -> anyhow::Result<MeasurementSet> {
    let read = read_with_goals(input, series, full_pose)?;
    match read.placement_text()? {
        (Placements::One(_), _) => Ok(read.set),
        (Placements::Two { .. }, text) => Err(anyhow::anyhow!(
            "{text}: convert it with `cargo xtask convert-ur10`, which writes each to its own file"
        )),
    }
}

/// Reads one series with each row's commanded goal.
pub fn read_with_goals(input: &Path, series: &str, full_pose: bool) -> anyhow::Result<Series> {
    let relative = SERIES
        .iter()
        .find(|(name, _)| name.eq_ignore_ascii_case(series))
        .map(|(_, path)| *path)
        .ok_or_else(|| anyhow::anyhow!("unknown series '{series}': expected A, B, C or D"))?;
    let file = input.join(relative);
    let text = std::fs::read_to_string(&file).map_err(|e| {
        anyhow::anyhow!("{}: {e} (get the dataset of Landgraf et al., CASE 2021, and pass --input)", file.display())
    })?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(';').map(str::trim).collect();
    let columns = Columns::find(&header, &file)?;
    let mut rows = Vec::new();
    let mut goals_mm = Vec::new();
    for (index, raw) in lines.enumerate() {
        let line = index + 2;
        if raw.trim().is_empty() {
            continue;
        }
        let (row, goal_mm) = columns.row(raw, &file, line, full_pose)?;
        goals_mm.push(goal_mm);
        rows.push(row);
    }
    // A time column only when every stamp survived.
    if rows.iter().any(|r| r.t_s.is_none()) {
        rows.iter_mut().for_each(|r| r.t_s = None);
    } else if let Some(t0) = rows.first().and_then(|r| r.t_s) {
        rows.iter_mut().for_each(|r| r.t_s = r.t_s.map(|t| t - t0));
    }
    Ok(Series { set: MeasurementSet::from_rows(&file.display().to_string(), rows, vec![]), goals_mm })
}

/// Where a row's values are in the data set's CSV.
struct Columns {
    joints: Vec<usize>,
    position: [usize; 3],
    angles: [usize; 3],
    temperature: usize,
    position_std: [usize; 3],
    angle_std: [usize; 3],
    stamp: usize,
    goal: [usize; 3],
}

impl Columns {
    /// Each column's place in `header` (line 1 of `file`); the first missing is refused.
    fn find(header: &[&str], file: &Path) -> anyhow::Result<Self> {
        let column = |name: &str| {
            header
                .iter()
                .position(|h| *h == name)
                .ok_or_else(|| anyhow::anyhow!("{}:1: no column '{name}'", file.display()))
        };
        let joints: Vec<usize> = JOINTS.iter().map(|j| column(j)).collect::<Result<_, _>>()?;
        let position = [column("measurement_x")?, column("measurement_y")?, column("measurement_z")?];
        let angles = [column("measurement_rx")?, column("measurement_ry")?, column("measurement_rz")?];
        let temperature = column("measurement_temperature")?;
        // The tracker's stated standard deviation of every row: mm, and degrees of the
        // three angles, kept as std_x_mm … and std_rx_mrad ….
        let position_std = [column("measurement_std_x")?, column("measurement_std_y")?, column("measurement_std_z")?];
        let angle_std = [column("measurement_std_rx")?, column("measurement_std_ry")?, column("measurement_std_rz")?];
        let stamp = column("Timestamp")?;
        let goal = [column("Goal x")?, column("Goal y")?, column("Goal z")?];
        Ok(Columns { joints, position, angles, temperature, position_std, angle_std, stamp, goal })
    }

    /// Data row `raw` (line `line` of `file`) as a measurement, and its goal.
    fn row(&self, raw: &str, file: &Path, line: usize, full_pose: bool) -> anyhow::Result<(Measurement, Vector3)> {
        let cells: Vec<&str> = raw.split(';').collect();
        let cell = |c: usize| -> anyhow::Result<f64> { number(cells.get(c).copied().unwrap_or(""), file, line, c + 1) };
        let (position, angles, goal) = (self.position, self.angles, self.goal);
        let (position_std, angle_std) = (self.position_std, self.angle_std);
        let q = self.joints.iter().map(|&c| cell(c)).collect::<Result<Vec<_>, _>>()?;
        let p = Vector3::new(cell(position[0])?, cell(position[1])?, cell(position[2])?) * 1e-3;
        // The goal in metres, as the planner wrote it.
        let goal_mm = Vector3::new(cell(goal[0])?, cell(goal[1])?, cell(goal[2])?) * 1e3;
        let orientation =
            if full_pose { Some(rotation(cell(angles[0])?, cell(angles[1])?, cell(angles[2])?)) } else { None };
        let row = Measurement {
            line: line as u64,
            q,
            position: p,
            orientation,
            payload_kg: 0.0,
            tool: 0,
            temp_c: Some(cell(self.temperature)?),
            t_s: cells.get(self.stamp).and_then(|s| seconds(s)),
            torques_nm: None,
            inputs: measurements::Inputs::default(),
            std: Some(measurements::StatedSigma {
                position_m: Some([
                    cell(position_std[0])? * 1e-3,
                    cell(position_std[1])? * 1e-3,
                    cell(position_std[2])? * 1e-3,
                ]),
                rotation_rad: Some([
                    cell(angle_std[0])?.to_radians(),
                    cell(angle_std[1])?.to_radians(),
                    cell(angle_std[2])?.to_radians(),
                ]),
            }),
        };
        Ok((row, goal_mm))
    }
}

fn write(set: &MeasurementSet, path: &Path) -> anyhow::Result<()> {
    let file = std::fs::File::create(path).with_context(|| path.display().to_string())?;
    set.write_csv(std::io::BufWriter::new(file)).with_context(|| path.display().to_string())?;
    println!("wrote {} rows to {}", set.rows.len(), path.display());
    Ok(())
}

/// `path` with `.placement{k}` before its extension: `D.csv` → `D.placement1.csv`.
fn placement_path(path: &Path, k: usize) -> PathBuf {
    let stem = path.file_stem().map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let extension = path.extension().map_or_else(String::new, |e| format!(".{}", e.to_string_lossy()));
    path.with_file_name(format!("{stem}.placement{k}{extension}"))
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let read = read_with_goals(&args.dataset.input, &args.dataset.series, args.full_pose)?;
    let (placements, text) = read.placement_text()?;
    println!("{text}");
    let set = read.set;
    if let Placements::Two { first, second, .. } = placements {
        // Each placement its own file: one set of rows is one tracker frame.
        let Some(out) = &args.out else {
            return Err(anyhow::anyhow!(
                "two tracker placements: --train/--test would mix their frames; give --out FILE (FILE.placement1.csv \
                 and FILE.placement2.csv are written)"
            ));
        };
        for (k, part) in [first, second].iter().enumerate() {
            write(&set.subset(&(part.rows.0..part.rows.1).collect::<Vec<_>>()), &placement_path(out, k + 1))?;
        }
        return Ok(());
    }
    match (&args.out, &args.train, &args.test) {
        (Some(out), _, _) => write(&set, out),
        (None, Some(train), Some(test)) => {
            let half = set.rows.len() / 2;
            write(&set.subset(&(0..half).collect::<Vec<_>>()), train)?;
            write(&set.subset(&(half..set.rows.len()).collect::<Vec<_>>()), test)
        }
        _ => Err(anyhow::anyhow!("give --out FILE, or --train FILE and --test FILE")),
    }
}

#[cfg(test)]
mod tests {
    use measurements::{ColumnMap, ReadOptions, parse_measurements};

    /// The T-Mac angles of the first rows of series C, as the export writes them.
    const ANGLES: [&str; 3] =
        ["-90,179563;-20,112975;-90,157388", "-84,20352;-22,726835;-88,245609", "-89,065785;0,79839706;-89,749441"];

    #[test]
    fn the_readers_euler_columns_give_the_rotation_of_this_conversion() {
        let mut text = String::from(
            "q1_rad;measurement_x;measurement_y;measurement_z;measurement_rx;measurement_ry;measurement_rz\n",
        );
        for angles in ANGLES {
            text.push_str(&format!("0;383,97123;-3240,7562;201,72621;{angles}\n"));
        }
        let columns: ColumnMap = "x_mm=measurement_x,y_mm=measurement_y,z_mm=measurement_z,\
                                  rx_deg=measurement_rx,ry_deg=measurement_ry,rz_deg=measurement_rz"
            .parse()
            .unwrap();
        let set =
            parse_measurements(text.as_bytes(), "tmac.csv", &ReadOptions::default().with_columns(columns)).unwrap();
        for (row, angles) in set.rows.iter().zip(ANGLES) {
            let a: Vec<f64> = angles.split(';').map(|c| c.replace(',', ".").parse().unwrap()).collect();
            let converted = super::rotation(a[0], a[1], a[2]).to_quaternion();
            let read = row.orientation.unwrap().to_quaternion();
            let difference = converted.iter().zip(&read).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
            assert!(difference < 1e-14, "{angles}: {converted:?} converted, {read:?} read");
        }
    }
}
