//! The diagnosis as people read it: a ten-second summary, a markdown report with plots written
//! into a folder, and the SPEC's JSON (the [`Diagnosis`] itself, serialised as it is).

use super::Diagnosis;
use super::candidates::Effect;
use super::noise::NoiseSource;
use super::regions::{PoseDiagnosis, Region};
use crate::ErrorKind;
use errors::Error;
use serde::{Deserialize, Serialize};

/// One of the diagnosis's scatter plots: the held-out position error of every pose under the
/// geometric model and with the selected effects, against one quantity.
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorPlot {
    /// The file it is written to in the report folder (`joint2.svg`, `payload.svg`, …), which the
    /// markdown links to.
    pub file_name: String,
    /// The plot's title.
    pub title: String,
    /// The x axis's name with its unit.
    pub x_label: String,
    /// `(x, error in mm)` per pose under the geometric model.
    pub before_mm: Vec<(f64, f64)>,
    /// `(x, error in mm)` per pose with the selected effects.
    pub after_mm: Vec<(f64, f64)>,
}

/// One candidate tried alone on top of the geometric model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateScore {
    /// The effect.
    pub effect: Effect,
    /// 1-based joints.
    pub joints: Vec<usize>,
    /// For gear periodic error: the order of the Fourier series (harmonics 1 to this), as the
    /// cross-validation of all folds prefers it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub harmonic: Option<u32>,
    /// Number of parameters it adds.
    pub parameters: usize,
    /// Cross-validated mean position error with it, mm.
    pub heldout_after_mm: f64,
}

/// One harmonic of a selected periodic error, fitted on every row.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DominantHarmonic {
    /// Cycles per turn of the joint.
    pub order: u32,
    /// Its period in the joint's angle, degrees.
    pub period_deg: f64,
    /// Its amplitude, µrad.
    pub amplitude_urad: f64,
}

/// The shape of a selected periodic error, fitted on every row.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeriesShape {
    /// RMS of the joint error over the data (its mean removed), µrad.
    pub rms_urad: f64,
    /// The span of the joint's angles in the data, degrees: no period longer than this is
    /// resolved.
    pub range_deg: f64,
    /// The strongest harmonics among those whose period fits in the range, largest first.
    pub dominant: Vec<DominantHarmonic>,
}

/// One order of a selected series and its held-out errors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OrderScore {
    /// Harmonics 1 to this.
    pub order: u32,
    /// Mean held-out position error over the random folds, mm.
    pub random_folds_mm: f64,
    /// Mean held-out position error over arcs of every other moving joint, mm; `None` where no
    /// other joint moves.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub arcs_mm: Option<f64>,
}

/// An effect the selection kept.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SelectedEffect {
    /// The effect.
    pub effect: Effect,
    /// 1-based joints.
    pub joints: Vec<usize>,
    /// For gear periodic error: the order of the Fourier series a fit on every row should use
    /// (harmonics 1 to this).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub harmonic: Option<u32>,
    /// For gear periodic error: the order each fold chose by cross-validation on its own rows.
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub fold_orders: Vec<u32>,
    /// For gear periodic error: every order it may take, with its held-out error over the random
    /// folds and over the other joints' arcs; `harmonic` minimises their weighted sum
    /// (`SelectionOptions::arc_order_weight`).
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub order_curve: Vec<OrderScore>,
    /// For gear periodic error: its size and strongest periods.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub shape: Option<SeriesShape>,
    /// Cross-validated mean position error with it and every earlier selection, mm.
    pub heldout_after_mm: f64,
    /// Signed-rank statistic of its per-pose gain over the previous step.
    pub z: f64,
}

fn describe(effect: Effect, joints: &[usize], harmonic: Option<u32>) -> String {
    let mut text = effect.name().replace('_', " ");
    if !joints.is_empty() {
        let list: Vec<String> = joints.iter().map(usize::to_string).collect();
        text.push_str(&format!(" on joint{} {}", if joints.len() > 1 { "s" } else { "" }, list.join(", ")));
    }
    if let Some(h) = harmonic {
        text.push_str(&format!(" (harmonics 1–{h})"));
    }
    text
}

