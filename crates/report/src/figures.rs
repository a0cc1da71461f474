//! The report's charts, drawn with `plotters` into SVG text: the error histogram, the workspace
//! projections coloured by error, an effect's curve with its σ band, and the scatter plots of the
//! diagnosis.

use crate::ErrorKind;
use crate::content::{EffectCurve, RowError};
use errors::Error;
use plotters::prelude::*;

/// Grey for the model before calibration (or the geometric model of the diagnosis).
const BEFORE: RGBColor = RGBColor(0x9a, 0x9a, 0x9a);
/// Blue for the calibrated model.
const AFTER: RGBColor = RGBColor(0x1f, 0x6f, 0xb4);
/// Orange for training angles.
const TRAINING: RGBColor = RGBColor(0xd9, 0x6c, 0x1e);

const FONT: &str = "sans-serif";
/// Tick labels and legend text, px of a 640-pixel-wide chart (shown at up to 880 px: 14 to 19 px
/// on the page, the body text's size).
const LABEL: u32 = 14;
/// Axis names.
const DESC: u32 = 15;
/// Tick labels and axis names of the 1100-pixel-wide workspace figure, shown at the page's width
/// (about 0.65 of its pixels on a laptop screen: 12 px on the page).
const WIDE_LABEL: u32 = 18;
/// Its plot titles.
const WIDE_CAPTION: u32 = 20;

/// Viridis (van der Walt & Smith, matplotlib 2.0's default: perceptually uniform, legible in grey
/// and to the colour-blind) at `t` in [0, 1], linear between nine of its samples.
fn viridis(t: f64) -> RGBColor {
    const ANCHORS: [(u8, u8, u8); 9] = [
        (68, 1, 84),
        (71, 44, 122),
        (59, 81, 139),
        (44, 113, 142),
        (33, 144, 141),
        (39, 173, 129),
        (92, 200, 99),
        (170, 220, 50),
        (253, 231, 37),
    ];
    let x = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 } * (ANCHORS.len() - 1) as f64;
    let k = (x.floor() as usize).min(ANCHORS.len() - 2);
    let f = x - k as f64;
    let mix = |a: u8, b: u8| (f64::from(a) + f * (f64::from(b) - f64::from(a))).round() as u8;
    let (a, b) = (ANCHORS[k], ANCHORS[k + 1]);
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// One set of points drawn in one colour.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text.
    pub name: String,
    /// Whether it is the "before" (grey) or the "after" (blue) series.
    pub after: bool,
    /// `(x, y)` points.
    pub points: Vec<(f64, f64)>,
}

fn plot_error(figure: &str) -> impl Fn(String) -> Error + '_ {
    move |message| Error::new(ErrorKind::Plot { figure: figure.to_owned(), message })
}

/// `[low, high]` of finite values, widened where they coincide; `fallback` where there are none.
fn span(values: impl Iterator<Item = f64>, fallback: (f64, f64)) -> (f64, f64) {
    let (a, b) =
        values.filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if !a.is_finite() {
        return fallback;
    }
    if b - a < 1e-12 { (a - 0.5, b + 0.5) } else { (a, b) }
}

/// Runs `draw` on a `width × height` SVG canvas and returns the SVG text.
fn svg(
    figure: &str,
    (width, height): (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, plotters::coord::Shift>) -> Result<(), String>,
) -> Result<String, Error> {
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot_error(figure)(e.to_string()))?;
        draw(&root).map_err(plot_error(figure))?;
        root.present().map_err(|e| plot_error(figure)(e.to_string()))?;
    }
    Ok(out)
}

/// A scatter plot of `series` with a zero-based y axis (the diagnosis's plots).
pub fn scatter(title: &str, x_label: &str, y_label: &str, series: &[Series]) -> Result<String, Error> {
    let (x0, x1) = span(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)), (0.0, 1.0));
    let (_, y1) = span(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)).chain([0.0]), (0.0, 1.0));
    svg(title, (820, 400), |root| {
        let (plot, legend) = root.split_horizontally(640);
        let mut chart = ChartBuilder::on(&plot)
            .caption(title, (FONT, 16))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(x0..x1, 0.0..y1 * 1.05)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .label_style((FONT, LABEL))
            .axis_desc_style((FONT, DESC))
            .x_desc(x_label)
            .y_desc(y_label)
            .draw()
            .map_err(|e| e.to_string())?;
        for s in series {
            let colour = if s.after { AFTER } else { BEFORE };
            chart
                .draw_series(
                    s.points
                        .iter()
                        .filter(|(x, y)| x.is_finite() && y.is_finite())
                        .map(|&p| Circle::new(p, 2, colour.mix(0.55).filled())),
                )
                .map_err(|e| e.to_string())?;
        }
        let entries: Vec<(&str, Glyph)> =
            series.iter().map(|s| (s.name.as_str(), Glyph::Dot(if s.after { AFTER } else { BEFORE }.into()))).collect();
        side_legend(&legend, &entries)
    })
}

