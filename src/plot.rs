//! SVG figures drawn with plotters: the unfolding (fold angles against iteration and 3D
//! views, like the thesis's figures 3-3 to 3-5) and the constraint curves (figure 5-9).

mod canvas;
pub(crate) mod fit;
pub(crate) mod folding;
pub(crate) mod nets;
pub(crate) mod page;
pub(crate) mod response;
pub(crate) mod scene_page;
pub(crate) mod work_precision;
pub use page::{page_html, page_of_fold, PageFrame, PageScene, MAX_PAGE_POINTS};
pub use scene_page::{closed_modes_page, closed_scene, response_page, MODE_PHASES};
pub use work_precision::{
    error_by_parameter_svg, largest_sizes, power_law_fit, scaling_svg, work_precision_svg, ErrorSeries, ScalingSeries,
    WorkPoint, WorkSeries,
};

use crate::constraints::{ConstraintPoly, CurveSamples};
use crate::error::{NanofoldError, Result};
use crate::names::Named;
use crate::pattern::VertexPattern;
use crate::unfold::UnfoldReport;
use crate::write::output::{snapshot_indices, write_atomic};
use canvas::{canvas, px, pxi, shown_at};
use plotters::prelude::*;
use std::path::Path;

/// An axis range from the data's `lo`..`hi` plus `pad` (a fraction of the width) each side,
/// always finite and wider than rounding: a degenerate or non-finite range (all values
/// equal, a NaN) would otherwise stall or break the axis's tick placement.
pub(crate) fn axis_range(lo: f64, hi: f64, pad: f64) -> std::ops::Range<f64> {
    let (lo, hi) = if lo.is_finite() && hi.is_finite() && lo <= hi {
        (lo, hi)
    } else {
        (-1.0, 1.0)
    };
    let scale = lo.abs().max(hi.abs()).max(1e-300);
    let width = (hi - lo).max(1e-6 * scale);
    let margin = pad * width;
    (lo - margin)..(hi + margin)
}

pub(crate) fn plot_error(e: impl std::fmt::Display) -> NanofoldError {
    NanofoldError::Plot {
        figure: "an SVG figure".into(),
        message: e.to_string(),
    }
}

/// A legend drawn beside a chart (in the right margin of [`LEGEND_MARGIN`] output pixels of
/// `area`, `top` output pixels down), so it covers no data: each entry's line sample, dashed as its series, and label.
pub(crate) fn draw_side_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    top: i32,
    entries: &[(String, RGBColor, LineKind)],
) -> Result<()> {
    draw_legend_in_margin(area, LEGEND_MARGIN, top, entries)
}

/// [`draw_side_legend`] in a right margin of `margin` output pixels.
pub(crate) fn draw_legend_in_margin<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    margin: u32,
    top: i32,
    entries: &[(String, RGBColor, LineKind)],
) -> Result<()> {
    let x = area.dim_in_pixel().0 as i32 - pxi(margin as i32 - 16);
    for (k, (label, colour, kind)) in entries.iter().enumerate() {
        let y = pxi(top + 16 * k as i32);
        let style = colour.stroke_width(2);
        let pieces: Vec<(i32, i32)> = match kind {
            LineKind::Solid => vec![(0, 22)],
            LineKind::Dashed => vec![(0, 9), (14, 22)],
            LineKind::Dotted => vec![(0, 3), (7, 10), (14, 17), (21, 24)],
            LineKind::Cross => {
                area.draw(&Cross::new((x + pxi(11), y), px(5), style))
                    .map_err(plot_error)?;
                vec![]
            }
            LineKind::Note => vec![],
        };
        for (a, b) in pieces {
            area.draw(&PathElement::new(vec![(x + pxi(a), y), (x + pxi(b), y)], style))
                .map_err(plot_error)?;
        }
        area.draw(&Text::new(label.clone(), (x + pxi(30), y - pxi(6)), ("sans-serif", 12)))
            .map_err(plot_error)?;
    }
    Ok(())
}

/// Room to the right of a plotting area for its legend, pixels.
pub(crate) const LEGEND_MARGIN: u32 = 190;