fn describe_selected(s: &SelectedEffect) -> String {
    let mut text = describe(s.effect, &s.joints, s.harmonic);
    if let Some(shape) = &s.shape {
        text.push_str(&format!(", {:.0} µrad RMS", shape.rms_urad));
        if shape.dominant.is_empty() {
            text.push_str(&format!(", no period shorter than its {:.0}° range", shape.range_deg));
        } else {
            let periods: Vec<String> =
                shape.dominant.iter().map(|h| format!("{:.1}° ({:.0} µrad)", h.period_deg, h.amplitude_urad)).collect();
            text.push_str(&format!(", dominant periods {}", periods.join(", ")));
        }
    }
    text
}

fn noise_source(noise: &super::NoiseFloor) -> String {
    match noise.source {
        NoiseSource::Given => "given".into(),
        NoiseSource::Repeats => "from repeated poses".into(),
        NoiseSource::Stated => "the tracker's stated uncertainty of each row".into(),
        NoiseSource::TrackerDefault => {
            format!("tracker default: {}", noise.instrument.as_deref().unwrap_or("laser tracker"))
        }
    }
}

fn list(joints: &[usize]) -> String {
    joints.iter().map(usize::to_string).collect::<Vec<_>>().join(", ")
}

impl Diagnosis {
    /// The SPEC JSON text: the diagnosis as it is, without the per-pose table.
    pub fn to_json(&self) -> Result<String, Error> {
        serde_json::to_string(self).map_err(|source| Error::new(ErrorKind::Json { what: "diagnosis", source }))
    }

    /// The region whose geometric-model error is largest, with at least 15 poses.
    fn worst_region(&self) -> Option<&Region> {
        self.regions
            .iter()
            .filter(|r| r.dimension != "component" && r.n >= 15)
            .max_by(|a, b| a.before_mm.total_cmp(&b.before_mm))
    }

    /// A summary a person reads in ten seconds.
    pub fn summary(&self) -> String {
        let mut out = String::new();
        let kind = if self.full_pose { "full pose" } else { "position only" };
        out.push_str(&format!(
            "{}: {} poses, {kind}, joints moving: {}\n",
            self.robot,
            self.n,
            list(&self.moving_joints)
        ));
        out.push_str(&self.gross_outliers.summary_line().unwrap_or_default());
        out.push_str(&format!("  verdict:        {}\n", self.verdict_text()));
        self.summary_errors(&mut out);
        for s in &self.selected {
            out.push_str(&format!(
                "  selected:       {} -> {:.4} mm (z = {:.1})\n",
                describe_selected(s),
                s.heldout_after_mm,
                s.z
            ));
        }
        self.summary_structure(&mut out);
        self.summary_floor_and_runners(&mut out);
        out
    }

    /// The verdict as the summary words it.
    fn verdict_text(&self) -> String {
        match self.verdict.effect {
            _ if self.gross_outliers.attribution_refused => self.gross_outliers.verdict_reason().unwrap_or_default(),
            Effect::None => "none: nothing beats the noise floor significantly".to_owned(),
            Effect::Unknown if self.verdict.joints.is_empty() => {
                "unknown: structure is left that no candidate explains".to_owned()
            }
            Effect::Unknown => format!(
                "unknown: structure no candidate explains, in the {} of joint{} {}",
                // A prismatic joint has a position, not an angle.
                match self.verdict.joints.iter().filter(|j| self.prismatic_joints.contains(j)).count() {
                    0 => "angles",
                    n if n == self.verdict.joints.len() => "positions",
                    _ => "angles and positions",
                },
                if self.verdict.joints.len() > 1 { "s" } else { "" },
                list(&self.verdict.joints)
            ),
            _ => describe(self.verdict.effect, &self.verdict.joints, None),
        }
    }

