//! `calib fit`: fit a calibration method to measurements and write the model.

use crate::args::{JsonFlag, RobotDataArgs};
use calib::flow::FitOverrides;
use effects::{EffectKind, EffectSelection, EffectSpec};
use model::{ErrorSummary, Method};
use pipeline::{FitOptions, FitReport};
use std::fmt::Write;
use std::path::PathBuf;

/// Fit a calibrated model to measurements.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    data: RobotDataArgs,
    /// Calibration method: base-tool, poe, poe-gp or poe-gp-load.
    #[arg(long)]
    method: Method,
    /// Measured signals the GP takes as inputs beside the joints (and the payload for
    /// poe-gp-load): numeric columns of --data by name (after --columns), e.g.
    /// tilt_x_mrad,motor2_temp_c. The model keeps each name, unit (from the name's suffix) and the
    /// span it was fitted on; eval, predict, compensate and report then require those columns.
    #[arg(long, value_name = "NAME[,NAME…]")]
    inputs: Option<measurements::InputNames>,
    /// Where to write the calibrated model (RON).
    #[arg(long)]
    out: PathBuf,
    // The help lists the items from the one list of kinds (`effects_help`).
    #[arg(long, value_name = "LIST|auto", help = effects_help())]
    effects: Option<EffectSelection>,
    /// The same as --effects joint_compliance: joint compliance through measured torques
    /// (tauN_nm) where the data has them, gravity-torque regressors otherwise (no masses needed).
    #[arg(long, conflicts_with = "effects")]
    joint_compliance: bool,
    /// Fit options (RON): any field of pipeline's FitOptions, e.g. (identification: (max_iterations:
    /// 100), effects: (prior_sigma: 1e-3)); --effects given here too is overridden by the flag.
    #[arg(long, value_name = "FIT.ron")]
    options: Option<PathBuf>,
    /// The GP of the -gp methods: exact, sparse (variational, inducing inputs: for large data
    /// sets) or auto (sparse above 4000 training rows) [default: auto, or what --options says].
    #[arg(long)]
    gp: Option<model::GpChoice>,
    #[command(flatten)]
    json: JsonFlag,
    /// Fit data that the plausibility checks refuse (positions whose spread is not the robot's,
    /// a mirror-image frame, joint values beyond the limits), with a warning instead.
    #[arg(long)]
    force: bool,
}

/// The help of `--effects`: its items, each kind of the one list with its arguments.
fn effects_help() -> String {
    format!(
        "Non-geometric effects identified with the geometry, applied before any GP (beyond the paper): a \
         comma-separated list of {}; or auto, what `calib diagnose` selects on the data",
        effects::effect_items()
    )
}

pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    // Refused before any work: the model must not replace a file this fit reads.
    measurements::InputFiles::new()
        .with("--robot", &args.data.robot.robot)
        .with("--data", &args.data.data.data)
        .with_optional("--options", args.options.as_deref())
        .check_output("--out", &args.out)?;
    let progress = crate::progress::Progress::on_terminal("fit");
    let (fitted, timings) = timings::record_with(progress.feed(), || fit_and_write(args));
    progress.finish();
    let (robot, data, model, mut report) = fitted?;
    report.timings = timings.phases;
    // With --json the report is the one object on stdout and the summary goes to stderr.
    let mut summary = String::new();
    summary.push_str(&data.read_summary());
    summary.push('\n');
    summarise(&mut summary, args, &robot.name, &data, &model, &report);
    if args.json.json {
        eprint!("{summary}");
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print!("{summary}");
    }
    Ok(())
}

/// The columns read as inputs: those of `--inputs`.
fn input_names(args: &Args) -> Vec<String> {
    args.inputs.as_ref().map(|names| names.names().to_vec()).unwrap_or_default()
}

type Fitted = (robot::RobotDescription, measurements::MeasurementSet, model::CalibratedModel, FitReport);

/// The command's work, in the phases its report times: reading, the fit, writing the model.
fn fit_and_write(args: &Args) -> Result<Fitted, Box<dyn std::error::Error>> {
    let (robot, data) =
        timings::phase("read", || -> Result<_, Box<dyn std::error::Error>> { Ok(args.data.read(input_names(args))?) })?;
    let mut options = match &args.options {
        Some(path) => FitOptions::read(path)?,
        None => FitOptions::default(),
    };
    let joint_compliance = || EffectSelection::List(vec![EffectSpec::new(EffectKind::JointCompliance)]);
    let overrides = FitOverrides {
        effects: args.effects.clone().or_else(|| args.joint_compliance.then(joint_compliance)),
        force: args.force,
        gp: args.gp,
        inputs: args.inputs.as_ref().map(|names| names.names().to_vec()),
    };
    overrides.apply(&mut options, args.method).map_err(|e| format!("--inputs: {e} (poe-gp, poe-gp-load)"))?;
    let (model, report, ()) =
        calib::flow::fit_and_write(&robot, &data, args.method, &options, |model| model::write_model(&args.out, model))?;
    Ok((robot, data, model, report))
}

