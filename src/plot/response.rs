//! Figures of a dynamics run: `response.svg` (fold angles and energies against time, like the
//! thesis's figures 5-4 and 5-6) and `snapshots.svg` (side view of a strip, figure 5-7; the
//! plates in 3D for a closed chain, figures 5-10 to 5-12).

use super::canvas::{canvas, px, shown_at};
use super::{
    axis_range, coinciding, draw_series_line, draw_side_legend, plot_error, series_colour, LineKind, LEGEND_MARGIN,
};
use crate::dynamics::algorithms::{update_corners, update_poses};
use crate::dynamics::closed::ClosedChain;
use crate::dynamics::model::Data;
use crate::dynamics::network::algorithms::update_poses as place_panels;
use crate::dynamics::network::{NetworkData, NetworkModel};
use crate::dynamics::plant::Sample;
use crate::dynamics::scene::{Scene, System};
use crate::dynamics::simulate::{ModelKind, Response};
use crate::dynamics::strip::StripChain;
use crate::error::Result;
use nalgebra::Point3;
use plotters::prelude::*;

/// One energy term of a sample, J.
type EnergyTerm = Box<dyn Fn(&Sample) -> f64>;

/// A time unit that keeps the axis numbers readable: (divisor, label).
fn time_unit(t_end: f64) -> (f64, &'static str) {
    if t_end < 1e-3 {
        (1e-6, "µs")
    } else if t_end < 1.0 {
        (1e-3, "ms")
    } else {
        (1.0, "s")
    }
}

fn model_label(response: &Response) -> String {
    match response.model {
        ModelKind::Dynamic => format!(
            "dynamic, {}, rtol {:.0e}",
            response
                .method
                .map_or("-".to_string(), |m| format!("{m:?}").to_lowercase()),
            response.rtol
        ),
        ModelKind::QuasiStatic => format!("quasi-static (time-scale ratio {:.1e})", response.time_scales.ratio),
    }
}

/// What the response figure labels: one entry per plotted angle.
pub struct ResponseView {
    /// The scene's name, for the title.
    pub name: String,
    /// Legend label of each angle series.
    pub labels: Vec<String>,
    /// How a series that repeats another names it in the legend ("hinge 1 (= hinge 0)").
    pub names: Vec<String>,
    /// A dashed target line per series, if any (rad).
    pub targets: Vec<Option<f64>>,
    /// Whether drag is modelled (the energy plot says so).
    pub drag: bool,
    /// The sample's angle each series plots (series i plots angle `columns[i]`).
    pub columns: Vec<usize>,
    /// A note on which angles are plotted (None: all of them).
    pub selection: Option<String>,
}

/// Networks plot at most this many creases in `response.svg` (those that move most).
const MAX_SERIES: usize = 16;

impl ResponseView {
    /// A scene's series: a strip's hinges (passive or with their targets), or a closed
    /// chain's creases with their roles (driven, locked, cut).
    pub fn of_scene(scene: &Scene) -> Self {
        match &scene.system {
            System::Strip(chain) => Self::of_strip(&scene.name, chain),
            System::Closed(chain) => Self::of_closed(&scene.name, chain),
            System::Network(model) => Self::of_network(&scene.name, model, None),
        }
    }

