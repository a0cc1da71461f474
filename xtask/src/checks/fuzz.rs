//! `cargo xtask fuzz`: every reader of a user's file fed generated inputs (random bytes, and valid
//! files broken the ways files break, `fuzz_inputs.rs`), checked for: no panic (caught and
//! counted), no crash (abort, stack overflow), no hang (a time limit per input), memory bounded
//! (the worker runs under an address-space cap, `ulimit -v`), and every refusal naming the file,
//! a line inside it and a column. Cases run in a child process (`fuzz_worker.rs`) that the parent
//! watches and restarts after a crash or a hang, so one bad input costs one case, not the run.
//! Deterministic for a seed: the same inputs in the same order; the counts are the same on every
//! machine that has the time and memory the limits allow.

use super::fuzz_inputs::{generate, regressions};
use super::fuzz_seeds::{Reader, seeds};
use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::{Duration, Instant};

/// Feed every reader generated inputs; fail on any panic, crash, hang or unlocated refusal.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Which reader: csv, robot, model, effects (`calib simulate`), effects-list (`calib fit
    /// --effects`), options (`calib fit --options`), or all of them.
    #[arg(long, default_value = "all")]
    reader: ReaderChoice,
    /// Inputs per reader.
    #[arg(long, default_value_t = 1000)]
    cases: u64,
    /// Seed of the inputs.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Time limit per input, ms: a reader taking longer hangs. The slowest valid inputs take
    /// milliseconds in release builds; the limit leaves room for debug builds and a loaded machine.
    #[arg(long, default_value_t = 10_000)]
    timeout_ms: u64,
    /// Address space of the worker, MiB (`ulimit -v`): inputs are at most 4 MiB, so a reader that
    /// needs more than this much for one is unbounded. The worker is given this plus what faer's
    /// matrix products reserve ([`gemm_reserve_mib`]), which depends on the processor, not on
    /// the input.
    #[arg(long, default_value_t = 2048)]
    memory_mib: u64,
    /// Write case number DUMP of `--reader` (not `all`) to `--out` instead of running, to
    /// reproduce a finding.
    #[arg(long, requires = "out")]
    dump: Option<u64>,
    /// Where `--dump` writes the case.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Readers whose accepted-but-unusable inputs (a NaN pose from a file the reader let through)
    /// are reported without failing the run: a known open defect, named where this is used.
    #[arg(long, value_enum, value_delimiter = ',')]
    unusable_ok: Vec<Reader>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum ReaderChoice {
    Csv,
    Robot,
    Model,
    Effects,
    EffectsList,
    Options,
    All,
}

impl ReaderChoice {
    fn readers(self) -> Vec<Reader> {
        match self {
            ReaderChoice::Csv => vec![Reader::Csv],
            ReaderChoice::Robot => vec![Reader::Robot],
            ReaderChoice::Model => vec![Reader::Model],
            ReaderChoice::Effects => vec![Reader::Effects],
            ReaderChoice::EffectsList => vec![Reader::EffectsList],
            ReaderChoice::Options => vec![Reader::Options],
            ReaderChoice::All => Reader::ALL.to_vec(),
        }
    }
}

/// What happened to one reader's cases.
#[derive(Debug, Default)]
struct Tally {
    inputs: u64,
    accepted: u64,
    refused: u64,
    unlocated: u64,
    late: u64,
    panics: u64,
    crashes: u64,
    hangs: u64,
    slowest: (Duration, u64),
    peak_kib: u64,
    /// Up to three cases of each failure: (kind, case, message).
    examples: Vec<(&'static str, u64, String)>,
}

impl Tally {
    /// The cases that fail the run; accepted-but-unusable ones unless `unusable_ok`.
    fn failures(&self, unusable_ok: bool) -> u64 {
        let late = if unusable_ok { 0 } else { self.late };
        self.unlocated + late + self.panics + self.crashes + self.hangs
    }

    fn record(&mut self, kind: &'static str, case: u64, message: &str) {
        self.inputs += 1;
        let counter = match kind {
            "accepted" => &mut self.accepted,
            "refused" => &mut self.refused,
            "unlocated" => &mut self.unlocated,
            "late" => &mut self.late,
            "panic" => &mut self.panics,
            "crash" => &mut self.crashes,
            _ => &mut self.hangs,
        };
        *counter += 1;
        if !matches!(kind, "accepted" | "refused") && self.examples.iter().filter(|e| e.0 == kind).count() < 3 {
            let short: String = message.chars().take(300).collect();
            self.examples.push((kind, case, short));
        }
    }
}

/// The address space faer's matrix products reserve, MiB: `private-gemm-x86` (faer 0.24's
/// product kernel, `src/lib.rs`) keeps a thread-local buffer of twice the last-level cache on
/// every thread that multiplies (960 MiB on a virtual machine that reports a 480 MiB L3), once,
/// whatever the input. Twice that per thread the worker may run on (its own and rayon's),
/// from `/sys/devices/system/cpu/cpu0/cache/index3/size` (0 where it cannot be read).
fn gemm_reserve_mib() -> u64 {
    let Ok(text) = std::fs::read_to_string("/sys/devices/system/cpu/cpu0/cache/index3/size") else { return 0 };
    let text = text.trim();
    let (digits, unit) = text.split_at(text.find(|c: char| !c.is_ascii_digit()).unwrap_or(text.len()));
    let Ok(value) = digits.parse::<u64>() else { return 0 };
    let kib = match unit {
        "K" => value,
        "M" => value * 1024,
        "G" => value * 1024 * 1024,
        _ => value / 1024,
    };
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get() as u64) + 1;
    2 * kib.div_ceil(1024) * threads
}

