//! The diagnosis as people read it: the verdict, the ranking, a ten-second summary, a markdown
//! report with plots, and the SPEC's JSON.

use super::candidates::{Candidate, Effect};
use super::noise::{NoiseFloor, NoiseSource};
use super::regions::{PoseDiagnosis, Region};
use super::selection::{CrossValidated, Selection};
use super::{Diagnosis, svg};
use crate::{MeasurementSet, RobotDescription};
use serde::{Deserialize, Serialize};

/// The SPEC's `verdict`: the effect that explains the residual and the joints it involves.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Verdict {
    /// The effect.
    pub effect: Effect,
    /// 1-based joints, ascending; empty where none.
    pub joints: Vec<usize>,
}

/// One candidate tried alone on top of the geometric model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateScore {
    /// The effect.
    pub effect: Effect,
    /// 1-based joints.
    pub joints: Vec<usize>,
    /// Harmonic order, for gear periodic error.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub harmonic: Option<u32>,
    /// Number of parameters it adds.
    pub parameters: usize,
    /// Cross-validated mean position error with it, mm.
    pub heldout_after_mm: f64,
}

/// An effect the selection kept.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SelectedEffect {
    /// The effect.
    pub effect: Effect,
    /// 1-based joints.
    pub joints: Vec<usize>,
    /// Harmonic order, for gear periodic error.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub harmonic: Option<u32>,
    /// Cross-validated mean position error with it and every earlier selection, mm.
    pub heldout_after_mm: f64,
    /// Paired t statistic of its gain.
    pub t: f64,
}

/// What a GP on the final held-out residual still finds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Remaining {
    /// Cross-validated mean position error once the GP's prediction of the residual is removed, mm.
    pub heldout_after_gp_mm: f64,
    /// Paired t statistic of the GP's gain.
    pub t: f64,
    /// Whether the gain is significant and large enough to call the residual structured.
    pub significant: bool,
}

/// The per-axis RMS of the held-out residual, as a noise level (an upper bound).
pub(crate) fn residual_noise(result: &CrossValidated) -> NoiseFloor {
    let n = result.residuals.len().max(1) as f64;
    let sum: f64 = result.residuals.iter().map(|r| r.fixed_rows::<3>(0).norm_squared()).sum();
    NoiseFloor::from_sigma((sum / (3.0 * n)).sqrt() * 1e3, NoiseSource::HeldOutResidual)
}

pub(crate) fn assemble(
    robot: &RobotDescription,
    data: &MeasurementSet,
    candidates: &[Candidate],
    selection: &Selection,
    remaining: Option<Remaining>,
    noise: NoiseFloor,
    poses: Vec<PoseDiagnosis>,
) -> Diagnosis {
    let regions = super::regions::regions(&poses);
    let mut scores: Vec<CandidateScore> = candidates
        .iter()
        .zip(&selection.single)
        .map(|(c, r)| CandidateScore {
            effect: c.effect,
            joints: c.joints.clone(),
            harmonic: c.harmonic,
            parameters: c.columns.len(),
            heldout_after_mm: r.mean_error() * 1e3,
        })
        .collect();
    scores.sort_by(|a, b| a.heldout_after_mm.total_cmp(&b.heldout_after_mm));
    let selected: Vec<SelectedEffect> = selection
        .steps
        .iter()
        .map(|s| {
            let c = &candidates[s.candidate];
            SelectedEffect {
                effect: c.effect,
                joints: c.joints.clone(),
                harmonic: c.harmonic,
                heldout_after_mm: s.result.mean_error() * 1e3,
                t: s.t,
            }
        })
        .collect();
    let verdict = match selected.first() {
        None if remaining.is_some_and(|r| r.significant) => Verdict { effect: Effect::Unknown, joints: vec![] },
        None => Verdict { effect: Effect::None, joints: vec![] },
        Some(first) => {
            let mut joints: Vec<usize> =
                selected.iter().filter(|s| s.effect == first.effect).flat_map(|s| s.joints.iter().copied()).collect();
            joints.sort_unstable();
            joints.dedup();
            Verdict { effect: first.effect, joints }
        }
    };
    let after = selection.steps.last().map_or(&selection.baseline, |s| &s.result);
    Diagnosis {
        robot: robot.name.clone(),
        n: data.rows.len(),
        full_pose: data.full_pose,
        verdict,
        heldout_before_mm: selection.baseline.mean_error() * 1e3,
        heldout_after_mm: after.mean_error() * 1e3,
        candidates: scores,
        selected,
        critical_t: selection.critical_t,
        remaining,
        noise,
        regions,
        poses,
    }
}

fn describe(effect: Effect, joints: &[usize], harmonic: Option<u32>) -> String {
    let mut text = effect.name().replace('_', " ");
    if !joints.is_empty() {
        let list: Vec<String> = joints.iter().map(usize::to_string).collect();
        text.push_str(&format!(" on joint{} {}", if joints.len() > 1 { "s" } else { "" }, list.join(", ")));
    }
    if let Some(h) = harmonic {
        text.push_str(&format!(" (harmonic {h})"));
    }
    text
}

fn noise_source(source: NoiseSource) -> &'static str {
    match source {
        NoiseSource::Given => "given",
        NoiseSource::Repeats => "from repeated poses",
        NoiseSource::HeldOutResidual => "upper bound from the held-out residual",
        NoiseSource::ResidualGp => "what a GP leaves of the held-out residual",
    }
}

