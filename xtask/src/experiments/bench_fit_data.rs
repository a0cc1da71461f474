//! The measurement files `cargo xtask bench-fit` hands to `calib`: the UR10 series converted (as
//! `cargo xtask convert-ur10` writes them) or read from converted CSVs, split into even and odd
//! rows, with the orientations dropped for the position-only row; and simulated IRB 4400
//! campaigns written by `calib simulate`, split into the first rows and the rest.

use anyhow::Context;
use measurements::{MeasurementSet, ReadOptions};
use robot::RobotDescription;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A row's training and test files.
#[derive(Debug, Clone, PartialEq)]
pub struct Files {
    /// What `calib fit` reads.
    pub train: PathBuf,
    /// What `calib eval` reads.
    pub test: PathBuf,
    /// Their row counts.
    pub rows: (usize, usize),
    /// Whether they have orientations.
    pub full_pose: bool,
}

/// A SPEC CSV of `robot`'s joints; an error names the file.
pub fn read_csv(path: &Path, robot: &RobotDescription) -> anyhow::Result<MeasurementSet> {
    measurements::read_measurements(path, &ReadOptions::for_joints(robot.joint_kinds()))
        .with_context(|| path.display().to_string())
}

/// A UR10 series, full pose where the source has orientations, all rows in measurement order:
/// converted from the data set when `dir` holds it (`Series_C/…`), else read from converted CSVs
/// (`C.csv` or `ur10_C.csv`, or the even and odd rows `C_even.csv` and `C_odd.csv` put back in
/// order). `None` when `dir` has neither.
pub fn ur10_series(dir: &Path, robot: &RobotDescription, series: &str) -> anyhow::Result<Option<MeasurementSet>> {
    if dir.join(format!("Series_{series}")).is_dir() {
        return super::convert_ur10::read_series(dir, series, true).map(Some);
    }
    let read = |p: &Path| read_csv(p, robot);
    let stems = [series.to_owned(), format!("ur10_{series}")];
    for stem in &stems {
        let whole = dir.join(format!("{stem}.csv"));
        if whole.is_file() {
            return read(&whole).map(Some);
        }
    }
    for stem in &stems {
        let (even, odd) = (dir.join(format!("{stem}_even.csv")), dir.join(format!("{stem}_odd.csv")));
        if even.is_file() && odd.is_file() {
            return interleave(read(&even)?, read(&odd)?).map(Some);
        }
    }
    Ok(None)
}

/// The series whose even rows are `even` and odd rows `odd`, in its order.
pub fn interleave(even: MeasurementSet, odd: MeasurementSet) -> anyhow::Result<MeasurementSet> {
    let (e, o) = (even.rows.len(), odd.rows.len());
    if e != o && e != o + 1 {
        anyhow::bail!("{} has {e} rows and {} {o}: not the even and odd rows of one series", even.source, odd.source);
    }
    if even.tools != odd.tools {
        anyhow::bail!("{} and {} name different tools: {:?}, {:?}", even.source, odd.source, even.tools, odd.tools);
    }
    // The even set's columns and tools, every row of both.
    let mut series = even.subset(&[]);
    series.full_pose = even.full_pose && odd.full_pose;
    let mut odd_rows = odd.rows.into_iter();
    for row in even.rows {
        series.rows.push(row);
        series.rows.extend(odd_rows.next());
    }
    Ok(series)
}

/// Rows `0, 2, 4, …` and `1, 3, 5, …`.
pub fn even_odd(set: &MeasurementSet) -> (MeasurementSet, MeasurementSet) {
    let n = set.rows.len();
    (set.subset(&(0..n).step_by(2).collect::<Vec<_>>()), set.subset(&(1..n).step_by(2).collect::<Vec<_>>()))
}

/// The same rows without their orientations: what a position-only tracker would have given.
pub fn position_only(set: &MeasurementSet) -> MeasurementSet {
    let mut set = set.clone();
    set.full_pose = false;
    set.rows.iter_mut().for_each(|r| r.orientation = None);
    set
}

/// At most `cap` rows spread over the set (every k-th, from the first): `--quick`'s smaller sets.
pub fn spread(set: &MeasurementSet, cap: Option<usize>) -> MeasurementSet {
    match cap {
        Some(cap) if set.rows.len() > cap && cap > 0 => {
            let step = set.rows.len().div_ceil(cap);
            set.subset(&(0..set.rows.len()).step_by(step).collect::<Vec<_>>())
        }
        _ => set.clone(),
    }
}

/// Writes `set` as SPEC CSV to `path`.
pub fn write(set: &MeasurementSet, path: &Path) -> anyhow::Result<()> {
    let file = std::fs::File::create(path).with_context(|| path.display().to_string())?;
    set.write_csv(std::io::BufWriter::new(file)).with_context(|| path.display().to_string())
}

/// `train` and `test` written into `dir` as `NAME_train.csv` and `NAME_test.csv`.
pub fn write_pair(dir: &Path, name: &str, train: &MeasurementSet, test: &MeasurementSet) -> anyhow::Result<Files> {
    let files = Files {
        train: dir.join(format!("{name}_train.csv")),
        test: dir.join(format!("{name}_test.csv")),
        rows: (train.rows.len(), test.rows.len()),
        full_pose: train.full_pose && test.full_pose,
    };
    write(train, &files.train)?;
    write(test, &files.test)?;
    Ok(files)
}

