//! Small self-contained SVG charts (scatter plots with axes, ticks and a legend).
//!
//! Hand-written rather than through `plotters`: its text layout needs a system font library
//! (font-kit / fontconfig) that a clean CI machine may lack, and these charts need no more than
//! points, lines and `<text>` that the viewer lays out itself.

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

const WIDTH: f64 = 640.0;
const HEIGHT: f64 = 400.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 20.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 55.0;

/// Round tick positions covering `[low, high]`, about five of them.
pub(crate) fn ticks(low: f64, high: f64) -> Vec<f64> {
    let span = (high - low).abs().max(1e-12);
    let raw = span / 5.0;
    let magnitude = 10f64.powf(raw.log10().floor());
    // The round step nearest to a fifth of the span (in ratio), so that 4 to 8 ticks show.
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * magnitude)
        .min_by(|a, b| (a / raw).ln().abs().total_cmp(&(b / raw).ln().abs()))
        .unwrap_or(magnitude);
    let first = (low / step).ceil() * step;
    (0..).map(|k| first + k as f64 * step).take_while(|t| *t <= high + 1e-9 * step).collect()
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

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
    let (pw, ph) = (WIDTH - LEFT - RIGHT, HEIGHT - TOP - BOTTOM);
    let sx = |x: f64| LEFT + (x - x0) / (x1 - x0) * pw;
    let sy = |y: f64| TOP + ph - y / y1 * ph;
    let mut out = String::new();
    let _ = write!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" viewBox="0 0 {WIDTH} {HEIGHT}" font-family="sans-serif" font-size="12">"#
    );
    let _ = write!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ =
        write!(out, r#"<text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>"#, WIDTH / 2.0, escape(title));
    for t in ticks(x0, x1) {
        let x = sx(t);
        let _ = write!(out, r##"<line x1="{x:.1}" y1="{TOP}" x2="{x:.1}" y2="{:.1}" stroke="#eeeeee"/>"##, TOP + ph);
        let _ = write!(
            out,
            r#"<text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            TOP + ph + 16.0,
            format_tick(t)
        );
    }
    for t in ticks(0.0, y1) {
        let y = sy(t);
        let _ = write!(out, r##"<line x1="{LEFT}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#eeeeee"/>"##, LEFT + pw);
        let _ = write!(
            out,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"#,
            LEFT - 6.0,
            y + 4.0,
            format_tick(t)
        );
    }
    let _ = write!(out, r##"<rect x="{LEFT}" y="{TOP}" width="{pw}" height="{ph}" fill="none" stroke="#444444"/>"##);
    let _ = write!(
        out,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
        LEFT + pw / 2.0,
        HEIGHT - 12.0,
        escape(x_label)
    );
    let _ = write!(
        out,
        r#"<text transform="translate(18 {:.1}) rotate(-90)" text-anchor="middle">{}</text>"#,
        TOP + ph / 2.0,
        escape(y_label)
    );
    for s in series {
        let _ = write!(out, r#"<g fill="{}" fill-opacity="0.55">"#, s.colour);
        for &(x, y) in s.points.iter().filter(|(x, y)| x.is_finite() && y.is_finite()) {
            let _ = write!(out, r#"<circle cx="{:.1}" cy="{:.1}" r="2.2"/>"#, sx(x), sy(y));
        }
        out.push_str("</g>");
    }
    for (k, s) in series.iter().enumerate() {
        let y = TOP + 14.0 + 16.0 * k as f64;
        let x = LEFT + pw - 150.0;
        let _ = write!(out, r#"<circle cx="{x:.1}" cy="{:.1}" r="4" fill="{}"/>"#, y - 4.0, s.colour);
        let _ = write!(out, r#"<text x="{:.1}" y="{y:.1}">{}</text>"#, x + 8.0, escape(&s.name));
    }
    out.push_str("</svg>\n");
    out
}

fn format_tick(t: f64) -> String {
    if t == 0.0 {
        return "0".into();
    }
    let text = format!("{t:.4}");
    text.trim_end_matches('0').trim_end_matches('.').to_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_cover_the_range() {
        assert_eq!(ticks(0.0, 1.0), vec![0.0, 0.2, 0.4, 0.6000000000000001, 0.8, 1.0]);
        for (low, high) in [(-173.0, 161.0), (0.0, 0.037), (20.0, 23.5), (0.0, 9000.0)] {
            let t = ticks(low, high);
            assert!(t[0] >= low && *t.last().unwrap() <= high && (4..=8).contains(&t.len()), "{low}..{high}: {t:?}");
        }
    }

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