    /// A network's creases with their assignments and roles; with a response and more than
    /// `MAX_SERIES` creases, the ones whose angle ranges furthest over the run.
    pub fn of_network(name: &str, model: &NetworkModel, response: Option<&Response>) -> Self {
        let n = model.columns();
        let mut columns: Vec<usize> = (0..n).collect();
        let mut selection = None;
        if let (Some(response), true) = (response, n > MAX_SERIES) {
            let range = |c: usize| {
                let (lo, hi) = response
                    .samples
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), s| {
                        (l.min(s.angles[c]), h.max(s.angles[c]))
                    });
                hi - lo
            };
            columns.sort_by(|&a, &b| range(b).total_cmp(&range(a)).then(a.cmp(&b)));
            columns.truncate(MAX_SERIES);
            columns.sort_unstable();
            selection = Some(format!("{MAX_SERIES} of {n} creases, those that move most"));
        }
        let pattern = &model.folding.pattern;
        ResponseView {
            name: name.to_string(),
            // A crease's name alone ("edges[12]", not its letter and role), so the legend fits.
            names: columns.iter().map(|&c| model.labels[c].clone()).collect(),
            labels: columns
                .iter()
                .map(|&c| {
                    let letter = match pattern.kinds[pattern.creases[c]] {
                        crate::pattern::crease_pattern::EdgeKind::Crease(a) => a.letter(),
                        _ => "?",
                    };
                    // Actuated is the rule; the others say what they are.
                    let role = if model.locked(c) {
                        " locked"
                    } else if model.forcing.hinges[c].actuated {
                        ""
                    } else {
                        " passive"
                    };
                    format!("{} {letter}{role}", model.labels[c])
                })
                .collect(),
            targets: columns
                .iter()
                .map(|&c| {
                    model.forcing.hinges[c]
                        .actuated
                        .then_some(model.forcing.hinges[c].target)
                })
                .collect(),
            drag: model.drag.is_some(),
            columns,
            selection,
        }
    }

    fn of_strip(name: &str, chain: &StripChain) -> Self {
        let labels: Vec<String> = (0..chain.model.dof())
            .map(|i| {
                let passive = !chain.forcing.hinges[i].actuated;
                format!("hinge {i}{}", if passive { " (passive)" } else { "" })
            })
            .collect();
        ResponseView {
            name: name.to_string(),
            names: labels.clone(),
            labels,
            targets: chain.forcing.hinges.iter().map(|h| Some(h.target)).collect(),
            drag: chain.model.drag().is_some(),
            columns: (0..chain.model.dof()).collect(),
            selection: None,
        }
    }

    fn of_closed(name: &str, chain: &ClosedChain) -> Self {
        let creases = chain.crease_stiffness.len();
        let labels: Vec<String> = (0..creases)
            .map(|c| {
                let role = if c == chain.driver {
                    "driven"
                } else if chain.locked.iter().any(|&(l, _)| l == c) {
                    "locked"
                } else if c == chain.cut_crease {
                    "cut, follows"
                } else {
                    "follows"
                };
                format!("{} ({role})", chain.crease_labels[c])
            })
            .collect();
        ResponseView {
            name: name.to_string(),
            names: labels.clone(),
            labels,
            targets: (0..creases)
                .map(|c| (c == chain.driver).then_some(chain.target()))
                .collect(),
            drag: chain.model.drag().is_some(),
            columns: (0..creases).collect(),
            selection: None,
        }
    }
}

/// Renders a scene's `response.svg`.
pub fn response_svg(scene: &Scene, response: &Response) -> Result<String> {
    let view = match &scene.system {
        System::Network(model) => ResponseView::of_network(&scene.name, model, Some(response)),
        _ => ResponseView::of_scene(scene),
    };
    response_view_svg(&view, response)
}

/// Renders a scene's `snapshots.svg`: a strip seen along its creases, a closed chain's
/// plates in 3D.
pub fn snapshots_svg(scene: &Scene, response: &Response) -> Result<String> {
    match &scene.system {
        System::Strip(chain) => strip_snapshots_svg(&scene.name, chain, scene.outputs.snapshots, response),
        System::Closed(chain) => closed_snapshots_svg(&scene.name, chain, response, 5),
        System::Network(model) => network_snapshots_svg(&scene.name, model, response, 5),
    }
}