/// Series `i`'s line: eight colours, solid for the first eight series, dashed for the next
/// eight, dotted after, so sixteen creases stay apart.
pub(crate) fn series_line(i: usize) -> (RGBColor, LineKind) {
    // The palette without its red and grey, which mark contacts and targets.
    const LINE_COLOURS: [usize; 8] = [0, 1, 2, 4, 5, 6, 9, 8];
    let kind = match i / LINE_COLOURS.len() {
        0 => LineKind::Solid,
        1 => LineKind::Dashed,
        _ => LineKind::Dotted,
    };
    (PALETTE[LINE_COLOURS[i % LINE_COLOURS.len()]], kind)
}

/// How a series' line is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LineKind {
    Solid,
    Dashed,
    Dotted,
    /// A marker (a contact), no line.
    Cross,
    /// A legend line of text alone.
    Note,
}

/// Draws `points` as series `i` in its colour and dash (see [`series_line`]); returns its
/// legend entry.
pub(crate) fn draw_series_line<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<
        'a,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    points: Vec<(f64, f64)>,
    i: usize,
    label: String,
) -> Result<(String, RGBColor, LineKind)> {
    let (colour, kind) = series_line(i);
    let style = colour.stroke_width(2);
    match kind {
        LineKind::Solid => chart.draw_series(LineSeries::new(points, style)),
        LineKind::Dashed => chart.draw_series(DashedLineSeries::new(points, px(9), px(5), style)),
        LineKind::Dotted | LineKind::Cross | LineKind::Note => {
            chart.draw_series(DashedLineSeries::new(points, px(3), px(4), style))
        }
    }
    .map_err(plot_error)?;
    Ok((label, colour, kind))
}

/// For each series, an earlier one it coincides with (largest difference ≤ `tol`), so the
/// legend can say that one line hides another.
pub(crate) fn coinciding(series: &[Vec<f64>], tol: f64) -> Vec<Option<usize>> {
    (0..series.len())
        .map(|i| {
            (0..i).find(|&j| {
                series[i].len() == series[j].len()
                    && series[i].iter().zip(&series[j]).all(|(a, b)| (a - b).abs() <= tol)
            })
        })
        .collect()
}

/// The ten colours every figure draws series in.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Colour of series `i`.
pub fn series_colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Renders `unfold.svg` to a string.
pub fn unfold_svg(pattern: &VertexPattern, report: &UnfoldReport) -> Result<String> {
    let mut svg = String::new();
    {
        let root = canvas(&mut svg, (1000, 680));
        root.fill(&WHITE).map_err(plot_error)?;
        let (top, bottom) = root.split_vertically(px(400));
        let traj = &report.trajectory;
        let last = traj.last().map_or(1, |r| r.iteration.max(1));
        let mut chart = ChartBuilder::on(&top)
            .caption(
                format!(
                    "{}: fold angles while unfolding ({}, {} iterations)",
                    pattern.name,
                    report.verdict.as_str(),
                    report.iterations
                ),
                ("sans-serif", 20),
            )
            .margin(px(12))
            .margin_right(px(LEGEND_MARGIN))
            .x_label_area_size(px(36))
            .y_label_area_size(px(52))
            .build_cartesian_2d(0.0..last as f64, -180.0..180.0)
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .set_all_tick_mark_size(px(5))
            .x_desc("iteration")
            .y_desc("fold angle (deg)")
            .draw()
            .map_err(plot_error)?;
        let series: Vec<Vec<f64>> = (0..pattern.creases.len())
            .map(|i| traj.iter().map(|r| r.fold_angles[i]).collect())
            .collect();
        let same = coinciding(&series, 1e-9);
        let mut entries = Vec::new();
        for (i, crease) in pattern.creases.iter().enumerate() {
            let mut label = format!("{} ({})", crease.label, crease.assignment.letter());
            if let Some(j) = same[i] {
                label.push_str(&format!(" = {}", pattern.creases[j].label));
            }
            let points = traj
                .iter()
                .map(|r| (r.iteration as f64, r.fold_angles[i].to_degrees()))
                .collect();
            entries.push(draw_series_line(&mut chart, points, i, label)?);
        }
        draw_side_legend(&top, 44, &entries)?;

        // 3D views at four moments.
        let picks = snapshot_indices(report, 11);
        let shown: Vec<usize> = if picks.len() <= 4 {
            picks
        } else {
            (0..4).map(|j| picks[j * (picks.len() - 1) / 3]).collect()
        };
        let panels = bottom.split_evenly((1, 4));
        for (panel, &index) in panels.iter().zip(&shown) {
            let step = &traj[index];
            let mut view = ChartBuilder::on(panel)
                .caption(format!("iteration {}", step.iteration), ("sans-serif", 16))
                .margin(px(6))
                .build_cartesian_3d(-1.1..1.1, -1.1..1.1, -1.1..1.1)
                .map_err(plot_error)?;
            view.with_projection(|mut p| {
                p.yaw = 0.6;
                p.pitch = 0.45;
                p.scale = 1.3;
                p.into_matrix()
            });
            // plotters' 3D y axis is vertical: plot (x, z, y) so the pattern's z is up.
            let to_plot = |v: &crate::geometry::sphere::Vec3| (v.x, v.z, v.y);
            let n = step.nodes.len();
            for (k, _) in pattern.sector_angles.iter().enumerate() {
                let a = step.nodes[k];
                let b = step.nodes[(k + 1) % n];
                let mut outline = vec![(0.0, 0.0, 0.0)];
                for s in 0..=8 {
                    let t = s as f64 / 8.0;
                    let p = (a * (1.0 - t) + b * t).normalize();
                    outline.push(to_plot(&p));
                }
                let colour = series_colour(k);
                view.draw_series(std::iter::once(Polygon::new(
                    outline.clone(),
                    colour.mix(0.35).filled(),
                )))
                .map_err(plot_error)?;
                outline.push((0.0, 0.0, 0.0));
                view.draw_series(std::iter::once(PathElement::new(outline, BLACK.stroke_width(1))))
                    .map_err(plot_error)?;
            }
        }
        root.present().map_err(plot_error)?;
    }
    Ok(shown_at(svg))
}

