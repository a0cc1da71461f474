//! The one writer: a [`Report`] as one self-contained HTML page (inline CSS and SVG, no script,
//! printable). Every number a test compares carries its full value in a `data-value` attribute
//! next to the rounded text, under a `data-key` naming it.

use crate::ErrorKind;
use crate::content::{ErrorStats, GroupedErrors, Report};
use crate::figures;
use diagnose::Diagnosis;
use errors::Error;
use std::fmt::Write;

/// The sections of a calibration report, in order: `(id, heading)`. The diagnosis section is
/// there only when a training file was given.
pub const SECTIONS: [(&str, &str); 12] = [
    ("summary", "At a glance"),
    ("robot", "Robot"),
    ("data", "Data"),
    ("method", "Method"),
    ("warnings", "Warnings"),
    ("errors", "Error before and after calibration"),
    ("iso9283", "ISO 9283 position accuracy and repeatability"),
    ("effects", "Identified effects"),
    ("gp", "Gaussian process"),
    ("workspace", "Error over the workspace"),
    ("worst", "The ten worst poses"),
    ("diagnosis", "Diagnosis of the training data"),
];

const STYLE: &str = "body{font-family:sans-serif;max-width:1120px;margin:1.5em auto;padding:0 1em;color:#222;line-height:1.4}\
h1{font-size:1.6em;margin-bottom:.2em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.6em}\
table{border-collapse:collapse;margin:.6em 0}td,th{border:1px solid #ddd;padding:.2em .6em;text-align:right}\
th{background:#f4f4f4}td.l,th.l{text-align:left}.cards{display:flex;flex-wrap:wrap;gap:.8em}\
.card{border:1px solid #ccc;border-radius:6px;padding:.6em 1em;min-width:12em}.card .v{font-size:1.7em;font-weight:bold}\
.card .s{color:#666;font-size:.9em}.warn{background:#fff4e0;border-left:4px solid #e09000;padding:.4em .8em;margin:.4em 0}\
.ok{color:#2a7a2a}svg{width:100%;max-width:880px;height:auto}#workspace svg{max-width:100%}pre{background:#f7f7f7;padding:.6em;overflow-x:auto;font-size:.85em}\
p.how{color:#555;font-size:.92em}@media print{body{max-width:none}section{break-inside:avoid-page}h2{break-after:avoid}}";

/// Escapes text for HTML.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// A table cell with a number: rounded text, the full value in `data-value`.
fn cell(key: &str, value: f64, decimals: usize) -> String {
    format!(r#"<td data-key="{}" data-value="{value}">{value:.decimals$}</td>"#, escape(key))
}

fn optional_cell(key: &str, value: Option<f64>, decimals: usize) -> String {
    value.map_or_else(|| "<td>–</td>".to_owned(), |v| cell(key, v, decimals))
}

/// Renders `report` as one HTML page.
pub fn render_html(report: &Report) -> Result<String, Error> {
    let mut out = String::with_capacity(1 << 20);
    let title = format!("Calibration report: {} ({})", report.robot.name, report.model.method);
    let _ = writeln!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title><style>{STYLE}</style></head><body>\n<h1>{}</h1>",
        escape(&title),
        escape(&title)
    );
    let _ = writeln!(
        out,
        "<p class=\"how\">Model <code>{}</code> evaluated on <code>{}</code> ({} rows). Every error is the distance between \
         the measured tool point and the one the model predicts from the measured joint values.</p>",
        escape(&report.model.file),
        escape(&report.data.source),
        report.data.rows
    );
    summary(&mut out, report);
    robot(&mut out, report);
    data(&mut out, report);
    method(&mut out, report);
    warnings(&mut out, report);
    errors(&mut out, report)?;
    iso9283(&mut out, report);
    effects(&mut out, report)?;
    gp(&mut out, report);
    workspace(&mut out, report)?;
    worst(&mut out, report);
    if let Some(d) = &report.diagnosis {
        let plots = crate::diagnosis_figures(d)?;
        diagnosis_section(&mut out, d, &plots);
    }
    // `calib eval --json` as it prints it: data for a reader or a test, not a script to run.
    let eval =
        serde_json::to_string(&report.eval).map_err(|source| Error::new(ErrorKind::EvaluationJson { source }))?;
    let _ = writeln!(
        out,
        "<script type=\"application/json\" id=\"eval-json\">{}</script>\n</body></html>",
        eval.replace("</", "<\\/")
    );
    Ok(out)
}