/// Renders `response.svg`: angles (deg) per series with dashed targets, and the energy terms.
pub fn response_view_svg(view: &ResponseView, response: &Response) -> Result<String> {
    let mut svg = String::new();
    {
        let root = canvas(&mut svg, (1000, 760));
        root.fill(&WHITE).map_err(plot_error)?;
        let (top, bottom) = root.split_vertically(px(470));
        let (scale, unit) = time_unit(response.t_end.max(response.samples.last().map_or(0.0, |s| s.time)));
        let t_max = response.samples.last().map_or(1.0, |s| s.time).max(f64::MIN_POSITIVE) / scale;
        let mut lo: f64 = -10.0;
        let mut hi: f64 = 10.0;
        for s in &response.samples {
            for &c in &view.columns {
                lo = lo.min(s.angles[c].to_degrees());
                hi = hi.max(s.angles[c].to_degrees());
            }
        }
        for t in view.targets.iter().flatten() {
            lo = lo.min(t.to_degrees());
            hi = hi.max(t.to_degrees());
        }
        let y_range = axis_range(lo, hi, 0.06);
        let collision = response.collision.as_ref().map_or("no collision".to_string(), |c| {
            format!("{} hits {} at t = {:.4} {unit}", c.pair[0], c.pair[1], c.time / scale)
        });
        let shown = view.selection.as_ref().map_or(String::new(), |s| format!("; {s}"));
        let mut chart = ChartBuilder::on(&top)
            .caption(
                format!(
                    "{}: fold angles ({}; {collision}{shown})",
                    view.name,
                    model_label(response)
                ),
                ("sans-serif", 18),
            )
            .margin(px(12))
            .margin_right(px(LEGEND_MARGIN))
            .x_label_area_size(px(36))
            .y_label_area_size(px(56))
            // A run that ends at a contact leaves room past it, so its line shows.
            .build_cartesian_2d(
                if response.collision.is_some() {
                    0.0..t_max * 1.02
                } else {
                    axis_range(0.0, t_max, 0.0)
                },
                y_range.clone(),
            )
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .set_all_tick_mark_size(px(5))
            .x_desc(format!("time ({unit})"))
            .y_desc("fold angle (deg)")
            .draw()
            .map_err(plot_error)?;
        // Hinges that move alike draw one line over another: the legend says which.
        let series: Vec<Vec<f64>> = view
            .columns
            .iter()
            .map(|&c| response.samples.iter().map(|s| s.angles[c]).collect())
            .collect();
        let same = coinciding(&series, 1e-9);
        let mut entries = Vec::new();
        let mut targets = Vec::new();
        for (i, label) in view.labels.iter().enumerate() {
            let label = match same[i] {
                Some(j) => format!("{label} (= {})", view.names[j]),
                None => label.clone(),
            };
            let column = view.columns[i];
            let points = response
                .samples
                .iter()
                .map(|s| (s.time / scale, s.angles[column].to_degrees()))
                .collect();
            let (label, colour, kind) = draw_series_line(&mut chart, points, i, label)?;
            entries.push((label, colour, kind));
            if let Some(target) = view.targets[i].map(f64::to_degrees) {
                targets.push((target, colour));
            }
        }
        // Targets over every series (a fast ringing hinge would hide them), on a white
        // underlay so they show on any band.
        for (target, colour) in targets {
            for (width, shade) in [(4, WHITE), (2, colour)] {
                let dashes = (0..40).map(|k| {
                    let a = t_max * k as f64 / 40.0;
                    PathElement::new(
                        vec![(a, target), (a + 0.5 * t_max / 40.0, target)],
                        shade.stroke_width(width),
                    )
                });
                chart.draw_series(dashes).map_err(plot_error)?;
            }
        }
        if let Some(c) = &response.collision {
            // Black, dotted: no hinge's colour.
            let x = c.time / scale;
            chart
                .draw_series(DashedLineSeries::new(
                    vec![(x, y_range.start), (x, y_range.end)],
                    px(4),
                    px(4),
                    BLACK.stroke_width(2),
                ))
                .map_err(plot_error)?;
            entries.push(("first contact".into(), BLACK, LineKind::Dotted));
        }
        entries.push(("target (dashes)".into(), RGBColor(150, 150, 150), LineKind::Dashed));
        draw_side_legend(&top, 44, &entries)?;

        // Energies in the unit that suits them.
        let largest = response
            .samples
            .iter()
            .flat_map(|s| {
                [
                    s.kinetic_energy.abs(),
                    s.elastic_energy.abs(),
                    s.actuator_potential.abs(),
                    s.actuation_work.unwrap_or(0.0).abs(),
                ]
            })
            .fold(0.0_f64, f64::max);
        let (e_scale, e_unit) = if largest < 1e-9 {
            (1e-12, "pJ")
        } else if largest < 1e-6 {
            (1e-9, "nJ")
        } else {
            (1e-6, "µJ")
        };
        let balance = response.samples.iter().all(|s| s.energy_balance().is_some());
        let series: Vec<(&str, EnergyTerm)> = if balance {
            vec![
                ("kinetic ½θ̇ᵀMθ̇", Box::new(|s| s.kinetic_energy)),
                ("hinges ½θᵀKθ", Box::new(|s| s.elastic_energy)),
                ("−work of the actuation", Box::new(|s| -s.actuation_work.unwrap_or(0.0))),
                ("drag dissipation", Box::new(|s| s.drag_dissipation.unwrap_or(0.0))),
                ("balance (sum)", Box::new(|s| s.energy_balance().unwrap_or(0.0))),
            ]
        } else {
            vec![
                ("kinetic ½θ̇ᵀMθ̇", Box::new(|s| s.kinetic_energy)),
                ("elastic ½θᵀKθ", Box::new(|s| s.elastic_energy)),
                ("actuator −τ·θ", Box::new(|s| s.actuator_potential)),
                ("total", Box::new(|s| s.total_energy())),
            ]
        };
        let last = series.len() - 1;
        let (mut e_lo, mut e_hi) = (0.0_f64, 0.0_f64);
        for s in &response.samples {
            for (_, f) in &series {
                e_lo = e_lo.min(f(s) / e_scale);
                e_hi = e_hi.max(f(s) / e_scale);
            }
        }
        let mut energy = ChartBuilder::on(&bottom)
            .caption(
                format!("energy (drag {})", if view.drag { "on" } else { "off" }),
                ("sans-serif", 16),
            )
            .margin(px(12))
            .margin_right(px(LEGEND_MARGIN))
            .x_label_area_size(px(36))
            .y_label_area_size(px(56))
            .build_cartesian_2d(
                if response.collision.is_some() {
                    0.0..t_max * 1.02
                } else {
                    axis_range(0.0, t_max, 0.0)
                },
                axis_range(e_lo, e_hi, 0.06),
            )
            .map_err(plot_error)?;
        energy
            .configure_mesh()
            .set_all_tick_mark_size(px(5))
            .x_desc(format!("time ({unit})"))
            .y_desc(format!("energy ({e_unit})"))
            .draw()
            .map_err(plot_error)?;
        let mut entries = Vec::new();
        for (k, (label, f)) in series.iter().enumerate() {
            let colour = if k == last { BLACK } else { series_colour(k + 5) };
            energy
                .draw_series(LineSeries::new(
                    response.samples.iter().map(|s| (s.time / scale, f(s) / e_scale)),
                    colour.stroke_width(2),
                ))
                .map_err(plot_error)?;
            entries.push((label.to_string(), colour, LineKind::Solid));
        }
        draw_side_legend(&bottom, 40, &entries)?;
        root.present().map_err(plot_error)?;
    }
    Ok(shown_at(svg))
}

