//! One `calib` command measured for `cargo xtask bench-fit`: wall seconds, CPU seconds of the
//! process and every thread it ran, peak resident memory, and what it printed.

use anyhow::{Context, bail};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// What one command took.
#[derive(Debug, Clone, PartialEq)]
pub struct Cost {
    /// Wall clock from spawn to exit, s.
    pub wall_s: f64,
    /// User and system CPU of the child, every thread, s; `None` where `/proc` does not tell.
    pub cpu_s: Option<f64>,
    /// The child's resident high-water mark (`VmHWM`), MiB; `None` where `/proc` does not tell.
    pub peak_mib: Option<f64>,
}

/// How often the child's high-water mark is read: `VmHWM` only grows, so a poll misses at most
/// the growth of the last interval before the child exits.
const POLL: Duration = Duration::from_millis(10);

/// The clock ticks per second `/proc`'s CPU times count in (`getconf CLK_TCK`; 100 on every
/// Linux this runs on when `getconf` is missing).
fn clock_ticks() -> f64 {
    Command::new("getconf")
        .arg("CLK_TCK")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .and_then(|s| s.trim().parse::<f64>().ok())
        .filter(|t| *t > 0.0)
        .unwrap_or(100.0)
}

/// The CPU ticks of this process's children that it has waited for (`cutime + cstime`, fields 16
/// and 17 of `/proc/self/stat`): a child's whole CPU time is added to them when it is reaped.
fn children_ticks() -> Option<f64> {
    children_ticks_of(&std::fs::read_to_string("/proc/self/stat").ok()?)
}

/// [`children_ticks`] of a `stat` line. The command name (field 2) may hold spaces and brackets,
/// so the fields are counted after its closing bracket.
fn children_ticks_of(stat: &str) -> Option<f64> {
    let after = &stat[stat.rfind(')')? + 1..];
    // After the name: state is field 3, so cutime (16) and cstime (17) are the 14th and 15th.
    let fields: Vec<&str> = after.split_whitespace().collect();
    let cutime: f64 = fields.get(13)?.parse().ok()?;
    let cstime: f64 = fields.get(14)?.parse().ok()?;
    Some(cutime + cstime)
}

