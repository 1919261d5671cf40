//! The figure of a fit (`fit.svg`): each measured column's samples against the fitted
//! model's line, and the residuals below, against time.

use super::canvas::{canvas, px, shown_at};
use super::{axis_range, draw_series_line, draw_side_legend, plot_error, series_line, LineKind, LEGEND_MARGIN};
use crate::calibrate::FitReport;
use crate::error::Result;
use plotters::prelude::*;

/// Renders fit.svg.
pub fn fit_svg(report: &FitReport) -> Result<String> {
    let table = &report.table;
    let mut svg = String::new();
    {
        let root = canvas(&mut svg, (1000, 760));
        root.fill(&WHITE).map_err(plot_error)?;
        let (top, bottom) = root.split_vertically(px(470));
        let t_end = table.times.last().copied().unwrap_or(1.0);
        let (scale, unit) = if t_end < 1e-3 {
            (1e-6, "µs")
        } else if t_end < 1.0 {
            (1e-3, "ms")
        } else {
            (1.0, "s")
        };
        let x_range = axis_range(
            table.times.first().copied().unwrap_or(0.0).min(0.0) / scale,
            t_end / scale,
            0.0,
        );
        let values = table
            .measured
            .iter()
            .flat_map(|c| c.iter().flatten().copied())
            .chain(table.fitted.iter().flatten().copied());
        let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
        let determined = report.parameters.iter().filter(|p| p.determined).count();
        let mut chart = ChartBuilder::on(&top)
            .caption(
                format!(
                    "fit of {} to {}: {} of {} parameters determined, {:?}",
                    short(&report.scene),
                    short(&report.measurement),
                    determined,
                    report.parameters.len(),
                    report.status
                ),
                ("sans-serif", 18),
            )
            .margin(px(12))
            .margin_right(px(LEGEND_MARGIN))
            .x_label_area_size(px(36))
            .y_label_area_size(px(56))
            .build_cartesian_2d(x_range.clone(), axis_range(lo, hi, 0.06))
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .set_all_tick_mark_size(px(5))
            .x_desc(format!("time ({unit})"))
            .y_desc("measured (dots) and fitted (lines)")
            .draw()
            .map_err(plot_error)?;
        let mut entries = Vec::new();
        for (c, name) in table.columns.iter().enumerate() {
            let (colour, _) = series_line(c);
            let dots = table
                .times
                .iter()
                .zip(&table.measured[c])
                .filter_map(|(t, y)| y.map(|y| Circle::new((t / scale, y), px(2), colour.filled())));
            chart.draw_series(dots).map_err(plot_error)?;
            let line = table
                .times
                .iter()
                .zip(&table.fitted[c])
                .map(|(t, y)| (t / scale, *y))
                .collect();
            entries.push(draw_series_line(&mut chart, line, c, name.clone())?);
        }
        draw_side_legend(&top, 44, &entries)?;

        draw_residuals(&bottom, report, scale, unit, x_range)?;
        root.present().map_err(plot_error)?;
    }
    Ok(shown_at(svg))
}

/// The lower panel: measured − fitted per column, with each column's σ.
fn draw_residuals<DB: DrawingBackend>(
    bottom: &DrawingArea<DB, plotters::coord::Shift>,
    report: &FitReport,
    scale: f64,
    unit: &str,
    x_range: std::ops::Range<f64>,
) -> Result<()> {
    let table = &report.table;
    let residuals: Vec<Vec<(f64, f64)>> = (0..table.columns.len())
        .map(|c| {
            table
                .times
                .iter()
                .zip(&table.measured[c])
                .zip(&table.fitted[c])
                .filter_map(|((t, y), f)| y.map(|y| (t / scale, y - f)))
                .collect()
        })
        .collect();
    let largest = residuals.iter().flatten().fold(0.0_f64, |a, (_, r)| a.max(r.abs()));
    let mut chart = ChartBuilder::on(bottom)
        .caption(
            format!(
                "residuals (reduced χ² {:.3}, {} degrees of freedom)",
                report.reduced_chi_square, report.degrees_of_freedom
            ),
            ("sans-serif", 16),
        )
        .margin(px(12))
        .margin_right(px(LEGEND_MARGIN))
        .x_label_area_size(px(36))
        .y_label_area_size(px(56))
        .build_cartesian_2d(x_range, axis_range(-largest, largest, 0.06))
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .set_all_tick_mark_size(px(5))
        .x_desc(format!("time ({unit})"))
        .y_desc("measured − fitted")
        .draw()
        .map_err(plot_error)?;
    let mut noise = Vec::new();
    for (c, points) in residuals.into_iter().enumerate() {
        let (colour, _) = series_line(c);
        chart
            .draw_series(points.into_iter().map(|p| Circle::new(p, px(2), colour.filled())))
            .map_err(plot_error)?;
        let column = &report.residuals[c];
        noise.push((
            format!("{}: σ {:.4}", column.name, column.noise),
            colour,
            LineKind::Note,
        ));
    }
    if let Some(first) = report.residuals.first() {
        noise.push((format!("(σ {})", first.noise_source), BLACK, LineKind::Note));
    }
    draw_side_legend(bottom, 44, &noise)?;
    Ok(())
}

/// A path's file name, for a title.
fn short(path: &str) -> &str {
    path.rsplit(['/', '\\']).next().unwrap_or(path)
}
