//! A hand-written SVG box plot (the paper's Fig. 1 kind): one box per group, Tukey whiskers,
//! outliers as circles, every value drawn as a dot beside its box.
//!
//! Drawn on the experiments' shared frame, `chart.rs` (hand-written SVG; see there for why not
//! `plotters`).

use crate::experiments::chart::{Canvas, escape, linear_ticks};
use std::fmt::Write;

/// One box: its label under the axis and the values it summarises.
#[derive(Debug, Clone)]
pub struct BoxGroup {
    /// Text under the box.
    pub label: String,
    /// The values (e.g. the per-fold mean errors).
    pub values: Vec<f64>,
}

/// The five numbers a box shows and the values beyond its whiskers.
#[derive(Debug, Clone, PartialEq)]
pub struct BoxStatistics {
    /// First quartile.
    pub q1: f64,
    /// Median.
    pub median: f64,
    /// Third quartile.
    pub q3: f64,
    /// Lowest value within 1.5 IQR below the first quartile.
    pub whisker_low: f64,
    /// Highest value within 1.5 IQR above the third quartile.
    pub whisker_high: f64,
    /// Values outside the whiskers.
    pub outliers: Vec<f64>,
}

/// The `p`-quantile of sorted values, interpolated linearly between order statistics (numpy's and
/// matplotlib's default, so that the boxes match what the paper's Python would have drawn).
fn quantile(sorted: &[f64], p: f64) -> f64 {
    let position = p * (sorted.len() - 1) as f64;
    let below = position.floor() as usize;
    let above = (below + 1).min(sorted.len() - 1);
    sorted[below] + (position - below as f64) * (sorted[above] - sorted[below])
}

impl BoxStatistics {
    /// Tukey's box of the finite values; `None` when there are none.
    pub fn of(values: &[f64]) -> Option<Self> {
        let mut sorted: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
        if sorted.is_empty() {
            return None;
        }
        sorted.sort_by(f64::total_cmp);
        let (q1, median, q3) = (quantile(&sorted, 0.25), quantile(&sorted, 0.5), quantile(&sorted, 0.75));
        let reach = 1.5 * (q3 - q1);
        let inside = |v: &&f64| **v >= q1 - reach && **v <= q3 + reach;
        let whisker_low = sorted.iter().find(inside).copied().unwrap_or(q1);
        let whisker_high = sorted.iter().rev().find(inside).copied().unwrap_or(q3);
        let outliers = sorted.iter().copied().filter(|v| !inside(&v)).collect();
        Some(Self { q1, median, q3, whisker_low, whisker_high, outliers })
    }
}

const CANVAS: Canvas = Canvas { width: 720.0, height: 460.0, left: 70.0, right: 20.0, top: 40.0, bottom: 60.0 };
const LEFT: f64 = CANVAS.left;
const TOP: f64 = CANVAS.top;
const COLOURS: [&str; 6] = ["#4c72b0", "#dd8452", "#55a868", "#c44e52", "#8172b3", "#937860"];

/// Tick values of a log axis over `[low, high]`: 1, 2 and 5 times the powers of ten inside.
fn log_ticks(low: f64, high: f64) -> Vec<f64> {
    let first = low.log10().floor() as i32;
    let last = high.log10().ceil() as i32;
    (first..=last)
        .flat_map(|e| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(e)))
        .filter(|t| *t >= low * (1.0 - 1e-9) && *t <= high * (1.0 + 1e-9))
        .collect()
}

/// The largest of 1, 2 and 5 times a power of ten at or below `v > 0`.
fn step_below(v: f64) -> f64 {
    let decade = 10f64.powf(v.log10().floor());
    [5.0, 2.0, 1.0].iter().map(|m| m * decade).find(|s| *s <= v * (1.0 + 1e-9)).unwrap_or(decade)
}

/// The smallest of 1, 2 and 5 times a power of ten at or above `v > 0`.
fn step_above(v: f64) -> f64 {
    let decade = 10f64.powf(v.log10().floor());
    [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * decade).find(|s| *s >= v * (1.0 - 1e-9)).unwrap_or(10.0 * decade)
}