fn open(out: &mut String, id: &str) {
    let heading = SECTIONS.iter().find(|(i, _)| *i == id).map_or(id, |(_, h)| h);
    let _ = writeln!(out, "<section id=\"{id}\"><h2>{heading}</h2>");
}

fn card(out: &mut String, key: &str, label: &str, value: f64, unit: &str, sub: &str) {
    let _ = write!(
        out,
        r#"<div class="card"><div class="s">{label}</div><div class="v" data-key="{key}" data-value="{value}">{value:.3} {unit}</div><div class="s">{sub}</div></div>"#
    );
}

/// The summary's cards: the position errors after calibration, each with its value before.
fn summary_cards(out: &mut String, r: &Report) {
    let after = &r.after_groups.all;
    let before_sub = |pick: fn(&ErrorStats) -> f64| {
        r.before.as_ref().map_or_else(
            || "before: unknown".to_owned(),
            |b| format!("before calibration: {:.3} mm", pick(&b.groups.all)),
        )
    };
    card(
        out,
        "card.mean",
        "Mean position error",
        after.summary.mean_position_error_mm,
        "mm",
        &before_sub(|s| s.summary.mean_position_error_mm),
    );
    card(
        out,
        "card.rms",
        "RMS position error",
        after.summary.rms_position_error_mm,
        "mm",
        &before_sub(|s| s.summary.rms_position_error_mm),
    );
    card(
        out,
        "card.p95",
        "95 % of poses within",
        after.p95_position_error_mm,
        "mm",
        &before_sub(|s| s.p95_position_error_mm),
    );
    card(
        out,
        "card.max",
        "Largest position error",
        after.summary.max_position_error_mm,
        "mm",
        &before_sub(|s| s.summary.max_position_error_mm),
    );
    if let Some(rotation) = after.summary.mean_rotation_error_mrad {
        card(out, "card.rotation", "Mean rotation error", rotation, "mrad", "full-pose data");
    }
}

fn summary(out: &mut String, r: &Report) {
    open(out, "summary");
    out.push_str("<div class=\"cards\">");
    summary_cards(out, r);
    out.push_str("</div>\n");
    let _ = write!(
        out,
        "<p>{} test rows of <code>{}</code>; method <b>{}</b>; parts: {}.",
        r.data.rows,
        escape(&r.data.source),
        escape(&r.model.method),
        escape(&r.model.parts.join(" → "))
    );
    if let Some(split) = &r.eval.coverage {
        let _ = write!(
            out,
            " {} of them inside the angles the effects were fitted on, {} outside.",
            split.inside.n, split.outside.n
        );
    }
    if let Some(d) = &r.diagnosis {
        let _ = write!(out, " Diagnosis of the training data: <b>{}</b>.", escape(&verdict(d)));
    }
    out.push_str("</p>\n");
    let count = r.warnings.len() + r.fit_warnings.as_ref().map_or(0, Vec::len);
    if count > 0 {
        let _ = writeln!(out, "<div class=\"warn\">{count} warning(s): see <a href=\"#warnings\">Warnings</a>.</div>");
    }
    out.push_str("</section>\n");
}

fn robot(out: &mut String, r: &Report) {
    open(out, "robot");
    let _ = write!(
        out,
        "<p><b>{}</b> from <code>{}</code>, {} joints.</p>",
        escape(&r.robot.name),
        escape(&r.robot.file),
        r.robot.joints.len()
    );
    out.push_str("<table><tr><th>joint</th><th class=\"l\">kind</th><th>lower limit</th><th>upper limit</th></tr>");
    for (k, j) in r.robot.joints.iter().enumerate() {
        let limit = |i: usize| j.limits.map_or_else(|| "–".to_owned(), |l| format!("{:.1} {}", l[i], j.unit));
        let _ = write!(
            out,
            "<tr><td>{}</td><td class=\"l\">{}</td><td>{}</td><td>{}</td></tr>",
            k + 1,
            j.kind,
            limit(0),
            limit(1)
        );
    }
    out.push_str("</table></section>\n");
}

