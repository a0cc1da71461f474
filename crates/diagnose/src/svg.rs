//! The diagnosis's charts: scatter plots of the held-out error, on the shared [`crate::chart`]
//! frame.

use crate::chart::{Canvas, escape, format_tick, linear_ticks};
use std::fmt::Write;

/// One set of points drawn in one colour.
#[derive(Debug, Clone)]
pub(crate) struct Series {
    /// Legend text.
    pub name: String,
    /// CSS colour.
    pub colour: &'static str,
    /// `(x, y)` points.
    pub points: Vec<(f64, f64)>,
}

const CANVAS: Canvas = Canvas { width: 640.0, height: 400.0, left: 70.0, right: 20.0, top: 40.0, bottom: 55.0 };

/// A scatter plot of `series` with a zero-based y axis.
pub(crate) fn scatter(title: &str, x_label: &str, y_label: &str, series: &[Series]) -> String {
    let all = series.iter().flat_map(|s| s.points.iter()).filter(|(x, y)| x.is_finite() && y.is_finite());
    let (mut x0, mut x1, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, 0.0_f64);
    for &(x, y) in all {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y1 = y1.max(y);
    }
    if !x0.is_finite() {
        (x0, x1) = (0.0, 1.0);
    }
    if x1 - x0 < 1e-12 {
        (x0, x1) = (x0 - 0.5, x1 + 0.5);
    }
    let y1 = if y1 > 0.0 { y1 * 1.05 } else { 1.0 };
    let (left, top) = (CANVAS.left, CANVAS.top);
    let (pw, ph) = (CANVAS.plot_width(), CANVAS.plot_height());
    let sx = |x: f64| left + (x - x0) / (x1 - x0) * pw;
    let sy = |y: f64| top + ph - y / y1 * ph;
    let mut out = CANVAS.open(title);
    for t in linear_ticks(x0, x1) {
        let x = sx(t);
        let _ = write!(out, r##"<line x1="{x:.1}" y1="{top}" x2="{x:.1}" y2="{:.1}" stroke="#e8e8e8"/>"##, top + ph);
        let _ = write!(
            out,
            r#"<text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            top + ph + 16.0,
            format_tick(t)
        );
    }
    CANVAS.y_grid(&mut out, &linear_ticks(0.0, y1), &sy);
    CANVAS.frame(&mut out, y_label);
    let _ = write!(
        out,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
        left + pw / 2.0,
        CANVAS.height - 12.0,
        escape(x_label)
    );
    for s in series {
        let _ = write!(out, r#"<g fill="{}" fill-opacity="0.55">"#, s.colour);
        for &(x, y) in s.points.iter().filter(|(x, y)| x.is_finite() && y.is_finite()) {
            let _ = write!(out, r#"<circle cx="{:.1}" cy="{:.1}" r="2.2"/>"#, sx(x), sy(y));
        }
        out.push_str("</g>");
    }
    for (k, s) in series.iter().enumerate() {
        let y = top + 14.0 + 16.0 * k as f64;
        let x = left + pw - 150.0;
        let _ = write!(out, r#"<circle cx="{x:.1}" cy="{:.1}" r="4" fill="{}"/>"#, y - 4.0, s.colour);
        let _ = write!(out, r#"<text x="{:.1}" y="{y:.1}">{}</text>"#, x + 8.0, escape(&s.name));
    }
    out.push_str("</svg>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scatter_plot_is_well_formed_svg_with_every_point() {
        let series =
            [Series { name: "a <b>".into(), colour: "#000", points: vec![(0.0, 1.0), (1.0, 2.0), (f64::NAN, 1.0)] }];
        let svg = scatter("t & u", "x", "y", &series);
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert_eq!(svg.matches("<circle").count(), 2 + 1, "two points and one legend marker");
        assert!(svg.contains("a &lt;b&gt;") && svg.contains("t &amp; u"));
    }
}