/// Indices of `count` samples spread evenly in time, the last sample included.
pub fn snapshot_samples(response: &Response, count: usize) -> Vec<usize> {
    let n = response.samples.len();
    if n == 0 {
        return Vec::new();
    }
    let count = count.clamp(1, n);
    let t_last = response.samples[n - 1].time;
    let mut picks: Vec<usize> = (0..count)
        .map(|k| {
            let t = if count == 1 {
                t_last
            } else {
                t_last * k as f64 / (count - 1) as f64
            };
            response
                .samples
                .iter()
                .position(|s| s.time >= t - 1e-12 * t_last.abs())
                .unwrap_or(n - 1)
        })
        .collect();
    picks.dedup();
    picks
}

/// A strip's `snapshots.svg`: the chain seen along the creases (the y–z plane) at several
/// times, the substrate solid where it remains and dashed where it is etched away.
fn strip_snapshots_svg(name: &str, chain: &StripChain, count: usize, response: &Response) -> Result<String> {
    let model = &chain.model;
    let mut data = Data::new(model);
    let picks = snapshot_samples(response, count);
    // Centre lines of the plates in µm, per snapshot.
    let mut outlines: Vec<(f64, Vec<(f64, f64)>)> = Vec::new();
    for &k in &picks {
        let sample = &response.samples[k];
        update_poses(model, sample.angles.as_slice(), &mut data);
        update_corners(model, &mut data);
        let mut points = Vec::new();
        for i in 0..model.dof() {
            let first = model.corner_index(i, 0);
            let c = &data.corners[first..first + 4];
            let start = (c[0] + c[1].coords) / 2.0;
            let end = (c[2] + c[3].coords) / 2.0;
            if i == 0 {
                points.push((start.y * 1e6, start.z * 1e6));
            }
            points.push((end.y * 1e6, end.z * 1e6));
        }
        outlines.push((sample.time, points));
    }
    let (mut y_lo, mut y_hi, mut z_lo, mut z_hi) = (f64::INFINITY, f64::NEG_INFINITY, 0.0_f64, 0.0_f64);
    for (_, points) in &outlines {
        for &(y, z) in points {
            y_lo = y_lo.min(y);
            y_hi = y_hi.max(y);
            z_lo = z_lo.min(z);
            z_hi = z_hi.max(z);
        }
    }
    let edge = chain.substrate_edge_y * 1e6;
    y_lo = y_lo.min(edge - 50.0);
    let (width, height) = (1000u32, 620u32);
    // Equal scales on both axes: widen whichever range is short.
    let plot_w = (width - 90 - LEGEND_MARGIN) as f64;
    let plot_h = (height - 110) as f64;
    let pad = 0.08 * (y_hi - y_lo).max(z_hi - z_lo);
    let (mut y0, mut y1, mut z0, mut z1) = (y_lo - pad, y_hi + pad, z_lo - pad, z_hi + pad);
    let per_px = ((y1 - y0) / plot_w).max((z1 - z0) / plot_h);
    let (ym, zm) = (0.5 * (y0 + y1), 0.5 * (z0 + z1));
    y0 = ym - 0.5 * per_px * plot_w;
    y1 = ym + 0.5 * per_px * plot_w;
    z0 = zm - 0.5 * per_px * plot_h;
    z1 = zm + 0.5 * per_px * plot_h;
    let mut svg = String::new();
    {
        let root = canvas(&mut svg, (width, height));
        root.fill(&WHITE).map_err(plot_error)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!("{}: side view along the creases ({})", name, model_label(response)),
                ("sans-serif", 18),
            )
            .margin(px(12))
            .margin_right(px(LEGEND_MARGIN))
            .x_label_area_size(px(36))
            .y_label_area_size(px(56))
            .build_cartesian_2d(axis_range(y0, y1, 0.0), axis_range(z0, z1, 0.0))
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .set_all_tick_mark_size(px(5))
            .x_desc("y (µm)")
            .y_desc("z (µm)")
            .draw()
            .map_err(plot_error)?;
        let grey = RGBColor(90, 90, 90);
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(y0, 0.0), (edge, 0.0)],
                grey.stroke_width(4),
            )))
            .map_err(plot_error)?;
        let mut entries = vec![("substrate".to_string(), grey, LineKind::Solid)];
        let dashes = (0..60).map(|k| {
            let a = edge + (y1 - edge) * k as f64 / 60.0;
            PathElement::new(
                vec![(a, 0.0), (a + 0.5 * (y1 - edge) / 60.0, 0.0)],
                grey.stroke_width(1),
            )
        });
        chart.draw_series(dashes).map_err(plot_error)?;
        for (k, (time, points)) in outlines.iter().enumerate() {
            let colour = series_colour(k);
            chart
                .draw_series(std::iter::once(PathElement::new(
                    points.clone(),
                    colour.stroke_width(3),
                )))
                .map_err(plot_error)?;
            entries.push((format!("t = {}", time_label(*time)), colour, LineKind::Solid));
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, px(3), colour.filled())))
                .map_err(plot_error)?;
        }
        if let Some(c) = &response.collision {
            let p = (c.point.y * 1e6, c.point.z * 1e6);
            chart
                .draw_series(std::iter::once(Cross::new(p, px(9), RED.stroke_width(3))))
                .map_err(plot_error)?;
            entries.push((format!("contact: {} / {}", c.pair[0], c.pair[1]), RED, LineKind::Cross));
        }
        draw_side_legend(&root, 44, &entries)?;
        root.present().map_err(plot_error)?;
    }
    Ok(shown_at(svg))
}

