//! Times the rigid-kinematics pieces on folded Miura-ori of growing size, with the error
//! beside each time: closure residual (worst vertex), tree mismatch, and the rank's gap.
//! `cargo run --release --example crease_pattern_speed`

use nanofold::folding::{
    closure_jacobian, fold_path, jacobian_rank, panel_contacts, panel_poses, tree_mismatch, vertex_residuals,
    ContactSettings, Drive, FoldSettings, FoldingModel,
};
use nanofold::pattern::generate::MiuraSpec;
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

fn main() {
    println!("Miura-ori, γ = 60°, zigzag creases at 90°; best of 3 runs, milliseconds");
    println!(
        "{:>7} {:>7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>4} {:>10} {:>10} {:>10}",
        "panels", "creases", "model", "J+r", "rank", "poses", "contact", "dof", "residual", "mismatch", "R gap"
    );
    for n in [4, 8, 16, 24, 32] {
        let spec = MiuraSpec {
            rows: n,
            cols: n,
            zigzag_fold_angle: 90f64.to_radians(),
            ..MiuraSpec::default()
        };
        let (t_model, model) = best_of(3, || FoldingModel::new(spec.build().unwrap().build().unwrap()).unwrap());
        let rho = model.given_fold_angles();
        let (t_jac, jac) = best_of(3, || closure_jacobian(&model, &rho));
        let (t_rank, rank) = best_of(3, || jacobian_rank(&jac));
        let mut poses = Vec::new();
        let (t_poses, _) = best_of(3, || panel_poses(&model, &rho, &mut poses));
        let (t_contact, contacts) = best_of(3, || panel_contacts(&model, &poses, &ContactSettings::default()));
        let residual = vertex_residuals(&model, &rho).into_iter().fold(0.0, f64::max);
        let mismatch = tree_mismatch(&model, &rho, &poses) / model.size;
        println!(
            "{:>7} {:>7} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>4} {:>10.1e} {:>10.1e} {:>10.1e}",
            n * n,
            model.crease_count(),
            1e3 * t_model,
            1e3 * t_jac,
            1e3 * t_rank,
            1e3 * t_poses,
            1e3 * t_contact,
            rank.dof,
            residual,
            mismatch,
            rank.smallest_kept / rank.largest_dropped.max(f64::MIN_POSITIVE),
        );
        assert_eq!(contacts.crossing().count(), 0);
    }
    println!();
    println!("Folding the flat Miura-ori to 95% (max step 0.05 rad); best of 3 runs");
    println!(
        "{:>7} {:>7} {:>9} {:>6} {:>7} {:>12} {:>12}",
        "panels", "creases", "seconds", "steps", "newton", "residual", "clearance"
    );
    for n in [8, 16, 32] {
        let spec = MiuraSpec {
            rows: n,
            cols: n,
            ..MiuraSpec::default()
        };
        let model = FoldingModel::new(spec.build().unwrap().build().unwrap()).unwrap();
        let settings = FoldSettings {
            drive: Drive::Assignment { to: 0.95 },
            ..FoldSettings::default()
        };
        let (t, path) = best_of(3, || fold_path(&model, &model.given_fold_angles(), &settings).unwrap());
        println!(
            "{:>7} {:>7} {:>9.3} {:>6} {:>7} {:>12.1e} {:>12.3e}  {}",
            n * n,
            model.crease_count(),
            t,
            path.steps.len(),
            path.newton_iterations,
            path.max_closure_residual,
            path.min_panel_clearance.unwrap_or(f64::NAN),
            path.stop.as_str()
        );
    }
}
