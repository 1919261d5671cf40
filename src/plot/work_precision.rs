//! Work–precision figures: wall time against error on log–log axes, one labelled point per
//! setting, one line per series (a method, or one kind of error); and cost-against-size
//! figures for scaling, with the fitted power law.

use super::canvas::{canvas, px, pxi, shown_at};
use super::{draw_legend_in_margin, plot_error, series_colour, LineKind};
use crate::error::Result;
use plotters::prelude::*;

/// One point of a work–precision series.
#[derive(Debug, Clone)]
pub struct WorkPoint {
    /// The setting, written beside the point ("poly 4", "rtol 1e-8").
    pub label: String,
    /// Wall time, s.
    pub seconds: f64,
    /// Its error (any unit; the plot states it).
    pub error: f64,
}

/// A line of points.
#[derive(Debug, Clone)]
pub struct WorkSeries {
    /// Legend entry.
    pub name: String,
    /// The points, in the order the line joins them.
    pub points: Vec<WorkPoint>,
}

/// The unit that shows times best: (name, seconds per unit), chosen so the largest time is
/// at least 1.
pub(crate) fn time_unit(largest_seconds: f64) -> (&'static str, f64) {
    [("s", 1.0), ("ms", 1e-3), ("µs", 1e-6), ("ns", 1e-9)]
        .into_iter()
        .find(|&(_, unit)| largest_seconds >= unit)
        .unwrap_or(("ns", 1e-9))
}

