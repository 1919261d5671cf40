//! The commands for crease patterns of many vertices: `fold`, `generate`, and `check` on a
//! pattern the single-vertex engine does not take.

use super::{default_folder, print_written, reading, write_outputs};
use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use nanofold::commands::outputs::write_atomic;
use nanofold::prelude::Named;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// Arguments of `fold`.
#[derive(Args, Clone)]
pub struct FoldArgs {
    /// A FOLD crease pattern (any number of vertices): from flat, or from its state.
    pub pattern: PathBuf,
    /// Drive these creases (FOLD edge index) to these angles, e.g. `--drive 12=-90`;
    /// without it, every crease folds towards its target where the file gives targets, else
    /// every mountain and valley towards ±180° as assigned.
    #[arg(long, value_name = "EDGE=DEG", allow_hyphen_values = true)]
    pub drive: Vec<String>,
    /// Stop when the most folded crease reaches this percentage of 180° (assignment drive),
    /// or this percentage of the way to the targets (0.1 to 100).
    #[arg(long, allow_hyphen_values = true, value_parser = super::finite, default_value_t = 100.0)]
    pub to: f64,
    /// Drive every crease towards its target angle (a file's `edges_foldAngle` read as
    /// targets): `--drive-to-targets` requires them, `--drive-to-targets false` folds by the
    /// assignment instead; without it, a file's targets are used when it gives them.
    #[arg(long, value_name = "BOOL", num_args = 0..=1, default_missing_value = "true")]
    pub drive_to_targets: Option<bool>,
    /// Number of snapshots written as FOLD frames (start and end included; 2 to 10 000).
    #[arg(long, allow_hyphen_values = true, default_value_t = 11)]
    pub frames: usize,
    /// Largest change of any fold angle in one step (degrees; 5.7e-5 to 28.6): a cap, the
    /// step control chooses each step below it.
    #[arg(long, allow_hyphen_values = true, value_parser = super::finite, default_value_t = 15.0)]
    pub max_step: f64,
    /// Output folder (default: output/<pattern name>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print one JSON object instead of a summary.
    #[arg(long)]
    pub json: bool,
}

/// Patterns `generate` builds.
#[derive(Subcommand, Clone)]
pub enum GenerateKind {
    /// Miura-ori: rows × cols parallelogram panels (`docs/model.md#pattern-generators`).
    Miura {
        /// Panels along y.
        #[arg(long, allow_hyphen_values = true, default_value_t = 4)]
        rows: usize,
        /// Panels along x.
        #[arg(long, allow_hyphen_values = true, default_value_t = 4)]
        cols: usize,
        /// The panels' acute angle (degrees).
        #[arg(long, allow_hyphen_values = true, value_parser = super::finite, alias = "angle", default_value_t = 60.0)]
        angle_deg: f64,
        /// Length of the panels' horizontal sides.
        #[arg(long, allow_hyphen_values = true, value_parser = super::finite, default_value_t = 1.0)]
        width: f64,
        /// Length of the panels' slanted sides.
        #[arg(long, allow_hyphen_values = true, value_parser = super::finite, default_value_t = 1.0)]
        slant: f64,
        /// Also write the folded state with the zigzag creases at this angle (degrees; 0 or
        /// absent: the crease pattern alone).
        #[arg(long, allow_hyphen_values = true, value_parser = super::finite, alias = "fold")]
        fold_deg: Option<f64>,
        /// The FOLD file to write.
        #[arg(long)]
        out: PathBuf,
    },
    /// Square twist: a central square and four pleats turned by the twist angle.
    SquareTwist {
        /// Side of the central square.
        #[arg(long, allow_hyphen_values = true, value_parser = super::finite, default_value_t = 1.0)]
        side: f64,
        /// Half the side of the square sheet.
        #[arg(long, allow_hyphen_values = true, value_parser = super::finite, default_value_t = 1.5)]
        half_sheet: f64,
        /// Twist angle (degrees, 1 to 45).
        #[arg(long, allow_hyphen_values = true, value_parser = super::finite, alias = "twist", default_value_t = 30.0)]
        twist_deg: f64,
        /// Flip each corner's crease after its smallest sector (breaks big-little-big: no
        /// longer flat-foldable) instead of the classic assignment.
        #[arg(long)]
        flip_pleats: bool,
        /// The FOLD file to write.
        #[arg(long)]
        out: PathBuf,
    },
    /// Waterbomb tessellation: rows of triangles, degree-6 vertices; with --row-height other
    /// than 1, the Huffman-style rectangular waterbomb.
    Waterbomb {
        /// Rows of triangles.
        #[arg(long, allow_hyphen_values = true, default_value_t = 4)]
        rows: usize,
        /// Units across (the sheet is twice as wide).
        #[arg(long, allow_hyphen_values = true, default_value_t = 4)]
        cols: usize,
        /// Height of a row in half-cell widths (1: square cells; 0.1 to 10).
        #[arg(long, allow_hyphen_values = true, value_parser = super::finite, default_value_t = 1.0)]
        row_height: f64,
        /// The FOLD file to write.
        #[arg(long)]
        out: PathBuf,
    },
    /// Bird base: the flat-foldable crease pattern (midlines, kites, one diagonal).
    BirdBase {
        /// Half the side of the square sheet.
        #[arg(long, allow_hyphen_values = true, value_parser = super::finite, default_value_t = 1.0)]
        half_side: f64,
        /// The FOLD file to write.
        #[arg(long)]
        out: PathBuf,
    },
}