/// A time in the unit that shows it with four significant digits, trailing zeros dropped:
/// "27.22 µs", "252 s", "0 s".
pub fn time_label(seconds: f64) -> String {
    if seconds == 0.0 || !seconds.is_finite() {
        return format!("{seconds} s");
    }
    let (unit, scale) = super::work_precision::time_unit(seconds.abs());
    let value = seconds / scale;
    let decimals = (3 - value.abs().log10().floor() as i32).max(0) as usize;
    let text = format!("{value:.decimals$}");
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    };
    format!("{text} {unit}")
}

/// A closed chain's `snapshots.svg`: the sector plates in 3D (the anchored one grey) at
/// `count` moments of the response, like the thesis's figures 5-10 to 5-12.
fn closed_snapshots_svg(name: &str, chain: &ClosedChain, response: &Response, count: usize) -> Result<String> {
    let model = &chain.model;
    let mut data = Data::new(model);
    let reach = chain
        .ground
        .iter()
        .chain(model.plates().iter().flat_map(|p| p.outline.iter()))
        .map(|c| c.coords.norm())
        .chain(
            model
                .plates()
                .iter()
                .map(|p| p.radius() + p.reference_pose.translation.vector.norm()),
        )
        .fold(0.0, f64::max)
        .max(1e-12)
        * 1e6;
    let picks = snapshot_samples(response, count);
    let mut svg = String::new();
    {
        let root = canvas(&mut svg, (1100, 400));
        root.fill(&WHITE).map_err(plot_error)?;
        let (title, body) = root.split_vertically(px(34));
        title
            .titled(
                &format!(
                    "{}: the plates in 3D (grey: anchored sector; each view {:.0} µm across){}",
                    name,
                    2.0 * reach,
                    response.collision.as_ref().map_or(String::new(), |c| format!(
                        ", first contact at t = {}",
                        time_label(c.time)
                    ))
                ),
                ("sans-serif", 18),
            )
            .map_err(plot_error)?;
        let panels = body.split_evenly((1, picks.len().max(1)));
        // plotters' 3D y axis is vertical: plot (x, z, y) so the pattern's z is up.
        let to_plot = |p: &Point3<f64>| (p.x * 1e6, p.z * 1e6, p.y * 1e6);
        for (panel, &index) in panels.iter().zip(&picks) {
            let sample = &response.samples[index];
            let joint_angles: Vec<f64> = chain.joint_creases.iter().map(|&c| sample.angles[c]).collect();
            update_poses(model, &joint_angles, &mut data);
            update_corners(model, &mut data);
            let mut view = ChartBuilder::on(panel)
                .caption(format!("t = {}", time_label(sample.time)), ("sans-serif", 14))
                .margin(px(4))
                .build_cartesian_3d(-reach..reach, -reach..reach, -reach..reach)
                .map_err(plot_error)?;
            view.with_projection(|mut p| {
                p.yaw = -0.9;
                p.pitch = 0.45;
                p.scale = 1.25;
                p.into_matrix()
            });
            let mut polygons = vec![(
                chain.ground.iter().map(to_plot).collect::<Vec<_>>(),
                RGBColor(150, 150, 150),
            )];
            for (j, plate) in model.plates().iter().enumerate() {
                let corners = (0..plate.outline.len())
                    .map(|k| to_plot(&data.corners[model.corner_index(j, k)]))
                    .collect();
                polygons.push((corners, series_colour(chain.joint_creases[j])));
            }
            for (mut outline, colour) in polygons {
                view.draw_series(std::iter::once(Polygon::new(outline.clone(), colour.mix(0.4).filled())))
                    .map_err(plot_error)?;
                outline.push(outline[0]);
                view.draw_series(std::iter::once(PathElement::new(outline, BLACK.stroke_width(1))))
                    .map_err(plot_error)?;
            }
        }
        root.present().map_err(plot_error)?;
    }
    Ok(shown_at(svg))
}