fn data_table(out: &mut String, title: &str, d: &crate::content::DataSummary, units: &[&str]) {
    let _ = write!(
        out,
        "<h3>{title}: <code>{}</code></h3><p>{} rows, {}. Payloads: {}. Tools: {}.</p>",
        escape(&d.source),
        d.rows,
        if d.full_pose { "full pose (position and orientation)" } else { "position only" },
        d.payloads.iter().map(|(kg, n)| format!("{kg} kg ({n} rows)")).collect::<Vec<_>>().join(", "),
        escape(
            &d.tools
                .iter()
                .map(|(t, n)| format!("{} ({n} rows)", if t.is_empty() { "default" } else { t }))
                .collect::<Vec<_>>()
                .join(", ")
        )
    );
    out.push_str("<table><tr><th>joint</th><th>smallest</th><th>largest</th></tr>");
    for (k, [a, b]) in d.joint_ranges.iter().enumerate() {
        let unit = units.get(k).copied().unwrap_or("");
        let _ = write!(out, "<tr><td>{}</td><td>{a:.2} {unit}</td><td>{b:.2} {unit}</td></tr>", k + 1);
    }
    out.push_str("</table>");
}

fn data(out: &mut String, r: &Report) {
    open(out, "data");
    let units: Vec<&str> = r.robot.joints.iter().map(|j| j.unit).collect();
    data_table(out, "Test data", &r.data, &units);
    match &r.training {
        Some(t) => data_table(out, "Training data", t, &units),
        None => out.push_str("<p>No training data given (<code>--train</code>): no training angles on the effect curves and no diagnosis.</p>"),
    }
    out.push_str("</section>\n");
}

fn method(out: &mut String, r: &Report) {
    open(out, "method");
    let _ = write!(
        out,
        "<p>Method <b>{}</b>, fitted on {} (tools: {}). The model applies, in order: {}.</p>",
        escape(&r.model.method),
        if r.model.full_pose { "full poses" } else { "positions only" },
        escape(
            &r.model
                .tools
                .iter()
                .map(|t| if t.is_empty() { "default" } else { t.as_str() })
                .collect::<Vec<_>>()
                .join(", ")
        ),
        escape(&r.model.parts.join(" → "))
    );
    let _ = writeln!(
        out,
        "<p>Effects: {}. Gaussian process: {}.</p></section>",
        if r.effects.is_empty() {
            "none".to_owned()
        } else {
            escape(&r.effects.iter().map(|e| e.label.as_str()).collect::<Vec<_>>().join(", "))
        },
        r.gp.as_ref().map_or("none".to_owned(), |g| format!("{} GP on {}", g.kind, g.inputs.join(", ")))
    );
}

fn warnings(out: &mut String, r: &Report) {
    open(out, "warnings");
    out.push_str("<h3>From the fit</h3>");
    match &r.fit_warnings {
        Some(fit) if fit.is_empty() => out.push_str("<p class=\"ok\">No warning from the fit.</p>"),
        Some(fit) => {
            for w in fit {
                let _ = write!(out, "<div class=\"warn\">{}</div>", escape(w));
            }
        }
        None => out.push_str(
            "<p class=\"how\">This model file was written before the fit's own warnings (few rows per parameter, gross \
             outliers, a fit forced past the plausibility check) were kept in it: see <code>calib fit --json</code>'s \
             <code>warnings</code>.</p>",
        ),
    }
    out.push_str("<h3>From the evaluation</h3>");
    if r.warnings.is_empty() {
        out.push_str("<p class=\"ok\">No warning from the evaluation.</p>");
    }
    for w in &r.warnings {
        let _ = write!(out, "<div class=\"warn\">{}</div>", escape(w));
    }
    out.push_str("</section>\n");
}

