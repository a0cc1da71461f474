//! `cargo xtask hostile`: every row of the hostile-input table (nothing lost, and no fit that
//! looks right and is not) run against the release `calib` in a temporary folder, each asserting the
//! exit status and the message; one line per row, a non-zero exit if any row fails. The same rows
//! are tests of the suite (`crates/calib/tests/{nothing_lost_cli,plausibility_cli,sanity_cli,
//! hostile_cli}.rs`); this runs them on the binary a user runs. The 68 MB memory row runs with
//! `--with-memory` (`cargo xtask bench-memory` alone gives its table).

use anyhow::{Context, Result, bail, ensure};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

/// The hostile-input table against the built binary.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Also run the 68 MB memory row (about a minute; with the dev profile's binary unless
    /// --release: its libraries are optimised as the release's are, and heap use is the same).
    #[arg(long)]
    with_memory: bool,
    /// Run the release binary (the dev profile's, which `cargo test` built, by default: the
    /// messages are the same, and CI needs no second build).
    #[arg(long)]
    release: bool,
}

/// What a row found.
enum Outcome {
    Passed(String),
}

struct Bench {
    calib: PathBuf,
    dir: PathBuf,
    robot: String,
}

impl Bench {
    fn path(&self, name: &str) -> String {
        self.dir.join(name).display().to_string()
    }

    fn run(&self, args: &[&str]) -> Result<Output> {
        Command::new(&self.calib).args(args).output().with_context(|| format!("calib {args:?}"))
    }

    /// Runs a command that must succeed; its stdout and stderr.
    fn ok(&self, args: &[&str]) -> Result<(String, String)> {
        let out = self.run(args)?;
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        ensure!(out.status.success(), "calib {} failed: {}", args[0], stderr.trim());
        Ok((String::from_utf8_lossy(&out.stdout).into_owned(), stderr))
    }

    /// Runs a command that must fail with one line on stderr containing every one of `expect`.
    fn refused(&self, args: &[&str], expect: &[&str]) -> Result<String> {
        let out = self.run(args)?;
        let stderr = String::from_utf8_lossy(&out.stderr).trim().to_owned();
        ensure!(!out.status.success(), "calib {} exited 0: {}", args[0], String::from_utf8_lossy(&out.stdout));
        ensure!(out.status.code() == Some(1), "calib {} ended by {:?}, not an error exit", args[0], out.status);
        ensure!(stderr.lines().count() == 1, "not one line on stderr: {stderr}");
        for e in expect {
            ensure!(stderr.contains(e), "message lacks {e:?}: {stderr}");
        }
        Ok(stderr)
    }

    fn simulate(&self, out: &str, rows: usize, extra: &[&str]) -> Result<()> {
        let rows = rows.to_string();
        let mut args = vec!["simulate", "--robot", &self.robot, "--out", out, "--rows", &rows, "--seed", "7"];
        args.extend_from_slice(extra);
        self.ok(&args).map(|_| ())
    }

    fn fit(&self, data: &str, out: &str, extra: &[&str]) -> Result<Output> {
        let mut args = vec!["fit", "--robot", &self.robot, "--data", data, "--method", "poe", "--out", out];
        args.extend_from_slice(extra);
        self.run(&args)
    }
}

/// `from` rewritten cell by cell: `edit(header, row index from 1, cells)`.
fn rewrite(from: &str, to: &str, edit: impl Fn(&[String], usize, &mut Vec<String>)) -> Result<()> {
    let text = std::fs::read_to_string(from)?;
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().context("empty CSV")?.split(',').map(String::from).collect();
    let mut out = header.join(",") + "\n";
    for (i, line) in lines.enumerate() {
        let mut cells: Vec<String> = line.split(',').map(String::from).collect();
        edit(&header, i + 1, &mut cells);
        out.push_str(&cells.join(","));
        out.push('\n');
    }
    std::fs::write(to, out)?;
    Ok(())
}

fn col(header: &[String], name: &str) -> usize {
    header.iter().position(|h| h == name).unwrap_or(usize::MAX)
}

fn scale(cells: &mut [String], at: usize, factor: f64) {
    if let Some(v) = cells.get(at).and_then(|c| c.parse::<f64>().ok()) {
        cells[at] = format!("{:?}", v * factor);
    }
}

