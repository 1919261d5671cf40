//! The gallery of a solid's best nets (`gallery.svg`, `docs/model.md#nets-of-polyhedra`):
//! each net flat, inside up, all drawn to one scale, folds in blue, the cut boundary in
//! black, with its rank and scores.

use super::canvas::{canvas, px, shown_at};
use super::plot_error;
use crate::design::nets::{NetRow, RankBy};
use crate::error::Result;
use crate::pattern::crease_pattern::EdgeKind;
use crate::pattern::net::NetPattern;
use plotters::prelude::*;

/// `x` to four significant digits, without an exponent in the gallery's range.
fn significant(x: f64) -> String {
    let digits = if x == 0.0 {
        0
    } else {
        (3 - x.abs().log10().floor() as i32).max(0) as usize
    };
    format!("{x:.digits$}")
}

/// Columns of the gallery.
const COLUMNS: usize = 4;

/// Renders gallery.svg of `nets` with their `rows`, lengths scaled by `unit_um`.
pub fn gallery_svg(
    solid: &str,
    nets: &[&NetPattern],
    rows: &[&NetRow],
    rank_by: RankBy,
    unit_um: f64,
) -> Result<String> {
    let cells = nets.len().max(1);
    let (columns, lines) = (cells.min(COLUMNS), cells.div_ceil(COLUMNS));
    let cell = 260;
    let mut svg = String::new();
    // One scale for all: the largest net's extent fills its cell.
    let bounds = |net: &NetPattern| {
        net.pattern
            .vertices
            .iter()
            .fold(([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]), |(lo, hi), p| {
                ([lo[0].min(p[0]), lo[1].min(p[1])], [hi[0].max(p[0]), hi[1].max(p[1])])
            })
    };
    let extent = nets
        .iter()
        .map(|n| {
            let (lo, hi) = bounds(n);
            (hi[0] - lo[0]).max(hi[1] - lo[1])
        })
        .fold(f64::MIN_POSITIVE, f64::max);
    {
        let root = canvas(&mut svg, (columns as u32 * cell, lines as u32 * cell + 40));
        root.fill(&WHITE).map_err(plot_error)?;
        let (title, grid) = root.split_vertically(px(40));
        title
            .titled(
                &format!(
                    "{solid}: the {} best nets by {}, one scale (a cell is {:.3} µm across)",
                    nets.len(),
                    rank_by.label(),
                    1.1 * extent * unit_um
                ),
                ("sans-serif", 16),
            )
            .map_err(plot_error)?;
        let areas = grid.split_evenly((lines, columns));
        for ((net, row), area) in nets.iter().zip(rows).zip(areas.iter()) {
            let (lo, hi) = bounds(net);
            let centre = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
            let half = 0.55 * extent;
            let mut chart = ChartBuilder::on(area)
                .caption(
                    format!(
                        "#{}: Rg {}, {} leaves, seams {}, {} × {} µm",
                        row.rank,
                        significant(row.radius_of_gyration_um),
                        row.leaves,
                        significant(row.seam_length_um),
                        significant(row.footprint_um[0]),
                        significant(row.footprint_um[1])
                    ),
                    ("sans-serif", 11),
                )
                .margin(px(4))
                .build_cartesian_2d(centre[0] - half..centre[0] + half, centre[1] - half..centre[1] + half)
                .map_err(plot_error)?;
            let p = &net.pattern;
            for face in &p.faces {
                let outline: Vec<(f64, f64)> = face.iter().map(|&v| (p.vertices[v][0], p.vertices[v][1])).collect();
                chart
                    .draw_series(std::iter::once(Polygon::new(
                        outline,
                        RGBColor(230, 200, 120).mix(0.5).filled(),
                    )))
                    .map_err(plot_error)?;
            }
            for (e, &[a, b]) in p.edges.iter().enumerate() {
                let style = match p.kinds[e] {
                    EdgeKind::Boundary => BLACK.stroke_width(2),
                    EdgeKind::Crease(_) => RGBColor(40, 90, 200).stroke_width(1),
                    EdgeKind::Facet => RGBColor(160, 160, 160).stroke_width(1),
                };
                let line = vec![
                    (p.vertices[a][0], p.vertices[a][1]),
                    (p.vertices[b][0], p.vertices[b][1]),
                ];
                chart
                    .draw_series(std::iter::once(PathElement::new(line, style)))
                    .map_err(plot_error)?;
            }
        }
        root.present().map_err(plot_error)?;
    }
    Ok(shown_at(svg))
}
