//! Command-line interface: argument definitions and the `unfold` / `check` commands.

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};
use nanofold::energy::EnergyKind;
use nanofold::output::{fold_animation, trajectory_json, write_atomic};
use nanofold::pattern::{LoadOptions, Pattern};
use nanofold::plot::unfold_svg;
use nanofold::qp::QpMethod;
use nanofold::unfold::{unfold, UnfoldModel, UnfoldReport, UnfoldSettings};
use serde_json::json;
use std::path::{Path, PathBuf};

#[derive(Parser)]
#[command(
    name = "nanofold",
    version,
    about = "Rigid origami: unfold single-vertex crease patterns to flat"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// Unfold one pattern; write trajectory.json, unfold.svg and unfold.fold.
    Unfold {
        /// A FOLD file (.fold) or a native vertex (.json).
        pattern: PathBuf,
        #[command(flatten)]
        solver: SolverArgs,
        /// Output folder (default: output/<pattern name>/).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Print one JSON object on stdout instead of a summary.
        #[arg(long)]
        json: bool,
    },
    /// Verdict of each pattern, one line each; writes no files.
    Check {
        #[arg(required = true)]
        patterns: Vec<PathBuf>,
        #[command(flatten)]
        solver: SolverArgs,
        /// One JSON object per line.
        #[arg(long)]
        json: bool,
    },
}

#[derive(Args, Clone)]
pub struct SolverArgs {
    /// Repulsive energy (SPEC §4).
    #[arg(long, value_enum, default_value_t = EnergyKind::Separable)]
    pub energy: EnergyKind,
    /// Exponent p (default 2 separable, 4 non-separable).
    #[arg(long, allow_negative_numbers = true)]
    pub p: Option<f64>,
    /// Direction solver: the direct null-space projection or the Clarabel QP.
    #[arg(long, value_enum, default_value_t = QpMethod::Direct)]
    pub qp: QpMethod,
    /// Flat when every |fold angle| ≤ this (rad).
    #[arg(long, default_value_t = 1e-6, allow_negative_numbers = true)]
    pub flat_tol: f64,
    /// Iteration limit.
    #[arg(long, default_value_t = 20_000)]
    pub max_iter: usize,
    /// Restarts from perturbed states before a stuck verdict.
    #[arg(long, default_value_t = 3)]
    pub restarts: usize,
    /// Largest accepted loop-closure residual of the input's folded state (rad).
    #[arg(long, default_value_t = 1e-6, allow_negative_numbers = true)]
    pub closure_tol: f64,
}

impl SolverArgs {
    fn settings(&self) -> Result<UnfoldSettings> {
        if let Some(p) = self.p {
            anyhow::ensure!(
                p.is_finite() && p > 0.0,
                "invalid --p {p}: the exponent must be a positive number"
            );
        }
        anyhow::ensure!(
            self.flat_tol.is_finite() && self.flat_tol > 0.0,
            "invalid --flat-tol {}: must be a positive number",
            self.flat_tol
        );
        anyhow::ensure!(
            self.closure_tol.is_finite() && self.closure_tol > 0.0,
            "invalid --closure-tol {}: must be a positive number",
            self.closure_tol
        );
        Ok(UnfoldSettings {
            energy: self.energy,
            p: self.p,
            qp: self.qp,
            flat_tol: self.flat_tol,
            max_iterations: self.max_iter,
            restarts: self.restarts,
            ..UnfoldSettings::default()
        })
    }

    fn load_options(&self) -> LoadOptions {
        LoadOptions {
            closure_tol: self.closure_tol,
            ..LoadOptions::default()
        }
    }
}

/// The `--json` summary of one run.
fn summary(pattern: &Pattern, path: &Path, report: &UnfoldReport) -> serde_json::Value {
    json!({
        "pattern": pattern.name,
        "file": path.display().to_string(),
        "verdict": report.verdict,
        "evidence": report.evidence,
        "iterations": report.iterations,
        "seconds": report.seconds,
        "energy_initial": report.energy_initial,
        "energy_final": report.energy_final,
        "initial_fold_angles_rad": report.initial_fold_angles_rad,
        "final_fold_angles_rad": report.final_fold_angles_rad,
        "crease_labels": pattern.creases.iter().map(|c| c.label.clone()).collect::<Vec<_>>(),
        "max_arc_residual": report.max_arc_residual,
        "planarity_residual": report.planarity_residual,
        "flat_layout_error": report.flat_layout_error,
        "restarts_used": report.restarts_used,
        "crossings_refused": report.crossings_refused,
        "adjustments": report.adjustments,
    })
}