fn summarise(
    out: &mut String,
    args: &Args,
    robot: &str,
    data: &measurements::MeasurementSet,
    model: &model::CalibratedModel,
    report: &FitReport,
) {
    let kind = if data.full_pose { "full pose" } else { "position only" };
    let tools = data.tools.iter().filter(|t| !t.is_empty()).count().max(1);
    let plural = if tools == 1 { "" } else { "s" };
    let rows = data.rows.len();
    let _ = writeln!(
        out,
        "{} on {} ({rows} rows, {kind}, {tools} tool{plural}) for {robot}",
        args.method,
        args.data.display()
    );
    errors(out, "training error before (nominal, registered)", &report.before);
    errors(out, "training error after", &report.after);
    // Beside the training error, which a GP that interpolates its poses drives to nothing: the
    // same rows, each corrected by the GP fitted without it (closed form, issue 25).
    if let Some(gp) = &report.residual_gp {
        // Where rows repeat a configuration, a row left out alone keeps its twin, whose value the
        // GP returns: the grouped error is the one to read, and is what the model keeps (issue 26).
        match (&gp.leave_one_out, &gp.leave_group_out) {
            (Some(loo), Some(grouped)) => {
                errors(out, "GP leave-one-out error (each row predicted without it, its repeats kept)", loo);
                let label = format!(
                    "GP leave-group-out error ({} rows repeat {} configurations, each left out whole)",
                    gp.repeated_rows, gp.repeated_configurations
                );
                errors(out, &label, grouped);
            }
            (Some(loo), None) => errors(out, "GP leave-one-out error (each row predicted without it)", loo),
            _ => {}
        }
    }
    let id = &report.identification;
    let _ = writeln!(
        out,
        "  identifiable: {} of {} free parameters, condition number {:.3e}",
        id.rank, id.free_parameters, id.condition_number
    );
    if let Some(stated) = &id.stated_noise {
        let mm = stated.median_position_m.map_or("–".to_owned(), |m| format!("{:.4} mm", m * 1e3));
        let mrad = stated.median_rotation_rad.map_or(String::new(), |m| format!(", {:.4} mrad", m * 1e3));
        let excess_mrad = stated.excess_rotation_rad.map_or(String::new(), |t| format!(", {:.4} mrad", t * 1e3));
        let _ = writeln!(
            out,
            "  rows weighted by the tracker's stated uncertainty ({} of {rows} rows state one; median {mm}{mrad}; \
             residual scatter beyond it {:.4} mm{excess_mrad} per axis)",
            stated.stated,
            stated.excess_position_m * 1e3
        );
    }
    if let Some(prior) = &report.nominal_prior {
        let _ = writeln!(out, "  {prior}");
    }
    if let Some(auto) = &report.auto {
        let chosen: Vec<String> = auto.chosen.iter().map(ToString::to_string).collect();
        let _ = writeln!(
            out,
            "  effects auto: the diagnosis of the training data (verdict {}; held-out {:.4} mm with the geometry alone) selected {}",
            auto.verdict.effect.name(),
            auto.heldout_before_mm,
            if chosen.is_empty() { "nothing".to_owned() } else { chosen.join(", ") }
        );
        if let Some([before, after]) = auto.off_poses_mm {
            let _ = writeln!(
                out,
                "    predicted held out: {:.4} -> {:.4} mm on poses like these (random folds); {before:.4} -> {after:.4} mm off them (arcs of each moving joint's angles held out)",
                auto.heldout_before_mm, auto.heldout_after_mm
            );
        }
        if let Some(with_gp) = &auto.predicted_with_gp {
            let off = with_gp.off_poses_mm.map_or(String::new(), |off| format!("; {off:.4} mm off them"));
            let _ = writeln!(
                out,
                "    predicted held out with the GP on top: {:.4} mm on poses like these{off} (the same folds, each fold's GP conditioned on the residuals its geometry and effects leave on its training rows, the final GP's hyperparameters held fixed: a standard approximation, searching them again in every fold would be too slow)",
                with_gp.on_poses_mm
            );
            if let Some(choice) = &with_gp.fallback_gp {
                let mm = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.4} mm"));
                let _ = writeln!(
                    out,
                    "    where the effects fade: {} (arcs off the poses: {} with a GP of what the geometry alone leaves, {} with the GP of what the effects leave)",
                    if choice.kept {
                        "the GP falls back with the geometry to one fitted on what the geometry alone leaves"
                    } else {
                        "the GP of what the effects leave stays (it predicted the arcs better)"
                    },
                    mm(choice.off_poses_with_mm),
                    mm(choice.off_poses_without_mm)
                );
            }
        }
        for s in &auto.selected {
            let joints: Vec<String> = s.joints.iter().map(ToString::to_string).collect();
            let harmonic = s.harmonic.map_or(String::new(), |h| format!(", harmonics 1 to {h}"));
            let _ = writeln!(
                out,
                "    {} on joint(s) {}{harmonic}: cross-validated {:.4} mm with it and those above",
                s.effect.name(),
                joints.join(","),
                s.heldout_after_mm
            );
        }
    }
    for choice in &report.beyond_span {
        let _ = writeln!(out, "  {choice}");
    }
    for choice in &report.beyond_payload {
        let _ = writeln!(out, "  {choice}");
    }
    for effect in &report.effects {
        let held: Vec<&str> = effect.parameters.iter().filter(|p| p.held_at_prior).map(|p| p.name.as_str()).collect();
        let _ = writeln!(
            out,
            "  effect {}: {} parameters identified with the geometry",
            effect.label,
            effect.parameters.len()
        );
        if !held.is_empty() {
            let _ = writeln!(out, "    held at the prior, the data barely sees them: {}", held.join(", "));
        }
    }
    if let (Some(residual_gp), Some(gp)) = (&model.residual_gp, &report.residual_gp) {
        let kernels = match &gp.gp {
            model::GpFitReport::Exact(r) => r.components.len(),
            model::GpFitReport::Sparse(r) => r.components.len(),
        };
        let converged = kernels - gp.gp.unconverged().len();
        // Where the additive term was weighed (BIC), how often it paid for itself.
        let additive = match &gp.gp {
            model::GpFitReport::Exact(r) => {
                let choices: Vec<bool> =
                    r.components.iter().filter_map(|c| c.additive_choice.as_ref().map(|a| a.kept)).collect();
                let kept = choices.iter().filter(|k| **k).count();
                if choices.is_empty() {
                    String::new()
                } else {
                    format!("; additive term kept (BIC) for {kept} of {}", choices.len())
                }
            }
            model::GpFitReport::Sparse(_) => String::new(),
        };
        // Where the paper's isotropic kernel was weighed (leave-one-out), how often it won.
        let isotropic = match &gp.gp {
            model::GpFitReport::Exact(r) => {
                let choices: Vec<bool> =
                    r.components.iter().filter_map(|c| c.isotropic_choice.as_ref().map(|a| a.kept_isotropic)).collect();
                let kept = choices.iter().filter(|k| **k).count();
                if choices.is_empty() {
                    String::new()
                } else {
                    format!("; the paper's isotropic Eq. 5 kernel kept (leave-one-out) for {kept} of {}", choices.len())
                }
            }
            model::GpFitReport::Sparse(_) => String::new(),
        };
        let _ = writeln!(
            out,
            "  GP: {}, {kernels} kernel(s), hyperparameter search met its tolerance for {converged} of {kernels}{additive}{isotropic}",
            residual_gp.gp.choice()
        );
        if !gp.inputs.is_empty() {
            let spans: Vec<String> = gp.inputs.iter().map(ToString::to_string).collect();
            let _ = writeln!(out, "  GP inputs beside the joints, with the spans fitted on: {}", spans.join("; "));
        }
    }
    for direction in &id.unidentifiable {
        let _ = writeln!(out, "    unidentifiable: {direction}");
    }
    for folded in &report.folded {
        let _ = writeln!(out, "    unidentifiable (mimic joints folded): {folded}");
    }
    let _ = writeln!(
        out,
        "  iterations: {} ({}; cost {:.6e}, gradient cosine {:.1e})",
        id.iteration_count(),
        id.termination,
        id.final_cost,
        id.gradient_cosine
    );
    if let Some(fallback) = &id.damping_fallback {
        let _ = writeln!(out, "  damping: {fallback}");
    }
    if let Some(check) = &report.plausibility {
        let ratio = check.scale_ratio.map_or("none".to_owned(), |r| format!("{r:.4}"));
        let _ = writeln!(
            out,
            "  plausibility: measured spread {:.1} mm, the nominal robot's {:.1} mm (ratio {ratio}); rotated onto the measurements {:.2} mm RMS, mirrored {:.1} mm",
            check.measured_spread_mm, check.robot_spread_mm, check.rotation_rms_mm, check.reflection_rms_mm
        );
    }
    for warning in &report.warnings {
        let _ = writeln!(out, "  warning: {warning}");
    }
    // Where a fit of more than a second spent it (every phase is in --json's `timings`).
    let slow: Vec<String> = report
        .timings
        .iter()
        .filter(|p| p.wall_s >= 1.0)
        .map(|p| {
            let calls = if p.calls > 1 { format!(" ({} calls)", p.calls) } else { String::new() };
            format!("    {}: {:.1} s, {:.1} s CPU{calls}", p.phase, p.wall_s, p.cpu_s)
        })
        .collect();
    if !slow.is_empty() {
        let _ = writeln!(out, "  time (phases of a second or more):\n{}", slow.join("\n"));
    }
    let _ = writeln!(out, "  wrote {}", args.out.display());
}

fn errors(out: &mut String, label: &str, summary: &ErrorSummary) {
    let _ = write!(
        out,
        "  {label}: mean {:.4} mm, rms {:.4} mm, max {:.4} mm",
        summary.mean_position_error_mm, summary.rms_position_error_mm, summary.max_position_error_mm
    );
    match summary.mean_rotation_error_mrad {
        Some(rotation) => {
            let _ = writeln!(out, ", rotation mean {rotation:.4} mrad");
        }
        None => out.push('\n'),
    }
}
