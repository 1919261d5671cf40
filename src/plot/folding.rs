//! The folding path's figure: fold angles against progress, and 3D views of the panels at
//! four moments.

use super::canvas::{canvas, px, shown_at};
use super::{axis_range, draw_side_legend, plot_error, LineKind, LEGEND_MARGIN};
use crate::error::Result;
use crate::folding::{panel_poses, FoldPath, FoldingModel};
use crate::pattern::crease_pattern::EdgeKind;
use crate::pattern::Assignment;
use crate::write::folding_output::evenly;
use plotters::prelude::*;

/// Renders `fold.svg` to a string.
pub fn fold_svg(model: &FoldingModel, path: &FoldPath, title: &str) -> Result<String> {
    let xs: Vec<f64> = path.steps.iter().map(|s| s.progress).collect();
    let states: Vec<&[f64]> = path.steps.iter().map(|s| s.fold_angles.as_slice()).collect();
    angles_svg(
        model,
        &xs,
        &states,
        "progress (fraction of the goal)",
        "progress",
        title,
    )
}

/// Line colours by assignment: valley, mountain, other (flat or unassigned).
const ASSIGNMENT_COLOURS: [RGBColor; 3] = [RGBColor(31, 119, 180), RGBColor(214, 39, 40), RGBColor(127, 127, 127)];

/// Index into [`ASSIGNMENT_COLOURS`].
fn assignment_kind(kind: &EdgeKind) -> usize {
    match kind {
        EdgeKind::Crease(Assignment::Valley) => 0,
        EdgeKind::Crease(Assignment::Mountain) => 1,
        _ => 2,
    }
}

/// The side legend of a figure coloured by assignment: how many lines of each, and how many
/// of all were drawn.
fn draw_assignment_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    counts: [usize; 3],
    drawn: usize,
    total: usize,
) -> Result<()> {
    let names = ["valley", "mountain", "flat or unassigned"];
    let mut entries: Vec<(String, RGBColor, LineKind)> = (0..3)
        .filter(|&k| counts[k] > 0)
        .map(|k| {
            (
                format!("{} ({})", names[k], counts[k]),
                ASSIGNMENT_COLOURS[k],
                LineKind::Solid,
            )
        })
        .collect();
    if drawn < total {
        entries.push((format!("{drawn} of {total} drawn"), BLACK, LineKind::Note));
    }
    // Creases that fold alike draw one line.
    entries.push(("same angles: one line".into(), BLACK, LineKind::Note));
    draw_side_legend(area, 44, &entries)
}

/// Fold angles of every crease against `xs` (one state per x), and 3D views of the panels
/// at four of the states; `x_label` names the axis, `x_name` the views' captions.
pub fn angles_svg(
    model: &FoldingModel,
    xs: &[f64],
    states: &[&[f64]],
    x_label: &str,
    x_name: &str,
    title: &str,
) -> Result<String> {
    let pattern = &model.pattern;
    let mut svg = String::new();
    {
        let root = canvas(&mut svg, (1000, 680));
        root.fill(&WHITE).map_err(plot_error)?;
        let (top, bottom) = root.split_vertically(px(400));
        let first = xs.iter().copied().fold(f64::INFINITY, f64::min);
        let last = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let mut chart = ChartBuilder::on(&top)
            .caption(title, ("sans-serif", 20))
            .margin(px(12))
            .margin_right(px(LEGEND_MARGIN))
            .x_label_area_size(px(36))
            .y_label_area_size(px(52))
            .build_cartesian_2d(axis_range(first, last, 0.02), -180.0..180.0)
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .set_all_tick_mark_size(px(5))
            .x_desc(x_label)
            .y_desc("fold angle (deg)")
            .draw()
            .map_err(plot_error)?;
        // Creases that fold alike draw one line over another; colour says the assignment.
        let shown = evenly(pattern.creases.len(), 400);
        let mut counts = [0usize; 3];
        for &column in &shown {
            let kind = assignment_kind(&pattern.kinds[pattern.creases[column]]);
            counts[kind] += 1;
            let colour = ASSIGNMENT_COLOURS[kind];
            chart
                .draw_series(LineSeries::new(
                    xs.iter().zip(states).map(|(x, s)| (*x, s[column].to_degrees())),
                    colour.stroke_width(1),
                ))
                .map_err(plot_error)?;
        }
        draw_assignment_legend(&top, counts, shown.len(), pattern.creases.len())?;

        // 3D views at four moments, one scale for all.
        let picks = evenly(states.len(), 4);
        let mut poses_at = Vec::new();
        for &i in &picks {
            let mut poses = Vec::new();
            panel_poses(model, states[i], &mut poses);
            poses_at.push(poses);
        }
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for poses in &poses_at {
            for (f, face) in pattern.faces.iter().enumerate() {
                let pose = &poses[pattern.panel_of_face[f]];
                for &v in face {
                    let x = pose.place(pattern.vertices[v]);
                    for k in 0..3 {
                        lo[k] = lo[k].min(x[k]);
                        hi[k] = hi[k].max(x[k]);
                    }
                }
            }
        }
        let centre = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
        let half = (0..3).map(|k| 0.5 * (hi[k] - lo[k])).fold(1e-12, f64::max);
        let views = bottom.split_evenly((1, 4));
        for ((area, poses), &i) in views.iter().zip(&poses_at).zip(&picks) {
            let mut view = ChartBuilder::on(area)
                .caption(format!("{x_name} {:.4}", xs[i]), ("sans-serif", 16))
                .margin(px(6))
                .build_cartesian_3d(-1.05..1.05, -1.05..1.05, -1.05..1.05)
                .map_err(plot_error)?;
            view.with_projection(|mut p| {
                p.yaw = 0.6;
                p.pitch = 0.45;
                p.scale = 1.2;
                p.into_matrix()
            });
            // plotters' 3D y axis is vertical: plot (x, z, y) so the pattern's z is up.
            let to_plot = |x: nalgebra::Vector3<f64>| {
                (
                    (x[0] - centre[0]) / half,
                    (x[2] - centre[2]) / half,
                    (x[1] - centre[1]) / half,
                )
            };
            for (f, face) in pattern.faces.iter().enumerate() {
                let panel = pattern.panel_of_face[f];
                let pose = &poses[panel];
                let outline: Vec<(f64, f64, f64)> =
                    face.iter().map(|&v| to_plot(pose.place(pattern.vertices[v]))).collect();
                let shade = if panel.is_multiple_of(2) {
                    RGBColor(120, 160, 220)
                } else {
                    RGBColor(230, 200, 120)
                };
                view.draw_series(std::iter::once(Polygon::new(outline.clone(), shade.mix(0.45).filled())))
                    .map_err(plot_error)?;
                let mut closed = outline;
                closed.push(closed[0]);
                view.draw_series(std::iter::once(PathElement::new(closed, BLACK.stroke_width(1))))
                    .map_err(plot_error)?;
            }
        }
        root.present().map_err(plot_error)?;
    }
    Ok(shown_at(svg))
}