fn run_unfold(pattern_path: &Path, solver: &SolverArgs, out: Option<PathBuf>, as_json: bool) -> Result<()> {
    let settings = solver.settings()?;
    let pattern = Pattern::load(pattern_path, &solver.load_options())?;
    let report = unfold(&pattern, &settings)?;
    let model = UnfoldModel::new(&pattern);
    let dir = out.unwrap_or_else(|| PathBuf::from("output").join(&pattern.name));
    // Render everything before writing anything.
    let trajectory = serde_json::to_string(&trajectory_json(&pattern, &settings, &report, 1000))?;
    let fold = serde_json::to_string_pretty(&fold_animation(&pattern, &model, &report))?;
    let svg = unfold_svg(&pattern, &report)?;
    for (name, contents) in [
        ("trajectory.json", trajectory.as_bytes()),
        ("unfold.fold", fold.as_bytes()),
        ("unfold.svg", svg.as_bytes()),
    ] {
        write_atomic(&dir.join(name), contents).with_context(|| format!("writing {}", dir.display()))?;
    }
    let mut summary = summary(&pattern, pattern_path, &report);
    summary["out"] = json!(dir.display().to_string());
    if as_json {
        println!("{summary}");
    } else {
        println!("{}: {} ({})", pattern.name, report.verdict.as_str(), report.evidence);
        println!(
            "  {} iterations in {:.3} ms; energy {:.6e} -> {:.6e}",
            report.iterations,
            report.seconds * 1e3,
            report.energy_initial,
            report.energy_final
        );
        println!(
            "  max arc residual {:.2e} rad, planarity residual {:.2e}, restarts {}",
            report.max_arc_residual, report.planarity_residual, report.restarts_used
        );
        for (c, rho) in pattern.creases.iter().zip(&report.final_fold_angles_rad) {
            println!(
                "  {:<12} {:>11.6}° -> {:>12.3e} rad",
                c.label,
                c.folded_angle.to_degrees(),
                rho
            );
        }
        for note in &report.adjustments {
            println!("  note: {note}");
        }
        println!("  wrote {}/{{trajectory.json, unfold.svg, unfold.fold}}", dir.display());
    }
    Ok(())
}

fn run_check(patterns: &[PathBuf], solver: &SolverArgs, as_json: bool) -> Result<bool> {
    let settings = solver.settings()?;
    let mut all_readable = true;
    for path in patterns {
        let outcome = Pattern::load(path, &solver.load_options()).and_then(|p| unfold(&p, &settings).map(|r| (p, r)));
        match outcome {
            Ok((pattern, report)) => {
                if as_json {
                    println!("{}", summary(&pattern, path, &report));
                } else {
                    println!(
                        "{}: {} ({} iterations, {:.3} ms) {}",
                        path.display(),
                        report.verdict.as_str(),
                        report.iterations,
                        report.seconds * 1e3,
                        report.evidence
                    );
                }
            }
            Err(e) => {
                all_readable = false;
                if as_json {
                    println!(
                        "{}",
                        json!({"file": path.display().to_string(), "error": e.to_string()})
                    );
                } else {
                    println!("{}: error: {e}", path.display());
                }
            }
        }
    }
    Ok(all_readable)
}

/// Runs the parsed command; Ok(false) means "finished, but exit non-zero".
pub fn run(cli: Cli) -> Result<bool> {
    match cli.command {
        Command::Unfold {
            pattern,
            solver,
            out,
            json,
        } => run_unfold(&pattern, &solver, out, json).map(|_| true),
        Command::Check { patterns, solver, json } => run_check(&patterns, &solver, json),
    }
}