/// A box plot of `groups`. The y axis is logarithmic when `log` (so that boxes an order of
/// magnitude apart are all readable), else linear from zero.
pub fn box_plot(title: &str, y_label: &str, groups: &[BoxGroup], log: bool) -> String {
    let finite =
        || groups.iter().flat_map(|g| g.values.iter().copied()).filter(|v| v.is_finite() && (!log || *v > 0.0));
    let (low, high) = finite().fold((f64::INFINITY, 0.0_f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let (y0, y1) = match (log, high > 0.0) {
        (true, true) => (step_below(low), step_above(high)),
        (false, true) => (0.0, high * 1.08),
        (_, false) => (if log { 0.1 } else { 0.0 }, 1.0),
    };
    let (pw, ph) = (CANVAS.plot_width(), CANVAS.plot_height());
    let sy = |y: f64| {
        let fraction = if log { (y.log10() - y0.log10()) / (y1.log10() - y0.log10()) } else { (y - y0) / (y1 - y0) };
        TOP + ph - fraction * ph
    };
    let slot = pw / groups.len().max(1) as f64;
    let mut out = CANVAS.open(title);
    let ticks = if log { log_ticks(y0, y1) } else { linear_ticks(0.0, y1) };
    CANVAS.y_grid(&mut out, &ticks, &sy);
    CANVAS.frame(&mut out, y_label);
    for (k, group) in groups.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        let centre = LEFT + slot * (k as f64 + 0.5);
        let half = (slot * 0.22).min(40.0);
        label(&mut out, centre, TOP + ph + 18.0, &group.label);
        let Some(s) = BoxStatistics::of(&group.values.iter().copied().filter(|v| !log || *v > 0.0).collect::<Vec<_>>())
        else {
            continue;
        };
        draw_box(&mut out, &s, centre, half, colour, &sy);
        let right = centre + half;
        // Every value as a small dot to the right of its box: ten folds are few enough to show.
        let _ = write!(out, r#"<g fill="{colour}">"#);
        for v in group.values.iter().filter(|v| v.is_finite() && (!log || **v > 0.0)) {
            let _ = write!(out, r#"<circle cx="{:.1}" cy="{:.1}" r="2"/>"#, right + 8.0, sy(*v));
        }
        out.push_str("</g>");
    }
    out.push_str("</svg>\n");
    out
}

/// The label under a box, one `<tspan>` per line: SVG text does not wrap.
fn label(out: &mut String, centre: f64, y: f64, text: &str) {
    let _ = write!(out, r#"<text x="{centre:.1}" y="{y:.1}" text-anchor="middle">"#);
    for (i, line) in text.lines().enumerate() {
        let dy = if i == 0 { 0.0 } else { 14.0 };
        let _ = write!(out, r#"<tspan x="{centre:.1}" dy="{dy}">{}</tspan>"#, escape(line));
    }
    out.push_str("</text>");
}

/// One box of half-width `half` at `centre`: whiskers, the quartiles' box, the median and the
/// outliers, `sy` mapping a value to its y.
fn draw_box(out: &mut String, s: &BoxStatistics, centre: f64, half: f64, colour: &str, sy: &dyn Fn(f64) -> f64) {
    let (left, right) = (centre - half, centre + half);
    let _ = write!(out, r##"<g stroke="#333333" fill="none">"##);
    let _ = write!(
        out,
        r#"<line x1="{centre:.1}" y1="{:.1}" x2="{centre:.1}" y2="{:.1}"/><line x1="{centre:.1}" y1="{:.1}" x2="{centre:.1}" y2="{:.1}"/>"#,
        sy(s.whisker_low),
        sy(s.q1),
        sy(s.q3),
        sy(s.whisker_high)
    );
    for w in [s.whisker_low, s.whisker_high] {
        let _ = write!(
            out,
            r#"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}"/>"#,
            centre - half / 2.0,
            sy(w),
            centre + half / 2.0,
            sy(w)
        );
    }
    out.push_str("</g>");
    let _ = write!(
        out,
        r##"<rect x="{left:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="{colour}" fill-opacity="0.35" stroke="#333333"/>"##,
        sy(s.q3),
        right - left,
        (sy(s.q1) - sy(s.q3)).max(0.5)
    );
    let _ = write!(
        out,
        r##"<line x1="{left:.1}" y1="{:.1}" x2="{right:.1}" y2="{:.1}" stroke="#000000" stroke-width="2"/>"##,
        sy(s.median),
        sy(s.median)
    );
    for o in &s.outliers {
        let _ = write!(out, r##"<circle cx="{centre:.1}" cy="{:.1}" r="3.5" fill="none" stroke="#333333"/>"##, sy(*o));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quartiles_interpolate_like_numpy_and_far_values_are_outliers() {
        let s = BoxStatistics::of(&[1.0, 2.0, 3.0, 4.0, 100.0]).unwrap();
        assert_eq!((s.q1, s.median, s.q3), (2.0, 3.0, 4.0));
        assert_eq!((s.whisker_low, s.whisker_high), (1.0, 4.0));
        assert_eq!(s.outliers, vec![100.0]);
        assert!(BoxStatistics::of(&[f64::NAN]).is_none());
    }

    #[test]
    fn a_box_plot_is_well_formed_svg_with_one_box_per_group() {
        let groups = [
            BoxGroup { label: "base <tool>".into(), values: vec![1.9, 2.0, 1.8] },
            BoxGroup { label: "poe".into(), values: vec![0.05, 0.06, 0.04] },
        ];
        for log in [false, true] {
            let svg = box_plot("t & u", "mm", &groups, log);
            assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
            assert_eq!(svg.matches("fill-opacity=\"0.35\"").count(), 2);
            assert!(svg.contains("base &lt;tool&gt;") && svg.contains("t &amp; u"));
            assert!(!svg.contains("NaN") && !svg.contains("inf"));
        }
    }

    #[test]
    fn log_axes_run_between_one_two_five_steps() {
        let close = |a: &[f64], b: &[f64]| a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
        assert!(close(&log_ticks(0.01, 1.0), &[0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0]));
        assert!(close(&[step_below(0.143), step_above(3.11)], &[0.1, 5.0]));
        assert!(close(&[step_below(0.25), step_above(0.5)], &[0.2, 0.5]));
    }
}
