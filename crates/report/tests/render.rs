//! The report rendered for a simulated payload campaign: every section there, every number the
//! page states for the calibrated model equal to `calib eval --json`'s, nothing loaded from outside.

use campaign::{Perturbation, Remount, campaign_cell, joint_ranges, payload_run_campaign, simulate};
use diagnose::{DiagnoseOptions, diagnose};
use effects::{EffectSelection, EffectSpec};
use loadsim::{Effects, GearPeriodicModel, Harmonic};
use measurements::MeasurementSet;
use model::{EvalReport, Method};
use pipeline::FitOptions;
use std::collections::HashMap;
use std::sync::OnceLock;

struct Rendered {
    html: String,
    eval: EvalReport,
    errors: Vec<(u64, f64)>,
    diagnosis_plot_names: Vec<String>,
}

/// A payload campaign (joints 1 and 2 moving, four payload runs, a remounted tool each) with a
/// gear error on joint 2, fitted `poe-gp` with that gear series, rendered once for every test.
fn rendered() -> &'static Rendered {
    static RENDERED: OnceLock<Rendered> = OnceLock::new();
    RENDERED.get_or_init(|| {
        let robot = testkit::robot("irb4400.ron");
        let effects = Effects {
            gear_periodic: Some(GearPeriodicModel {
                harmonics: vec![
                    Harmonic { joint_index: 1, order: 1.0, amplitude_rad: 2e-4, phase_rad: 0.3 },
                    Harmonic { joint_index: 1, order: 2.0, amplitude_rad: 1e-4, phase_rad: -1.0 },
                ],
            }),
            ..campaign::paper_effects()
        };
        let train_config = payload_run_campaign(160, 11);
        let cell = campaign_cell(&robot, &Perturbation::default(), &Remount::default(), &train_config).unwrap();
        let ranges = joint_ranges(&robot);
        let train = simulate(&cell, &effects, &ranges, &train_config, false).unwrap();
        let test: MeasurementSet = simulate(&cell, &effects, &ranges, &payload_run_campaign(120, 12), false).unwrap();
        let mut options = FitOptions::default();
        options.effects.selection = EffectSelection::List(vec![EffectSpec::gear_periodic(2, 2)]);
        let (model, _) = pipeline::fit(&robot, &train, Method::PoeGp, &options).unwrap();
        let diagnosis = diagnose(&robot, &train, &DiagnoseOptions::default()).unwrap();
        let diagnosis_plot_names = diagnosis.error_plots().into_iter().map(|plot| plot.file_name).collect();
        let inputs = report::ReportInputs {
            model: &model,
            model_file: "model.ron",
            robot: &robot,
            robot_file: "irb4400.ron",
            data: &test,
            training: Some(&train),
        };
        let built = report::Report::build(&inputs, Some(diagnosis), &report::ReportOptions::default()).unwrap();
        let html = report::render_html(&built).unwrap();
        let bound = model.bind(&test).unwrap();
        let evaluation = model::evaluate(&model, &bound).unwrap();
        let eval = EvalReport::new(&model, &bound, &evaluation);
        let errors = test.rows.iter().zip(&evaluation.errors).map(|(r, e)| (r.line, e.position_mm)).collect();
        Rendered { html, eval, errors, diagnosis_plot_names }
    })
}

/// Every `data-key="K" data-value="V"` pair of the page; a key that repeats keeps every value.
fn values(html: &str) -> HashMap<String, Vec<f64>> {
    let mut out: HashMap<String, Vec<f64>> = HashMap::new();
    for piece in html.split("data-key=\"").skip(1) {
        let (key, rest) = piece.split_once('"').unwrap();
        if let Some(value) = rest.strip_prefix(" data-value=\"") {
            let text = value.split('"').next().unwrap();
            out.entry(key.to_owned()).or_default().push(text.parse().unwrap_or(f64::NAN));
        }
    }
    out
}

#[test]
fn every_section_is_there_once_in_order() {
    let html = &rendered().html;
    let mut last = 0;
    for (id, heading) in report::SECTIONS {
        let tag = format!("<section id=\"{id}\"><h2>{heading}</h2>");
        assert_eq!(html.matches(&tag).count(), 1, "section {id}");
        let at = html.find(&tag).unwrap();
        assert!(at > last, "section {id} out of order");
        last = at;
    }
}

#[test]
fn the_after_numbers_are_eval_json_s_own() {
    let r = rendered();
    let v = values(&r.html);
    let e = &r.eval.errors;
    for (key, want) in [
        ("after.mean_position_error_mm", e.mean_position_error_mm),
        ("after.rms_position_error_mm", e.rms_position_error_mm),
        ("after.max_position_error_mm", e.max_position_error_mm),
        ("after.median_position_error_mm", e.median_position_error_mm),
        ("after.n", e.n as f64),
        ("card.mean", e.mean_position_error_mm),
        ("card.rms", e.rms_position_error_mm),
        ("card.max", e.max_position_error_mm),
    ] {
        assert_eq!(v[key], vec![want], "{key}");
    }
    let split = r.eval.coverage.expect("a gear series records its angles");
    assert_eq!(v["coverage.inside.mean_position_error_mm"], vec![split.inside.mean_position_error_mm]);
    assert_eq!(v["coverage.outside.n"], vec![split.outside.n as f64]);
    let embedded = r.html.split("<script type=\"application/json\" id=\"eval-json\">").nth(1).unwrap();
    let embedded = embedded.split("</script>").next().unwrap().replace("<\\/", "</");
    assert_eq!(embedded, serde_json::to_string(&r.eval).unwrap(), "the page embeds eval --json as it prints it");
}