/// Log–log SVG of error against wall time (in s, ms, µs or ns, whichever shows the times
/// best). Points with a zero or non-finite error or time are left out (a log axis cannot
/// show them); say so in the caption if it matters.
pub fn work_precision_svg(title: &str, error_label: &str, series: &[WorkSeries]) -> Result<String> {
    let shown = |p: &WorkPoint| p.seconds > 0.0 && p.error > 0.0 && p.seconds.is_finite() && p.error.is_finite();
    let largest = series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|p| shown(p))
        .fold(0.0_f64, |m, p| m.max(p.seconds));
    let (unit_name, unit) = time_unit(largest);
    let (mut t_lo, mut t_hi, mut e_lo, mut e_hi) = (f64::INFINITY, 0.0_f64, f64::INFINITY, 0.0_f64);
    for p in series.iter().flat_map(|s| s.points.iter()).filter(|p| shown(p)) {
        t_lo = t_lo.min(p.seconds / unit);
        t_hi = t_hi.max(p.seconds / unit);
        e_lo = e_lo.min(p.error);
        e_hi = e_hi.max(p.error);
    }
    if t_hi == 0.0 {
        (t_lo, t_hi, e_lo, e_hi) = (0.1, 1.0, 1e-16, 1.0);
    }
    // Room for the labels, which sit right of their points.
    let (t_lo, t_hi) = (t_lo / 1.6, t_hi * 1.6);
    let (e_lo, e_hi) = (e_lo / 10.0, e_hi * 10.0);
    let mut svg = String::new();
    {
        let base = canvas(&mut svg, (1100, 600));
        base.fill(&WHITE).map_err(plot_error)?;
        let root = base.titled(title, ("sans-serif", 18)).map_err(plot_error)?;
        // The legend gets its own column: with a dozen series it would hide points.
        let (plot_area, legend_area) = root.split_horizontally(px(PLOT_WIDTH));
        let mut chart = ChartBuilder::on(&plot_area)
            .margin(px(14))
            .x_label_area_size(px(40))
            .y_label_area_size(px(70))
            .build_cartesian_2d((t_lo..t_hi).log_scale(), (e_lo..e_hi).log_scale())
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .set_all_tick_mark_size(px(5))
            .max_light_lines(4)
            .x_desc(format!("wall time ({unit_name})"))
            .y_desc(error_label)
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .x_label_formatter(&|v| sparse_tick(*v))
            .draw()
            .map_err(plot_error)?;
        let mut pending_labels = Vec::new();
        let mut markers = Vec::new();
        for (i, line) in series.iter().enumerate() {
            let colour = series_colour(i);
            let points: Vec<(f64, f64)> = line
                .points
                .iter()
                .filter(|p| shown(p))
                .map(|p| (p.seconds / unit, p.error))
                .collect();
            chart
                .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                .map_err(plot_error)?;
            if triangles(i) {
                chart.draw_series(points.iter().map(|&p| TriangleMarker::new(p, px(6), colour.filled())))
            } else {
                chart.draw_series(points.iter().map(|&p| Circle::new(p, px(4), colour.filled())))
            }
            .map_err(plot_error)?;
            markers.extend(points.iter().map(|p| chart.backend_coord(p)));
            // Points that land on each other (within 0.05 decade in time and 0.1 in error)
            // share one label, "1e-2, 1e-4, 1e-6", instead of printing over each other.
            let mut groups: Vec<(f64, f64, Vec<String>)> = Vec::new();
            for p in line.points.iter().filter(|p| shown(p)) {
                let (x, y) = (p.seconds / unit, p.error);
                let near = groups
                    .iter_mut()
                    .find(|(gx, gy, _)| (gx.log10() - x.log10()).abs() < 0.05 && (gy.log10() - y.log10()).abs() < 0.1);
                match near {
                    Some((_, _, labels)) => {
                        if !labels.contains(&p.label) {
                            labels.push(p.label.clone());
                        }
                    }
                    None => groups.push((x, y, vec![p.label.clone()])),
                }
            }
            for (x, y, labels) in groups {
                pending_labels.push((chart.backend_coord(&(x, y)), labels.join(", "), colour));
            }
            let y = pxi(30 + 20 * i as i32);
            legend_area
                .draw(&PathElement::new(
                    vec![(pxi(4), y), (pxi(26), y)],
                    colour.stroke_width(2),
                ))
                .map_err(plot_error)?;
            if triangles(i) {
                legend_area.draw(&TriangleMarker::new((pxi(15), y), px(6), colour.filled()))
            } else {
                legend_area.draw(&Circle::new((pxi(15), y), px(4), colour.filled()))
            }
            .map_err(plot_error)?;
            legend_area
                .draw(&Text::new(line.name.clone(), (pxi(32), y - pxi(7)), ("sans-serif", 13)))
                .map_err(plot_error)?;
        }
        // Labels of every series placed last, each at the free spot nearest its point: right
        // or left of it, below or above, then a line further out each round; a spot is free
        // when it covers no label already placed and no marker (boxes estimated at 6.5 px a
        // character, 13 px high). None prints over another, and each stays by its point.
        let (figure_w, figure_h) = base.dim_in_pixel();
        let line_height = pxi(13);
        let mut placed: Vec<(i32, i32, i32, i32)> = markers
            .iter()
            .map(|&(x, y)| (x - pxi(5), y - pxi(5), x + pxi(5), y + pxi(5)))
            .collect();
        // The legend's column is not a place for labels either.
        placed.push((pxi(PLOT_WIDTH as i32), 0, figure_w as i32, figure_h as i32));
        for ((x, y), text, colour) in pending_labels {
            let width = pxi((6.5 * text.chars().count() as f64) as i32);
            let free = |x0: i32, y0: i32| {
                x0 >= 0
                    && y0 >= 0
                    && x0 + width <= figure_w as i32
                    && y0 + line_height <= figure_h as i32
                    && !placed
                        .iter()
                        .any(|&(a, b, c, d)| x0 < c && a < x0 + width && y0 < d && b < y0 + line_height)
            };
            let candidates = (0..12).flat_map(|k| {
                let below = y + pxi(2) + k * line_height;
                let above = y - pxi(2) - (k + 1) * line_height;
                let (right, left) = (x + pxi(7), x - pxi(7) - width);
                [(right, below), (right, above), (left, below), (left, above)]
            });
            let mut spot = (x + pxi(7), y + pxi(2));
            for (x0, y0) in candidates {
                if free(x0, y0) {
                    spot = (x0, y0);
                    break;
                }
            }
            let (x0, y0) = spot;
            placed.push((x0, y0, x0 + width, y0 + line_height));
            // backend_coord is in the whole figure's pixels: draw on the untitled area.
            base.draw(&Text::new(
                text,
                (x0, y0),
                ("sans-serif", 12).into_font().color(&colour.mix(0.9)),
            ))
            .map_err(plot_error)?;
        }
        base.present().map_err(plot_error)?;
    }
    Ok(shown_at(svg))
}

