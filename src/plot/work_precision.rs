//! Work–precision figures: wall time against error on log–log axes, one labelled point per
//! setting, one line per series (a method, or one kind of error).

use super::{draw_legend, plot_error, series_colour};
use crate::error::Result;
use plotters::prelude::*;

/// One point of a work–precision series.
#[derive(Debug, Clone)]
pub struct WorkPoint {
    /// The setting, written beside the point ("poly 4", "rtol 1e-8").
    pub label: String,
    /// Wall time, s.
    pub seconds: f64,
    pub error: f64,
}

/// A line of points.
#[derive(Debug, Clone)]
pub struct WorkSeries {
    pub name: String,
    pub points: Vec<WorkPoint>,
}

/// Log–log SVG of error against wall time (ms). Points with a zero or non-finite error or time
/// are left out (a log axis cannot show them); say so in the caption if it matters.
pub fn work_precision_svg(title: &str, error_label: &str, series: &[WorkSeries]) -> Result<String> {
    let shown = |p: &WorkPoint| p.seconds > 0.0 && p.error > 0.0 && p.seconds.is_finite() && p.error.is_finite();
    let (mut t_lo, mut t_hi, mut e_lo, mut e_hi) = (f64::INFINITY, 0.0_f64, f64::INFINITY, 0.0_f64);
    for p in series.iter().flat_map(|s| s.points.iter()).filter(|p| shown(p)) {
        t_lo = t_lo.min(p.seconds * 1e3);
        t_hi = t_hi.max(p.seconds * 1e3);
        e_lo = e_lo.min(p.error);
        e_hi = e_hi.max(p.error);
    }
    if t_hi == 0.0 {
        (t_lo, t_hi, e_lo, e_hi) = (0.1, 1.0, 1e-16, 1.0);
    }
    // A decade of room on both sides for the labels.
    let (t_lo, t_hi) = (t_lo / 2.0, t_hi * 3.0);
    let (e_lo, e_hi) = (e_lo / 10.0, e_hi * 10.0);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 600)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin(14)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d((t_lo..t_hi).log_scale(), (e_lo..e_hi).log_scale())
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_desc("wall time (ms)")
            .y_desc(error_label)
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .x_label_formatter(&|v| format!("{v:.2}"))
            .draw()
            .map_err(plot_error)?;
        for (i, line) in series.iter().enumerate() {
            let colour = series_colour(i);
            let points: Vec<(f64, f64)> = line
                .points
                .iter()
                .filter(|p| shown(p))
                .map(|p| (p.seconds * 1e3, p.error))
                .collect();
            chart
                .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                .map_err(plot_error)?
                .label(line.name.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2)));
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 4, colour.filled())))
                .map_err(plot_error)?;
            chart
                .draw_series(
                    line.points
                        .iter()
                        .filter(|p| shown(p))
                        .map(|p| Text::new(p.label.clone(), (p.seconds * 1e3, p.error), ("sans-serif", 12))),
                )
                .map_err(plot_error)?;
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        root.present().map_err(plot_error)?;
    }
    Ok(svg)
}