/// `nanofold generate KIND ...`
pub fn run_generate(kind: &GenerateKind) -> Result<()> {
    use nanofold::commands::Generator;
    // The flags by the door's option names; the door builds and validates the family.
    let (family, options, out, table): (&str, Value, &Path, &[(&str, &str)]) = match kind {
        GenerateKind::Miura {
            rows,
            cols,
            angle_deg,
            width,
            slant,
            fold_deg,
            out,
        } => (
            "miura",
            json!({"rows": rows, "cols": cols, "angle_deg": angle_deg, "width": width, "slant": slant,
                   "fold_deg": fold_deg.unwrap_or(0.0)}),
            out,
            &[
                ("angle_deg", "--angle-deg"),
                ("fold_deg", "--fold-deg"),
                ("rows, cols", "--rows, --cols"),
                ("width", "--width"),
                ("slant", "--slant"),
            ],
        ),
        GenerateKind::SquareTwist {
            side,
            half_sheet,
            twist_deg,
            flip_pleats,
            out,
        } => (
            "square_twist",
            json!({"side": side, "half_sheet": half_sheet, "twist_deg": twist_deg, "flip_pleats": flip_pleats}),
            out,
            &[
                ("side", "--side"),
                ("half_sheet", "--half-sheet"),
                ("twist_deg", "--twist-deg"),
            ],
        ),
        GenerateKind::Waterbomb {
            rows,
            cols,
            row_height,
            out,
        } => (
            "waterbomb",
            json!({"rows": rows, "cols": cols, "row_height": row_height}),
            out,
            &[("rows, cols", "--rows, --cols"), ("row_height", "--row-height")],
        ),
        GenerateKind::BirdBase { half_side, out } => (
            "bird_base",
            json!({ "half_side": half_side }),
            out,
            &[("half_side", "--half-side")],
        ),
    };
    let generator = Generator::from_options(family, &options).map_err(|e| flags(e, table))?;
    let generated = generator.generate().map_err(|e| flags(e, table))?;
    write_file(out, &generated.fold)?;
    println!(
        "{}: {} vertices, {} creases, {} interior vertices, {} panels{}; wrote {}",
        generated.name,
        generated.vertices,
        generated.creases,
        generated.interior_vertices,
        generated.panels,
        if generated.folded {
            " (folded state included)"
        } else {
            ""
        },
        out.display()
    );
    Ok(())
}

fn write_file(out: &Path, value: &Value) -> Result<()> {
    if out.extension().and_then(|e| e.to_str()) != Some("fold") {
        bail!("--out {}: the file name must end in .fold", out.display());
    }
    let text = serde_json::to_string_pretty(value)?;
    write_atomic(out, text.as_bytes()).with_context(|| format!("writing {}", out.display()))
}

/// Maps library field names to this command's flags.
fn flags(error: nanofold::prelude::NanofoldError, table: &[(&str, &str)]) -> anyhow::Error {
    super::with_flags(error, table)
}

/// `EDGE=DEG` of `flag`: a FOLD edge index and an angle in [-180, 180] degrees.
fn parse_edge_angle(text: &str, flag: &str) -> Result<(usize, f64)> {
    let (edge, degrees) = text
        .split_once('=')
        .with_context(|| format!("{flag} {text}: expected EDGE=DEG, e.g. 12=-90"))?;
    let edge: usize = edge
        .trim()
        .parse()
        .with_context(|| format!("{flag} {text}: the edge index"))?;
    let degrees: f64 = degrees
        .trim()
        .parse()
        .with_context(|| format!("{flag} {text}: the angle (degrees)"))?;
    if !(degrees.is_finite() && degrees.abs() <= 180.0) {
        bail!("{flag} {text}: the angle must lie in [-180, 180] degrees");
    }
    Ok((edge, degrees))
}