/// A line from the worker, or the end of its output.
enum Event {
    Line(String),
    End,
}

struct Worker {
    child: Child,
    events: Receiver<Event>,
    stderr: PathBuf,
}

fn spawn(reader: Reader, args: &Args, from: u64, scratch: &Path) -> Result<Worker> {
    let exe = std::env::current_exe().context("finding the xtask binary")?;
    let stderr = scratch.join("worker-stderr.txt");
    let log = std::fs::File::create(&stderr).with_context(|| format!("creating {}", stderr.display()))?;
    // The cap is set in a shell that then becomes the worker: the standard library has no
    // setrlimit, and the workspace forbids the unsafe code a pre-exec hook would need.
    let cap_kib = (args.memory_mib + gemm_reserve_mib()) * 1024;
    let script = format!("ulimit -v {cap_kib} && exec \"$0\" \"$@\"");
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg(&exe)
        .arg("fuzz-worker")
        .args(["--reader", reader.name(), "--seed", &args.seed.to_string()])
        .args(["--from", &from.to_string(), "--to", &args.cases.to_string()])
        .arg("--scratch")
        .arg(scratch)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(log)
        .spawn()
        .context("starting a fuzz worker")?;
    let stdout = child.stdout.take().context("the worker's stdout")?;
    let (sender, events) = channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines() {
            let Ok(line) = line else { break };
            if sender.send(Event::Line(line)).is_err() {
                break;
            }
        }
        let _ = sender.send(Event::End);
    });
    Ok(Worker { child, events, stderr })
}

/// The last line the worker wrote on stderr (an abort's reason), or its exit status.
fn death(worker: &mut Worker) -> String {
    let status = worker.child.wait().map(|s| s.to_string()).unwrap_or_else(|e| e.to_string());
    let stderr = std::fs::read_to_string(&worker.stderr).unwrap_or_default();
    let last = stderr.lines().rev().find(|l| !l.trim().is_empty()).unwrap_or("");
    format!("worker ended ({status}): {last}")
}

/// Runs every case of one reader, restarting the worker after a crash or a hang.
fn fuzz_reader(reader: Reader, args: &Args, scratch: &Path) -> Result<Tally> {
    let mut tally = Tally::default();
    let bar = ProgressBar::new(args.cases).with_prefix(reader.name());
    bar.set_style(
        ProgressStyle::with_template("{prefix:>8} [{bar:40}] {pos}/{len} {per_sec} {msg}")
            .context("progress style")?
            .progress_chars("=> "),
    );
    let mut next = 0;
    while next < args.cases {
        next = run_worker(reader, args, scratch, next, &mut tally, &bar)?;
    }
    bar.finish_and_clear();
    Ok(tally)
}

/// What the worker listened to is doing.
struct Listening {
    /// The case it started and when, until it says the case is done.
    current: Option<(u64, Instant)>,
    /// Whether it has made its seeds.
    ready: bool,
    /// The case after the last one done.
    next: u64,
}

/// One worker from case `next` until it ends, crashes or hangs; returns the case to go on from.
fn run_worker(
    reader: Reader,
    args: &Args,
    scratch: &Path,
    next: u64,
    tally: &mut Tally,
    bar: &ProgressBar,
) -> Result<u64> {
    let limit = Duration::from_millis(args.timeout_ms);
    // Making the seeds (simulating, fitting models) takes seconds, not a case's time.
    let setup_limit = Duration::from_secs(600).max(limit);
    let mut worker = spawn(reader, args, next, scratch)?;
    let mut state = Listening { current: None, ready: false, next };
    loop {
        let wait = match state.current {
            _ if !state.ready => setup_limit,
            Some((_, started)) => limit.saturating_sub(started.elapsed()).max(Duration::from_millis(1)),
            None => limit,
        };
        match worker.events.recv_timeout(wait) {
            Ok(Event::Line(line)) => heard(&line, &mut state, tally, bar)?,
            Ok(Event::End) | Err(RecvTimeoutError::Disconnected) => {
                if let Some((case, _)) = state.current {
                    tally.record("crash", case, &death(&mut worker));
                    state.next = case + 1;
                    bar.inc(1);
                } else if state.next < args.cases {
                    bail!("{}", death(&mut worker));
                } else {
                    let _ = worker.child.wait();
                }
                return Ok(state.next);
            }
            Err(RecvTimeoutError::Timeout) => {
                let Some((case, started)) = state.current else {
                    let _ = worker.child.kill();
                    bail!("the worker stalled outside a case (setup or input generation)");
                };
                if started.elapsed() < limit {
                    continue;
                }
                let _ = worker.child.kill();
                let _ = worker.child.wait();
                tally.record("hang", case, &format!("no answer within {limit:?}"));
                tally.slowest = tally.slowest.max((limit, case));
                bar.inc(1);
                return Ok(case + 1);
            }
        }
    }
}