/// Overlaid histograms of the position error before and after calibration, mm.
pub fn histogram(before: Option<&[f64]>, after: &[f64]) -> Result<String, Error> {
    const BINS: usize = 40;
    let all = after.iter().chain(before.into_iter().flatten()).copied();
    let (_, top) = span(all.chain([0.0]), (0.0, 1.0));
    let width = top / BINS as f64;
    let counts = |values: &[f64]| {
        let mut c = vec![0usize; BINS];
        for v in values.iter().filter(|v| v.is_finite()) {
            c[((v / width) as usize).min(BINS - 1)] += 1;
        }
        c
    };
    let after_counts = counts(after);
    let before_counts = before.map(counts);
    let peak = after_counts.iter().chain(before_counts.iter().flatten()).copied().max().unwrap_or(1).max(1);
    svg("histogram", (640, 360), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption("Position error on the test data", (FONT, 16))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..top, 0.0..peak as f64 * 1.08)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .label_style((FONT, LABEL))
            .axis_desc_style((FONT, DESC))
            .x_desc("position error (mm)")
            .y_desc("rows")
            .draw()
            .map_err(|e| e.to_string())?;
        let mut bars = |counts: &[usize], colour: RGBColor, name: &str| -> Result<(), String> {
            chart
                .draw_series(counts.iter().enumerate().filter(|(_, c)| **c > 0).map(|(k, &c)| {
                    let x = k as f64 * width;
                    Rectangle::new([(x, 0.0), (x + width, c as f64)], colour.mix(0.55).filled())
                }))
                .map_err(|e| e.to_string())?
                .label(name)
                .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], colour.filled()));
            Ok(())
        };
        if let Some(c) = &before_counts {
            bars(c, BEFORE, "before calibration (nominal)")?;
        }
        bars(&after_counts, AFTER, "after calibration")?;
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font((FONT, LABEL))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.3))
            .draw()
            .map_err(|e| e.to_string())
    })
}

/// The test poses seen from above (x–y) and from the side (x–z), coloured by the position error
/// after calibration, with the colour scale.
pub fn workspace(rows: &[RowError]) -> Result<String, Error> {
    let (_, e_max) = span(rows.iter().map(|r| r.after_mm).chain([0.0]), (0.0, 1.0));
    // Worst last, so that they are drawn on top.
    let mut order: Vec<&RowError> = rows.iter().collect();
    order.sort_by(|a, b| a.after_mm.total_cmp(&b.after_mm));
    svg("workspace", (1100, 440), |root| {
        let (plots, bar) = root.split_horizontally(990);
        let halves = plots.split_evenly((1, 2));
        for (area, (k, name)) in halves.iter().zip([(1, "y (m)"), (2, "z (m)")]) {
            workspace_view(area, rows, &order, (k, name), e_max)?;
        }
        error_scale(&bar, e_max)
    })
}

/// One view of the workspace: tracker x against coordinate `k` (named `name`), each pose a dot
/// coloured by its error (the colour scale's top `e_max`), `order` drawn in turn.
fn workspace_view(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    rows: &[RowError],
    order: &[&RowError],
    (k, name): (usize, &str),
    e_max: f64,
) -> Result<(), String> {
    let colour = |e: f64| viridis(e / e_max);
    let coordinate = |r: &RowError, k: usize| r.position_m[k];
    let (x0, x1) = span(rows.iter().map(|r| coordinate(r, 0)), (0.0, 1.0));
    let (y0, y1) = span(rows.iter().map(|r| coordinate(r, k)), (0.0, 1.0));
    let pad = |a: f64, b: f64| (a - 0.03 * (b - a), b + 0.03 * (b - a));
    let ((x0, x1), (y0, y1)) = (pad(x0, x1), pad(y0, y1));
    let title = if k == 1 { "From above (tracker x–y)" } else { "From the side (tracker x–z)" };
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, WIDE_CAPTION))
        .margin(10)
        .x_label_area_size(50)
        .y_label_area_size(75)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .label_style((FONT, WIDE_LABEL))
        .axis_desc_style((FONT, WIDE_LABEL))
        .x_desc("x (m)")
        .y_desc(name)
        .draw()
        .map_err(|e| e.to_string())?;
    chart
        .draw_series(
            order.iter().map(|r| Circle::new((coordinate(r, 0), coordinate(r, k)), 3, colour(r.after_mm).filled())),
        )
        .map_err(|e| e.to_string())?;
    Ok(())
}