/// `nanofold fold PATTERN`.
pub fn run_fold(args: &FoldArgs) -> Result<()> {
    let options = nanofold::commands::FoldOptions {
        to: args.to,
        drive: args
            .drive
            .iter()
            .map(|text| parse_edge_angle(text, "--drive"))
            .collect::<Result<_>>()?,
        max_step: args.max_step,
        frames: args.frames,
        drive_to_targets: args.drive_to_targets,
        ..nanofold::commands::FoldOptions::default()
    };
    let pattern = nanofold::commands::Pattern::open(&args.pattern, &nanofold::prelude::LoadOptions::default())
        .map_err(|e| reading(&args.pattern, e))?;
    let run = nanofold::commands::fold_run(&pattern, &options).map_err(|e| {
        flags(
            e,
            &[
                ("drive.to", "--to"),
                ("drive_to_targets", "--drive-to-targets"),
                ("drive", "--drive"),
                ("max_step", "--max-step"),
                ("frames", "--frames"),
            ],
        )
    })?;
    let model = pattern.sheet().expect("a pattern that folds has its sheet");
    let nanofold::commands::Detail::Fold(path) = &run.report.detail else {
        unreachable!("fold answers with a path")
    };
    let (path, frames, seconds) = (path.as_ref(), &run.frames, run.report.seconds);
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| default_folder(&model.pattern.name, &args.pattern));
    let files = nanofold::commands::fold_files(&pattern, &run)?;
    write_outputs(&dir, &args.pattern, &files)?;
    let mut summary = run.report.to_json();
    summary["frames"] = json!(frames.len());
    summary["out"] = json!(dir.display().to_string());
    if args.json {
        println!("{summary}");
        return Ok(());
    }
    println!(
        "{}: {} ({}) after {} steps in {:.3} s",
        model.pattern.name,
        path.stop.as_str(),
        path.evidence,
        path.steps.len(),
        seconds
    );
    if let Some(branch) = &path.branch {
        println!("  branch: {branch}");
    }
    for note in &model.pattern.reading {
        println!("  read: {note}");
    }
    println!(
        "  {} creases, {} interior vertices, {} panels; {} DOF at the end; progress {:.4}",
        model.crease_count(),
        model.stars.len(),
        model.pattern.panel_count,
        summary["dof"],
        path.steps.last().map_or(0.0, |s| s.progress)
    );
    println!(
        "  worst vertex closure over the path {:.2e} rad; smallest panel clearance {}",
        path.max_closure_residual,
        path.min_panel_clearance
            .map_or("none within the search range".to_string(), |c| format!("{c:.3e}"))
    );
    print_written(&dir, &files.iter().map(|(n, c)| (*n, c.clone())).collect::<Vec<_>>());
    Ok(())
}

/// `check`'s line for a crease pattern of many vertices.
pub fn check_line(
    path: &Path,
    pattern: &nanofold::commands::Pattern,
    report: &nanofold::commands::Report<nanofold::commands::CheckVerdict>,
) -> String {
    let nanofold::commands::Detail::NetworkCheck(check, unfolding) = &report.detail else {
        unreachable!("a crease pattern of many vertices is checked by the network engine")
    };
    let mut line = format!(
        "{}: {} ({} DOF at the {} state, {:.3} ms) {}",
        path.display(),
        report.verdict.as_str(),
        check.rank.dof,
        if check.has_state { "given" } else { "flat" },
        report.seconds * 1e3,
        report.evidence
    );
    if let Some(projection) = pattern.projection() {
        line.push_str(&format!("; {}", projection.note));
    }
    if let Some(unfolding) = unfolding {
        line.push_str(&format!(
            "; unfolding by energy: {} ({})",
            unfolding.verdict.as_str(),
            unfolding.evidence
        ));
    }
    line
}

