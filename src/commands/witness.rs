//! A single vertex's unfolding witnessed by a rigid folding path
//! (`docs/model.md#unfolding-by-a-folding-path`): where the energy descent stops short of
//! flat, the crease-pattern engine folds the vertex's sheet from flat onto its folded state,
//! and that path, reversed, unfolds it.

use crate::folding::{fold_path, Drive, FoldPath, FoldSettings, FoldingModel, StopReason};
use crate::geometry::kinematics;
use crate::names::Named;
use crate::pattern::{RayRole, VertexPattern};
use crate::unfold::{planarity_residual, StepKind, StepRecord, UnfoldModel, UnfoldReport, UnfoldSettings, Verdict};
use crate::Result;
use std::f64::consts::PI;

/// A path that ends within this of the folded state, rad (every crease), reaches it: the
/// rest is the corrector's approach to a singular end (a state folded flat).
const WITNESS_GAP: f64 = 1e-6;

/// Back-offs from the folded state tried by the backward search, as fractions of every
/// angle: the first that leads to flat serves.
const BACKOFFS: [f64; 3] = [1e-3, 1e-2, 1e-4];

/// The unfolding of `vertex` by the reversed rigid folding path from flat onto its folded
/// state, where the energy descent (`energy_run`) ended without reaching flat; None where no
/// path reaches that state. The path is tried straight (every crease towards its angle at
/// once) and, where that stalls, in two stages: a straight line of two creases folded alike
/// first (a sheet folded in half), the rest after.
pub(crate) fn unfold_by_folding_path(
    vertex: &VertexPattern,
    sheet: &FoldingModel,
    energy_run: &UnfoldReport,
    settings: &UnfoldSettings,
) -> Result<Option<UnfoldReport>> {
    let rays_of_columns: Vec<usize> = sheet.pattern.creases.clone();
    if rays_of_columns
        .iter()
        .any(|&ray| !matches!(vertex.rays.get(ray), Some(RayRole::Crease(_))))
        || sheet.locked_columns.iter().any(|&l| l)
    {
        return Ok(None);
    }
    let targets = sheet.given_fold_angles();
    // A file's rounding leaves a designed straight line or flat-foldable vertex a little
    // off; the path is sought on the design its sectors are within noise of.
    let design = design_sectors(vertex);
    let designed_sheet;
    let (path_sheet, moved) = match &design {
        Some((sectors, moved)) if *moved > 0.0 => {
            let mut designed = vertex.clone();
            designed.sector_angles.clone_from(sectors);
            designed_sheet = super::sheet_of_vertex(&designed)?;
            (&designed_sheet, *moved)
        }
        _ => (sheet, 0.0),
    };
    let Some((states, mut how)) = folding_path(path_sheet, &targets)? else {
        return Ok(None);
    };
    if moved > 0.0 {
        how.push_str(&format!(
            "; on the design within the file's noise: sectors moved by up to {moved:.1e} rad to make its straight lines straight and its alternate sectors sum to 180°"
        ));
    }
    let model = UnfoldModel::new(vertex);
    let energy = settings.energy.build(settings.p);
    let mut workspace = crate::unfold::EnergyWorkspace::default();
    let mut trajectory = Vec::with_capacity(states.len());
    let mut max_arc_residual: f64 = 0.0;
    let mut previous: Option<&Vec<f64>> = None;
    for (iteration, state) in states.iter().rev().enumerate() {
        let mut ray_angles = vec![0.0; vertex.rays.len()];
        for (&ray, &rho) in rays_of_columns.iter().zip(state) {
            ray_angles[ray] = rho;
        }
        let nodes = kinematics::forward(&model.sector_angles, &ray_angles);
        let arc_residual = model.max_arc_residual(&nodes);
        max_arc_residual = max_arc_residual.max(arc_residual);
        let direction_norm = previous.map_or(0.0, |p| {
            p.iter().zip(state).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()))
        });
        previous = Some(state);
        trajectory.push(StepRecord {
            iteration,
            kind: if iteration == 0 {
                StepKind::Start
            } else {
                StepKind::FoldingPath
            },
            // The folded state itself has touching charges (infinite energy): its energy is
            // the backed-off start's, as the descent reports it.
            energy: Some(energy.value(&nodes, &model.arcs, &mut workspace))
                .filter(|u| u.is_finite())
                .unwrap_or(energy_run.energy_initial),
            fold_angles: model.crease_angles(&nodes),
            max_arc_residual: arc_residual,
            direction_norm,
            nodes,
        });
    }
    let last = trajectory.last().expect("a path has its start");
    let final_nodes = last.nodes.clone();
    let gap = states
        .last()
        .expect("a path has its end")
        .iter()
        .zip(&targets)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    let evidence = format!(
        "the energy descent ended {} ({}); a rigid folding path from flat onto the folded state ({how}; {} states, every closure within 1e-11 rad, no panels crossing, every crease's sign as assigned; it ends {gap:.1e} rad from the state), reversed, unfolds it",
        energy_run.verdict.as_str(),
        energy_run.evidence,
        states.len()
    );
    let mut adjustments = energy_run.adjustments.clone();
    adjustments.push("unfolded by the reversed rigid folding path from flat (the energy descent stopped short)".into());
    Ok(Some(UnfoldReport {
        verdict: Verdict::Flat,
        evidence,
        termination: None,
        iterations: trajectory.len(),
        seconds: energy_run.seconds,
        energy_initial: trajectory[0].energy,
        energy_final: last.energy,
        initial_fold_angles_rad: energy_run.initial_fold_angles_rad.clone(),
        final_fold_angles_rad: last.fold_angles.clone(),
        max_arc_residual,
        planarity_residual: planarity_residual(&final_nodes),
        flat_layout_error: model.flat_layout_error(&final_nodes),
        restarts_used: 0,
        crossings_refused: 0,
        qp_almost_solved: 0,
        adjustments,
        trajectory,
        final_nodes,
    }))
}

