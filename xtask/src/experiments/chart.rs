//! The frame the experiments' charts share, as SVG text: the canvas with its title, grid lines
//! with tick labels, the plot area's border and the axis label. The box plots and the GP sweep's
//! plots draw their marks inside it. (The calibration report's and the diagnosis's charts are
//! `report`'s, drawn with `plotters`.)
//!
//! Hand-written rather than through `plotters`: its text layout needs a system font library
//! (font-kit / fontconfig) that a clean CI machine may lack, and these charts need no more than
//! rectangles, lines and `<text>` that the viewer lays out itself.

use std::fmt::Write;

/// A canvas and the margins around its plot area, pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Canvas {
    /// Width of the picture.
    pub width: f64,
    /// Height of the picture.
    pub height: f64,
    /// Margin left of the plot area (tick labels, the y label).
    pub left: f64,
    /// Margin right of it.
    pub right: f64,
    /// Margin above it (the title).
    pub top: f64,
    /// Margin below it (tick labels, the x label).
    pub bottom: f64,
}

impl Canvas {
    /// Width of the plot area.
    pub fn plot_width(&self) -> f64 {
        self.width - self.left - self.right
    }

    /// Height of the plot area.
    pub fn plot_height(&self) -> f64 {
        self.height - self.top - self.bottom
    }

    /// The `<svg>` element, a white background and the title.
    pub fn open(&self, title: &str) -> String {
        let (w, h) = (self.width, self.height);
        let mut out = format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">"#
        );
        out.push_str(r#"<rect width="100%" height="100%" fill="white"/>"#);
        let _ =
            write!(out, r#"<text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>"#, w / 2.0, escape(title));
        out
    }

    /// Horizontal grid lines with their labels at `ticks`; `to_y` maps a value to a pixel row.
    pub fn y_grid(&self, out: &mut String, ticks: &[f64], to_y: &dyn Fn(f64) -> f64) {
        for &t in ticks {
            let y = to_y(t);
            let _ = write!(
                out,
                r##"<line x1="{}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#e8e8e8"/>"##,
                self.left,
                self.left + self.plot_width()
            );
            let _ = write!(
                out,
                r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"#,
                self.left - 6.0,
                y + 4.0,
                format_tick(t)
            );
        }
    }

    /// The border of the plot area and the y axis's label, turned upright.
    pub fn frame(&self, out: &mut String, y_label: &str) {
        let _ = write!(
            out,
            r##"<rect x="{}" y="{}" width="{}" height="{}" fill="none" stroke="#444444"/>"##,
            self.left,
            self.top,
            self.plot_width(),
            self.plot_height()
        );
        let _ = write!(
            out,
            r#"<text transform="translate(18 {:.1}) rotate(-90)" text-anchor="middle">{}</text>"#,
            self.top + self.plot_height() / 2.0,
            escape(y_label)
        );
    }
}

/// Text made safe for SVG.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// A tick value without trailing zeros.
pub fn format_tick(t: f64) -> String {
    if t == 0.0 {
        return "0".into();
    }
    let text = format!("{t:.4}");
    text.trim_end_matches('0').trim_end_matches('.').to_owned()
}

/// Round tick positions inside `[low, high]`: the step of 1, 2, 2.5 or 5 times a power of ten
/// nearest (in ratio) to a fifth of the span, so that 4 to 8 ticks show.
pub fn linear_ticks(low: f64, high: f64) -> Vec<f64> {
    let span = (high - low).abs().max(1e-12);
    let raw = span / 5.0;
    let magnitude = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * magnitude)
        .min_by(|a, b| (a / raw).ln().abs().total_cmp(&(b / raw).ln().abs()))
        .unwrap_or(magnitude);
    let first = (low / step).ceil() * step;
    (0..).map(|k| first + k as f64 * step).take_while(|t| *t <= high + 1e-9 * step).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_cover_the_range() {
        assert_eq!(linear_ticks(0.0, 1.0), vec![0.0, 0.2, 0.4, 0.6000000000000001, 0.8, 1.0]);
        for (low, high) in [(-173.0, 161.0), (0.0, 0.037), (20.0, 23.5), (0.0, 9000.0)] {
            let t = linear_ticks(low, high);
            assert!(t[0] >= low && *t.last().unwrap() <= high && (4..=8).contains(&t.len()), "{low}..{high}: {t:?}");
        }
    }

    #[test]
    fn a_frame_is_well_formed_svg_with_escaped_text() {
        let canvas = Canvas { width: 300.0, height: 200.0, left: 50.0, right: 10.0, top: 30.0, bottom: 40.0 };
        let mut svg = canvas.open("a < b & c");
        canvas.y_grid(&mut svg, &[0.0, 0.5, 1.0], &|v| 160.0 - 130.0 * v);
        canvas.frame(&mut svg, "error (mm)");
        svg.push_str("</svg>");
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>"));
        assert!(svg.contains("a &lt; b &amp; c") && svg.contains(">0.5</text>"));
        assert_eq!(svg.matches("<line").count(), 3);
    }
}