/// What `constraints` prints of a crease pattern's curves.
pub fn print_network_constraints(name: &str, curves: &nanofold::commands::NetworkCurves) {
    println!(
        "{}: {} curves of crease {} over [{:.4}°, {:.4}°], degree {}, {} fitted points and {} checked between them; largest fit error {:.3e} rad, closure residual of the sweep {:.1e} rad",
        name,
        curves.curves.len(),
        curves.driver_edge,
        curves.domain_deg[0],
        curves.domain_deg[1],
        curves.degree,
        curves.samples,
        curves.samples - 1,
        curves.max_fit_error_rad,
        curves.max_closure_residual_rad
    );
}

/// `unfold` of a crease pattern of many vertices (`docs/model.md#energy-unfolding-of-many-vertices`):
/// returns the JSON summary and the human-readable lines.
pub fn unfold_network_one(
    pattern_path: &Path,
    pattern: &nanofold::commands::Pattern,
    solver: &super::SolverArgs,
    dir: Option<&Path>,
    progress: Option<nanofold::prelude::UnfoldProgress>,
) -> Result<(Value, String)> {
    use std::fmt::Write as _;
    let model = pattern
        .sheet()
        .expect("a crease pattern of many vertices has its sheet");
    let settings = nanofold::commands::Settings {
        unfold: solver.settings()?,
        ..nanofold::commands::Settings::default()
    };
    let answer = nanofold::commands::unfold_observed(pattern, &settings, progress)
        .map_err(|e| flags(e, &[("flat_tol", "--flat-tol"), ("start", "edges_foldAngle")]))?;
    let nanofold::commands::Detail::NetworkUnfold(report) = &answer.detail else {
        unreachable!("a crease pattern of many vertices unfolds by the network engine")
    };
    let seconds = answer.seconds;
    let dir = dir.map_or_else(|| default_folder(&model.pattern.name, pattern_path), Path::to_path_buf);
    let last = report.steps.last().expect("the start is recorded");
    let files = nanofold::commands::unfold_files(pattern, &answer, &settings)?;
    write_outputs(&dir, pattern_path, &files)?;
    let mut summary = answer.to_json();
    summary["out"] = json!(dir.display().to_string());
    let flat_layout_error = summary["flat_layout_error"].as_f64().unwrap_or(f64::NAN);
    let mut text = String::new();
    let notes = pattern
        .projection()
        .map(|p| p.note.as_str())
        .into_iter()
        .chain(pattern.frames_note());
    for note in notes {
        writeln!(text, "{}: {note}", model.pattern.name)?;
    }
    writeln!(
        text,
        "{}: {} ({})",
        model.pattern.name,
        report.verdict.as_str(),
        report.evidence
    )?;
    writeln!(
        text,
        "  {} creases at {} vertices: {} steps in {:.3} s; energy {}",
        model.crease_count(),
        model.stars.len(),
        report.iterations,
        seconds,
        if report.steps[0].energy.is_finite() {
            format!("{:.6e} -> {:.6e}", report.steps[0].energy, last.energy)
        } else {
            "not evaluated (the start is not a rigid state)".to_string()
        }
    )?;
    writeln!(
        text,
        "  worst vertex closure over the path {:.2e} rad; flat layout error {:.2e}; {} steps refused for crossing panels; {} steps along the ray to flat",
        report.max_closure_residual, flat_layout_error, report.crossings_refused, report.radial_steps
    )?;
    write!(
        text,
        "  wrote {}/{{trajectory.json, unfold.svg, unfold.fold, unfold.html}}",
        dir.display()
    )?;
    Ok((summary, text))
}

/// `nanofold view FILE.fold`.
#[derive(clap::Args)]
pub struct ViewArgs {
    /// The FOLD file: frames with 3D coordinates (an animation, a folded form), or a crease
    /// pattern (with `edges_foldAngle` for its state).
    pub file: PathBuf,
    /// Output folder (default: output/<file name>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// `nanofold view FILE.fold`: a page of the file's frames as written, or, for a crease
/// pattern (2D, no 3D frame), of its state placed by the spanning tree.
pub fn run_view(args: &ViewArgs) -> Result<()> {
    let html = nanofold::commands::view_page(&args.file).map_err(|e| reading(&args.file, e))?;
    let name = nanofold::commands::outputs::pattern_name(&args.file);
    let dir = args.out.clone().unwrap_or_else(|| default_folder(&name, &args.file));
    write_outputs(&dir, &args.file, &[("view.html", html.clone())])?;
    println!(
        "{}: wrote {}/view.html ({:.1} MB)",
        args.file.display(),
        dir.display(),
        html.len() as f64 / 1e6
    );
    Ok(())
}