/// Writes `unfold.svg`.
pub fn write_unfold_svg(path: &Path, pattern: &VertexPattern, report: &UnfoldReport) -> Result<()> {
    write_atomic(path, unfold_svg(pattern, report)?.as_bytes())
}

/// Renders `constraints.svg`: every crease against the driving angle, exact samples as
/// lines and the fitted polynomials dashed (like the thesis's figure 5-9), and the fit
/// error |f − exact| on a log scale below.
pub fn constraints_svg(pattern: &VertexPattern, samples: &CurveSamples, poly: &ConstraintPoly) -> Result<String> {
    let mut svg = String::new();
    {
        let root = canvas(&mut svg, (1000, 800));
        root.fill(&WHITE).map_err(plot_error)?;
        let (top, bottom) = root.split_vertically(px(480));
        let x_deg: Vec<f64> = samples.drive_angles.iter().map(|x| x.to_degrees()).collect();
        let domain_deg = (poly.fitted.domain[0].to_degrees(), poly.fitted.domain[1].to_degrees());
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for angles in &samples.fold_angles {
            for a in angles {
                lo = lo.min(a.to_degrees());
                hi = hi.max(a.to_degrees());
            }
        }
        let y_range = axis_range(lo.min(hi - 1.0), hi, 0.05);
        let driver = &pattern.creases[poly.driver];
        let mut chart = ChartBuilder::on(&top)
            .caption(
                format!(
                    "{}: fold angles against {} (lines: exact loop closure, dashed: degree-{} fit)",
                    pattern.name,
                    driver.label,
                    poly.degree()
                ),
                ("sans-serif", 18),
            )
            .margin(px(12))
            .margin_right(px(LEGEND_MARGIN))
            .x_label_area_size(px(36))
            .y_label_area_size(px(52))
            .build_cartesian_2d(axis_range(domain_deg.0, domain_deg.1, 0.0), y_range)
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .set_all_tick_mark_size(px(5))
            .x_desc(format!("{} (deg)", driver.label))
            .y_desc("fold angle (deg)")
            .draw()
            .map_err(plot_error)?;
        let fine = 400;
        let mut entries = Vec::new();
        for (c, crease) in pattern.creases.iter().enumerate() {
            let colour = series_colour(c);
            let role = if c == poly.driver {
                "driver"
            } else if poly.locked.iter().any(|&(l, _)| l == c) {
                "locked"
            } else {
                "fitted"
            };
            chart
                .draw_series(LineSeries::new(
                    x_deg
                        .iter()
                        .zip(&samples.fold_angles)
                        .map(|(&x, a)| (x, a[c].to_degrees())),
                    colour.mix(0.45).stroke_width(4),
                ))
                .map_err(plot_error)?;
            entries.push((format!("{} ({role})", crease.label), colour, LineKind::Solid));
            if let Some(j) = poly.dependents.iter().position(|&d| d == c) {
                let curve = &poly.fitted.curves[j];
                let points = (0..=fine).map(|i| {
                    let x = poly.fitted.domain[0]
                        + (poly.fitted.domain[1] - poly.fitted.domain[0]) * i as f64 / fine as f64;
                    (x.to_degrees(), curve.eval(x).to_degrees())
                });
                chart
                    .draw_series(DashedLineSeries::new(points, px(8), px(5), colour.stroke_width(2)))
                    .map_err(plot_error)?;
            }
        }
        entries.push((
            format!("degree-{} fit", poly.degree()),
            RGBColor(90, 90, 90),
            LineKind::Dashed,
        ));
        draw_side_legend(&top, 44, &entries)?;

        // Fit error per dependent, at the samples.
        let errors: Vec<Vec<f64>> = poly
            .dependents
            .iter()
            .zip(&poly.fitted.curves)
            .map(|(&c, curve)| {
                samples
                    .drive_angles
                    .iter()
                    .zip(&samples.fold_angles)
                    .map(|(&x, a)| (curve.eval(x) - a[c]).abs().max(1e-17))
                    .collect()
            })
            .collect();
        let top_error = errors.iter().flatten().copied().fold(1e-16, f64::max) * 3.0;
        let bottom_error = (errors.iter().flatten().copied().fold(f64::INFINITY, f64::min)).max(1e-17) / 3.0;
        let mut error_chart = ChartBuilder::on(&bottom)
            .caption("fit error |f(θ) − exact| (rad)", ("sans-serif", 16))
            .margin(px(12))
            .margin_right(px(LEGEND_MARGIN))
            .x_label_area_size(px(36))
            .y_label_area_size(px(64))
            .build_cartesian_2d(domain_deg.0..domain_deg.1, (bottom_error..top_error).log_scale())
            .map_err(plot_error)?;
        error_chart
            .configure_mesh()
            .set_all_tick_mark_size(px(5))
            .x_desc(format!("{} (deg)", driver.label))
            .y_desc("rad")
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(plot_error)?;
        // Errors that coincide (a symmetric pair of creases) draw one line: the legend says so.
        let same = coinciding(&errors, 1e-9 * top_error);
        let mut error_entries = Vec::new();
        for (j, (&c, series)) in poly.dependents.iter().zip(&errors).enumerate() {
            error_chart
                .draw_series(LineSeries::new(
                    x_deg.iter().copied().zip(series.iter().copied()),
                    series_colour(c).stroke_width(2),
                ))
                .map_err(plot_error)?;
            let mut label = pattern.creases[c].label.clone();
            if let Some(k) = same[j] {
                label.push_str(&format!(" = {}", pattern.creases[poly.dependents[k]].label));
            }
            error_entries.push((label, series_colour(c), LineKind::Solid));
        }
        draw_side_legend(&bottom, 40, &error_entries)?;
        root.present().map_err(plot_error)?;
    }
    Ok(shown_at(svg))
}

#[cfg(test)]
mod tests {
    use super::axis_range;

    #[test]
    fn axis_ranges_are_finite_and_wider_than_rounding() {
        for (lo, hi) in [
            (0.0, 0.0),
            (1e20, 1e20),
            (1e-40, 1e-40),
            (f64::NAN, 1.0),
            (3.0, 1.0),
            (-f64::INFINITY, 0.0),
        ] {
            let range = axis_range(lo, hi, 0.06);
            assert!(range.start.is_finite() && range.end.is_finite(), "{lo} {hi}");
            assert!(
                range.end - range.start > 1e-7 * range.end.abs().max(range.start.abs()),
                "{lo} {hi}: {range:?}"
            );
        }
        assert_eq!(axis_range(0.0, 10.0, 0.1), -1.0..11.0);
    }
}