/// Width of a work-precision figure's plot, output pixels; its legend takes the rest.
const PLOT_WIDTH: u32 = 760;

/// Series past the palette's ten colours get triangles instead of circles.
fn triangles(i: usize) -> bool {
    (i / 10) % 2 == 1
}

/// A log axis's label only at 1, 2 and 5 times a power of ten (the ticks between would
/// print over each other near the top of a decade).
fn sparse_tick(v: f64) -> String {
    if v.is_nan() || v <= 0.0 {
        return String::new();
    }
    let mantissa = v / 10f64.powf(v.log10().floor());
    if [1.0, 2.0, 5.0, 10.0].iter().any(|m| (mantissa - m).abs() < 1e-6 * m) {
        tick(v)
    } else {
        String::new()
    }
}

/// An axis number without trailing zeros ("10", "0.25", "3e-4").
fn tick(v: f64) -> String {
    if v != 0.0 && v.abs() < 1e-2 {
        return format!("{v:.0e}");
    }
    let text = format!("{v:.3}");
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// A least-squares power law c·nᵏ through (n, cost) points: returns (k, c). None with fewer
/// than two distinct sizes.
pub fn power_law_fit(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(n, c)| *n > 0.0 && *c > 0.0)
        .map(|(n, c)| (n.ln(), c.ln()))
        .collect();
    let count = logs.len() as f64;
    let mean_x = logs.iter().map(|p| p.0).sum::<f64>() / count;
    let mean_y = logs.iter().map(|p| p.1).sum::<f64>() / count;
    let sxx: f64 = logs.iter().map(|p| (p.0 - mean_x).powi(2)).sum();
    if logs.len() < 2 || sxx <= 0.0 {
        return None;
    }
    let sxy: f64 = logs.iter().map(|p| (p.0 - mean_x) * (p.1 - mean_y)).sum();
    let k = sxy / sxx;
    Some((k, (mean_y - k * mean_x).exp()))
}

/// The three largest sizes of a series (sorted by size), where the leading term shows.
pub fn largest_sizes(points: &[(f64, f64)]) -> &[(f64, f64)] {
    &points[points.len().saturating_sub(3)..]
}

/// One line of a scaling figure: cost (s) against size.
#[derive(Debug, Clone)]
pub struct ScalingSeries {
    /// Legend entry.
    pub name: String,
    /// (creases, seconds) pairs.
    pub points: Vec<(f64, f64)>,
}

/// Room for the scaling figure's legend (its entries carry fitted exponents), output pixels.
const SCALING_LEGEND: u32 = 420;