impl Diagnosis {
    /// The SPEC JSON object (with more fields than the SPEC requires).
    pub fn to_json(&self) -> serde_json::Value {
        let mut value = serde_json::to_value(self).unwrap_or(serde_json::Value::Null);
        if let Some(object) = value.as_object_mut() {
            object.remove("poses");
        }
        value
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
        out.push_str(&format!("{}: {} poses, {kind}\n", self.robot, self.n));
        let verdict = match self.verdict.effect {
            Effect::None => "none: nothing beats the noise floor significantly".to_owned(),
            Effect::Unknown => "unknown: structure is left that no candidate explains".to_owned(),
            _ => describe(self.verdict.effect, &self.verdict.joints, None),
        };
        out.push_str(&format!("  verdict:        {verdict}\n"));
        let change = 100.0 * (1.0 - self.heldout_after_mm / self.heldout_before_mm.max(f64::MIN_POSITIVE));
        out.push_str(&format!(
            "  held-out error: {:.4} mm -> {:.4} mm ({change:.0} % less)\n",
            self.heldout_before_mm, self.heldout_after_mm
        ));
        out.push_str(&format!(
            "  noise floor:    {:.4} mm ({:.4} mm per axis, {})\n",
            self.noise.floor_mm,
            self.noise.sigma_mm,
            noise_source(self.noise.source)
        ));
        for s in self.selected.iter().skip(1) {
            out.push_str(&format!(
                "  also:           {} -> {:.4} mm (t = {:.1})\n",
                describe(s.effect, &s.joints, s.harmonic),
                s.heldout_after_mm,
                s.t
            ));
        }
        if let Some(r) = self.remaining.filter(|r| r.significant) {
            out.push_str(&format!(
                "  left:           a GP on the residual still lowers it to {:.4} mm (t = {:.1}): something is unmodelled\n",
                r.heldout_after_gp_mm, r.t
            ));
        }
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
        out
    }

    /// The plots, as `(file name, SVG text)`: held-out error against each joint, the payload, the
    /// temperature and the time, before and after.
    pub fn plots(&self) -> Vec<(String, String)> {
        let mut plots = Vec::new();
        let series = |key: &dyn Fn(&PoseDiagnosis) -> f64| -> Vec<svg::Series> {
            vec![
                svg::Series {
                    name: "geometric model".into(),
                    colour: "#9a9a9a",
                    points: self.poses.iter().map(|p| (key(p), p.before_error_mm())).collect(),
                },
                svg::Series {
                    name: "with the verdict".into(),
                    colour: "#1f6fb4",
                    points: self.poses.iter().map(|p| (key(p), p.after_error_mm())).collect(),
                },
            ]
        };
        let joints = self.poses.first().map_or(0, |p| p.q.len());
        for j in 0..joints {
            let title = format!("Held-out error against joint {}", j + 1);
            let svg = svg::scatter(
                &title,
                &format!("joint {} (deg)", j + 1),
                "error (mm)",
                &series(&|p| p.q[j].to_degrees()),
            );
            plots.push((format!("joint{}.svg", j + 1), svg));
        }
        let varies = |key: &dyn Fn(&PoseDiagnosis) -> Option<f64>| {
            let values: Vec<f64> = self.poses.iter().filter_map(key).collect();
            values.len() == self.poses.len() && values.iter().any(|v| *v != values[0])
        };
        if varies(&|p| Some(p.payload_kg)) {
            plots.push((
                "payload.svg".into(),
                svg::scatter(
                    "Held-out error against payload",
                    "payload (kg)",
                    "error (mm)",
                    &series(&|p| p.payload_kg),
                ),
            ));
        }
        if varies(&|p| p.temp_c) {
            let s = series(&|p| p.temp_c.unwrap_or(0.0));
            plots.push((
                "temperature.svg".into(),
                svg::scatter("Held-out error against temperature", "temperature (°C)", "error (mm)", &s),
            ));
        }
        if varies(&|p| p.t_s) {
            let s = series(&|p| p.t_s.unwrap_or(0.0) / 3600.0);
            plots.push(("time.svg".into(), svg::scatter("Held-out error against time", "time (h)", "error (mm)", &s)));
        }
        plots
    }

    /// The markdown report; `plots` are the file names of [`Diagnosis::plots`], relative to it.
    pub fn markdown(&self, plots: &[String]) -> String {
        let mut out = format!("# Diagnosis: {}\n\n```\n{}```\n\n", self.robot, self.summary());
        out.push_str("## Which effect\n\nEvery candidate alone on top of the geometric model, cross-validated ");
        out.push_str(&format!(
            "({} poses; a step is kept when its paired t exceeds {:.2}):\n\n",
            self.n, self.critical_t
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
            out.push_str(&format!(
                "- {}: {:.4} mm (t = {:.1})\n",
                describe(s.effect, &s.joints, s.harmonic),
                s.heldout_after_mm,
                s.t
            ));
        }
        out.push_str(&format!(
            "\n## Where\n\nHeld-out position error by region (mm), noise floor {:.4} mm ({}).\n\n",
            self.noise.floor_mm,
            noise_source(self.noise.source)
        ));
        out.push_str("| by | group | poses | geometric model | with the verdict | before / floor |\n| --- | --- | ---: | ---: | ---: | ---: |\n");
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
        if !plots.is_empty() {
            out.push_str("\n## Plots\n\n");
            for p in plots {
                out.push_str(&format!("![{p}]({p})\n\n"));
            }
        }
        out
    }
}