/// The states of a rigid folding path from flat that ends within [`WITNESS_GAP`] of
/// `targets`, and how it was driven; None where neither drive reaches them.
fn folding_path(sheet: &FoldingModel, targets: &[f64]) -> Result<Option<(Vec<Vec<f64>>, String)>> {
    let flat = vec![0.0; targets.len()];
    let drive_to = |drive: Drive, start: &[f64]| -> Result<FoldPath> {
        let settings = FoldSettings {
            drive,
            ..FoldSettings::default()
        };
        fold_path(sheet, start, &settings)
    };
    let reaches = |path: &FoldPath| {
        let end = &path.steps.last().expect("a path has its start").fold_angles;
        end.iter().zip(targets).all(|(a, b)| (a - b).abs() <= WITNESS_GAP)
    };
    let straight = drive_to(
        Drive::Targets {
            targets: targets.to_vec(),
            to: 100.0,
        },
        &flat,
    )?;
    if reaches(&straight) {
        let states = straight.steps.into_iter().map(|s| s.fold_angles).collect();
        return Ok(Some((states, "every crease driven towards its angle at once".into())));
    }
    // From the folded state backed off (damped least squares onto the closures) towards
    // flat, the path then reversed.
    for backoff in BACKOFFS {
        let mut backed: Vec<f64> = targets.iter().map(|t| t * (1.0 - backoff)).collect();
        let mut solver = crate::folding::NormalSolver::new(1e-10);
        if crate::folding::damped_projection(sheet, &mut backed, 1e-11, &mut solver)?.is_some() {
            let back = drive_to(
                Drive::Targets {
                    targets: flat.clone(),
                    to: 100.0,
                },
                &backed,
            )?;
            let end = &back.steps.last().expect("a path has its start").fold_angles;
            if end.iter().all(|a| a.abs() <= WITNESS_GAP) {
                let jump = backed
                    .iter()
                    .zip(targets)
                    .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
                let states = back
                    .steps
                    .into_iter()
                    .rev()
                    .map(|s| s.fold_angles)
                    .chain(std::iter::once(targets.to_vec()))
                    .collect();
                return Ok(Some((
                states,
                format!("found backwards: from the folded state backed off by {backoff:.0e} of every angle and put onto the closures by damped least squares (a move of {jump:.1e} rad), every crease driven towards flat"),
            )));
            }
        }
    }

    // A straight line of two creases folded alike, fully: the sheet folded in half first.
    let folded_flat = |c: usize| (targets[c].abs() - PI).abs() <= 1e-9;
    let direction = |c: usize| sheet.pattern.vertices[sheet.pattern.edges[sheet.pattern.creases[c]][1]];
    let n = targets.len();
    for a in (0..n).filter(|&a| folded_flat(a)) {
        for b in (a + 1..n).filter(|&b| folded_flat(b) && targets[b] == targets[a]) {
            let (u, v) = (direction(a), direction(b));
            let opposite = (u[0] * v[0] + u[1] * v[1]) / (u[0].hypot(u[1]) * v[0].hypot(v[1]));
            if opposite > -1.0 + 1e-12 {
                continue;
            }
            let first = drive_to(Drive::Creases(vec![(a, targets[a]), (b, targets[b])]), &flat)?;
            if first.stop != StopReason::Reached {
                continue;
            }
            let middle = first.steps.last().expect("a path has its start").fold_angles.clone();
            let others: Vec<(usize, f64)> = (0..n).filter(|&c| c != a && c != b).map(|c| (c, targets[c])).collect();
            let rest = drive_to(Drive::Creases(others), &middle)?;
            if reaches(&rest) {
                let states = first
                    .steps
                    .into_iter()
                    .chain(rest.steps.into_iter().skip(1))
                    .map(|s| s.fold_angles)
                    .collect();
                return Ok(Some((
                    states,
                    format!(
                        "creases {a} and {b}, one straight line, folded first, then the others towards their angles"
                    ),
                )));
            }
        }
    }
    Ok(None)
}