/// One line of the worker's: ready, a case started or done, or its peak memory.
fn heard(line: &str, state: &mut Listening, tally: &mut Tally, bar: &ProgressBar) -> Result<()> {
    let mut words = line.splitn(5, ' ');
    match (words.next(), words.next(), words.next(), words.next()) {
        (Some("ready"), ..) => state.ready = true,
        (Some("start"), Some(case), ..) => state.current = Some((case.parse()?, Instant::now())),
        (Some("done"), Some(case), Some(kind), Some(micros)) => {
            let case: u64 = case.parse()?;
            let took = Duration::from_micros(micros.parse()?);
            let kind = ["accepted", "refused", "unlocated", "late", "panic"]
                .into_iter()
                .find(|k| *k == kind)
                .with_context(|| format!("worker said {line}"))?;
            tally.record(kind, case, words.next().unwrap_or(""));
            if took > tally.slowest.0 {
                tally.slowest = (took, case);
            }
            state.current = None;
            state.next = case + 1;
            bar.inc(1);
        }
        (Some("peak"), Some(kib), ..) => tally.peak_kib = tally.peak_kib.max(kib.parse()?),
        _ => bail!("the worker said: {line}"),
    }
    Ok(())
}

fn dump(reader: Reader, args: &Args, case: u64, out: &Path) -> Result<()> {
    let scratch = tempfolder()?;
    let seeds = seeds(reader, &scratch)?;
    let input = generate(&seeds, &regressions(&seeds, reader), reader, args.seed, case);
    std::fs::write(out, &input.bytes).with_context(|| format!("writing {}", out.display()))?;
    let seed = &seeds[input.seed];
    let original = out.with_extension("seed");
    std::fs::write(&original, &seed.bytes).with_context(|| format!("writing {}", original.display()))?;
    println!(
        "case {case} of {} (seed {}): from '{}' (written to {}), {} bytes",
        reader.name(),
        args.seed,
        seed.name,
        original.display(),
        input.bytes.len()
    );
    if let Some(columns) = &input.columns {
        println!("--columns '{columns}'");
    }
    let _ = std::fs::remove_dir_all(&scratch);
    Ok(())
}

fn tempfolder() -> Result<PathBuf> {
    let folder = std::env::temp_dir().join(format!("calib-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&folder).with_context(|| format!("creating {}", folder.display()))?;
    Ok(folder)
}

/// The table of every reader's tally.
fn print_tallies(tallies: &[(Reader, Tally)]) {
    println!(
        "\n| reader | inputs | accepted | refused, located | refused, unlocated | accepted, then failed | panics | crashes | hangs | slowest (ms, case) | peak RSS (MiB) |"
    );
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for (reader, t) in tallies {
        println!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.1} (#{}) | {} |",
            reader.name(),
            t.inputs,
            t.accepted,
            t.refused,
            t.unlocated,
            t.late,
            t.panics,
            t.crashes,
            t.hangs,
            t.slowest.0.as_secs_f64() * 1e3,
            t.slowest.1,
            t.peak_kib / 1024
        );
    }
}

pub fn run(args: &Args) -> Result<()> {
    let readers = args.reader.readers();
    if let (Some(case), Some(out)) = (args.dump, &args.out) {
        let [reader] = readers.as_slice() else { bail!("--dump needs one --reader, not all") };
        return dump(*reader, args, case, out);
    }
    let scratch = tempfolder()?;
    println!(
        "fuzzing {} reader(s), {} inputs each, seed {}, {} ms and {} MiB per input (+ {} MiB that faer's \
         products reserve on this processor)",
        readers.len(),
        args.cases,
        args.seed,
        args.timeout_ms,
        args.memory_mib,
        gemm_reserve_mib()
    );
    let mut tallies = Vec::new();
    for reader in readers {
        let started = Instant::now();
        let tally = fuzz_reader(reader, args, &scratch)?;
        println!("{}: {} inputs in {:.1} s", reader.name(), tally.inputs, started.elapsed().as_secs_f64());
        tallies.push((reader, tally));
    }
    let _ = std::fs::remove_dir_all(&scratch);
    print_tallies(&tallies);
    let mut failures = 0;
    for (reader, t) in &tallies {
        failures += t.failures(args.unusable_ok.contains(reader));
        for (kind, case, message) in &t.examples {
            println!(
                "\n{kind}: {} case {case} (cargo xtask fuzz --reader {} --seed {} --dump {case} --out case.bin)\n  {message}",
                reader.name(),
                reader.name(),
                args.seed
            );
        }
    }
    if failures > 0 {
        bail!("{failures} inputs were not handled: see the cases above");
    }
    Ok(())
}
