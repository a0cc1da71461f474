//! `calib plan`: the poses worth measuring, chosen from candidates (crate `cell`).

use crate::args::{ColumnsArg, JsonFlag};
use crate::robot_args::RobotArgs;
use measurements::ReadOptions;
use std::path::PathBuf;

/// Choose the poses that determine the identification best, covering every moving joint's range.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    robot: RobotArgs,
    /// A calibrated model (RON): plan with its geometry and tools (else the robot's nominal
    /// model), and, unless the options set them, with its held-out error as the unmodelled error
    /// (`unmodelled_mm`, `unmodelled_mrad`: mean 3-D error × √(π/8) per axis).
    #[arg(long)]
    model: Option<PathBuf>,
    /// Candidate configurations (the measurement CSV; position columns may be left out; every
    /// column is kept). Without it, candidates are drawn within the robot's joint limits.
    #[arg(long)]
    candidates: Option<PathBuf>,
    /// How many poses to choose.
    #[arg(long)]
    poses: usize,
    /// The chosen rows, unchanged, in the order to measure them (CSV); never one of the inputs.
    #[arg(long)]
    out: PathBuf,
    /// Plan for full-pose measurements (a model fitted on full poses implies it).
    #[arg(long)]
    full_pose: bool,
    /// Candidates drawn without --candidates.
    #[arg(long, default_value_t = 5000)]
    generate: usize,
    /// Seed of the drawn candidates.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// The criterion: i (the mean predicted variance over the candidates; the default) or d (log det).
    #[arg(long, value_parser = parse_criterion)]
    criterion: Option<planning::Criterion>,
    /// Tracker position noise per axis, mm: scales the predicted errors.
    #[arg(long)]
    noise_mm: Option<f64>,
    /// Every planning setting (RON, `planning::PlanOptions`: criterion, noise, bins, exchanges…);
    /// --criterion and --noise-mm override it.
    #[arg(long)]
    options: Option<PathBuf>,
    #[command(flatten)]
    columns: ColumnsArg,
    #[command(flatten)]
    json: JsonFlag,
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    measurements::InputFiles::new()
        .with("--robot", &args.robot.robot)
        .with_optional("--model", args.model.as_deref())
        .with_optional("--candidates", args.candidates.as_deref())
        .with_optional("--options", args.options.as_deref())
        .check_output("--out", &args.out)?;
    let robot = args.robot.read()?;
    let model = args.model.as_deref().map(model::read_model).transpose()?;
    let full_pose = args.full_pose || model.as_ref().is_some_and(|m| m.full_pose);
    let (options, unmodelled) = plan_options(args, model.as_ref())?;
    let started = std::time::Instant::now();
    let mut notes = Vec::new();
    let (set, file) = candidates(args, &robot, model.as_ref(), &mut notes)?;
    for tool in &set.unknown_tools {
        notes.push(format!("warning: tool '{tool}' is not in the model: planned with its first tool"));
    }
    let mut plan = planning::plan(&set.model, &set.candidates, args.poses, full_pose, &options)?;
    plan.report.set_unmodelled_from(unmodelled);
    let seconds = started.elapsed().as_secs_f64();
    let mut out = measurements::OutputFile::create(&args.out)?;
    match &file {
        Some((cells, delimiter)) => planning::write_chosen_rows(&mut out, cells, *delimiter, &plan.order)?,
        None => {
            let kinds: Vec<_> = set.model.joints().iter().map(|j| j.kind).collect();
            planning::write_generated_rows(&mut out, &kinds, &set.candidates, &plan.order)?;
        }
    }
    out.finish()?;
    if args.json.json {
        println!("{}", serde_json::to_string(&plan.report)?);
        for note in &notes {
            eprintln!("{note}");
        }
    } else {
        for note in &notes {
            println!("{note}");
        }
        for line in plan.report.lines() {
            println!("{line}");
        }
        println!("planned in {seconds:.2} s; wrote {} rows to {}", plan.order.len(), args.out.display());
    }
    Ok(())
}

/// The planning options: --options' file (or the defaults), the unmodelled error from the model
/// unless the file sets it, --criterion and --noise-mm over both; validated.
fn plan_options(
    args: &Args,
    model: Option<&model::CalibratedModel>,
) -> Result<(planning::PlanOptions, planning::UnmodelledSetting), Box<dyn std::error::Error>> {
    let (mut options, given) = match &args.options {
        Some(path) => {
            let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
            let file = path.display().to_string();
            (planning::PlanOptions::parse(&text, &file)?, planning::UnmodelledGiven::of_text(&text, &file)?)
        }
        None => (planning::PlanOptions::default(), planning::UnmodelledGiven::default()),
    };
    // Unless the options set it, the unmodelled error is the model's own held-out error.
    let unmodelled = options.set_unmodelled_from(model, given);
    options.criterion = args.criterion.unwrap_or(options.criterion);
    options.position_noise_mm = args.noise_mm.unwrap_or(options.position_noise_mm);
    options.validate()?;
    Ok((options, unmodelled))
}

/// The cells of --candidates and its delimiter, to write the chosen rows back unchanged.
type FileCells = (measurements::Cells, u8);

/// The candidates, from --candidates (with its cells and delimiter, to write the chosen rows back
/// unchanged) or drawn within the joint limits; what was read or drawn goes to `notes`.
fn candidates(
    args: &Args,
    robot: &robot::RobotDescription,
    model: Option<&model::CalibratedModel>,
    notes: &mut Vec<String>,
) -> Result<(planning::CandidateSet, Option<FileCells>), Box<dyn std::error::Error>> {
    Ok(match &args.candidates {
        Some(path) => {
            let kinds = robot.nominal_model()?.joints().iter().map(|j| j.kind).collect();
            let read = ReadOptions::for_joints(kinds).with_columns(args.columns.map());
            let (data, cells) = measurements::read_configurations_with_cells(path, &read)?;
            notes.push(data.read_summary());
            (planning::file_candidates(&data, robot, model)?, Some((cells, data.format.dialect.delimiter.byte())))
        }
        None => {
            notes.push(format!("drew {} candidates within the joint limits (seed {})", args.generate, args.seed));
            (planning::generated_candidates(robot, model, args.generate, args.seed)?, None)
        }
    })
}

fn parse_criterion(s: &str) -> Result<planning::Criterion, String> {
    match s {
        "d" | "D" => Ok(planning::Criterion::D),
        "i" | "I" => Ok(planning::Criterion::I),
        other => Err(format!("unknown criterion '{other}': expected d or i")),
    }
}