/// Sectors within this of a design (a straight line of two creases, alternate sums of π),
/// rad, are that design with a file's rounding.
const DESIGN_NOISE: f64 = 1e-5;

/// The sectors of the design `vertex` is within [`DESIGN_NOISE`] of: every pair of creases
/// within it of a straight line made straight, and the alternate sums made π where they are
/// within it, by the least change (minimum-norm over the sectors, the total kept 2π); with
/// the largest change. None where no such condition is near or the change exceeds the noise.
fn design_sectors(vertex: &VertexPattern) -> Option<(Vec<f64>, f64)> {
    use nalgebra::{DMatrix, DVector};
    let sectors = &vertex.sector_angles;
    let n = sectors.len();
    if n != vertex.rays.len() {
        return None;
    }
    let crease_rays: Vec<usize> = (0..n)
        .filter(|&k| matches!(vertex.rays[k], RayRole::Crease(i) if vertex.creases[i].folded_angle != 0.0 || vertex.creases[i].assignment != crate::pattern::Assignment::Flat))
        .collect();
    // Rows: Σ over ray ranges (from ray a to ray b, exclusive of b's sector) = value.
    let mut rows: Vec<(Vec<f64>, f64)> = Vec::new();
    let span = |a: usize, b: usize| -> Vec<f64> {
        let mut row = vec![0.0; n];
        let mut k = a;
        while k != b {
            row[k] = 1.0;
            k = (k + 1) % n;
        }
        row
    };
    let value = |row: &[f64]| row.iter().zip(sectors).map(|(r, s)| r * s).sum::<f64>();
    rows.push((vec![1.0; n], 2.0 * PI));
    let m = crease_rays.len();
    if m.is_multiple_of(2) && m >= 4 {
        let mut row = vec![0.0; n];
        for (j, &a) in crease_rays.iter().enumerate() {
            let sign = if j % 2 == 0 { 1.0 } else { -1.0 };
            for (k, r) in span(a, crease_rays[(j + 1) % m]).iter().enumerate() {
                row[k] += sign * r;
            }
        }
        if value(&row).abs() <= DESIGN_NOISE {
            rows.push((row, 0.0));
        }
    }
    for (j, &a) in crease_rays.iter().enumerate() {
        for &b in &crease_rays[j + 1..] {
            let row = span(a, b);
            if (value(&row) - PI).abs() <= DESIGN_NOISE {
                rows.push((row, PI));
            }
        }
    }
    if rows.len() == 1 {
        return None;
    }
    let jacobian = DMatrix::from_fn(rows.len(), n, |r, c| rows[r].0[c]);
    let gap = DVector::from_iterator(rows.len(), rows.iter().map(|(row, target)| target - value(row)));
    let change = jacobian.clone().svd(true, true).solve(&gap, 1e-12).ok()?;
    let moved = change.amax();
    let designed: Vec<f64> = sectors.iter().zip(change.iter()).map(|(s, d)| s + d).collect();
    let consistent = (&jacobian * &change - &gap).amax() <= 1e-12;
    (consistent && moved <= DESIGN_NOISE && designed.iter().all(|s| *s > 0.0)).then_some((designed, moved))
}