/// `VmHWM` of `/proc/PID/status`, KiB.
fn high_water_kib(status: &str) -> Option<f64> {
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Runs `command` to its end and measures it; its stdout on success, its stderr in the error
/// otherwise. `tick` is called at every poll with the seconds so far (a progress display).
/// Commands must run one at a time: the CPU time is what this process's reaped children gained.
pub fn measure(command: &mut Command, tick: &dyn Fn(f64)) -> anyhow::Result<(Cost, String)> {
    let ticks_per_s = clock_ticks();
    let before = children_ticks();
    let start = Instant::now();
    let mut child = command
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .with_context(|| format!("starting {command:?}"))?;
    let status_path = format!("/proc/{}/status", child.id());
    // Both pipes drained on threads so that a chatty child never blocks on a full pipe.
    let drain = |pipe: Option<Box<dyn std::io::Read + Send>>| {
        std::thread::spawn(move || {
            let mut text = String::new();
            if let Some(mut pipe) = pipe {
                let _ = pipe.read_to_string(&mut text);
            }
            text
        })
    };
    let stdout = drain(child.stdout.take().map(|p| Box::new(p) as Box<dyn std::io::Read + Send>));
    let stderr = drain(child.stderr.take().map(|p| Box::new(p) as Box<dyn std::io::Read + Send>));
    let mut peak_kib: Option<f64> = None;
    let status = loop {
        if let Some(kib) = std::fs::read_to_string(&status_path).ok().as_deref().and_then(high_water_kib) {
            peak_kib = Some(peak_kib.map_or(kib, |p| p.max(kib)));
        }
        if let Some(status) = child.try_wait()? {
            break status;
        }
        tick(start.elapsed().as_secs_f64());
        std::thread::sleep(POLL);
    };
    let wall_s = start.elapsed().as_secs_f64();
    let cpu_s = before.zip(children_ticks()).map(|(b, a)| (a - b) / ticks_per_s);
    let out = stdout.join().unwrap_or_default();
    let err = stderr.join().unwrap_or_default();
    if !status.success() {
        let last: Vec<&str> = err.lines().rev().take(6).collect();
        let last: Vec<&str> = last.into_iter().rev().collect();
        bail!("{command:?} failed ({status}): {}", last.join(" / "));
    }
    Ok((Cost { wall_s, cpu_s, peak_mib: peak_kib.map(|k| k / 1024.0) }, out))
}

/// The held-out errors `calib eval --json` printed: mean position (mm) and, where the model and
/// data have orientations, mean rotation (mrad).
pub fn heldout_of_eval(json: &str, source: &Path) -> anyhow::Result<(f64, Option<f64>)> {
    let v: serde_json::Value =
        serde_json::from_str(json).with_context(|| format!("calib eval --json on {}", source.display()))?;
    let mm = v["mean_position_error_mm"]
        .as_f64()
        .with_context(|| format!("calib eval --json on {}: no mean_position_error_mm", source.display()))?;
    Ok((mm, v["mean_rotation_error_mrad"].as_f64()))
}

/// The phases `calib fit --json` reported (`timings`; empty for a binary from before they were
/// recorded), names as it gives them.
pub fn phases_of_fit(json: &str) -> anyhow::Result<Vec<timings::PhaseTime>> {
    let v: serde_json::Value = serde_json::from_str(json).context("calib fit --json: not JSON")?;
    match v.get("timings") {
        None | Some(serde_json::Value::Null) => Ok(Vec::new()),
        Some(t) => serde_json::from_value(t.clone()).context("calib fit --json: timings"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_childrens_cpu_ticks_are_read_after_a_command_name_with_spaces_and_brackets() {
        // Fields 1-17 of a real line, with the name made awkward; cutime 250, cstime 31.
        let stat = "4242 (a (b) c) S 1 4242 4242 0 -1 4194304 900 12 0 0 75 9 250 31 20 0 1 0";
        assert_eq!(children_ticks_of(stat), Some(281.0));
        assert_eq!(children_ticks_of("4242 (short) S 1"), None);
        assert!(children_ticks().is_some(), "this process's own stat line reads");
    }

    #[test]
    fn a_measured_command_has_its_cpu_time_and_output() {
        // A shell that spins for a while: its CPU time is counted once it is reaped.
        let mut command = Command::new("sh");
        command.args(["-c", "i=0; while [ $i -lt 200000 ]; do i=$((i+1)); done; echo done"]);
        let (cost, out) = measure(&mut command, &|_| {}).unwrap();
        assert_eq!(out.trim(), "done");
        // Only a lower bound: the children's CPU time is the whole test process's, and other
        // tests running beside this one reap their own children inside the same window.
        let cpu = cost.cpu_s.unwrap();
        assert!(cpu > 0.0, "{cost:?}");
        assert!(cost.peak_mib.is_some_and(|p| p > 0.0), "{cost:?}");
        let failed = measure(Command::new("sh").args(["-c", "echo why >&2; exit 3"]), &|_| {}).unwrap_err();
        assert!(failed.to_string().contains("why"), "{failed}");
    }

    #[test]
    fn eval_and_fit_reports_are_read_and_a_report_without_timings_gives_none() {
        let (mm, mrad) = heldout_of_eval(r#"{"mean_position_error_mm": 0.137, "n": 3}"#, Path::new("t.csv")).unwrap();
        assert_eq!((mm, mrad), (0.137, None));
        let both = heldout_of_eval(r#"{"mean_position_error_mm":0.2,"mean_rotation_error_mrad":0.3}"#, Path::new("t"));
        assert_eq!(both.unwrap(), (0.2, Some(0.3)));
        assert!(heldout_of_eval("{}", Path::new("t.csv")).unwrap_err().to_string().contains("t.csv"));
        let fit = r#"{"timings":[{"phase":"fit / GP / search","calls":1,"wall_s":2.5,"cpu_s":4.0}]}"#;
        assert_eq!(phases_of_fit(fit).unwrap()[0].phase, "fit / GP / search");
        assert!(phases_of_fit(r#"{"method":"poe"}"#).unwrap().is_empty());
    }
}
