//! Times the rigid-kinematics pieces on folded Miura-ori of growing size, with the error
//! beside each time: closure residual (worst vertex), tree mismatch, and the DOF found by
//! the dense pivoted QR and by the sparse count. Then folding paths from flat, and energy
//! unfolding of Miura-ori and waterbombs (square and Huffman-style rectangular cells).
//! `cargo run --release --example crease_pattern_speed`

use nanofold::folding::{
    closure_jacobian, fold_path, jacobian_rank_dense, jacobian_rank_sparse, panel_contacts, panel_poses, tree_mismatch,
    vertex_residuals, ContactSettings, Drive, FoldSettings, FoldingModel,
};
use nanofold::pattern::generate::{MiuraSpec, WaterbombSpec};
use nanofold::prelude::Named;
use nanofold::unfold::network::{unfold_network, NetworkEnergy, NetworkUnfoldSettings};
use nanofold::unfold::{EnergyKind, EnergyWorkspace};
use std::time::Instant;

fn best_of<T>(runs: usize, mut work: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut out = None;
    for _ in 0..runs {
        let start = Instant::now();
        let value = work();
        best = best.min(start.elapsed().as_secs_f64());
        out = Some(value);
    }
    (best, out.expect("runs ≥ 1"))
}

fn miura(n: usize, zigzag_deg: f64) -> FoldingModel {
    let spec = MiuraSpec {
        rows: n,
        cols: n,
        zigzag_fold_angle: zigzag_deg.to_radians(),
        ..MiuraSpec::default()
    };
    FoldingModel::new(spec.build().unwrap().build().unwrap()).unwrap()
}