/// Log–log SVG of cost (in the unit that shows it best) against size (points sorted by
/// size), each series with its points joined and, in the legend, the exponent fitted over
/// its three largest sizes.
pub fn scaling_svg(title: &str, size_label: &str, series: &[ScalingSeries]) -> Result<String> {
    let all = || {
        series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|(n, c)| *n > 0.0 && *c > 0.0)
    };
    let largest = all().fold(0.0_f64, |m, p| m.max(p.1));
    let (unit_name, unit) = time_unit(largest);
    let (mut n_lo, mut n_hi, mut c_lo, mut c_hi) = (f64::INFINITY, 0.0_f64, f64::INFINITY, 0.0_f64);
    for &(n, c) in all() {
        n_lo = n_lo.min(n);
        n_hi = n_hi.max(n);
        c_lo = c_lo.min(c / unit);
        c_hi = c_hi.max(c / unit);
    }
    if n_hi == 0.0 {
        (n_lo, n_hi, c_lo, c_hi) = (1.0, 10.0, 0.1, 1.0);
    }
    let mut svg = String::new();
    {
        let root = canvas(&mut svg, (1100, 600));
        root.fill(&WHITE).map_err(plot_error)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin(px(14))
            .margin_right(px(SCALING_LEGEND))
            .x_label_area_size(px(40))
            .y_label_area_size(px(70))
            .build_cartesian_2d(
                (n_lo / 1.3..n_hi * 1.3).log_scale(),
                (c_lo / 3.0..c_hi * 3.0).log_scale(),
            )
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .set_all_tick_mark_size(px(5))
            .x_desc(size_label)
            .y_desc(format!("time ({unit_name})"))
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| tick(*v))
            .draw()
            .map_err(plot_error)?;
        let mut entries = Vec::new();
        for (i, line) in series.iter().enumerate() {
            let colour = series_colour(i);
            let points: Vec<(f64, f64)> = line
                .points
                .iter()
                .filter(|(n, c)| *n > 0.0 && *c > 0.0)
                .map(|&(n, c)| (n, c / unit))
                .collect();
            let name = match power_law_fit(largest_sizes(&line.points)) {
                Some((k, _)) => format!("{} (n^{k:.2} over the three largest n)", line.name),
                None => line.name.clone(),
            };
            chart
                .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                .map_err(plot_error)?;
            entries.push((name, colour, LineKind::Solid));
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, px(4), colour.filled())))
                .map_err(plot_error)?;
        }
        draw_legend_in_margin(&root, SCALING_LEGEND, 44, &entries)?;
        root.present().map_err(plot_error)?;
    }
    Ok(shown_at(svg))
}

/// One line of an error-by-parameter figure: (parameter, error) pairs.
#[derive(Debug, Clone)]
pub struct ErrorSeries {
    /// Legend entry.
    pub name: String,
    /// (parameter, error) pairs; errors ≤ 0 are left out of the log axis.
    pub points: Vec<(f64, f64)>,
}