#[test]
fn the_95th_percentile_and_the_groups_follow_from_the_rows() {
    let r = rendered();
    let v = values(&r.html);
    let mut sorted: Vec<f64> = r.errors.iter().map(|(_, e)| *e).collect();
    sorted.sort_by(f64::total_cmp);
    let rank = (0.95 * sorted.len() as f64).ceil() as usize;
    assert_eq!(v["after.p95_position_error_mm"], vec![sorted[rank - 1]]);
    let per_payload: f64 = [0.0, 1.25, 2.5, 5.0].iter().map(|kg| v[&format!("after.payload.{kg}.n")][0]).sum();
    assert_eq!(per_payload, r.errors.len() as f64, "the payload groups split the rows");
    let tools = v.keys().filter(|k| k.starts_with("after.tool.") && k.ends_with(".n")).count();
    assert_eq!(tools, 4, "one group per remounted tool");
}

#[test]
fn the_ten_worst_poses_are_listed_by_line_worst_first() {
    let r = rendered();
    let mut worst = r.errors.clone();
    worst.sort_by(|a, b| b.1.total_cmp(&a.1));
    let listed: Vec<u64> = r
        .html
        .split("<td data-key=\"worst.line\">")
        .skip(1)
        .map(|s| s.split('<').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(listed, worst.iter().take(10).map(|(line, _)| *line).collect::<Vec<_>>());
}

#[test]
fn the_page_loads_nothing_from_outside_and_runs_no_script() {
    let html = &rendered().html;
    assert_eq!(html.matches("<script").count(), 1, "only the embedded eval JSON");
    assert!(html.contains("<script type=\"application/json\""));
    for outside in ["src=\"http", "href=\"http", "@import", "url(http"] {
        assert!(!html.contains(outside), "{outside}");
    }
}

#[test]
fn the_charts_are_there_histogram_workspace_effect_curve_and_the_diagnosis_plots() {
    let r = rendered();
    let html = &r.html;
    assert!(html.contains("Position error on the test data"));
    assert!(html.contains("From above (tracker x–y)") && html.contains("From the side (tracker x–z)"));
    assert!(html.contains("gear_periodic:2:2: joint 2 error"), "the gear series' curve");
    for name in &r.diagnosis_plot_names {
        assert!(html.contains(&format!("<figcaption>{name}</figcaption>")), "{name}");
    }
    let svgs = html.matches("<svg").count();
    assert_eq!(svgs, 3 + r.diagnosis_plot_names.len(), "histogram, workspace, one effect curve and the diagnosis's");
}

#[test]
fn the_diagnosis_folder_keeps_its_file_names() {
    let r = rendered();
    let robot = testkit::robot("irb4400.ron");
    let config = payload_run_campaign(160, 11);
    let cell = campaign_cell(&robot, &Perturbation::default(), &Remount::default(), &config).unwrap();
    let train = simulate(&cell, &campaign::paper_effects(), &joint_ranges(&robot), &config, false).unwrap();
    let diagnosis = diagnose(&robot, &train, &DiagnoseOptions::default()).unwrap();
    let figures = report::diagnosis_figures(&diagnosis).unwrap();
    let names: Vec<&str> = figures.iter().map(|(n, _)| n.as_str()).collect();
    // The names the diagnosis's markdown links, one per moving joint and per varying condition.
    assert_eq!(names, ["joint1.svg", "joint2.svg", "payload.svg", "temperature.svg", "time.svg"]);
    assert!(figures.iter().all(|(_, svg)| svg.starts_with("<svg")));
    assert!(!r.diagnosis_plot_names.is_empty());
}

/// Each effect parameter's row names its unit: the gear series of revolute joint 2 in rad (a
/// prismatic joint's would read mm, `effects::reported_parameters`).
#[test]
fn the_effect_parameters_state_their_unit() {
    let html = &rendered().html;
    assert!(html.contains("<th>value</th><th class=\"l\">unit</th>"), "no unit column");
    for name in ["cos(1 q2)", "sin(1 q2)", "cos(2 q2)", "sin(2 q2)"] {
        let row = html.split(&format!("<td class=\"l\">{name}</td>")).nth(1).unwrap_or_else(|| panic!("{name}"));
        let row = row.split("</tr>").next().unwrap();
        assert!(row.ends_with("<td class=\"l\">rad</td>"), "{name}: {row}");
    }
}