fn main() {
    println!("Miura-ori n x n, γ = 60°, zigzag creases at 90°; best of 3 runs, milliseconds");
    println!(
        "{:>4} {:>6} {:>8} {:>7} {:>9} {:>9} {:>7} {:>8} {:>5} {:>5} {:>9} {:>9}",
        "n",
        "creases",
        "model",
        "J+r",
        "QR rank",
        "sparse",
        "poses",
        "contact",
        "dofQR",
        "dofSp",
        "residual",
        "mismatch"
    );
    for n in [4, 8, 16, 24, 32, 64, 100] {
        let (t_model, model) = best_of(3, || miura(n, 90.0));
        let rho = model.given_fold_angles();
        let (t_jac, jac) = best_of(3, || closure_jacobian(&model, &rho));
        let dense = (model.crease_count() <= 2000).then(|| best_of(3, || jacobian_rank_dense(&jac)));
        let (t_sparse, sparse) = best_of(3, || jacobian_rank_sparse(&jac).unwrap());
        let mut poses = Vec::new();
        let (t_poses, _) = best_of(3, || panel_poses(&model, &rho, &mut poses));
        let (t_contact, contacts) = best_of(3, || panel_contacts(&model, &poses, &ContactSettings::default()));
        let residual = vertex_residuals(&model, &rho).into_iter().fold(0.0, f64::max);
        let mismatch = tree_mismatch(&model, &rho, &poses) / model.size;
        println!(
            "{:>4} {:>6} {:>8.2} {:>7.2} {:>9} {:>9.2} {:>7.3} {:>8.2} {:>5} {:>5} {:>9.1e} {:>9.1e}",
            n,
            model.crease_count(),
            1e3 * t_model,
            1e3 * t_jac,
            dense
                .as_ref()
                .map_or("-".to_string(), |(t, _)| format!("{:.2}", 1e3 * t)),
            1e3 * t_sparse,
            1e3 * t_poses,
            1e3 * t_contact,
            dense.as_ref().map_or("-".to_string(), |(_, r)| r.dof.to_string()),
            sparse.dof,
            residual,
            mismatch,
        );
        assert_eq!(contacts.crossing().count(), 0);
    }
    println!();
    println!("DOF at the flat Miura-ori (many small singular values: the hard case of the sparse count); best of 3 runs, milliseconds");
    println!(
        "{:>4} {:>7} {:>9} {:>9} {:>5} {:>5} {:>11} {:>11}",
        "n", "creases", "QR rank", "sparse", "dofQR", "dofSp", "kept σ", "dropped σ"
    );
    for n in [8, 16, 24, 32, 40] {
        let model = miura(n, 0.0);
        let rho = model.given_fold_angles();
        let jac = closure_jacobian(&model, &rho);
        let dense = (model.crease_count() <= 2000).then(|| best_of(3, || jacobian_rank_dense(&jac)));
        let (t_sparse, sparse) = best_of(3, || jacobian_rank_sparse(&jac).unwrap());
        println!(
            "{:>4} {:>7} {:>9} {:>9.1} {:>5} {:>5} {:>11.2e} {:>11.2e}",
            n,
            model.crease_count(),
            dense
                .as_ref()
                .map_or("-".to_string(), |(t, _)| format!("{:.1}", 1e3 * t)),
            1e3 * t_sparse,
            dense.as_ref().map_or("-".to_string(), |(_, r)| r.dof.to_string()),
            sparse.dof,
            sparse.smallest_kept,
            sparse.largest_dropped,
        );
        if let Some((_, dense)) = &dense {
            assert_eq!(dense.dof, sparse.dof, "n = {n}: the two counts disagree");
        }
    }
    println!();
    println!("Folding the flat Miura-ori to 95% (continuation, steps at most 15°); best of 3 runs");
    println!(
        "{:>4} {:>7} {:>9} {:>6} {:>7} {:>12} {:>12}",
        "n", "creases", "seconds", "steps", "newton", "residual", "clearance"
    );
    for n in [8, 16, 32, 64] {
        let model = miura(n, 0.0);
        let settings = FoldSettings {
            drive: Drive::Assignment { to: 95.0 },
            ..FoldSettings::default()
        };
        let runs = if n >= 64 { 1 } else { 3 };
        let (t, path) = best_of(runs, || {
            fold_path(&model, &model.given_fold_angles(), &settings).unwrap()
        });
        println!(
            "{:>4} {:>7} {:>9.3} {:>6} {:>7} {:>12.1e} {:>12.3e}  {}",
            n,
            model.crease_count(),
            t,
            path.steps.len(),
            path.newton_iterations,
            path.max_closure_residual,
            path.min_panel_clearance.unwrap_or(f64::NAN),
            path.stop.as_str()
        );
    }
    println!();
    println!(
        "Unfolding the Miura-ori from 90% folded (zigzag creases at 162°) by energy; best of 3 runs (n = 64 once)"
    );
    println!(
        "{:>4} {:>7} {:>9} {:>6} {:>9} {:>11} {:>12} {:>14}  verdict",
        "n", "creases", "seconds", "steps", "ms/step", "energy ms", "residual", "finish from"
    );
    let mut points = Vec::new();
    for n in [8, 16, 32, 64] {
        let model = miura(n, 162.0);
        let runs = if n >= 64 { 1 } else { 3 };
        let (t, report) = best_of(runs, || {
            unfold_network(&model, &model.given_fold_angles(), &NetworkUnfoldSettings::default()).unwrap()
        });
        let before_finish = report.steps[report.steps.len().saturating_sub(2)]
            .fold_angles
            .iter()
            .fold(0.0_f64, |m, r| m.max(r.abs()));
        // The energy and its gradient at the start, alone (the per-step floor).
        let energy = NetworkEnergy::new(&model, EnergyKind::Separable, None);
        let mut ws = EnergyWorkspace::default();
        let mut gradient = vec![0.0; model.crease_count()];
        let (t_energy, _) = best_of(5, || {
            energy.value_and_gradient(&model.given_fold_angles(), &mut ws, &mut gradient)
        });
        println!(
            "{:>4} {:>7} {:>9.3} {:>6} {:>9.2} {:>11.3} {:>12.1e} {:>14.1e}  {}",
            n,
            model.crease_count(),
            t,
            report.steps.len(),
            1e3 * t / report.steps.len() as f64,
            1e3 * t_energy,
            report.max_closure_residual,
            before_finish,
            report.verdict.as_str()
        );
        points.push((model.crease_count() as f64, t / report.steps.len() as f64));
    }
    let (first, last) = (points[1], points[points.len() - 1]);
    println!(
        "time per step grows as creases^{:.2} (n = 16 to 64)",
        (last.1 / first.1).ln() / (last.0 / first.0).ln()
    );
    println!();
    println!("Waterbombs folded by `fold` along their assignment until blocked or to 40%, then unfolded by energy (one run each)");
    println!(
        "{:>26} {:>8} {:>7} {:>9} {:>9} {:>6} {:>7} {:>12}  verdict",
        "pattern", "vertices", "creases", "from max", "seconds", "steps", "radial", "residual"
    );
    for (rows, cols, row_height) in [(4, 3, 1.0), (6, 4, 0.6), (24, 12, 0.6)] {
        let spec = WaterbombSpec { rows, cols, row_height };
        let model = FoldingModel::new(spec.build().unwrap().build().unwrap()).unwrap();
        let settings = FoldSettings {
            drive: Drive::Assignment { to: 40.0 },
            ..FoldSettings::default()
        };
        let folded = fold_path(&model, &model.given_fold_angles(), &settings).unwrap();
        let start = folded.steps.last().unwrap().fold_angles.clone();
        let largest = start.iter().fold(0.0_f64, |m, r| m.max(r.abs()));
        let (t, report) = best_of(1, || {
            unfold_network(&model, &start, &NetworkUnfoldSettings::default()).unwrap()
        });
        println!(
            "{:>26} {:>8} {:>7} {:>9.3} {:>9.4} {:>6} {:>7} {:>12.1e}  {}",
            format!("{rows} x {cols}, row height {row_height}"),
            model.stars.len(),
            model.crease_count(),
            largest,
            t,
            report.iterations,
            report.radial_steps,
            report.max_closure_residual,
            report.verdict.as_str()
        );
    }
}