/// `calib simulate --robot ROBOT --rows TRAIN+TEST --seed SEED` (position only, the paper's
/// effects: its defaults) into `dir`, split into the first `train` rows and the next `test` as
/// written, byte for byte.
pub fn simulate(
    calib: &Path,
    robot: &Path,
    dir: &Path,
    name: &str,
    (train, test): (usize, usize),
    seed: u64,
) -> anyhow::Result<Files> {
    let all = dir.join(format!("{name}_all.csv"));
    let output = Command::new(calib)
        .arg("simulate")
        .arg("--robot")
        .arg(robot)
        .arg("--out")
        .arg(&all)
        .args(["--rows", &(train + test).to_string(), "--seed", &seed.to_string()])
        .output()
        .with_context(|| format!("running {} simulate", calib.display()))?;
    if !output.status.success() {
        anyhow::bail!("{} simulate: {}", calib.display(), String::from_utf8_lossy(&output.stderr).trim());
    }
    let text = std::fs::read_to_string(&all).with_context(|| all.display().to_string())?;
    let (head, rows) = split_rows(&text, train, test).with_context(|| all.display().to_string())?;
    let files = Files {
        train: dir.join(format!("{name}_train.csv")),
        test: dir.join(format!("{name}_test.csv")),
        rows: (train, test),
        full_pose: false,
    };
    let join = |part: &[&str]| format!("{head}\n{}\n", part.join("\n"));
    std::fs::write(&files.train, join(&rows[..train])).with_context(|| files.train.display().to_string())?;
    std::fs::write(&files.test, join(&rows[train..])).with_context(|| files.test.display().to_string())?;
    let _ = std::fs::remove_file(&all);
    Ok(files)
}

/// The header line and the data lines of a CSV that must hold `train + test` rows of one line
/// each (what `calib simulate` writes: no comments, no quoted line breaks).
fn split_rows(text: &str, train: usize, test: usize) -> anyhow::Result<(&str, Vec<&str>)> {
    let mut lines = text.lines();
    let head = lines.next().context("empty file")?;
    let rows: Vec<&str> = lines.filter(|l| !l.trim().is_empty()).collect();
    if rows.len() != train + test || rows.iter().any(|l| l.starts_with('#')) {
        anyhow::bail!("expected {} data lines after the header, found {} (or comment lines)", train + test, rows.len());
    }
    Ok((head, rows))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(line: u64) -> measurements::Measurement {
        measurements::Measurement {
            line,
            q: vec![line as f64; 6],
            position: lie::Vector3::new(line as f64, 0.0, 0.0),
            orientation: Some(lie::SO3::identity()),
            payload_kg: 0.0,
            tool: 0,
            temp_c: None,
            t_s: None,
            torques_nm: None,
            inputs: measurements::Inputs::default(),
            std: None,
        }
    }

    fn set(lines: impl Iterator<Item = u64>) -> MeasurementSet {
        MeasurementSet::from_rows("mem", lines.map(row).collect(), vec![])
    }

    fn lines(s: &MeasurementSet) -> Vec<u64> {
        s.rows.iter().map(|r| r.line).collect()
    }

    #[test]
    fn even_and_odd_rows_interleave_back_into_the_series() {
        let series = set(0..7);
        let (even, odd) = even_odd(&series);
        assert_eq!((lines(&even), lines(&odd)), (vec![0, 2, 4, 6], vec![1, 3, 5]));
        let back = interleave(even, odd).unwrap();
        assert_eq!(lines(&back), lines(&series));
        assert!(back.full_pose);
        assert!(interleave(set(0..2), set(2..5)).is_err(), "three odd rows cannot follow two even ones");
    }

    #[test]
    fn position_only_drops_every_orientation_and_spread_keeps_at_most_the_cap() {
        let positions = position_only(&set(0..3));
        assert!(!positions.full_pose);
        assert!(positions.rows.iter().all(|r| r.orientation.is_none()));
        assert_eq!(lines(&spread(&set(0..10), Some(4))), [0, 3, 6, 9]);
        assert_eq!(lines(&spread(&set(0..10), Some(5))), [0, 2, 4, 6, 8]);
        assert_eq!(spread(&set(0..10), None).rows.len(), 10);
        assert_eq!(spread(&set(0..3), Some(5)).rows.len(), 3);
    }

    #[test]
    fn a_simulated_file_splits_into_its_first_rows_and_the_rest_or_is_refused() {
        let (head, rows) = split_rows("a,b\n1,2\n3,4\n5,6\n", 2, 1).unwrap();
        assert_eq!((head, rows), ("a,b", vec!["1,2", "3,4", "5,6"]));
        assert!(split_rows("a,b\n1,2\n3,4\n", 2, 1).is_err());
        assert!(split_rows("a,b\n# note\n3,4\n5,6\n", 2, 1).is_err());
    }

    #[test]
    fn a_position_only_pair_is_written_without_orientations_and_reads_back() {
        let dir = std::env::temp_dir().join(format!("calib-bench-fit-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (even, odd) = even_odd(&position_only(&set(1..8)));
        let files = write_pair(&dir, "c", &even, &odd).unwrap();
        assert_eq!((files.rows, files.full_pose), ((4, 3), false));
        let head = std::fs::read_to_string(&files.train).unwrap();
        assert!(!head.lines().next().unwrap().contains("qw"), "{head}");
        let back = measurements::read_measurements(&files.test, &ReadOptions::default()).unwrap();
        assert_eq!(back.rows.len(), 3);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