/// Renders `constraints.svg` for a crease pattern of many vertices: every crease's exact
/// sweep (dots) and its fit (line) against the driver.
pub fn network_constraints_svg(
    sweep: &crate::constraints::network::NetworkSweep,
    curves: &crate::constraints::network::NetworkCurves,
) -> Result<String> {
    let mut svg = String::new();
    {
        let root = canvas(&mut svg, (1000, 560));
        root.fill(&WHITE).map_err(plot_error)?;
        let [a, b] = curves.domain_deg;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!(
                    "{}: fold angles against crease {} (degree {}, largest error {:.2e} rad)",
                    curves.pattern, curves.driver_edge, curves.degree, curves.max_fit_error_rad
                ),
                ("sans-serif", 18),
            )
            .margin(px(12))
            .margin_right(px(LEGEND_MARGIN))
            .x_label_area_size(px(36))
            .y_label_area_size(px(52))
            .build_cartesian_2d(axis_range(a, b, 0.02), -180.0..180.0)
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .set_all_tick_mark_size(px(5))
            .x_desc(format!("driver: crease {} (deg)", curves.driver_edge))
            .y_desc("fold angle (deg)")
            .draw()
            .map_err(plot_error)?;
        let shown = evenly(curves.curves.len(), 200);
        let driver = sweep.driver;
        let columns: Vec<usize> = (0..sweep.states.first().map_or(0, Vec::len))
            .filter(|&c| c != driver)
            .collect();
        let mut counts = [0usize; 3];
        for &i in &shown {
            let curve = &curves.curves[i];
            let kind = match curve.assignment.as_str() {
                "V" => 0,
                "M" => 1,
                _ => 2,
            };
            counts[kind] += 1;
            let colour = ASSIGNMENT_COLOURS[kind];
            let column = columns[i];
            chart
                .draw_series(
                    sweep
                        .driver_values
                        .iter()
                        .zip(&sweep.states)
                        .step_by(4)
                        .map(|(t, s)| Circle::new((t.to_degrees(), s[column].to_degrees()), px(2), colour.filled())),
                )
                .map_err(plot_error)?;
            chart
                .draw_series(LineSeries::new(
                    (0..=200).map(|k| {
                        let t = curves.domain_rad[0] + (curves.domain_rad[1] - curves.domain_rad[0]) * k as f64 / 200.0;
                        (t.to_degrees(), curve.chebyshev.eval(t).to_degrees())
                    }),
                    colour.stroke_width(1),
                ))
                .map_err(plot_error)?;
        }
        draw_assignment_legend(&root, counts, shown.len(), curves.curves.len())?;
        draw_side_legend(
            &root,
            110,
            &[
                ("dots: exact (every 4th)".into(), RGBColor(90, 90, 90), LineKind::Dotted),
                ("lines: fits".into(), RGBColor(90, 90, 90), LineKind::Solid),
            ],
        )?;
        root.present().map_err(plot_error)?;
    }
    Ok(shown_at(svg))
}