/// SVG of errors (log axis) against an integer parameter (a fit's degree, say), each series
/// joined, with optional horizontal reference lines (label, value) dashed across the plot.
pub fn error_by_parameter_svg(
    title: &str,
    parameter_label: &str,
    error_label: &str,
    series: &[ErrorSeries],
    references: &[(String, f64)],
) -> Result<String> {
    let shown = |e: f64| e > 0.0 && e.is_finite();
    let (mut x_lo, mut x_hi, mut e_lo, mut e_hi) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, 0.0_f64);
    for &(x, e) in series.iter().flat_map(|s| s.points.iter()).filter(|p| shown(p.1)) {
        x_lo = x_lo.min(x);
        x_hi = x_hi.max(x);
        e_lo = e_lo.min(e);
        e_hi = e_hi.max(e);
    }
    for (_, value) in references.iter().filter(|r| shown(r.1)) {
        e_lo = e_lo.min(*value);
        e_hi = e_hi.max(*value);
    }
    if !x_hi.is_finite() {
        (x_lo, x_hi, e_lo, e_hi) = (0.0, 1.0, 1e-16, 1.0);
    }
    let mut svg = String::new();
    {
        let root = canvas(&mut svg, (1100, 600));
        root.fill(&WHITE).map_err(plot_error)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin(px(14))
            .margin_right(px(SCALING_LEGEND))
            .x_label_area_size(px(40))
            .y_label_area_size(px(70))
            .build_cartesian_2d(x_lo - 0.5..x_hi + 0.5, (e_lo / 10.0..e_hi * 10.0).log_scale())
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .set_all_tick_mark_size(px(5))
            .disable_x_mesh()
            .x_labels((x_hi - x_lo) as usize + 2)
            .x_desc(parameter_label)
            .y_desc(error_label)
            .x_label_formatter(&|v| {
                if (v - v.round()).abs() < 1e-9 {
                    format!("{v:.0}")
                } else {
                    String::new()
                }
            })
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(plot_error)?;
        let mut entries = Vec::new();
        for (i, line) in series.iter().enumerate() {
            let colour = series_colour(i);
            let points: Vec<(f64, f64)> = line.points.iter().copied().filter(|p| shown(p.1)).collect();
            chart
                .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                .map_err(plot_error)?;
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, px(4), colour.filled())))
                .map_err(plot_error)?;
            entries.push((line.name.clone(), colour, LineKind::Solid));
        }
        for (k, (label, value)) in references.iter().enumerate().filter(|(_, r)| shown(r.1)) {
            let colour = series_colour(series.len() + k);
            let mut dashes = Vec::new();
            let mut x = x_lo - 0.5;
            while x < x_hi + 0.5 {
                dashes.push(PathElement::new(
                    vec![(x, *value), ((x + 0.15).min(x_hi + 0.5), *value)],
                    colour.stroke_width(2),
                ));
                x += 0.3;
            }
            chart.draw_series(dashes).map_err(plot_error)?;
            entries.push((label.clone(), colour, LineKind::Dashed));
        }
        draw_legend_in_margin(&root, SCALING_LEGEND, 44, &entries)?;
        root.present().map_err(plot_error)?;
    }
    Ok(shown_at(svg))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_law_fit_recovers_an_exact_power_law() {
        let points: Vec<(f64, f64)> = [4.0, 16.0, 64.0, 256.0]
            .iter()
            .map(|&n: &f64| (n, 3e-7 * n.powf(2.5)))
            .collect();
        let (k, c) = power_law_fit(&points).unwrap();
        assert!((k - 2.5).abs() < 1e-12 && (c / 3e-7 - 1.0).abs() < 1e-10);
        assert!(power_law_fit(&[(8.0, 1.0)]).is_none());
    }

    /// Point labels of a crowded figure neither cover one another nor any marker. Boxes here
    /// are 6 px a character and 12 px high, independent of the placement's own estimate.
    #[test]
    fn point_labels_cover_no_label_and_no_marker() {
        let series: Vec<WorkSeries> = (0..4)
            .map(|s| WorkSeries {
                name: format!("series {s}"),
                points: (0..6)
                    .map(|k| WorkPoint {
                        label: format!("rtol 1e-{}", 4 + k),
                        seconds: 1e-3 * (1.0 + 0.08 * k as f64 + 0.02 * s as f64),
                        error: 10f64.powf(-2.0 - 0.15 * k as f64 - 0.05 * s as f64),
                    })
                    .collect(),
            })
            .collect();
        let svg = work_precision_svg("crowded", "error", &series).unwrap();
        let attribute = |tag: &str, key: &str| -> f64 {
            let start = tag.find(&format!(" {key}=\"")).unwrap() + key.len() + 3;
            tag[start..].split('"').next().unwrap().parse().unwrap()
        };
        let scale = f64::from(super::super::canvas::SCALE);
        let mut boxes = Vec::new();
        for piece in svg.split("<text").skip(1) {
            let (tag, rest) = piece.split_once('>').unwrap();
            if !tag.contains("opacity=\"0.9\"") {
                continue;
            }
            let text = rest.split("</text>").next().unwrap().trim();
            let (x, y) = (attribute(tag, "x"), attribute(tag, "y"));
            boxes.push((x, y, x + 6.0 * scale * text.chars().count() as f64, y + 12.0 * scale));
        }
        assert!(boxes.len() >= 4, "{} labels", boxes.len());
        for (i, a) in boxes.iter().enumerate() {
            for b in &boxes[..i] {
                let overlap = a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3;
                assert!(!overlap, "labels at {a:?} and {b:?} overlap");
            }
        }
        for piece in svg.split("<circle").skip(1) {
            let tag = piece.split_once('>').unwrap().0;
            let (cx, cy) = (attribute(tag, "cx"), attribute(tag, "cy"));
            for b in &boxes {
                assert!(
                    !(b.0 < cx && cx < b.2 && b.1 < cy && cy < b.3),
                    "a label at {b:?} covers the marker at ({cx}, {cy})"
                );
            }
        }
    }

    #[test]
    fn times_are_shown_in_a_readable_unit() {
        assert_eq!(time_unit(2.0).0, "s");
        assert_eq!(time_unit(0.5).0, "ms");
        assert_eq!(time_unit(3e-6).0, "µs");
        assert_eq!(time_unit(5e-8).0, "ns");
    }
}
