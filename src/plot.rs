//! SVG figures: fold angles against iteration and 3D views of the vertex (like the
//! thesis's figures 3-3 to 3-5), drawn with plotters.

use crate::error::{NanofoldError, Result};
use crate::output::{snapshot_indices, write_atomic};
use crate::pattern::Pattern;
use crate::unfold::UnfoldReport;
use plotters::prelude::*;
use std::path::Path;

fn plot_error(e: impl std::fmt::Display) -> NanofoldError {
    NanofoldError::Output {
        path: "unfold.svg".into(),
        message: e.to_string(),
    }
}

/// Colour of series `i`.
pub fn series_colour(i: usize) -> RGBColor {
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
    PALETTE[i % PALETTE.len()]
}

/// Renders `unfold.svg` to a string.
pub fn unfold_svg(pattern: &Pattern, report: &UnfoldReport) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1000, 760)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        let (top, bottom) = root.split_vertically(400);
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
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(52)
            .build_cartesian_2d(0.0..last as f64, -180.0..180.0)
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_desc("iteration")
            .y_desc("fold angle (deg)")
            .draw()
            .map_err(plot_error)?;
        for (i, crease) in pattern.creases.iter().enumerate() {
            let colour = series_colour(i);
            chart
                .draw_series(LineSeries::new(
                    traj.iter().map(|r| (r.iteration as f64, r.fold_angles[i].to_degrees())),
                    colour.stroke_width(2),
                ))
                .map_err(plot_error)?
                .label(format!("{} ({})", crease.label, crease.assignment.letter()))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(2)));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(plot_error)?;

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
                .margin(6)
                .build_cartesian_3d(-1.1..1.1, -1.1..1.1, -1.1..1.1)
                .map_err(plot_error)?;
            view.with_projection(|mut p| {
                p.yaw = 0.6;
                p.pitch = 0.45;
                p.scale = 0.85;
                p.into_matrix()
            });
            // plotters' 3D y axis is vertical: plot (x, z, y) so the pattern's z is up.
            let to_plot = |v: &crate::sphere::Vec3| (v.x, v.z, v.y);
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
    Ok(svg)
}

/// Writes `unfold.svg`.
pub fn write_unfold_svg(path: &Path, pattern: &Pattern, report: &UnfoldReport) -> Result<()> {
    write_atomic(path, unfold_svg(pattern, report)?.as_bytes())
}
