//! `cargo xtask urdf-check`: the UR10 described three ways (RON axes, DH table, URDF as
//! ur_description builds it) fits the real UR10 tracker data to the same held-out error, and the
//! calibrated URDF exported like `ur10.urdf` reads back to the calibrated model within 1e-9 m.
//! Writes `urdf.md` into `--out`.

use super::convert_ur10::{Dataset, read_series};
use anyhow::Context;
use cell::UrdfTemplate;
use lie::{SE3, Vector3};
use measurements::MeasurementSet;
use model::Method;
use pipeline::FitOptions;
use robot::{ChainEnds, NominalTolerance, RobotDescription, UrdfDocument};
use std::fmt::Write;
use std::path::PathBuf;

/// Fit the UR10 data with each description of the robot; export and reload the calibrated URDF.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    dataset: Dataset,
    /// Where `urdf.md` goes.
    #[arg(long, default_value = "docs/results")]
    out: PathBuf,
}

const FORMS: [&str; 3] = ["fixtures/robots/ur10.ron", "fixtures/robots/ur10_dh.ron", "fixtures/robots/ur10.urdf"];

fn halves(set: &MeasurementSet) -> (MeasurementSet, MeasurementSet) {
    let half = set.rows.len() / 2;
    (set.subset(&(0..half).collect::<Vec<_>>()), set.subset(&(half..set.rows.len()).collect::<Vec<_>>()))
}

/// Largest distance between the tool poses (origin and the ends of 1 m axes) of two models.
fn largest_difference_m(a: &poe::LocalPoe, b: &poe::LocalPoe, rows: &MeasurementSet) -> anyhow::Result<f64> {
    let points = [Vector3::zeros(), Vector3::x(), Vector3::y(), Vector3::z()];
    let mut largest = 0.0_f64;
    for row in &rows.rows {
        let (ta, tb): (SE3, SE3) = (a.forward(&row.q, 0)?, b.forward(&row.q, 0)?);
        for p in &points {
            largest = largest.max((ta.transform_point(p) - tb.transform_point(p)).norm());
        }
    }
    Ok(largest)
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let mut md = String::new();
    let _ = writeln!(md, "# The UR10 as RON, DH table and URDF, and the calibrated URDF\n");
    let _ = writeln!(
        md,
        "Data: series {} of the IPA UR10 data set (Landgraf et al., CASE 2021; not part of this repository), \
         trained on the first half of the rows in measurement order and tested on the second, as in \
         [ur10.md](ur10.md). Method `poe`. Produced by `cargo xtask urdf-check`.\n",
        args.dataset.series
    );
    let _ =
        writeln!(md, "| data | robot description | held-out mean (mm) | RMS (mm) | max (mm) | rotation mean (mrad) |");
    let _ = writeln!(md, "| --- | --- | ---: | ---: | ---: | ---: |");
    let mut round_trips = Vec::new();
    for (label, full_pose) in [("position", false), ("full pose", true)] {
        let set = read_series(&args.dataset.input, &args.dataset.series, full_pose)?;
        let (train, test) = halves(&set);
        let mut means = Vec::new();
        for form in FORMS {
            let robot = RobotDescription::read(&PathBuf::from(form))?;
            let (model, _) = pipeline::fit(&robot, &train, Method::Poe, &FitOptions::default())?;
            let s = model::evaluate(&model, &model.bind(&test)?)?.summary;
            let _ = writeln!(
                md,
                "| {label} | `{form}` | {:.6} | {:.6} | {:.6} | {} |",
                s.mean_position_error_mm,
                s.rms_position_error_mm,
                s.max_position_error_mm,
                s.mean_rotation_error_mrad.map_or("–".into(), |v| format!("{v:.6}"))
            );
            means.push(s.mean_position_error_mm);
            if form.ends_with(".urdf") {
                round_trips.push((label, round_trip(form, &model, &test)?));
            }
        }
        let spread = means.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            - means.iter().copied().fold(f64::INFINITY, f64::min);
        let _ = writeln!(md, "| {label} | largest difference between the three | {spread:.2e} | | | |");
    }
    let _ = writeln!(
        md,
        "\nThe calibrated model fitted with `ur10.urdf`, exported with `calib export --like fixtures/robots/ur10.urdf` \
         and read back with `--base-link tracker --tip-link tool`: largest difference from the calibrated model's \
         forward kinematics over the test configurations (tool point and the ends of 1 m axes):\n"
    );
    let _ = writeln!(md, "| data | largest difference (m) |");
    let _ = writeln!(md, "| --- | ---: |");
    for (label, difference) in &round_trips {
        let _ = writeln!(md, "| {label} | {difference:.2e} |");
    }
    let path = args.out.join("urdf.md");
    std::fs::write(&path, &md).with_context(|| path.display().to_string())?;
    println!("{md}");
    if let Some((label, difference)) = round_trips.iter().find(|(_, d)| *d > 1e-9) {
        anyhow::bail!("{label}: the exported URDF reads back {difference:e} m from the model");
    }
    Ok(())
}

/// Exports `model` like `urdf` and reads the result back from the tracker link to the tool.
fn round_trip(urdf: &str, model: &model::CalibratedModel, test: &MeasurementSet) -> anyhow::Result<f64> {
    let document = UrdfDocument::read(&PathBuf::from(urdf))?;
    let chain = document.chain(&ChainEnds::default())?;
    let template = UrdfTemplate::Like { document: &document, chain: &chain };
    let export = cell::export_urdf(model, template, None, &NominalTolerance::default())?;
    let ends = ChainEnds {
        base_link: Some(export.report.tracker_link.clone()),
        tip_link: export.report.tool_links.first().cloned(),
    };
    let back = UrdfDocument::parse(&export.text, "exported.urdf")
        .and_then(|d| d.chain(&ends))
        .and_then(|c| c.description().nominal_model())?;
    largest_difference_m(&back, &model.kinematics, test)
}