/// A network's panels in 3D at `count` moments (anchored panel grey, the others by their
/// tree crease's colour).
fn network_snapshots_svg(name: &str, model: &NetworkModel, response: &Response, count: usize) -> Result<String> {
    let pattern = &model.folding.pattern;
    let mut data = NetworkData::new(model);
    let flat = |v: usize| {
        nalgebra::Vector3::new(
            pattern.vertices[v][0] * model.unit,
            pattern.vertices[v][1] * model.unit,
            0.0,
        )
    };
    let picks = snapshot_samples(response, count);
    // One cube around every view's panels, so the views share a scale and fill their frames.
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for &index in &picks {
        place_panels(model, response.samples[index].angles.as_slice(), &mut data);
        for (p, triangles) in model.folding.panel_triangles.iter().enumerate() {
            for &v in triangles.iter().flatten() {
                let x = data.place(p, &flat(v)) * 1e6;
                for k in 0..3 {
                    lo[k] = lo[k].min(x[k]);
                    hi[k] = hi[k].max(x[k]);
                }
            }
        }
    }
    let centre = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    let reach = (0..3).map(|k| 0.55 * (hi[k] - lo[k])).fold(1e-6, f64::max);
    let mut svg = String::new();
    {
        let root = canvas(&mut svg, (1100, 400));
        root.fill(&WHITE).map_err(plot_error)?;
        let (title, body) = root.split_vertically(px(34));
        title
            .titled(
                &format!(
                    "{}: the panels in 3D (grey: anchored panel; each view {:.0} µm across){}",
                    name,
                    2.0 * reach,
                    response.collision.as_ref().map_or(String::new(), |c| format!(
                        ", first contact at t = {}",
                        time_label(c.time)
                    ))
                ),
                ("sans-serif", 18),
            )
            .map_err(plot_error)?;
        let panels = body.split_evenly((1, picks.len().max(1)));
        let to_plot = |p: nalgebra::Vector3<f64>| (p.x * 1e6, p.z * 1e6, p.y * 1e6);
        for (area, &index) in panels.iter().zip(&picks) {
            let sample = &response.samples[index];
            place_panels(model, sample.angles.as_slice(), &mut data);
            // plotters' 3D y axis is vertical: (x, z, y) so the pattern's z is up.
            let mut view = ChartBuilder::on(area)
                .caption(format!("t = {}", time_label(sample.time)), ("sans-serif", 14))
                .margin(px(4))
                .build_cartesian_3d(
                    centre[0] - reach..centre[0] + reach,
                    centre[2] - reach..centre[2] + reach,
                    centre[1] - reach..centre[1] + reach,
                )
                .map_err(plot_error)?;
            view.with_projection(|mut p| {
                p.yaw = -0.9;
                p.pitch = 0.45;
                p.scale = 1.25;
                p.into_matrix()
            });
            for (p, triangles) in model.folding.panel_triangles.iter().enumerate() {
                let colour = if p == model.anchored_panel {
                    RGBColor(150, 150, 150)
                } else {
                    series_colour(model.parent_column[p].unwrap_or(0))
                };
                for t in triangles {
                    let corners: Vec<_> = t.iter().map(|&v| to_plot(data.place(p, &flat(v)))).collect();
                    view.draw_series(std::iter::once(Polygon::new(corners.clone(), colour.mix(0.4).filled())))
                        .map_err(plot_error)?;
                }
                // The panel's outline: its faces' edges that are not facet lines inside it.
                for (f, face) in pattern
                    .faces
                    .iter()
                    .enumerate()
                    .filter(|(f, _)| pattern.panel_of_face[*f] == p)
                {
                    let _ = f;
                    let k = face.len();
                    for i in 0..k {
                        let (a, b) = (face[i], face[(i + 1) % k]);
                        let line = vec![to_plot(data.place(p, &flat(a))), to_plot(data.place(p, &flat(b)))];
                        view.draw_series(std::iter::once(PathElement::new(line, BLACK.stroke_width(1))))
                            .map_err(plot_error)?;
                    }
                }
            }
        }
        root.present().map_err(plot_error)?;
    }
    Ok(shown_at(svg))
}