fn stats_row(out: &mut String, key: &str, label: &str, s: &ErrorStats) {
    let e = &s.summary;
    let _ = write!(
        out,
        "<tr><td class=\"l\">{}</td><td data-key=\"{key}.n\" data-value=\"{}\">{}</td>{}{}{}{}{}{}</tr>",
        escape(label),
        e.n,
        e.n,
        cell(&format!("{key}.mean_position_error_mm"), e.mean_position_error_mm, 4),
        cell(&format!("{key}.rms_position_error_mm"), e.rms_position_error_mm, 4),
        cell(&format!("{key}.median_position_error_mm"), e.median_position_error_mm, 4),
        cell(&format!("{key}.p95_position_error_mm"), s.p95_position_error_mm, 4),
        cell(&format!("{key}.max_position_error_mm"), e.max_position_error_mm, 4),
        optional_cell(&format!("{key}.mean_rotation_error_mrad"), e.mean_rotation_error_mrad, 4),
    );
}

const STATS_HEAD: &str = "<tr><th class=\"l\"></th><th>rows</th><th>mean (mm)</th><th>RMS (mm)</th><th>median (mm)</th><th>95th pct (mm)</th><th>max (mm)</th><th>mean rotation (mrad)</th></tr>";

fn grouped_table(out: &mut String, key: &str, g: &GroupedErrors) {
    out.push_str("<table>");
    out.push_str(STATS_HEAD);
    stats_row(out, key, "all rows", &g.all);
    if g.per_payload.len() > 1 {
        for (kg, s) in &g.per_payload {
            stats_row(out, &format!("{key}.payload.{kg}"), &format!("payload {kg} kg"), s);
        }
    }
    if g.per_tool.len() > 1 {
        for (tool, s) in &g.per_tool {
            stats_row(out, &format!("{key}.tool.{tool}"), &format!("tool {tool}"), s);
        }
    }
    out.push_str("</table>");
}

fn errors(out: &mut String, r: &Report) -> Result<(), Error> {
    open(out, "errors");
    out.push_str("<h3>After calibration</h3>");
    grouped_table(out, "after", &r.after_groups);
    out.push_str("<h3>Before calibration</h3>");
    match &r.before {
        Some(b) => {
            let _ = write!(out, "<p class=\"how\">Before calibration means {}.</p>", escape(&b.how));
            grouped_table(out, "before", &b.groups);
        }
        None => out.push_str("<p>Unknown: the robot file's nominal model could not be placed on the calibrated one (it is not this robot).</p>"),
    }
    if let Some(split) = &r.eval.coverage {
        out.push_str("<h3>Inside and outside the model's coverage</h3><p class=\"how\">Inside: every effect's joint within the angles it was fitted on; outside, the effects fade out and the model falls back to the geometry.</p><table>");
        out.push_str(STATS_HEAD);
        for (key, label, part) in [("inside", "inside", &split.inside), ("outside", "outside", &split.outside)] {
            let rows: Vec<model::PoseError> = r
                .rows
                .iter()
                .filter(|row| row.inside_coverage == (key == "inside"))
                .map(|row| model::PoseError { position_mm: row.after_mm, rotation_mrad: row.after_mrad })
                .collect();
            let stats = ErrorStats { summary: *part, ..crate::build::stats(&rows) };
            stats_row(out, &format!("coverage.{key}"), label, &stats);
        }
        out.push_str("</table>");
    }
    let after: Vec<f64> = r.rows.iter().map(|row| row.after_mm).collect();
    let before: Option<Vec<f64>> = r.rows.iter().map(|row| row.before_mm).collect();
    out.push_str(&figures::histogram(before.as_deref(), &after)?);
    out.push_str("</section>\n");
    Ok(())
}