/// The colour scale of the workspace's errors, 0 to `e_max` mm, in `bar`.
fn error_scale(bar: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>, e_max: f64) -> Result<(), String> {
    let colour = |e: f64| viridis(e / e_max);
    let mut scale = ChartBuilder::on(bar)
        .margin_top(40)
        .margin_bottom(50)
        .y_label_area_size(80)
        .build_cartesian_2d(0.0..1.0, 0.0..e_max)
        .map_err(|e| e.to_string())?;
    scale
        .configure_mesh()
        .disable_x_mesh()
        .disable_x_axis()
        .label_style((FONT, WIDE_LABEL))
        .axis_desc_style((FONT, WIDE_LABEL))
        .y_desc("error (mm)")
        .draw()
        .map_err(|e| e.to_string())?;
    const STEPS: usize = 64;
    scale
        .draw_series((0..STEPS).map(|s| {
            let (a, b) = (e_max * s as f64 / STEPS as f64, e_max * (s + 1) as f64 / STEPS as f64);
            Rectangle::new([(0.0, a), (1.0, b)], colour(0.5 * (a + b)).filled())
        }))
        .map_err(|e| e.to_string())?;
    Ok(())
}

/// An effect's joint error over its joint's angle with its σ band, the fitted arcs shaded, and
/// the training (above) and test (below) angles as ticks.
pub fn effect_curve(label: &str, curve: &EffectCurve) -> Result<String, Error> {
    let (x0, x1) = span(curve.angle_deg.iter().copied(), (-180.0, 180.0));
    let band = curve.error_urad.iter().zip(&curve.sigma_urad);
    let (y0, y1) = span(band.flat_map(|(e, s)| [e - s, e + s]).chain([0.0]), (-1.0, 1.0));
    let pad = 0.12 * (y1 - y0);
    let (y0, y1) = (y0 - pad, y1 + pad);
    svg(label, (820, 360), |root| {
        let (plot, legend) = root.split_horizontally(640);
        let mut chart = ChartBuilder::on(&plot)
            .caption(format!("{label}: joint {} error", curve.joint), (FONT, 15))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .label_style((FONT, LABEL))
            .axis_desc_style((FONT, DESC))
            .x_desc(format!("joint {} angle (deg)", curve.joint))
            .y_desc("joint error (µrad)")
            .draw()
            .map_err(|e| e.to_string())?;
        draw_effect_error(&mut chart, curve, (y0, y1))?;
        draw_angle_ticks(&mut chart, curve, (x0, x1), (y0, y1))?;
        let mut entries = vec![
            ("fitted angles", Glyph::Box(AFTER.mix(0.15))),
            ("± σ left uncorrected", Glyph::Box(AFTER.mix(0.25))),
            ("joint error applied", Glyph::Line(AFTER.into())),
        ];
        if !curve.training_deg.is_empty() {
            entries.push(("training angles (top)", Glyph::Tick(TRAINING.into())));
        }
        entries.push(("test angles (bottom)", Glyph::Tick(BLACK.mix(0.5))));
        side_legend(&legend, &entries)
    })
}

/// A chart of the SVG figures, f64 on both axes.
type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// The fitted arcs shaded from `y0` to `y1`, the σ band and the joint error applied.
fn draw_effect_error(chart: &mut Chart<'_, '_>, curve: &EffectCurve, (y0, y1): (f64, f64)) -> Result<(), String> {
    chart
        .draw_series(
            curve.fitted_deg.iter().map(|&[a, b]| Rectangle::new([(a, y0), (b, y1)], AFTER.mix(0.06).filled())),
        )
        .map_err(|e| e.to_string())?
        .label("fitted angles")
        .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], AFTER.mix(0.15).filled()));
    let upper = curve.angle_deg.iter().zip(&curve.error_urad).zip(&curve.sigma_urad).map(|((&a, e), s)| (a, e + s));
    let lower = curve.angle_deg.iter().zip(&curve.error_urad).zip(&curve.sigma_urad).map(|((&a, e), s)| (a, e - s));
    let polygon: Vec<(f64, f64)> = upper.chain(lower.rev()).collect();
    chart
        .draw_series(std::iter::once(Polygon::new(polygon, AFTER.mix(0.25).filled())))
        .map_err(|e| e.to_string())?
        .label("± σ left uncorrected")
        .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], AFTER.mix(0.25).filled()));
    chart
        .draw_series(LineSeries::new(
            curve.angle_deg.iter().copied().zip(curve.error_urad.iter().copied()),
            AFTER.stroke_width(2),
        ))
        .map_err(|e| e.to_string())?
        .label("joint error applied")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 12, y)], AFTER.stroke_width(2)));
    Ok(())
}