    /// The summary's held-out errors: with the verdict's effect, every selected effect, and off
    /// the poses.
    fn summary_errors(&self, out: &mut String) {
        let change = |after: f64| 100.0 * (1.0 - after / self.heldout_before_mm.max(f64::MIN_POSITIVE));
        out.push_str(&format!(
            "  held-out error: {:.4} mm -> {:.4} mm with the verdict's effect ({:.0} % less)\n",
            self.heldout_before_mm,
            self.heldout_after_mm,
            change(self.heldout_after_mm)
        ));
        if (self.heldout_after_selected_mm - self.heldout_after_mm).abs() > 1e-9 {
            out.push_str(&format!(
                "                  {:.4} mm with every selected effect ({:.0} % less)\n",
                self.heldout_after_selected_mm,
                change(self.heldout_after_selected_mm)
            ));
        }
        if let (Some(before), Some(after)) = (self.off_poses_before_mm, self.off_poses_after_mm) {
            let per_joint: Vec<String> =
                self.arcs.iter().map(|a| format!("{} {:.3} -> {:.3}", a.joint, a.before_mm, a.after_mm)).collect();
            out.push_str(&format!(
                "  off the poses:  {before:.4} mm -> {after:.4} mm ({:.0} % less) with arcs of one joint's angles held out\n                  (the ends of its range, gaps, other configurations; per joint, mm: {})\n",
                100.0 * (1.0 - after / before.max(f64::MIN_POSITIVE)),
                per_joint.join(", ")
            ));
        }
    }

    /// The summary's GP lines: what any smooth model could reach, and what is left.
    fn summary_structure(&self, out: &mut String) {
        if let Some(gp) = &self.explainable {
            out.push_str(&format!(
                "  a GP on the joint angles: {:.4} mm held out (what any smooth model could reach)",
                gp.heldout_after_gp_mm
            ));
            match self.explained_fraction {
                Some(f) => out.push_str(&format!("; the selected effects explain {:.0} % of that\n", 100.0 * f)),
                None => out.push('\n'),
            }
        }
        if let Some(r) = self.remaining.as_ref().filter(|r| r.significant) {
            out.push_str(&format!(
                "  left:           a GP on what the effects leave still lowers it to {:.4} mm (z = {:.1})\n",
                r.heldout_after_gp_mm, r.z
            ));
        }
    }

    /// The summary's last lines: the noise floor, the best candidates alone, the worst region.
    fn summary_floor_and_runners(&self, out: &mut String) {
        out.push_str(&format!(
            "  noise floor:    {:.4} mm ({:.4} mm per axis, {})\n",
            self.noise.floor_mm,
            self.noise.sigma_mm,
            noise_source(&self.noise)
        ));
        let runners: Vec<String> = self
            .candidates
            .iter()
            .take(3)
            .map(|c| format!("{} {:.4} mm", describe(c.effect, &c.joints, c.harmonic), c.heldout_after_mm))
            .collect();
        out.push_str(&format!("  best alone:     {}\n", runners.join("; ")));
        if let Some(r) = self.worst_region() {
            out.push_str(&format!(
                "  worst region:   {} {} ({} poses): {:.4} mm -> {:.4} mm\n",
                r.dimension, r.bin, r.n, r.before_mm, r.after_mm
            ));
        }
    }

    /// The plots, in the order the markdown shows them: held-out error against each moving joint,
    /// the payload, the temperature and the time (the last three where they vary), before and
    /// after. Data only: `report::diagnosis_figures` draws them.
    pub fn error_plots(&self) -> Vec<ErrorPlot> {
        let plot = |file_name: String, title: String, x_label: String, key: &dyn Fn(&PoseDiagnosis) -> f64| ErrorPlot {
            file_name,
            title,
            x_label,
            before_mm: self.poses.iter().map(|p| (key(p), p.before_error_mm())).collect(),
            after_mm: self.poses.iter().map(|p| (key(p), p.after_error_mm())).collect(),
        };
        let mut plots = Vec::new();
        for &joint in &self.moving_joints {
            let j = joint - 1;
            let title = format!("Held-out error against joint {joint}");
            let file_name = format!("joint{joint}.svg");
            plots.push(if self.prismatic_joints.contains(&joint) {
                plot(file_name, title, format!("joint {joint} (mm)"), &|p| p.q[j] * 1e3)
            } else {
                plot(file_name, title, format!("joint {joint} (deg)"), &|p| p.q[j].to_degrees())
            });
        }
        let varies = |key: &dyn Fn(&PoseDiagnosis) -> Option<f64>| {
            let values: Vec<f64> = self.poses.iter().filter_map(key).collect();
            values.len() == self.poses.len() && values.iter().any(|v| *v != values[0])
        };
        if varies(&|p| Some(p.payload_kg)) {
            let title = "Held-out error against payload".into();
            plots.push(plot("payload.svg".into(), title, "payload (kg)".into(), &|p| p.payload_kg));
        }
        if varies(&|p| p.temp_c) {
            let title = "Held-out error against temperature".into();
            let x_label = "temperature (°C)".into();
            plots.push(plot("temperature.svg".into(), title, x_label, &|p| p.temp_c.unwrap_or(0.0)));
        }
        if varies(&|p| p.t_s) {
            let title = "Held-out error against time".into();
            plots.push(plot("time.svg".into(), title, "time (h)".into(), &|p| p.t_s.unwrap_or(0.0) / 3600.0));
        }
        plots
    }