fn iso9283(out: &mut String, r: &Report) {
    open(out, "iso9283");
    let iso = &r.iso9283;
    out.push_str("<table><tr><th class=\"l\"></th><th>mean over poses (mm)</th><th>largest (mm)</th></tr>");
    let _ = write!(
        out,
        "<tr><td class=\"l\">position accuracy AP</td>{}{}</tr>",
        cell("iso.ap_mean_mm", iso.ap_mean_mm, 4),
        cell("iso.ap_max_mm", iso.ap_max_mm, 4)
    );
    match (iso.rp_mean_mm, iso.rp_max_mm) {
        (Some(mean), Some(max)) => {
            let _ = write!(out, "<tr><td class=\"l\">position repeatability RP</td>{}{}</tr>", cell("iso.rp_mean_mm", mean, 4), cell("iso.rp_max_mm", max, 4));
        }
        _ => out.push_str("<tr><td class=\"l\">position repeatability RP</td><td colspan=\"2\" class=\"l\">not measured: no pose of the data is repeated</td></tr>"),
    }
    let _ = writeln!(
        out,
        "</table><p class=\"how\">How: ISO 9283:1998 §7.2.1 and §7.2.2, with the calibrated model's prediction from the \
         measured joint values as the command and the measured position as the attained one. Rows whose joint values \
         agree within {} rad are one pose measured again: {} poses, {} of them repeated. Per pose, AP = |x̄ − x_c|, the \
         distance of the attained positions' barycentre from the command; RP = l̄ + 3 S_l, l = |x − x̄|, with S_l the \
         sample standard deviation of l. ISO 9283 drives to the pose in consecutive cycles; a campaign's \
         repeated rows may be hours apart, so this RP also holds what drifted between them (temperature, the \
         tracker's placement).</p></section>",
        iso.options.same_pose_rad, iso.poses, iso.repeated_poses
    );
}

fn effects(out: &mut String, r: &Report) -> Result<(), Error> {
    open(out, "effects");
    if r.effects.is_empty() {
        out.push_str("<p>The model has no identified effects.</p>");
    }
    for e in &r.effects {
        let _ = write!(out, "<h3>{}</h3>", escape(&e.label));
        match &e.curve {
            Some(curve) => {
                out.push_str(&figures::effect_curve(&e.label, curve)?);
                out.push_str(
                    "<p class=\"how\">The joint error the model applies (line), with ± the σ it leaves uncorrected where \
                     the series fades out of the angles it was fitted on (band, zero on them); shaded: the fitted angles; \
                     ticks: training angles (top, with <code>--train</code>) and test angles (bottom).</p>",
                );
            }
            None => out
                .push_str("<p class=\"how\">Not a function of one joint's angle alone: its parameters are listed.</p>"),
        }
        let shown = e.parameters.iter().take(24);
        out.push_str("<table><tr><th class=\"l\">parameter</th><th>value</th><th class=\"l\">unit</th></tr>");
        for (name, value, unit) in shown {
            let _ = write!(
                out,
                "<tr><td class=\"l\">{}</td><td>{value:.4e}</td><td class=\"l\">{unit}</td></tr>",
                escape(name)
            );
        }
        if e.parameters.len() > 24 {
            let _ = write!(
                out,
                "<tr><td class=\"l\" colspan=\"3\">… {} more in the model file</td></tr>",
                e.parameters.len() - 24
            );
        }
        out.push_str("</table>");
    }
    out.push_str("</section>\n");
    Ok(())
}