/// The training angles as ticks down from the top, the test angles up from the bottom.
fn draw_angle_ticks(
    chart: &mut Chart<'_, '_>,
    curve: &EffectCurve,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> Result<(), String> {
    let tick = 0.05 * (y1 - y0);
    // One tick per pixel of the ~560-pixel plot: a campaign's 1,400 angles drawn as at most
    // 560 marks, the same picture in a third of the bytes.
    let distinct = |angles: &[f64]| distinct_at(angles, (x1 - x0) / 560.0);
    let (training, test) = (distinct(&curve.training_deg), distinct(&curve.test_deg));
    if !curve.training_deg.is_empty() {
        chart
            .draw_series(training.iter().map(|&a| PathElement::new(vec![(a, y1), (a, y1 - tick)], TRAINING.mix(0.6))))
            .map_err(|e| e.to_string())?
            .label("training angles")
            .legend(|(x, y)| PathElement::new(vec![(x + 6, y - 5), (x + 6, y + 5)], TRAINING));
    }
    chart
        .draw_series(test.iter().map(|&a| PathElement::new(vec![(a, y0), (a, y0 + tick)], BLACK.mix(0.4))))
        .map_err(|e| e.to_string())?
        .label("test angles")
        .legend(|(x, y)| PathElement::new(vec![(x + 6, y - 5), (x + 6, y + 5)], BLACK.mix(0.5)));
    Ok(())
}

/// How a legend entry is drawn.
enum Glyph {
    /// A filled box (an area, a band).
    Box(RGBAColor),
    /// A thick horizontal line (a curve).
    Line(RGBAColor),
    /// A short vertical tick (marks along an axis).
    Tick(RGBAColor),
    /// A dot (points).
    Dot(RGBAColor),
}

/// A legend drawn beside the plot (in `area`, right of it) so that it never hides the data.
fn side_legend(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    entries: &[(&str, Glyph)],
) -> Result<(), String> {
    let top = 40;
    for (k, (name, glyph)) in entries.iter().enumerate() {
        let y = top + 24 * k as i32;
        let drawn = match *glyph {
            Glyph::Box(c) => area.draw(&Rectangle::new([(6, y - 6), (20, y + 6)], c.filled())),
            Glyph::Line(c) => area.draw(&PathElement::new(vec![(4, y), (22, y)], c.stroke_width(2))),
            Glyph::Tick(c) => area.draw(&PathElement::new(vec![(13, y - 7), (13, y + 7)], c.stroke_width(2))),
            Glyph::Dot(c) => area.draw(&Circle::new((13, y), 4, c.filled())),
        };
        drawn.map_err(|e| e.to_string())?;
        area.draw(&Text::new(name.to_string(), (28, y - 8), (FONT, LABEL))).map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// `values` rounded to multiples of `step`, each once, ascending.
fn distinct_at(values: &[f64], step: f64) -> Vec<f64> {
    let step = if step > 0.0 && step.is_finite() { step } else { 1.0 };
    let mut out: Vec<f64> = values.iter().filter(|v| v.is_finite()).map(|v| (v / step).round() * step).collect();
    out.sort_by(f64::total_cmp);
    out.dedup();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_closer_than_a_step_are_drawn_once() {
        assert_eq!(distinct_at(&[1.0, 1.04, 2.0, f64::NAN, 0.96], 0.1), vec![1.0, 2.0]);
    }

    #[test]
    fn viridis_runs_from_purple_to_yellow_and_clamps() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(7.0), viridis(1.0));
        assert_eq!(viridis(f64::NAN), viridis(0.0));
    }

    #[test]
    fn a_scatter_plot_is_svg_with_every_finite_point() {
        let series =
            [Series { name: "a <b>".into(), after: true, points: vec![(0.0, 1.0), (1.0, 2.0), (f64::NAN, 1.0)] }];
        let svg = scatter("t & u", "x", "y", &series).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert_eq!(svg.matches("<circle").count(), 2 + 1, "two points and one legend marker");
        assert!(svg.contains("a &lt;b&gt;") && svg.contains("t &amp; u"), "text is escaped");
    }
}