type Row = (&'static str, fn(&Bench) -> Result<Outcome>);

fn rows() -> Vec<Row> {
    vec![
        ("fit/export --out over an input", overwrite_input),
        ("--out a symlink or a device node", symlink_and_device),
        ("kill -9 during simulate / export", killed_writes),
        ("metres under _mm", metres),
        ("x and y columns swapped", swapped),
        ("degrees under _rad; 1e20 rad", degrees),
        ("one row 1 m off among 300", outlier),
        ("compliance model at 1e6 kg; predict at q1 = 100 rad", not_covered),
        ("position-only model on full-pose data", position_only),
        ("one cell of 1e308; two identical axes", clear_causes),
        ("simulate --rows 2^64-1 and 1e9", absurd_rows),
        ("export --like with another joint kind", export_like),
        ("--effects time_drift on a constant t_s", constant_time),
    ]
}

pub fn run(args: &Args) -> Result<()> {
    let started = Instant::now();
    let calib = crate::calib_runs::calib_binary(args.release)?;
    println!("{}", calib.display());
    let dir = std::env::temp_dir().join(format!("calib-hostile-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let robot = crate::workspace_root().join("fixtures/robots/irb4400.ron").display().to_string();
    let bench = Bench { calib, dir: dir.clone(), robot };
    let mut failures = 0;
    let mut table: Vec<Row> = rows();
    if args.with_memory {
        table.push(("a 68 MB measurement CSV", memory));
    }
    for (what, row) in table {
        let t = Instant::now();
        let (mark, note) = match row(&bench) {
            Ok(Outcome::Passed(note)) => ("pass", note),
            Err(e) => {
                failures += 1;
                ("FAIL", format!("{e:#}"))
            }
        };
        println!("{mark:7} | {what:52} | {:5.1} s | {}", t.elapsed().as_secs_f64(), note.replace('\n', " "));
    }
    if !args.with_memory {
        println!("{:7} | {:52} | {:5} | run with --with-memory", "skipped", "a 68 MB measurement CSV", "");
    }
    let _ = std::fs::remove_dir_all(&dir);
    println!("{} s in all", started.elapsed().as_secs());
    if failures > 0 {
        bail!("{failures} rows of the table failed");
    }
    Ok(())
}

fn overwrite_input(b: &Bench) -> Result<Outcome> {
    let data = b.path("run.csv");
    b.simulate(&data, 60, &[])?;
    let before = std::fs::read(&data)?;
    let out = b.fit(&data, &data, &[])?;
    ensure!(!out.status.success(), "fit --out = --data exited 0");
    let stderr = String::from_utf8_lossy(&out.stderr);
    ensure!(stderr.contains("--out") && stderr.contains("--data"), "names neither: {stderr}");
    ensure!(std::fs::read(&data)? == before, "the data changed");
    let robot_copy = b.path("robot.ron");
    std::fs::copy(&b.robot, &robot_copy)?;
    let out = b.run(&["fit", "--robot", &robot_copy, "--data", &data, "--method", "poe", "--out", &robot_copy])?;
    ensure!(!out.status.success(), "fit --out = --robot exited 0");
    let model = b.path("m.ron");
    ensure!(b.fit(&data, &model, &[])?.status.success(), "fit failed");
    let model_before = std::fs::read(&model)?;
    b.refused(&["export", "--model", &model, "--urdf", &model], &["--urdf", "--model"])?;
    ensure!(std::fs::read(&model)? == model_before, "the model changed");
    Ok(Outcome::Passed("refused with both names; inputs unchanged".into()))
}

fn symlink_and_device(b: &Bench) -> Result<Outcome> {
    let data = b.path("s.csv");
    b.simulate(&data, 60, &[])?;
    let (target, link) = (b.path("target.ron"), b.path("link.ron"));
    std::fs::write(&target, "old")?;
    std::os::unix::fs::symlink(&target, &link)?;
    ensure!(b.fit(&data, &link, &[])?.status.success(), "fit through a link failed");
    ensure!(std::fs::symlink_metadata(&link)?.file_type().is_symlink(), "the link was replaced");
    ensure!(std::fs::read_to_string(&target)?.contains("kinematics"), "the link's target holds no model");
    let out = b.fit(&data, "/dev/null", &[])?;
    ensure!(!out.status.success(), "fit --out /dev/null exited 0");
    let meta = std::fs::metadata("/dev/null")?;
    ensure!(!meta.is_file(), "/dev/null became a regular file");
    Ok(Outcome::Passed("link kept, its target written; /dev/null refused and left a device".into()))
}

fn killed_writes(b: &Bench) -> Result<Outcome> {
    let out = b.path("killed.csv");
    let old = b"the previous measurements\n";
    std::fs::write(&out, old)?;
    let mut child = Command::new(&b.calib)
        .args(["simulate", "--robot", &b.robot, "--out", &out, "--rows", "300000"])
        .stdout(std::process::Stdio::null())
        .spawn()?;
    let started = Instant::now();
    // Kill once writing has begun: the temporary file beside the output holds some bytes.
    let writing = |dir: &Path| -> bool {
        std::fs::read_dir(dir).into_iter().flatten().flatten().any(|e| {
            e.file_name().to_string_lossy().starts_with(".killed.csv.") && e.metadata().is_ok_and(|m| m.len() > 0)
        })
    };
    let mut mid_write = false;
    while started.elapsed().as_secs() < 60 {
        if child.try_wait()?.is_some() {
            break;
        }
        if writing(&b.dir) {
            mid_write = true;
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    child.kill()?;
    child.wait()?;
    ensure!(mid_write, "simulate was not caught writing (finished or never started within 60 s)");
    let content = std::fs::read(&out)?;
    ensure!(content == old, "the output changed under a kill mid-write ({} bytes)", content.len());
    // export: written through the same temporary file and rename; nothing beside it after.
    let (data, model, urdf) = (b.path("k.csv"), b.path("k.ron"), b.path("k.urdf"));
    b.simulate(&data, 60, &[])?;
    ensure!(b.fit(&data, &model, &[])?.status.success(), "fit failed");
    b.ok(&["export", "--model", &model, "--urdf", &urdf])?;
    let stray: Vec<String> = std::fs::read_dir(&b.dir)?
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .filter(|n| n.starts_with('.') && n.contains("k.urdf"))
        .collect();
    ensure!(stray.is_empty(), "temporary files left: {stray:?}");
    Ok(Outcome::Passed("simulate killed mid-write: the old file intact; export via temp + rename, nothing left".into()))
}

fn plausibility(
    b: &Bench,
    name: &str,
    edit: impl Fn(&[String], usize, &mut Vec<String>),
    expect: &[&str],
) -> Result<String> {
    let (right, wrong, model) = (b.path("right.csv"), b.path(&format!("{name}.csv")), b.path(&format!("{name}.ron")));
    b.simulate(&right, 120, &[])?;
    rewrite(&right, &wrong, edit)?;
    let mut args = vec!["fit", "--robot", &b.robot, "--data", &wrong, "--method", "poe", "--out", &model];
    let message = b.refused(&args, expect)?;
    ensure!(!Path::new(&model).exists(), "a refused fit wrote a model");
    args.push("--force");
    b.ok(&args)?;
    Ok(message)
}

fn metres(b: &Bench) -> Result<Outcome> {
    let edit = |h: &[String], _: usize, c: &mut Vec<String>| {
        for name in ["x_mm", "y_mm", "z_mm"] {
            scale(c, col(h, name), 1e-3);
        }
    };
    plausibility(b, "metres", edit, &["positions look like metres under _mm columns"])?;
    Ok(Outcome::Passed("refused as metres; --force fits".into()))
}

fn swapped(b: &Bench) -> Result<Outcome> {
    let edit = |h: &[String], _: usize, c: &mut Vec<String>| c.swap(col(h, "x_mm"), col(h, "y_mm"));
    plausibility(b, "swapped", edit, &["left-handed: two position columns swapped?"])?;
    Ok(Outcome::Passed("refused as a left-handed frame; --force fits".into()))
}

fn degrees(b: &Bench) -> Result<Outcome> {
    let edit = |h: &[String], _: usize, c: &mut Vec<String>| {
        for k in 1..=6 {
            scale(c, col(h, &format!("q{k}_rad")), 180.0 / std::f64::consts::PI);
        }
    };
    plausibility(b, "degrees", edit, &["degrees under `_rad`?"])?;
    let (right, huge) = (b.path("right.csv"), b.path("huge.csv"));
    rewrite(&right, &huge, |h, i, c| {
        if i == 5 {
            c[col(h, "q3_rad")] = "1e20".into();
        }
    })?;
    let place = format!("{huge}:6:3:");
    b.refused(&["fit", "--robot", &b.robot, "--data", &huge, "--method", "poe", "--out", &b.path("n.ron")], &[&place])?;
    Ok(Outcome::Passed("refused at a value beyond the limits; 1e20 rad at its line 6, column 3".into()))
}

fn outlier(b: &Bench) -> Result<Outcome> {
    let (data, bad, model) = (b.path("o.csv"), b.path("o_bad.csv"), b.path("o.ron"));
    b.simulate(&data, 300, &[])?;
    // Row 137 of the data (line 138) moved by a metre along x.
    rewrite(&data, &bad, |h, i, c| {
        if i == 137 {
            let x: f64 = c[col(h, "x_mm")].parse().unwrap_or(0.0);
            c[col(h, "x_mm")] = format!("{:?}", x + 1000.0);
        }
    })?;
    let out = b.fit(&bad, &model, &[])?;
    let said = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    ensure!(out.status.success(), "fit failed: {said}");
    ensure!(said.contains("line 138 ("), "the row is not named: {said}");
    let (text, _) = b.ok(&["diagnose", "--robot", &b.robot, "--data", &bad])?;
    ensure!(text.contains("left out of the diagnosis: line 138 ("), "diagnose does not name it: {text}");
    Ok(Outcome::Passed("fit names line 138 and leaves it out; diagnose names it and leaves it out".into()))
}

fn not_covered(b: &Bench) -> Result<Outcome> {
    let (data, model, heavy, far) = (b.path("c.csv"), b.path("c.ron"), b.path("heavy.csv"), b.path("far.csv"));
    b.simulate(&data, 120, &[])?;
    ensure!(b.fit(&data, &model, &["--joint-compliance"])?.status.success(), "compliance fit failed");
    rewrite(&data, &heavy, |h, _, c| c[col(h, "payload_kg")] = "1e6".into())?;
    let (_, stderr) = b.ok(&["predict", "--model", &model, "--data", &heavy])?;
    ensure!(
        stderr.contains("put payload_kg outside the range the model was fitted on (1.0000 … 7.5000 kg)"),
        "{stderr}"
    );
    rewrite(&data, &far, |h, i, c| {
        if i == 1 {
            c[col(h, "q1_rad")] = "100".into();
        }
    })?;
    let (_, stderr) = b.ok(&["predict", "--model", &model, "--data", &far])?;
    ensure!(stderr.contains("put joint 1 outside the range the model was fitted on"), "{stderr}");
    ensure!(stderr.contains("(the first at line 2, 100.0000 rad) put joint 1 beyond the robot's limits"), "{stderr}");
    Ok(Outcome::Passed("1e6 kg: payload outside 1 … 7.5 kg; 100 rad: outside the fitted angles and the limits".into()))
}

fn position_only(b: &Bench) -> Result<Outcome> {
    let (full, positions, model) = (b.path("full.csv"), b.path("positions.csv"), b.path("p.ron"));
    b.simulate(&full, 80, &["--full-pose"])?;
    let text = std::fs::read_to_string(&full)?;
    let header: Vec<&str> = text.lines().next().unwrap_or_default().split(',').collect();
    let keep: Vec<usize> = (0..header.len()).filter(|&i| !["qw", "qx", "qy", "qz"].contains(&header[i])).collect();
    let body: String = text
        .lines()
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            keep.iter().map(|&i| cells[i]).collect::<Vec<_>>().join(",") + "\n"
        })
        .collect();
    std::fs::write(&positions, body)?;
    ensure!(b.fit(&positions, &model, &[])?.status.success(), "fit failed");
    let (json, stderr) = b.ok(&["eval", "--model", &model, "--data", &full, "--json"])?;
    let report: model::EvalReport = serde_json::from_str(&json)?;
    ensure!(report.errors.mean_rotation_error_mrad.is_none(), "a rotation error is reported: {json}");
    ensure!(stderr.contains("orientations in the data are not evaluated"), "{stderr}");
    Ok(Outcome::Passed("no rotation error; says orientations are not evaluated".into()))
}

fn clear_causes(b: &Bench) -> Result<Outcome> {
    let (data, bad) = (b.path("cc.csv"), b.path("e308.csv"));
    b.simulate(&data, 60, &[])?;
    rewrite(&data, &bad, |h, i, c| {
        if i == 9 {
            c[col(h, "y_mm")] = "1e308".into();
        }
    })?;
    let place = format!("{bad}:10:8:");
    b.refused(&["fit", "--robot", &b.robot, "--data", &bad, "--method", "poe", "--out", &b.path("n.ron")], &[&place])?;
    let coaxial = b.path("coaxial.ron");
    let robot = std::fs::read_to_string(&b.robot)?
        .replace("axis: (0.0, 1.0, 0.0), point: (0.2, 0.0, 0.68)", "axis: (0.0, 0.0, 1.0), point: (0.0, 0.0, 0.68)");
    std::fs::write(&coaxial, robot)?;
    let expect = [coaxial.as_str(), "joints 1 and 2 turn about the same line"];
    b.refused(&["simulate", "--robot", &coaxial, "--out", &b.path("never.csv")], &expect)?;
    b.refused(&["fit", "--robot", &coaxial, "--data", &data, "--method", "poe", "--out", &b.path("n.ron")], &expect)?;
    Ok(Outcome::Passed("1e308 at line 10, column 8; coaxial joints 1 and 2 named at the robot file".into()))
}

fn absurd_rows(b: &Bench) -> Result<Outcome> {
    for rows in ["18446744073709551615", "1000000000"] {
        let out = b.path("many.csv");
        let expect = format!("--rows: {rows} rows asked for: at most 1000000 are simulated");
        b.refused(&["simulate", "--robot", &b.robot, "--out", &out, "--rows", rows], &[&expect])?;
        ensure!(!Path::new(&out).exists(), "a file was written");
    }
    Ok(Outcome::Passed("refused at once, no panic, nothing written".into()))
}

fn export_like(b: &Bench) -> Result<Outcome> {
    let (data, model, like, out) = (b.path("e.csv"), b.path("e.ron"), b.path("arm.urdf"), b.path("out.urdf"));
    b.simulate(&data, 60, &[])?;
    ensure!(b.fit(&data, &model, &[])?.status.success(), "fit failed");
    let urdf = crate::workspace_root().join("fixtures/robots/irb4400.urdf");
    let changed = std::fs::read_to_string(urdf)?
        .replace("<joint name=\"joint_3\" type=\"revolute\">", "<joint name=\"joint_3\" type=\"prismatic\">");
    std::fs::write(&like, changed)?;
    let expect = "joint 'joint_3' (movable joint 3) is prismatic in the URDF but revolute in the model";
    b.refused(&["export", "--model", &model, "--urdf", &out, "--like", &like], &[expect])?;
    ensure!(!Path::new(&out).exists(), "a URDF was written");
    Ok(Outcome::Passed("refused at joint_3's element".into()))
}

fn constant_time(b: &Bench) -> Result<Outcome> {
    let (data, constant) = (b.path("t.csv"), b.path("constant.csv"));
    b.simulate(&data, 80, &[])?;
    rewrite(&data, &constant, |h, _, c| c[col(h, "t_s")] = "600".into())?;
    let args = ["fit", "--robot", &b.robot, "--data", &constant, "--method", "poe", "--effects", "time_drift", "--out"];
    let mut args = args.to_vec();
    let model = b.path("t.ron");
    args.push(&model);
    b.refused(&args, &["time_drift needs the column 't_s' to vary", "unobservable"])?;
    Ok(Outcome::Passed("refused as unobservable (t_s = 600 on all 80 rows)".into()))
}

fn memory(b: &Bench) -> Result<Outcome> {
    let (simulate, fit, size_mb) = crate::calib_runs::simulate_and_fit(&b.calib, &b.dir, 242_000)?;
    ensure!(fit.peak_mb <= 400.0, "calib fit peaked at {:.0} MB on {size_mb:.1} MB", fit.peak_mb);
    Ok(Outcome::Passed(format!(
        "{size_mb:.1} MB: fit peak {:.0} MB ({:.1} s), simulate peak {:.0} MB",
        fit.peak_mb, fit.seconds, simulate.peak_mb
    )))
}