fn gp(out: &mut String, r: &Report) {
    open(out, "gp");
    let Some(g) = &r.gp else {
        out.push_str("<p>The model has no Gaussian process.</p></section>\n");
        return;
    };
    let _ = write!(
        out,
        "<p>An {} GP on the inputs {}. Length scales in standard deviations of each input over the training rows (a long length scale: the error barely changes with that input).</p>",
        g.kind,
        escape(&g.inputs.join(", "))
    );
    if !g.signals.is_empty() {
        let spans: Vec<String> = g
            .signals
            .iter()
            .map(|s| {
                let [low, high] = s.fitted;
                let unit = s.unit.map_or(String::new(), |u| format!(" {u}"));
                let span = if low.is_finite() { format!("{low} … {high}{unit}") } else { "span not kept".to_owned() };
                format!("{} (fitted on {span})", escape(&s.name))
            })
            .collect();
        let _ = write!(
            out,
            "<p>Measured signals beside the joints: {}. Outside a signal's span the GP extrapolates: <code>calib eval</code> counts those rows, and the correction fades where the GP knows little.</p>",
            spans.join("; ")
        );
    }
    out.push_str("<table><tr><th class=\"l\">outputs</th><th class=\"l\">kernel</th>");
    for input in &g.inputs {
        let _ = write!(out, "<th>{}</th>", escape(input));
    }
    out.push_str("</tr><tr><td class=\"l\" colspan=\"2\">one standard deviation of the input</td>");
    let joints = g.inputs.len() - g.signals.len();
    for (k, s) in g.input_scale.iter().enumerate() {
        let unit = if let Some(signal) = k.checked_sub(joints).and_then(|i| g.signals.get(i)) {
            format!("{s:.4}{}", signal.unit.map_or(String::new(), |u| format!(" {u}")))
        } else if g.inputs.get(k).is_some_and(|i| i == "payload") {
            format!("{s:.3} kg")
        } else {
            format!("{:.1}°", s.to_degrees())
        };
        let _ = write!(out, "<td>{unit}</td>");
    }
    out.push_str("</tr>");
    for k in &g.kernels {
        let names = ["x", "y", "z", "rx", "ry", "rz"];
        let outputs: Vec<&str> = k.outputs.iter().map(|&o| names.get(o).copied().unwrap_or("?")).collect();
        let _ =
            write!(out, "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td>", outputs.join(", "), escape(&k.family));
        for (i, l) in k.length_scales.iter().enumerate() {
            let _ = write!(out, "<td data-key=\"gp.{}.{i}\" data-value=\"{l}\">{l:.3}</td>", outputs.join(""));
        }
        out.push_str("</tr>");
    }
    out.push_str("</table></section>\n");
}

fn workspace(out: &mut String, r: &Report) -> Result<(), Error> {
    open(out, "workspace");
    out.push_str(&figures::workspace(&r.rows)?);
    let _ = writeln!(
        out,
        "<p class=\"how\">Each test pose at its measured tool point in the tracker frame, coloured by its position \
         error after calibration from 0 mm (dark purple) to the largest, {:.3} mm (yellow); the worst are drawn on \
         top.</p></section>",
        r.after_groups.all.summary.max_position_error_mm
    );
    Ok(())
}

fn worst(out: &mut String, r: &Report) {
    open(out, "worst");
    let mut order: Vec<&crate::content::RowError> = r.rows.iter().collect();
    order.sort_by(|a, b| b.after_mm.total_cmp(&a.after_mm));
    let joints = r.rows.first().map_or(0, |row| row.q.len());
    out.push_str("<table><tr><th>line</th><th>after (mm)</th><th>before (mm)</th><th>payload (kg)</th><th class=\"l\">tool</th><th class=\"l\">coverage</th>");
    for j in 1..=joints {
        let _ = write!(out, "<th>q{j}</th>");
    }
    out.push_str("</tr>");
    for row in order.iter().take(10) {
        let _ = write!(
            out,
            "<tr><td data-key=\"worst.line\">{}</td>{}{}<td>{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td>",
            row.line,
            cell("worst.after_mm", row.after_mm, 4),
            optional_cell("worst.before_mm", row.before_mm, 4),
            row.payload_kg,
            escape(if row.tool.is_empty() { "default" } else { &row.tool }),
            if row.inside_coverage { "inside" } else { "outside" }
        );
        for (j, q) in row.q.iter().enumerate() {
            let prismatic = r.robot.joints.get(j).is_some_and(|d| d.unit == "mm");
            let _ = if prismatic {
                write!(out, "<td>{:.2} mm</td>", q * 1e3)
            } else {
                write!(out, "<td>{:.2}°</td>", q.to_degrees())
            };
        }
        out.push_str("</tr>");
    }
    let _ = writeln!(
        out,
        "</table><p class=\"how\">Lines of <code>{}</code>, largest position error after calibration first.</p></section>",
        escape(&r.data.source)
    );
}