    /// The markdown report; `plots` are the file names of [`Diagnosis::error_plots`], relative to it.
    pub fn markdown(&self, plots: &[String]) -> String {
        let mut out = format!("# Diagnosis: {}\n\n```\n{}```\n\n", self.robot, self.summary());
        self.markdown_which(&mut out);
        self.markdown_where(&mut out);
        if !plots.is_empty() {
            out.push_str("\n## Plots\n\n");
            for p in plots {
                out.push_str(&format!("![{p}]({p})\n\n"));
            }
        }
        out
    }

    /// The report's *Which effect*: every candidate alone, the selected steps, the GP checks.
    fn markdown_which(&self, out: &mut String) {
        out.push_str("## Which effect\n\nEvery candidate alone on top of the geometric model, cross-validated ");
        out.push_str(&format!(
            "({} poses; a step is kept when its signed-rank z exceeds {:.2}):\n\n",
            self.n, self.critical_z
        ));
        out.push_str("| candidate | parameters | held-out mean error (mm) |\n| --- | ---: | ---: |\n");
        out.push_str(&format!("| geometric model alone | 0 | {:.4} |\n", self.heldout_before_mm));
        for c in &self.candidates {
            out.push_str(&format!(
                "| {} | {} | {:.4} |\n",
                describe(c.effect, &c.joints, c.harmonic),
                c.parameters,
                c.heldout_after_mm
            ));
        }
        out.push_str("\nSelected, in order:\n\n");
        if self.selected.is_empty() {
            out.push_str("- nothing\n");
        }
        for s in &self.selected {
            out.push_str(&format!("- {}: {:.4} mm (z = {:.1})", describe_selected(s), s.heldout_after_mm, s.z));
            if !s.fold_orders.is_empty() {
                out.push_str(&format!("; orders chosen inside the folds: {:?}", s.fold_orders));
            }
            out.push('\n');
        }
        for (title, check) in [
            ("the geometric model's residual", &self.explainable),
            ("what the selected effects leave", &self.remaining),
        ] {
            if let Some(gp) = check {
                out.push_str(&format!(
                    "\nA cross-validated GP on {title}: {:.4} mm held out (z = {:.1}, {:.0} % less{}). Length scales (input standard deviations): {}.\n",
                    gp.heldout_after_gp_mm,
                    gp.z,
                    100.0 * gp.gain,
                    if gp.significant { ", significant" } else { "" },
                    gp.length_scales
                        .iter()
                        .map(|s| format!("{:?} {:.2}", s.input, s.length_scale))
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            }
        }
    }

    /// The report's *Where*: the held-out error by region against the noise floor.
    fn markdown_where(&self, out: &mut String) {
        out.push_str(&format!(
            "\n## Where\n\nHeld-out position error by region (mm), noise floor {:.4} mm ({}).\n\n",
            self.noise.floor_mm,
            noise_source(&self.noise)
        ));
        out.push_str("| by | group | poses | geometric model | with the selected effects | before / floor |\n| --- | --- | ---: | ---: | ---: | ---: |\n");
        for r in &self.regions {
            out.push_str(&format!(
                "| {} | {} | {} | {:.4} | {:.4} | {:.1} |\n",
                r.dimension,
                r.bin,
                r.n,
                r.before_mm,
                r.after_mm,
                r.before_mm / self.noise.floor_mm.max(f64::MIN_POSITIVE)
            ));
        }
    }
}
