//! Library use: build a degree-6 vertex from numbers, fold it by loop closure, unfold it,
//! and print its verdict, evidence and a few states of the folding path (the trajectory
//! reversed). Run: `cargo run --release --example unfold_a_vertex`

use nanofold::geometry::kinematics::solve_closure;
use nanofold::prelude::*;

fn main() -> Result<()> {
    // Six sectors summing to 360°, rays 0, 2 and 4 driven, 1, 3 and 5 closing the loop.
    let sectors = [50.0f64, 70.0, 55.0, 65.0, 60.0, 60.0].map(f64::to_radians);
    let mut rho = [0.9, 0.0, -0.6, 0.0, 0.7, 0.0];
    solve_closure(&sectors, &mut rho, &[1, 3, 5], 1e-14, 100)?;
    let pattern = rho
        .iter()
        .fold(VertexBuilder::closed("degree6").sector_angles(sectors), |b, &r| {
            b.crease(Assignment::Unassigned, r)
        })
        .build()?;
    let report = unfold_vertex(&pattern, &UnfoldSettings::default())?;
    println!("{}: {} ({})", pattern.name, report.verdict.as_str(), report.evidence);
    println!(
        "{} steps in {:.2} ms; largest arc residual on the way {:.1e} rad; {:.1e} from the flat layout",
        report.iterations,
        report.seconds * 1e3,
        report.max_arc_residual,
        report.flat_layout_error
    );
    println!("folding path (flat → folded), fold angles in degrees:");
    let path = &report.trajectory;
    for step in path.iter().rev().step_by((path.len() / 6).max(1)) {
        let degrees: Vec<String> = step
            .fold_angles
            .iter()
            .map(|r| format!("{:7.2}", r.to_degrees()))
            .collect();
        println!("  step {:>3}: [{}]", step.iteration, degrees.join(", "));
    }
    Ok(())
}