/// The verdict in words.
fn verdict(d: &Diagnosis) -> String {
    let joints: Vec<String> = d.verdict.joints.iter().map(ToString::to_string).collect();
    let name = d.verdict.effect.name().replace('_', " ");
    if joints.is_empty() { name } else { format!("{name} (joint {})", joints.join(", ")) }
}

/// The diagnosis section: verdict, predicted shrink, what is left, the candidates and the plots.
pub(crate) fn diagnosis_section(out: &mut String, d: &Diagnosis, plots: &[(String, String)]) {
    open(out, "diagnosis");
    let shrink = 1.0 - d.heldout_after_selected_mm / d.heldout_before_mm.max(f64::MIN_POSITIVE);
    let _ = write!(
        out,
        "<div class=\"cards\"><div class=\"card\"><div class=\"s\">Verdict</div><div class=\"v\" data-key=\"diagnosis.verdict\">{}</div></div>",
        escape(&verdict(d))
    );
    card(
        out,
        "diagnosis.heldout_before_mm",
        "Held-out error, geometric model",
        d.heldout_before_mm,
        "mm",
        "cross-validated mean",
    );
    card(
        out,
        "diagnosis.heldout_after_selected_mm",
        "With the selected effects",
        d.heldout_after_selected_mm,
        "mm",
        &format!("predicted shrink {:.0} %", 100.0 * shrink),
    );
    card(out, "diagnosis.noise_floor_mm", "Noise floor", d.noise.floor_mm, "mm", "what no model can remove");
    out.push_str("</div>");
    let left = what_is_left(d);
    let _ = write!(out, "<p>{}</p><pre>{}</pre>", escape(&left), escape(&d.summary()));
    candidate_table(out, d);
    for (name, svg) in plots {
        let _ = write!(out, "<figure>{svg}<figcaption>{}</figcaption></figure>", escape(name));
    }
    out.push_str("</section>\n");
}

/// What the diagnosis says is left after the selected effects: structure a GP finds, or not.
fn what_is_left(d: &Diagnosis) -> String {
    match &d.remaining {
        Some(gp) if gp.significant => format!(
            "What is left: a GP on what the selected effects leave still lowers the held-out error to {:.4} mm \
             (z = {:.1}, {:.0} % less): structure no listed effect explains.",
            gp.heldout_after_gp_mm,
            gp.z,
            100.0 * gp.gain
        ),
        Some(gp) => format!(
            "What is left: a GP on what the selected effects leave reaches {:.4} mm held out (z = {:.1}, {:.0} % \
             less), below the diagnosis's threshold for structure that no listed effect explains.",
            gp.heldout_after_gp_mm,
            gp.z,
            100.0 * gp.gain
        ),
        None => "What is left: not checked by a GP.".to_owned(),
    }
}

/// Each candidate effect alone: its parameters and held-out mean error.
fn candidate_table(out: &mut String, d: &Diagnosis) {
    out.push_str("<table><tr><th class=\"l\">candidate alone</th><th>parameters</th><th>held-out mean (mm)</th></tr>");
    for c in &d.candidates {
        let joints: Vec<String> = c.joints.iter().map(ToString::to_string).collect();
        let _ = write!(
            out,
            "<tr><td class=\"l\">{} {}{}</td><td>{}</td><td>{:.4}</td></tr>",
            c.effect.name().replace('_', " "),
            joints.join(", "),
            c.harmonic.map_or_else(String::new, |h| format!(" (harmonics 1–{h})")),
            c.parameters,
            c.heldout_after_mm
        );
    }
    out.push_str("</table>");
}

/// The diagnosis alone as a page (`diagnosis.html` of `calib diagnose --report`).
pub(crate) fn diagnosis_page(d: &Diagnosis, plots: &[(String, String)]) -> String {
    let mut out = format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Diagnosis: {}</title><style>{STYLE}</style></head><body>\n<h1>Diagnosis: {}</h1>\n",
        escape(&d.robot),
        escape(&d.robot)
    );
    diagnosis_section(&mut out, d, plots);
    out.push_str("</body></html>\n");
    out
}
