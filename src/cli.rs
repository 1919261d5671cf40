//! Command-line interface: argument definitions and the `unfold`, `check`, `constraints`,
//! `simulate` and `modes` commands.

#[path = "cli/folding.rs"]
mod folding;

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};
use nanofold::commands::outputs::{default_output_folder, folder_name, write_folder_of};
use nanofold::prelude::{
    EnergyKind, LoadOptions, Method, ModelChoice, ModelKind, Named, ProgressObserver, QpMethod, Response, Scene,
    SimulationSettings, System, UnfoldProgress, UnfoldSettings,
};
use serde_json::json;
use std::path::{Path, PathBuf};

/// A number flag's value: a finite number, or clap's refusal naming the flag (NaN and ±inf
/// never reach the door, where a JSON bridge would turn them into null, that is, a default).
pub fn finite(text: &str) -> std::result::Result<f64, String> {
    let value: f64 = text.trim().parse().map_err(|_| format!("{text:?} is not a number"))?;
    if value.is_finite() {
        Ok(value)
    } else {
        Err(format!("{text} is not a finite number"))
    }
}

#[derive(Parser)]
#[command(
    name = "nanofold",
    version,
    about = "Rigid origami: check, fold and unfold crease patterns (single vertices and many), extract their constraint curves, simulate the folding of devices of rigid panels on stress-actuated hinges"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
    /// Replace an output folder that holds the results of another input file (without it,
    /// such a run is refused, naming the folder and the input it holds).
    #[arg(long, global = true)]
    pub force: bool,
}

#[derive(Subcommand)]
pub enum Command {
    /// Unfold patterns; write trajectory.json, unfold.svg and unfold.fold for each. Single
    /// vertices by the single-vertex engine; folded crease patterns of many vertices by the
    /// summed vertex energies (`docs/model.md#energy-unfolding-of-many-vertices`).
    Unfold {
        /// FOLD files (.fold), native vertices (.json) or directories of them (searched
        /// recursively; scene files are skipped). Several run in parallel.
        #[arg(required = true)]
        patterns: Vec<PathBuf>,
        #[command(flatten)]
        solver: SolverArgs,
        /// Output folder for one pattern (default: output/<pattern name>/); with several,
        /// the parent of their <pattern name>/ folders (default: output/).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Print one JSON object per pattern on stdout instead of a summary.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        parallel: ParallelArgs,
    },
    /// Verdict of each pattern, one line each; writes no files. Single vertices get the
    /// unfolding verdict; crease patterns of many vertices (or of creases that meet at no
    /// vertex) get `rigid`, `not_rigid` or `self_intersecting` for their state, or for an
    /// assignment alone `rigidly_foldable`, `not_rigidly_foldable` or `unknown`.
    Check {
        /// Pattern files or directories of them (searched recursively; scene files skipped).
        #[arg(required = true)]
        patterns: Vec<PathBuf>,
        #[command(flatten)]
        solver: SolverArgs,
        /// One JSON object per line.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        parallel: ParallelArgs,
    },
    /// Fold a crease pattern of any number of vertices rigidly (`docs/model.md#folding-paths`):
    /// from flat along its assignment, or driven creases to their angles; writes fold.fold,
    /// folded.fold, trajectory.json, fold.svg and fold.html (the 3D page).
    Fold(folding::FoldArgs),
    /// Write the 3D page (view.html: turn, zoom, scrub the frames) of a FOLD file: an
    /// animation's frames, a 3D folded form, or a crease pattern with its fold angles.
    View(folding::ViewArgs),
    /// Write a generated crease pattern as a FOLD file.
    Generate {
        #[command(subcommand)]
        kind: folding::GenerateKind,
    },
    /// Holonomic constraint curves: every free crease as a polynomial of one driving crease
    /// (`docs/model.md#constraint-curves`), for a single vertex or a folded crease pattern of
    /// many vertices with one degree of freedom; writes constraints.json, constraints.svg (and
    /// constraints.xml for MuJoCo).
    Constraints(ConstraintsArgs),
    /// Response of a scene (a strip of plates, a closed vertex or a device of many panels) to
    /// its actuation: writes response.json, response.svg, snapshots.svg, motion.fold (the
    /// run as a FOLD animation) and its 3D page response.html (`docs/model.md#dynamics`).
    Simulate(SimulateArgs),
    /// Fit a scene's parameters to a measured trajectory (`docs/model.md#calibration`):
    /// estimates with standard errors and 95 % intervals, correlations, what the data cannot
    /// separate, residuals; writes fit.json, fit.csv, fitted.scene.json, fit.svg and the fitted
    /// motion's page response.html.
    Fit(FitArgs),
    /// The distinct nets of a solid (an .obj, .stl, .ply, .off or .fold file, or a generated one such as
    /// cube, box:1x2x3, prism:6, polycube:0,0,0;1,0,0), each laid flat, tested for overlap,
    /// scored and ranked (`docs/model.md#nets-of-polyhedra`); writes nets.json, nets.csv,
    /// the best nets as FOLD crease patterns (net_<rank>.fold) and gallery.svg.
    Nets(NetsArgs),
    /// Write a scene in another tool's format: `export mujoco SCENE` writes one complete MJCF
    /// model (`docs/model.md#mujoco-scenes`).
    Export {
        #[command(subcommand)]
        format: ExportKind,
    },
    /// Natural frequencies, mode shapes and stability at the folded equilibrium of a scene; a
    /// network scene also writes modes.fold (each mode as a pair of frames).
    Modes {
        /// A scene file (.scene.json).
        scene: PathBuf,
        /// Print one JSON object on stdout instead of a table.
        #[arg(long)]
        json: bool,
        /// Where a network scene's modes.fold goes (default: output/<scene name>/).
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// `nanofold export FORMAT ...`
#[derive(clap::Subcommand)]
pub enum ExportKind {
    /// A scene as a MuJoCo MJCF model: a body per plate (mass, inertia), a hinge per crease
    /// (stiffness, springref 0), the step torque as an actuator, the substrate, a closed
    /// loop closed by `connect` equalities; units µm, pg, µs. Drag is in custom numerics for
    /// a passive callback (tests/mujoco/nanofold_mujoco.py).
    Mujoco {
        /// A scene file (.scene.json), strip or closed chain, step or ramp actuation.
        scene: PathBuf,
        /// The MJCF file to write (default: output/<scene name>/<scene name>.xml).
        #[arg(long)]
        out: Option<PathBuf>,
        /// RK4 time step in seconds (default: 1e-9; at most a twentieth of the scene's
        /// fastest natural period).
        #[arg(long, allow_hyphen_values = true, value_parser = finite, default_value_t = 1e-9)]
        timestep: f64,
        /// How a closed loop is closed: `connect` equalities (exact; every crease a hinge) or
        /// fitted quartic `polycoef` equalities (the cut crease has no joint).
        #[arg(long, value_enum, default_value_t = ClosureArg::Connect)]
        closure: ClosureArg,
    },
}

/// `export mujoco --closure`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ClosureArg {
    Connect,
    Poly,
}

/// Arguments of `nanofold simulate`.
#[derive(Args)]
pub struct SimulateArgs {
    /// A scene file (.scene.json).
    pub scene: PathBuf,
    /// Equations to solve; `auto` compares the forcing time with the fastest natural period.
    #[arg(long, value_enum, default_value_t = ModelArg::Auto)]
    pub model: ModelArg,
    /// Integrator (diffsol); `auto` is Tsit45 for short runs, ESDIRK34 for long (stiff) ones.
    #[arg(long, value_enum, default_value_t = MethodArg::Auto)]
    pub method: MethodArg,
    /// Relative tolerance (the absolute tolerance is the same in rad).
    #[arg(long, allow_hyphen_values = true, value_parser = finite, default_value_t = nanofold::commands::SimulateOptions::default().rtol)]
    pub rtol: f64,
    /// End time in seconds, overriding the scene's time.t_end_s.
    #[arg(long, allow_hyphen_values = true, value_parser = finite)]
    pub t_end: Option<f64>,
    /// Integrate through contacts instead of stopping at the first one.
    #[arg(long)]
    pub ignore_collisions: bool,
    /// Stop with an error after this many integrator steps (a method unsuited to the scene
    /// can need billions).
    #[arg(long, allow_hyphen_values = true, default_value_t = nanofold::commands::SimulateOptions::default().max_steps)]
    pub max_steps: usize,
    /// Output folder (default: output/<scene name>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print the summary as one JSON object on stdout (no progress bar).
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `nanofold fit`.
#[derive(Args)]
pub struct FitArgs {
    /// The scene file (.scene.json) whose parameters are fitted.
    pub scene: PathBuf,
    /// The measured trajectory: CSV with time_s and columns crease_<i>_deg (FOLD edge i; a
    /// strip's hinge i), hinge_<i>_deg, or panel_<p>_<u>_<v>_<x|y|z>_um (a tracked mark drawn
    /// at (u, v) µm on panel p); empty cells are missing observations.
    pub measured: PathBuf,
    /// A parameter to fit, PATH=LOWER:UPPER, its path into the scene file (e.g.
    /// environment.drag_coefficient=0.5:4, hinges[*].target_angle_deg=60:120); repeat it.
    #[arg(long, required = true, allow_hyphen_values = true)]
    pub free: Vec<String>,
    /// The measurement's noise in each column's unit: SIGMA for every column or
    /// COLUMN=SIGMA (repeat it); without it, each column's is estimated from its residuals.
    #[arg(long, allow_hyphen_values = true)]
    pub noise: Vec<String>,
    /// Relative tolerance of each simulation.
    #[arg(long, allow_hyphen_values = true, value_parser = finite, default_value_t = nanofold::commands::FitOptions::default().rtol)]
    pub rtol: f64,
    /// Levenberg–Marquardt iterations at most.
    #[arg(long, allow_hyphen_values = true, default_value_t = nanofold::commands::FitOptions::default().max_iterations)]
    pub max_iterations: usize,
    /// Integrator (diffsol).
    #[arg(long, value_enum, default_value_t = MethodArg::Auto)]
    pub method: MethodArg,
    /// Output folder (default: output/<scene name>-fit/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print the report as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `nanofold nets`.
#[derive(Args)]
pub struct NetsArgs {
    /// The solid: an .obj, .stl, .ply, .off or .fold file, or tetrahedron, cube, octahedron,
    /// dodecahedron, icosahedron, truncated_tetrahedron, cuboctahedron,
    /// truncated_octahedron, box:AxBxC, prism:N[:H], antiprism:N[:H], pyramid:N[:H],
    /// polycube:X,Y,Z;X,Y,Z;...
    pub shape: String,
    /// Enumerate every spanning tree when there are at most this many; else sample.
    #[arg(long, allow_hyphen_values = true, default_value_t = nanofold::commands::nets::NetsOptions::default().max_trees)]
    pub max_trees: usize,
    /// Trees drawn uniformly (Wilson's algorithm) when they are too many to enumerate.
    #[arg(long, allow_hyphen_values = true, default_value_t = nanofold::commands::nets::NetsOptions::default().samples)]
    pub samples: usize,
    /// The sampler's seed.
    #[arg(long, allow_hyphen_values = true, default_value_t = nanofold::commands::nets::NetsOptions::default().seed)]
    pub seed: u64,
    /// The score the nets are ranked by, smallest first (nets that can be made come first).
    #[arg(long, value_enum, default_value_t = RankByArg::RadiusOfGyration)]
    pub rank_by: RankByArg,
    /// How many of the best nets are written as FOLD and drawn.
    #[arg(long, allow_hyphen_values = true, default_value_t = nanofold::commands::nets::NetsOptions::default().top)]
    pub top: usize,
    /// The length of the solid's unit in µm.
    #[arg(long, allow_hyphen_values = true, value_parser = finite, default_value_t = nanofold::commands::nets::NetsOptions::default().unit_um)]
    pub unit_um: f64,
    /// The written scenes' hinges drive this many degrees past the turn that closes the
    /// solid, so the faces press shut (0 to 45).
    #[arg(long, allow_hyphen_values = true, value_parser = finite, default_value_t = nanofold::commands::nets::NetsOptions::default().overdrive_deg)]
    pub overdrive_deg: f64,
    /// Release the simulated and written nets by an etch front crossing the wafer along this
    /// direction alone (degrees; 0 along +x, 90 along +y); default: the --fronts directions,
    /// the written scenes released along each net's best.
    #[arg(long, allow_hyphen_values = true, value_parser = finite)]
    pub front_deg: Option<f64>,
    /// The etch front's speed, µm per minute.
    #[arg(long, allow_hyphen_values = true, value_parser = finite, default_value_t = 1.5)]
    pub etch_rate_um_per_min: f64,
    /// The face the written scenes anchor (a face index of the net's FOLD; default: the face
    /// at the centre of the net's tree).
    #[arg(long, allow_hyphen_values = true)]
    pub anchored_face: Option<usize>,
    /// How many of the best nets that can be made are simulated closing (0: none).
    #[arg(long, allow_hyphen_values = true, default_value_t = nanofold::commands::nets::NetsOptions::default().simulate)]
    pub simulate: usize,
    /// Etch-front directions each simulated net is released along, k·360°/N (0: all hinges
    /// at once); --front-deg tries that direction alone.
    #[arg(long, allow_hyphen_values = true, default_value_t = nanofold::commands::nets::NetsOptions::default().fronts)]
    pub fronts: usize,
    /// Devices sampled per net and release for the yield (0: the nominal device only).
    #[arg(long, allow_hyphen_values = true, default_value_t = nanofold::commands::nets::NetsOptions::default().yield_samples)]
    pub yield_samples: usize,
    /// Standard deviation of each hinge's stiffness across devices, %.
    #[arg(long, allow_hyphen_values = true, value_parser = finite, default_value_t = nanofold::commands::nets::NetsOptions::default().stiffness_spread_percent)]
    pub stiffness_spread_percent: f64,
    /// Standard deviation of each hinge's residual stress across devices, %.
    #[arg(long, allow_hyphen_values = true, value_parser = finite, default_value_t = nanofold::commands::nets::NetsOptions::default().stress_spread_percent)]
    pub stress_spread_percent: f64,
    /// A seam latches when its edges meet within this share of its length, %.
    #[arg(long, allow_hyphen_values = true, value_parser = finite, default_value_t = nanofold::commands::nets::NetsOptions::default().capture_percent)]
    pub capture_percent: f64,
    /// A solid file's faces in one plane: merged into one (always), kept as written (never),
    /// or merged when the file is all triangles, as STL is (auto).
    #[arg(long, value_enum, default_value_t = MergeArg::Auto)]
    pub merge_coplanar: MergeArg,
    /// Output folder (default: output/<shape>-nets/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print the report as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MergeArg {
    /// Merge when every face is a triangle (STL, triangulated exports).
    Auto,
    /// Merge every pair of faces that share an edge in one plane.
    Always,
    /// Keep the faces as the file writes them.
    Never,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum RankByArg {
    RadiusOfGyration,
    SeamLength,
    Footprint,
    Yield,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ModelArg {
    Auto,
    Dynamic,
    QuasiStatic,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    Auto,
    Bdf,
    Esdirk34,
    TrBdf2,
    Tsit45,
}

/// Arguments of `nanofold constraints`. Crease indices are the file's: FOLD edge index for
/// FOLD input, position in `creases` for the native schema. Angles are in degrees.
#[derive(Args)]
pub struct ConstraintsArgs {
    /// A FOLD file (.fold) or a native vertex (.json); or a folded crease pattern of many
    /// vertices with one degree of freedom (e.g. folded.fold from `nanofold fold`).
    pub pattern: PathBuf,
    /// The driving crease (a crease pattern of many vertices: its FOLD edge index).
    #[arg(long, allow_hyphen_values = true)]
    pub drive: usize,
    /// Hold crease J at DEG degrees (repeatable), e.g. --lock 1=0 (a crease pattern of many
    /// vertices: J is a FOLD edge index).
    #[arg(long = "lock", value_name = "J=DEG", allow_hyphen_values = true)]
    pub locks: Vec<String>,
    /// Keep only these creases free besides the driver (comma-separated indices, e.g.
    /// --free 2,3,4); every other crease is held at its folded angle, as if each had a
    /// --lock. An explicit --lock still sets its own angle.
    #[arg(long, allow_hyphen_values = true, value_name = "I,J,...", value_delimiter = ',')]
    pub free: Vec<usize>,
    /// Measure a given polynomial of crease J against exact loop closure (repeatable), e.g. a
    /// published table's: coefficients in degrees of the driving angle in degrees, constant
    /// first, e.g. --check 3=0.5,0.7,-3e-5 (single vertices).
    #[arg(long = "check", value_name = "J=C0,C1,...", allow_hyphen_values = true)]
    pub checks: Vec<String>,
    /// Polynomial degree 1..=20, or `auto` with --tol.
    #[arg(long, default_value = "4", allow_hyphen_values = true)]
    pub degree: String,
    /// With --degree auto: the largest accepted fit error, rad.
    #[arg(long, allow_hyphen_values = true, value_parser = finite)]
    pub tol: Option<f64>,
    /// Where the samples come from: an exact sweep or an unfolding trajectory.
    #[arg(long, value_enum, default_value_t = SourceArg::Sweep)]
    pub source: SourceArg,
    /// Driving-angle range A:B in degrees (default: flat to the folded angle; for many
    /// vertices from 5% of the folded angle, as the flat state is a branch point).
    #[arg(long, value_name = "A:B", allow_hyphen_values = true)]
    pub range: Option<String>,
    /// Number of sweep samples.
    #[arg(long, allow_hyphen_values = true, default_value_t = 201)]
    pub samples: usize,
    /// Export format besides constraints.json.
    #[arg(long, value_enum, default_value_t = ExportFormat::Json)]
    pub format: ExportFormat,
    /// Output folder (default: output/<pattern name>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print the report as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
    /// Largest accepted loop-closure residual of the input's folded state (rad).
    #[arg(long, allow_hyphen_values = true, value_parser = finite, default_value_t = 1e-6)]
    pub closure_tol: f64,
}

/// `--source`: where constraint samples come from.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SourceArg {
    /// Newton loop closure along a kinematic sweep: the exact reference.
    Sweep,
    /// The fold angles along an unfolding trajectory.
    Unfold,
}

/// `--energy`: the repulsive energy (`docs/model.md#energy`).
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum EnergyArg {
    /// Σ (γ(v,a) + γ(v,b) − α)^(−p), default p = 2: a barrier wherever a node touches an arc.
    Separable,
    /// Σ γ(v, m_e)^(−p), default p = 4: no barrier away from arc midpoints.
    NonSeparable,
}

impl From<EnergyArg> for EnergyKind {
    fn from(arg: EnergyArg) -> Self {
        match arg {
            EnergyArg::Separable => EnergyKind::Separable,
            EnergyArg::NonSeparable => EnergyKind::NonSeparable,
        }
    }
}

/// `--qp`: the direction solver.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum QpArg {
    /// Clarabel interior-point QP (the reference path).
    Clarabel,
    /// Closed-form projection onto the null space of the constraint rows.
    Direct,
}

impl From<QpArg> for QpMethod {
    fn from(arg: QpArg) -> Self {
        match arg {
            QpArg::Clarabel => QpMethod::Clarabel,
            QpArg::Direct => QpMethod::Direct,
        }
    }
}

/// Export format of `nanofold constraints`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ExportFormat {
    /// constraints.json only.
    Json,
    /// Also constraints.xml: a MuJoCo `<equality>` snippet (degree ≤ 4).
    Mujoco,
}

#[derive(Args, Clone)]
pub struct SolverArgs {
    /// Repulsive energy (`docs/model.md#energy`).
    #[arg(long, value_enum, default_value_t = EnergyArg::Separable)]
    pub energy: EnergyArg,
    /// Exponent p (default 2 separable, 4 non-separable).
    #[arg(long, allow_hyphen_values = true, value_parser = finite)]
    pub p: Option<f64>,
    /// Direction solver: the direct null-space projection or the Clarabel QP.
    #[arg(long, value_enum, default_value_t = QpArg::Direct)]
    pub qp: QpArg,
    /// Flat when every |fold angle| ≤ this (rad).
    #[arg(long, allow_hyphen_values = true, value_parser = finite, default_value_t = 1e-6)]
    pub flat_tol: f64,
    /// A crease pattern of many vertices (or a folded form) whose state does not close, as a
    /// compliant simulator exports it: move it to the nearest rigid state first and say how far.
    #[arg(long)]
    pub project: bool,
    /// Weight κ of the bending metric of the direction (0: the plain QP, M = I).
    #[arg(long, allow_hyphen_values = true, value_parser = finite, default_value_t = UnfoldSettings::default().bending_metric)]
    pub bending_metric: f64,
    /// Iteration limit.
    #[arg(long, allow_hyphen_values = true, alias = "max-iter", default_value_t = nanofold::commands::UnfoldOptions::default().max_iterations)]
    pub max_iterations: usize,
    /// Restarts from perturbed states before a stuck verdict.
    #[arg(long, allow_hyphen_values = true, default_value_t = nanofold::commands::UnfoldOptions::default().restarts)]
    pub restarts: usize,
    /// Seed of the restarts' perturbations.
    #[arg(long, allow_hyphen_values = true, default_value_t = nanofold::commands::UnfoldOptions::default().seed)]
    pub seed: u64,
    /// Largest accepted loop-closure residual of the input's folded state (rad).
    #[arg(long, allow_hyphen_values = true, value_parser = finite, default_value_t = 1e-6)]
    pub closure_tol: f64,
}

impl SolverArgs {
    fn settings(&self) -> Result<UnfoldSettings> {
        let options = nanofold::commands::UnfoldOptions {
            energy: self.energy.into(),
            p: self.p,
            qp: self.qp.into(),
            flat_tol: self.flat_tol,
            bending_metric: self.bending_metric,
            max_iterations: self.max_iterations,
            restarts: self.restarts,
            seed: self.seed,
        };
        let settings = options.settings().map_err(|e| with_flags(e, UNFOLD_FLAGS))?;
        self.load_options()
            .validate()
            .map_err(|e| with_flags(e, UNFOLD_FLAGS))?;
        Ok(settings)
    }

    fn load_options(&self) -> LoadOptions {
        LoadOptions {
            closure_tol: self.closure_tol,
            ..LoadOptions::default()
        }
    }
}

/// How many patterns run at once.
#[derive(Args, Debug, Clone)]
pub struct ParallelArgs {
    /// Patterns run at once (0: one per core; at most 256). Lines come out as patterns
    /// finish, each naming its file.
    #[arg(long, allow_hyphen_values = true, default_value_t = 0, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(0..=256))]
    pub jobs: usize,
}

impl ParallelArgs {
    /// Runs `work` on every item in a pool of `--jobs` threads; `work` prints its own lines
    /// and says whether its item succeeded. Returns whether all did.
    fn all<T: Sync>(&self, items: &[T], work: impl Fn(&T) -> bool + Sync) -> Result<bool> {
        use rayon::prelude::*;
        let pool = rayon::ThreadPoolBuilder::new()
            // No more threads than items: a thread per item at most.
            .num_threads(if self.jobs == 0 {
                0
            } else {
                self.jobs.min(items.len().max(1))
            })
            .build()
            .context("starting the worker threads")?;
        // `map` then `all`, not `all` alone: every item runs even after a failure.
        Ok(pool.install(|| {
            items
                .par_iter()
                .map(&work)
                .collect::<Vec<bool>>()
                .into_iter()
                .all(|ok| ok)
        }))
    }
}

/// The pattern files named on the command line: files as given, directories searched
/// recursively for `.fold` and `.json` files (scene files skipped), each directory's in
/// name order. A directory without any is an error naming it.
fn expand_patterns(paths: &[PathBuf]) -> Result<Vec<PathBuf>> {
    use std::collections::HashSet;
    /// Walks `dir`; a directory reached twice (a symlink loop, or a link to a sibling) is
    /// walked once.
    fn walk(dir: &Path, seen_dirs: &mut HashSet<PathBuf>, found: &mut Vec<PathBuf>) -> Result<()> {
        let canonical =
            std::fs::canonicalize(dir).with_context(|| format!("cannot read directory {}", dir.display()))?;
        if !seen_dirs.insert(canonical) {
            return Ok(());
        }
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .with_context(|| format!("cannot read directory {}", dir.display()))?
            .map(|entry| entry.map(|e| e.path()))
            .collect::<std::io::Result<_>>()
            .with_context(|| format!("cannot read directory {}", dir.display()))?;
        entries.sort();
        for path in entries {
            if path.is_dir() {
                walk(&path, seen_dirs, found)?;
            } else if nanofold::commands::outputs::is_pattern_file(&path) {
                found.push(path);
            }
            anyhow::ensure!(
                found.len() <= MAX_BATCH_FILES,
                "more than {MAX_BATCH_FILES} pattern files under {}: give fewer at a time",
                dir.display()
            );
        }
        Ok(())
    }
    let mut found = Vec::new();
    let mut seen_dirs = HashSet::new();
    for path in paths {
        if path.is_dir() {
            let before = found.len();
            walk(path, &mut seen_dirs, &mut found)?;
            anyhow::ensure!(
                found.len() > before,
                "no pattern files (.fold or .json, scene files aside) in directory {}",
                path.display()
            );
        } else {
            found.push(path.clone());
        }
    }
    // One run per file, however many names (links, repeated arguments) lead to it.
    let mut seen_files = HashSet::new();
    found.retain(|path| seen_files.insert(std::fs::canonicalize(path).unwrap_or_else(|_| path.clone())));
    anyhow::ensure!(
        found.len() <= MAX_BATCH_FILES,
        "{} pattern files: at most {MAX_BATCH_FILES} in one run",
        found.len()
    );
    Ok(found)
}

/// Most pattern files one `unfold` run takes.
const MAX_BATCH_FILES: usize = 10_000;

/// Unfolds one pattern into `dir`; returns its JSON summary and its human-readable lines.
fn unfold_one(
    pattern_path: &Path,
    solver: &SolverArgs,
    dir: Option<&Path>,
    progress: Option<UnfoldProgress>,
) -> Result<(serde_json::Value, String)> {
    use std::fmt::Write as _;
    let settings = solver.settings()?;
    let opened = open_pattern(pattern_path, solver)?;
    let Some(pattern) = opened.vertex() else {
        return folding::unfold_network_one(pattern_path, &opened, solver, dir, progress);
    };
    let door = nanofold::commands::Settings {
        unfold: settings.clone(),
        ..nanofold::commands::Settings::default()
    };
    let answer = nanofold::commands::unfold_observed(&opened, &door, progress)?;
    let dir = dir.map_or_else(|| default_folder(&pattern.name, pattern_path), Path::to_path_buf);
    // Render everything before writing anything.
    let files = nanofold::commands::unfold_files(&opened, &answer, &door)?;
    let written: Vec<(&str, &[u8])> = files.iter().map(|(name, text)| (*name, text.as_bytes())).collect();
    write_folder_of(
        &dir,
        pattern_path,
        FORCE.load(std::sync::atomic::Ordering::Relaxed),
        &written,
    )
    .with_context(|| format!("writing {}", dir.display()))?;
    let nanofold::commands::Detail::VertexUnfold(report) = &answer.detail else {
        unreachable!("a single vertex unfolds by the single-vertex engine")
    };
    let mut summary = answer.to_json();
    summary["out"] = json!(dir.display().to_string());
    let mut text = String::new();
    writeln!(
        text,
        "{}: {} ({})",
        pattern.name,
        report.verdict.as_str(),
        report.evidence
    )?;
    writeln!(
        text,
        "  {} iterations in {:.3} ms; energy {:.6e} -> {:.6e}",
        report.iterations,
        report.seconds * 1e3,
        report.energy_initial,
        report.energy_final
    )?;
    writeln!(
        text,
        "  max arc residual {:.2e} rad, planarity residual {:.2e}, flat layout error {}, restarts {}",
        report.max_arc_residual,
        report.planarity_residual,
        if report.flat_layout_error.is_finite() {
            format!("{:.2e}", report.flat_layout_error)
        } else {
            "none (no flat state)".to_string()
        },
        report.restarts_used
    )?;
    for (c, rho) in pattern.creases.iter().zip(&report.final_fold_angles_rad) {
        writeln!(
            text,
            "  {:<12} {:>11.6}° -> {:>12.3e} rad",
            c.label,
            c.folded_angle.to_degrees(),
            rho
        )?;
    }
    for note in &report.adjustments {
        writeln!(text, "  note: {note}")?;
    }
    write!(
        text,
        "  wrote {}/{{trajectory.json, unfold.svg, unfold.fold, unfold.html}}",
        dir.display()
    )?;
    Ok((summary, text))
}

/// One pattern: errors end the command. Several: each runs in parallel into
/// `<out>/<pattern name>/`, a failure is reported on its own line and the exit status is
/// non-zero at the end.
fn run_unfold(
    patterns: &[PathBuf],
    solver: &SolverArgs,
    out: Option<PathBuf>,
    as_json: bool,
    parallel: &ParallelArgs,
) -> Result<bool> {
    solver.settings()?;
    let single = patterns.len() == 1 && !patterns[0].is_dir();
    if single {
        // A long unfold (hundreds of creases) shows its progress on stderr.
        let spinner = if as_json {
            indicatif::ProgressBar::hidden()
        } else {
            indicatif::ProgressBar::new_spinner()
        };
        spinner.set_style(
            indicatif::ProgressStyle::with_template("{spinner} unfolding: {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
        );
        let shown = spinner.clone();
        let progress = UnfoldProgress(std::sync::Arc::new(move |step, largest, energy| {
            if step % 16 == 0 {
                shown.set_message(format!("step {step}, max |ρ| = {largest:.2e} rad, U = {energy:.6e}"));
                shown.tick();
            }
        }));
        let result = unfold_one(&patterns[0], solver, out.as_deref(), Some(progress));
        spinner.finish_and_clear();
        let (summary, text) = result?;
        println!("{}", if as_json { summary.to_string() } else { text });
        return Ok(true);
    }
    let files = expand_patterns(patterns)?;
    // Output folders by pattern name, refused up front if two patterns would share one.
    let parent = out.unwrap_or_else(|| PathBuf::from("output"));
    let mut jobs: Vec<(PathBuf, PathBuf)> = Vec::with_capacity(files.len());
    let mut writer_of: std::collections::HashMap<PathBuf, PathBuf> = std::collections::HashMap::new();
    for path in files {
        let file_name = nanofold::commands::outputs::pattern_name(&path);
        let dir = parent.join(folder_name(&file_name, &file_name));
        if let Some(other) = writer_of.insert(dir.clone(), path.clone()) {
            anyhow::bail!(
                "{} and {} would both write {}: unfold them separately with --out",
                other.display(),
                path.display(),
                dir.display()
            );
        }
        jobs.push((path, dir));
    }
    parallel.all(&jobs, |(path, dir)| match unfold_one(path, solver, Some(dir), None) {
        Ok((summary, text)) => {
            println!("{}", if as_json { summary.to_string() } else { text });
            true
        }
        Err(e) => {
            print_failure(path, &e, as_json);
            false
        }
    })
}

/// One line for a pattern that could not be read or run.
fn print_failure(path: &Path, error: &anyhow::Error, as_json: bool) {
    if as_json {
        println!(
            "{}",
            json!({"file": path.display().to_string(), "error": format!("{error:#}")})
        );
    } else {
        // The line starts with the file: the message need not name it again.
        let message = format!("{error:#}");
        let file = path.display().to_string();
        let message = [format!("reading {file}: "), format!("{file}: ")]
            .iter()
            .find_map(|prefix| message.strip_prefix(prefix.as_str()))
            .unwrap_or(&message);
        println!("{file}: error: {message}");
    }
}

/// Reads a pattern through the door: a single vertex for its engine, a crease pattern of
/// many vertices for the other; with `--project`, a sheet's state moved to the nearest rigid
/// state first.
fn open_pattern(path: &Path, solver: &SolverArgs) -> Result<nanofold::commands::Pattern> {
    let pattern = nanofold::commands::Pattern::open(path, &solver.load_options()).map_err(|e| reading(path, e))?;
    if !solver.project {
        return Ok(pattern);
    }
    pattern
        .projected()
        .map_err(|e| with_flags(e, &[("fold_angles", "--project")]))
}

fn run_check(patterns: &[PathBuf], solver: &SolverArgs, as_json: bool, parallel: &ParallelArgs) -> Result<bool> {
    let settings = nanofold::commands::Settings {
        unfold: solver.settings()?,
        check: nanofold::prelude::CheckSettings {
            closure_tol: solver.closure_tol,
            ..nanofold::prelude::CheckSettings::default()
        },
        ..nanofold::commands::Settings::default()
    };
    let files = expand_patterns(patterns)?;
    parallel.all(&files, |path| {
        let outcome = open_pattern(path, solver).and_then(|pattern| {
            let report = nanofold::commands::check(&pattern, &settings)?;
            let line = match &report.detail {
                // A single vertex: its unfolding's verdict.
                nanofold::commands::Detail::VertexUnfold(unfolding) => format!(
                    "{}: {} ({} iterations, {:.3} ms) {}",
                    path.display(),
                    report.verdict.as_str(),
                    unfolding.iterations,
                    unfolding.seconds * 1e3,
                    report.evidence
                ),
                // A crease pattern of many vertices: its state or its assignment.
                _ => folding::check_line(path, &pattern, &report),
            };
            Ok((report.to_json(), line))
        });
        match outcome {
            Ok((value, line)) => {
                println!("{}", if as_json { value.to_string() } else { line });
                true
            }
            Err(e) => {
                print_failure(path, &e, as_json);
                false
            }
        }
    })
}

/// Parses "J=C0,C1,..." into (crease index, coefficients in degrees).
fn parse_check(text: &str) -> Result<(usize, Vec<f64>)> {
    let (index, coeffs) = text
        .split_once('=')
        .with_context(|| format!("invalid --check {text:?}: expected J=C0,C1,..., e.g. --check 3=0.5,0.7,-3e-5"))?;
    let index: usize = index
        .trim()
        .parse()
        .with_context(|| format!("invalid --check {text:?}: crease index {index:?} is not a number"))?;
    let coeffs = coeffs
        .split(',')
        .map(|c| {
            c.trim()
                .parse::<f64>()
                .with_context(|| format!("invalid --check {text:?}: coefficient {c:?} is not a number"))
        })
        .collect::<Result<Vec<f64>>>()?;
    Ok((index, coeffs))
}

/// Parses "J=DEG" into (crease index, rad).
fn parse_lock(text: &str) -> Result<(usize, f64)> {
    let (index, degrees) = text
        .split_once('=')
        .with_context(|| format!("invalid --lock {text:?}: expected J=DEG, e.g. --lock 1=0"))?;
    let index: usize = index
        .trim()
        .parse()
        .with_context(|| format!("invalid --lock {text:?}: crease index {index:?} is not a number"))?;
    let degrees: f64 = degrees
        .trim()
        .parse()
        .with_context(|| format!("invalid --lock {text:?}: angle {degrees:?} is not a number of degrees"))?;
    Ok((index, degrees))
}

/// Parses "A:B" (degrees) into [a, b], degrees.
fn parse_range(text: &str) -> Result<[f64; 2]> {
    let (a, b) = text
        .split_once(':')
        .with_context(|| format!("invalid --range {text:?}: expected A:B in degrees, e.g. --range 0:180"))?;
    let parse = |v: &str| -> Result<f64> {
        v.trim()
            .parse::<f64>()
            .with_context(|| format!("invalid --range {text:?}: {v:?} is not a number of degrees"))
    };
    Ok([parse(a)?, parse(b)?])
}

fn run_constraints(args: &ConstraintsArgs) -> Result<()> {
    use nanofold::commands::{AutoDegree, ConstraintOptions, Constraints, CurveFormat, CurveSource, DegreeOption};
    let degree = match args.degree.as_str() {
        "auto" => None,
        text => {
            let degree: usize = text
                .parse()
                .with_context(|| format!("invalid --degree {text:?}: expected 1..=20 or auto"))?;
            anyhow::ensure!(args.tol.is_none(), "--tol applies only to --degree auto");
            Some(degree)
        }
    };
    if degree.is_none() && args.tol.is_none() {
        anyhow::bail!("--degree auto needs --tol RAD (the largest accepted fit error)");
    }
    let options = ConstraintOptions {
        drive: args.drive,
        lock: args.locks.iter().map(|text| parse_lock(text)).collect::<Result<_>>()?,
        free: args.free.clone(),
        degree: degree.map_or(DegreeOption::Named(AutoDegree::Auto), DegreeOption::Fixed),
        tol: args.tol,
        range: args.range.as_deref().map(parse_range).transpose()?,
        samples: args.samples,
        source: match args.source {
            SourceArg::Sweep => CurveSource::Sweep,
            SourceArg::Unfold => CurveSource::Unfold,
        },
        check: args
            .checks
            .iter()
            .map(|text| parse_check(text))
            .collect::<Result<_>>()?,
        format: match args.format {
            ExportFormat::Json => CurveFormat::Json,
            ExportFormat::Mujoco => CurveFormat::Mujoco,
        },
    };
    let settings = options.settings().map_err(constraints_flags)?;
    let read = LoadOptions {
        closure_tol: args.closure_tol,
        ..LoadOptions::default()
    };
    read.validate().map_err(constraints_flags)?;
    let pattern = nanofold::commands::Pattern::open(&args.pattern, &read).map_err(|e| reading(&args.pattern, e))?;
    // A long sweep (up to 100 000 Newton solves) shows that it is working.
    let spinner = if args.json {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new_spinner()
    };
    spinner.enable_steady_tick(std::time::Duration::from_millis(200));
    spinner.set_message(format!("sweeping {} samples", args.samples));
    let curves = nanofold::commands::constraints(&pattern, &settings).map_err(constraints_flags);
    spinner.finish_and_clear();
    let curves = curves?;
    if let Some(tol) = args.tol.filter(|_| args.format == ExportFormat::Mujoco) {
        if curves.max_fit_error_rad() > tol {
            eprintln!(
                "note: --degree auto is capped at 4 for MuJoCo; degree 4 leaves {:.3e} rad, above --tol {tol:e}",
                curves.max_fit_error_rad()
            );
        }
    }
    // Render everything before writing anything.
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| default_folder(pattern.name(), &args.pattern));
    let files = nanofold::commands::constraints_files(&pattern, &curves, options.format).map_err(constraints_flags)?;
    write_outputs(&dir, &args.pattern, &files)?;
    if args.json {
        println!("{}", serde_json::to_string(&curves)?);
        return Ok(());
    }
    match &curves {
        Constraints::Vertex { report, .. } => print_constraints(pattern.name(), report, &dir, &files),
        Constraints::Network { curves, .. } => {
            folding::print_network_constraints(pattern.name(), curves);
            print_written(&dir, &files);
        }
    }
    Ok(())
}

/// What `constraints` prints of a single vertex's curves.
fn print_constraints(name: &str, report: &nanofold::commands::ConstraintReport, dir: &Path, files: &[(&str, String)]) {
    println!(
        "{}: {} curve(s) of {} over [{:.4}°, {:.4}°], degree {}, {} samples ({:?}, closure residual of samples {:.1e} rad)",
        name,
        report.curves.len(),
        report.driver_label,
        report.domain_deg[0],
        report.domain_deg[1],
        report.degree,
        report.samples,
        report.source,
        report.samples_max_closure_residual
    );
    for (crease, value) in &report.locked {
        println!("  locked crease {crease} at {:.6}°", value.to_degrees());
    }
    for curve in &report.curves {
        println!(
            "  {:<12} fit error {:.3e} rad, slope error {:.3e}, closure residual {:.3e} rad; coefficients (deg):",
            curve.label, curve.max_fit_error_rad, curve.max_slope_error, curve.max_closure_residual
        );
        // Every coefficient at full precision (shortest round-trip form): at degree 16 the
        // top term is ~1e-34 · 180^16, so seven digits would move the curve by 1e-3°.
        let terms: Vec<String> = curve
            .coeffs_deg
            .iter()
            .enumerate()
            .map(|(k, c)| format!("{c:+e}·θ^{k}"))
            .collect();
        println!("      {}", terms.join(" "));
    }
    println!(
        "  all curves together: loop-closure residual {:.3e} rad",
        report.max_closure_residual
    );
    for checked in &report.checked_curves {
        println!(
            "  checked {:<12} largest error {:.3e} rad ({:.4}°) at {:.4}°; at the folded end {:.4}°: {:+.4}°",
            checked.label,
            checked.max_error_rad,
            checked.max_error_rad.to_degrees(),
            checked.max_error_at_deg,
            checked.folded_end_deg,
            checked.folded_end_error_rad.to_degrees()
        );
    }
    print_written(dir, files);
}

/// The first contact of a run, or that there was none, as one line.
/// `output/<name>`, where a name that is not one plain folder name (`..`, `/abs`, empty)
/// gives way to the file's own name.
fn default_folder(name: &str, file: &Path) -> PathBuf {
    default_output_folder(name, file)
}

/// Writes the (file name, contents) set into `dir` as one (see `io::folder`); everything is
/// rendered first.
fn write_outputs(dir: &Path, input: &Path, files: &[(&str, String)]) -> Result<()> {
    let files: Vec<(&str, &[u8])> = files
        .iter()
        .map(|(name, contents)| (*name, contents.as_bytes()))
        .collect();
    write_folder_of(dir, input, FORCE.load(std::sync::atomic::Ordering::Relaxed), &files)
        .with_context(|| format!("writing {}", dir.display()))
}

/// `--force`: replace an output folder that holds another input's results.
static FORCE: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// The "wrote DIR/{a, b}" line.
fn print_written(dir: &Path, files: &[(&str, String)]) {
    let names: Vec<&str> = files.iter().map(|f| f.0).collect();
    println!("  wrote {}/{{{}}}", dir.display(), names.join(", "));
}

/// The model line of `simulate`: which equations, their cost and their error against the other.
fn print_model(response: &Response) {
    match response.model {
        ModelKind::Dynamic => {
            println!(
                "  model: dynamic ({:?}, rtol {:.0e}): {} steps, {} right-hand sides, {:.3} s; the quasi-static path would be off by up to {:.2e} rad",
                response.method.unwrap_or(Method::Auto),
                response.rtol,
                response.steps,
                response.rhs_evaluations,
                response.seconds,
                response.quasi_static_error_estimate
            );
            if let Some((_, measured)) = response.measured_quasi_static_error {
                println!("  measured against the quasi-static path: {measured:.2e} rad");
            }
        }
        ModelKind::QuasiStatic => {
            let (window, measured) = response.measured_quasi_static_error.unwrap_or((0.0, f64::NAN));
            println!(
                "  model: quasi-static (K θ = τ(t)), {:.3} s; its error: ≤ {:.2e} rad estimated, {:.2e} rad measured by a dynamic run over the first {:.2e} s",
                response.seconds, response.quasi_static_error_estimate, measured, window
            );
        }
    }
}

/// A slow release carried through contact, or why it stopped at the first one.
fn print_released(scene: &Scene, simulation: &nanofold::prelude::Simulation) {
    use nanofold::prelude::first_contact_only;
    let response = &simulation.response;
    match (&simulation.released, scene.network()) {
        (Some(run), _) => {
            let ended = match run.outcome.label() {
                "jams" => "jams (held by contact forces)",
                other => other,
            };
            println!(
                "  carried through contact: {} at t = {:.6e} s; {} seams latched, {} contacts met",
                ended,
                run.time_s,
                run.latches.len(),
                run.contacts.len()
            );
            if let Some(why) = &run.undecided {
                println!("  why it stopped: {why}");
            }
            for open in &run.open_seams {
                println!("  seam {} open, its ends {:.3e} of its length apart", open.0, open.1);
            }
            for c in run.final_contacts.iter().filter(|c| c.force_n > 0.0) {
                let friction = c.friction_n.iter().map(|f| f * f).sum::<f64>().sqrt();
                let held = if friction > 0.0 {
                    format!(", friction {friction:.3e} N")
                } else {
                    String::new()
                };
                println!(
                    "  face {} pressed on face {} ({}) at ({:.2}, {:.2}, {:.2}) µm with {:.3e} N{held}",
                    c.faces[0], c.faces[1], c.feature, c.point_um[0], c.point_um[1], c.point_um[2], c.force_n
                );
            }
        }
        (None, Some(model)) if response.model == ModelKind::QuasiStatic && response.collision.is_some() => {
            if let Some(why) = first_contact_only(model) {
                println!("  the run ends at its first contact: {why}");
            }
        }
        _ => {}
    }
}

fn print_contact(response: &Response) {
    match &response.collision {
        Some(c) => println!(
            "  first contact at t = {:.6e} s: {} with {} at (x, y, z) = ({:.2}, {:.2}, {:.2}) µm",
            c.time,
            c.pair[0],
            c.pair[1],
            c.point.x * 1e6,
            c.point.y * 1e6,
            c.point.z * 1e6
        ),
        None => println!("  no contact up to t = {:.6e} s", response.t_end),
    }
}

/// A progress bar on stderr for a long simulation (hidden when `show` is false), and the
/// observer that moves it. The caller clears the bar when the run ends.
fn progress_bar(show: bool) -> (indicatif::ProgressBar, ProgressObserver) {
    let bar = if show {
        indicatif::ProgressBar::new(1000)
    } else {
        indicatif::ProgressBar::hidden()
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} simulating [{bar:40}] {percent}% t = {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let moved = bar.clone();
    let observer = ProgressObserver(std::sync::Arc::new(move |fraction, time| {
        moved.set_position((1000.0 * fraction) as u64);
        moved.set_message(format!("{time:.3e} s"));
    }));
    (bar, observer)
}

fn run_simulate(args: &SimulateArgs) -> Result<()> {
    let (bar, observer) = progress_bar(!args.json);
    let result = run_simulate_with(args, observer);
    bar.finish_and_clear();
    result
}

/// A loader's error with the file named, once: I/O and JSON errors name it already.
pub(crate) fn reading(path: &Path, error: nanofold::prelude::NanofoldError) -> anyhow::Error {
    use nanofold::prelude::NanofoldError::{Io, Json};
    let names_file = matches!(error, Io { .. } | Json { .. });
    let error = anyhow::Error::new(error);
    if names_file {
        error
    } else {
        error.context(format!("reading {}", path.display()))
    }
}

/// Loads a scene file and builds it (the closed chain's sweep and fit run here).
fn load_scene(path: &Path) -> Result<Scene> {
    let spec = nanofold::prelude::load_scene(path).map_err(|e| reading(path, e))?;
    spec.build()
        .with_context(|| format!("building the scene of {}", path.display()))
}

fn method_of(arg: MethodArg) -> Method {
    match arg {
        MethodArg::Auto => Method::Auto,
        MethodArg::Bdf => Method::Bdf,
        MethodArg::Esdirk34 => Method::Esdirk34,
        MethodArg::TrBdf2 => Method::TrBdf2,
        MethodArg::Tsit45 => Method::Tsit45,
    }
}

const FIT_FLAGS: &[(&str, &str)] = &[
    ("rtol", "--rtol"),
    ("max_iterations", "--max-iterations"),
    ("free", "--free"),
    ("noise", "--noise"),
];

const NETS_FLAGS: &[(&str, &str)] = &[
    ("max_trees", "--max-trees"),
    ("samples", "--samples"),
    ("top", "--top"),
    ("unit_um", "--unit-um"),
    ("overdrive_deg", "--overdrive-deg"),
    ("front_deg", "--front-deg"),
    ("etch_rate_um_per_min", "--etch-rate-um-per-min"),
    ("anchored_face", "--anchored-face"),
    ("simulate", "--simulate"),
    ("fronts", "--fronts"),
    ("yield_samples", "--yield-samples"),
    ("stiffness_spread_percent", "--stiffness-spread-percent"),
    ("stress_spread_percent", "--stress-spread-percent"),
    ("capture_percent", "--capture-percent"),
    ("rank_by", "--rank-by"),
];

fn run_nets(args: &NetsArgs) -> Result<()> {
    use nanofold::commands::nets::{
        nets, nets_files, open_solid_with, study_nets, MergeCoplanar, NetsOptions, Outcome, RankBy, Search,
    };
    let options = NetsOptions {
        max_trees: args.max_trees,
        samples: args.samples,
        seed: args.seed,
        rank_by: match args.rank_by {
            RankByArg::RadiusOfGyration => RankBy::RadiusOfGyration,
            RankByArg::SeamLength => RankBy::SeamLength,
            RankByArg::Footprint => RankBy::Footprint,
            RankByArg::Yield => RankBy::Yield,
        },
        top: args.top,
        unit_um: args.unit_um,
        overdrive_deg: args.overdrive_deg,
        front_deg: args.front_deg,
        etch_rate_um_per_min: args.etch_rate_um_per_min,
        anchored_face: args.anchored_face,
        simulate: args.simulate,
        fronts: args.fronts,
        yield_samples: args.yield_samples,
        stiffness_spread_percent: args.stiffness_spread_percent,
        stress_spread_percent: args.stress_spread_percent,
        capture_percent: args.capture_percent,
        merge_coplanar: match args.merge_coplanar {
            MergeArg::Auto => MergeCoplanar::Auto,
            MergeArg::Always => MergeCoplanar::Always,
            MergeArg::Never => MergeCoplanar::Never,
        },
    };
    let flags = |e| with_flags(e, NETS_FLAGS);
    options.validate().map_err(flags)?;
    let opened = open_solid_with(&args.shape, &options.solid_options())
        .map_err(|e| anyhow::anyhow!("reading {}: {e}", args.shape))?;
    let mut report = nets(&opened.name, &opened.solid, &options).map_err(flags)?;
    report.reading = opened.reading;
    let (name, solid) = (opened.name, opened.solid);
    let bar = if args.json || options.simulate == 0 {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(1)
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} simulating releases [{bar:40}] {pos}/{len} ({eta} left)")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let studied = study_nets(&solid, &mut report, &options, &|done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    });
    bar.finish_and_clear();
    studied.map_err(flags)?;
    let files = nets_files(&solid, &report, &options).map_err(flags)?;
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("output").join(folder_name(&format!("{name}-nets"), &name)));
    let named: Vec<(&str, String)> = files.iter().map(|(n, t)| (n.as_str(), t.clone())).collect();
    write_outputs(&dir, Path::new(&args.shape), &named)?;
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
        return Ok(());
    }
    let how = match report.search {
        Search::Enumerated => format!("all {} spanning trees enumerated", report.trees_considered),
        Search::Sampled => format!(
            "{} of its {:.3e} spanning trees sampled uniformly",
            report.trees_considered, report.spanning_trees
        ),
    };
    println!(
        "{}: {} faces, {} edges, {} vertices, symmetry group {} of order {} ({} rotations); {how}: {} distinct nets, {} overlapping ({:.2} s)",
        report.solid,
        report.faces,
        report.edges,
        report.vertices,
        report.symmetry.point_group,
        report.symmetry_order,
        report.rotations,
        report.distinct_nets,
        report.overlapping,
        report.seconds
    );
    if let Some(reading) = &report.reading {
        let merged = if reading.faces_merged < reading.faces_read {
            format!(
                "; its {} faces in {} planes{}",
                reading.faces_read,
                reading.faces_merged,
                if reading.concave_faces_cut > 0 {
                    format!(
                        ", {} concave ones cut at their reflex corners",
                        reading.concave_faces_cut
                    )
                } else {
                    String::new()
                }
            )
        } else {
            String::new()
        };
        println!(
            "  read as {}: {} vertices, {} of them copies{merged}; coordinates: {}; planar to {:.1e}, symmetric to {:.1e}",
            reading.format,
            reading.vertices_read,
            reading.vertices_welded,
            reading.tolerances.precision.describe(),
            reading.tolerances.planarity,
            reading.tolerances.symmetry
        );
    }
    for warning in &report.warnings {
        println!("  warning: {warning}");
    }
    if let Some(study) = &report.study {
        let releases = match study.releases.as_slice() {
            [None] => "released at once".to_string(),
            [Some(phi)] => format!("released by a front along {phi}°"),
            many => format!("released by fronts along {} directions", many.len()),
        };
        println!(
            "  simulated: the best {} nets, {releases}, the nominal device and {} varied ones each ({}% stiffness and {}% stress spread), seams latching within {}%: {} devices in {:.2} s",
            study.nets,
            study.variation.samples,
            study.variation.stiffness_spread_percent,
            study.variation.stress_spread_percent,
            study.closing.capture_percent,
            study.devices,
            study.seconds
        );
        let f = &study.failures;
        println!(
            "  varied devices that did not close: {} jam, {} stall, {} snap through, {} undecided",
            f.jams, f.stalls, f.snaps, f.undecided
        );
        if let Some(fidelity) = &study.fidelity {
            let shown = |name: &str, r: &Option<nanofold::commands::nets::RankCorrelation>| {
                r.map(|r| {
                    format!(
                        "{name} ρ = {:.2} (95% {:.2} to {:.2})",
                        r.rho, r.interval_95[0], r.interval_95[1]
                    )
                })
            };
            let parts: Vec<String> = [
                shown("radius of gyration", &fidelity.radius_of_gyration),
                shown("leaves", &fidelity.leaves),
            ]
            .into_iter()
            .flatten()
            .collect();
            println!(
                "  yield ranked against compactness over {} nets (Spearman): {}",
                study.nets,
                parts.join("; ")
            );
        }
    }
    for row in report.nets.iter().take(options.top.max(options.simulate)) {
        let simulated = row.closing.as_ref().map_or(String::new(), |c| {
            let best = &c.releases[c.best];
            let release = best
                .front_deg
                .map_or("at once".to_string(), |phi| format!("front {phi}°"));
            let outcome = match (best.outcome, best.jam_faces) {
                (Outcome::Jams, Some([a, b])) => format!("jams (faces {a}, {b}) at {:.6e} s", best.time_s),
                (outcome, _) => format!("{} at {:.6e} s", outcome.label(), best.time_s),
            };
            let yield_text = match (c.fresh_yield, best.yield_estimate) {
                (Some(y), Some(chosen)) => {
                    let captures: Vec<String> = c
                        .capture_yields
                        .iter()
                        .map(|k| {
                            format!(
                                "{}/{} at {} %",
                                k.yield_estimate.closed, k.yield_estimate.samples, k.capture_percent
                            )
                        })
                        .collect();
                    format!(
                        ", yield on fresh devices {}/{} ({:.3}, 95% {:.3}–{:.3}; chosen at {}/{}{}{})",
                        y.closed,
                        y.samples,
                        y.fraction,
                        y.interval_95[0],
                        y.interval_95[1],
                        chosen.closed,
                        chosen.samples,
                        if captures.is_empty() { "" } else { "; the same devices " },
                        captures.join(", ")
                    )
                }
                (_, Some(y)) => format!(
                    ", yield {}/{} ({:.3}, 95% {:.3}–{:.3})",
                    y.closed, y.samples, y.fraction, y.interval_95[0], y.interval_95[1]
                ),
                _ => String::new(),
            };
            format!(
                "; best release {release}: {outcome}{yield_text}; closes in {} of {} releases",
                c.closes_in,
                c.releases.len()
            )
        });
        println!(
            "  #{}: Rg {:.4} µm, {} leaves, seams {:.4} µm, footprint {:.4} × {:.4} µm{}{simulated}",
            row.rank,
            row.radius_of_gyration_um,
            row.leaves,
            row.seam_length_um,
            row.footprint_um[0],
            row.footprint_um[1],
            if row.overlapping {
                ", overlaps"
            } else if row.touching == Some(true) {
                ", touches itself"
            } else {
                ""
            }
        );
    }
    println!("wrote {}", dir.display());
    Ok(())
}

fn run_fit(args: &FitArgs) -> Result<()> {
    use nanofold::commands::{FitOptions, FreeOption, NoiseOption};
    let noise = match args.noise.as_slice() {
        [] => None,
        [single] if !single.contains('=') => {
            Some(NoiseOption::All(single.parse().map_err(|_| {
                anyhow::anyhow!("invalid --noise {single}: give SIGMA or COLUMN=SIGMA")
            })?))
        }
        many => {
            let mut columns = std::collections::BTreeMap::new();
            for item in many {
                let (name, value) = item
                    .split_once('=')
                    .ok_or_else(|| anyhow::anyhow!("invalid --noise {item}: with several, each is COLUMN=SIGMA"))?;
                let sigma = value
                    .parse()
                    .map_err(|_| anyhow::anyhow!("invalid --noise {item}: `{value}` is not a number"))?;
                columns.insert(name.to_string(), sigma);
            }
            Some(NoiseOption::Columns(columns))
        }
    };
    let options = FitOptions {
        free: args.free.iter().cloned().map(FreeOption::Text).collect(),
        noise,
        rtol: args.rtol,
        max_iterations: args.max_iterations,
        method: method_of(args.method),
    };
    let fit_flags = |e| with_flags(e, FIT_FLAGS);
    let settings = options.settings().map_err(fit_flags)?;
    let document = nanofold::commands::open_scene_document(&args.scene).map_err(|e| reading(&args.scene, e))?;
    let measured = nanofold::commands::open_measurement(&args.measured).map_err(|e| reading(&args.measured, e))?;
    let report = nanofold::commands::fit(&document, &measured, &settings).map_err(fit_flags)?;
    let files = nanofold::commands::fit_files(&report)?;
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| default_output_folder(&format!("{}-fit", document.fallback_name), &args.scene));
    write_outputs(&dir, &args.measured, &files)?;
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
        return Ok(());
    }
    println!(
        "{} fitted to {}: {:?} after {} iterations ({} simulations, {} with sensitivities, {:.2} s); {} observations, {} degrees of freedom, reduced χ² {:.3}",
        args.scene.display(),
        args.measured.display(),
        report.status,
        report.iterations,
        report.simulations,
        report.sensitivity_runs,
        report.seconds,
        report.observations,
        report.degrees_of_freedom,
        report.reduced_chi_square
    );
    for p in &report.parameters {
        match (p.standard_error, p.interval_95) {
            (Some(se), Some([lo, hi])) => println!(
                "  {}: {:.6e} ± {:.2e} (95 %: {:.6e} to {:.6e}; scene {}){}",
                p.path,
                p.estimate,
                se,
                lo,
                hi,
                p.start,
                if p.at_bound { ", at a bound" } else { "" }
            ),
            _ => println!(
                "  {}: {:.6e}, not determined by the data (scene {})",
                p.path, p.estimate, p.start
            ),
        }
    }
    for c in &report.undetermined {
        println!(
            "  undetermined: {} (singular value {:.2e}, relative error {:.1e})",
            c.description, c.singular_value, c.relative_standard_error
        );
    }
    for r in &report.residuals {
        let pattern = match (r.periodicity_z, r.runs_z) {
            (Some(periodic), Some(runs)) => format!(", periodicity z {periodic:.1}, runs z {runs:.1}"),
            _ => String::new(),
        };
        println!(
            "  {}: {} samples, rms {:.3e}, max {:.3e}, σ {:.3e} ({}){pattern}{}",
            r.name,
            r.observations,
            r.rms,
            r.max_abs,
            r.noise,
            r.noise_source,
            if r.systematic {
                " — not noise: the model does not describe it"
            } else {
                ""
            }
        );
    }
    for warning in &report.warnings {
        println!("  warning: {warning}");
    }
    print_written(&dir, &files);
    Ok(())
}

fn run_simulate_with(args: &SimulateArgs, progress: ProgressObserver) -> Result<()> {
    let options = nanofold::commands::SimulateOptions {
        model: match args.model {
            ModelArg::Auto => ModelChoice::Auto,
            ModelArg::Dynamic => ModelChoice::Dynamic,
            ModelArg::QuasiStatic => ModelChoice::QuasiStatic,
        },
        method: match args.method {
            MethodArg::Auto => Method::Auto,
            MethodArg::Bdf => Method::Bdf,
            MethodArg::Esdirk34 => Method::Esdirk34,
            MethodArg::TrBdf2 => Method::TrBdf2,
            MethodArg::Tsit45 => Method::Tsit45,
        },
        rtol: args.rtol,
        ignore_collisions: args.ignore_collisions,
        t_end: args.t_end,
        max_steps: args.max_steps,
    };
    let settings = SimulationSettings {
        progress: Some(progress),
        ..options.settings().map_err(simulate_flags)?
    };
    let scene = load_scene(&args.scene)?;
    let report = nanofold::commands::simulate(&scene, &settings).map_err(simulate_flags)?;
    let (simulation, response) = (&report.simulation, &report.simulation.response);
    // Render everything before writing anything.
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| default_output_folder(&scene.name, &args.scene));
    let files = nanofold::commands::simulation_files(&scene, &report)?;
    write_outputs(&dir, &args.scene, &files)?;
    if args.json {
        println!("{}", report.to_json());
        return Ok(());
    }
    let scales = &response.time_scales;
    match &scene.system {
        System::Strip(chain) => println!(
            "{}: {} hinge(s), {} actuation",
            scene.name,
            chain.model.dof(),
            chain.forcing.kind()
        ),
        System::Closed(chain) => {
            let closed = simulation
                .closed
                .as_ref()
                .expect("closed-chain runs report their chain");
            println!(
                "{}: closed chain, {} driven, {} cut, face {} anchored, f = {}{} (fit error {:.2e} rad, slope error {:.2e})",
                scene.name,
                chain.crease_labels[chain.driver],
                chain.crease_labels[chain.cut_crease],
                closed.anchored_face,
                closed.constraint_source,
                closed.degree.map_or(String::new(), |d| format!(" degree {d}")),
                closed.fit_error,
                closed.slope_error
            );
        }
        System::Network(model) => {
            let report = simulation.network.as_ref().expect("network runs report their network");
            println!(
                "{}: {} panels on {} creases, face {} anchored, {} actuation",
                scene.name,
                report.panels,
                report.creases,
                report.anchored_face,
                model.forcing.kind()
            );
            if let Some(branch) = &report.branch {
                println!("  {branch}");
            }
        }
    }
    println!(
        "  time scales: fastest natural period {:.3e} s, slowest {:.3e} s, forcing {:.3e} s (ratio {:.2e})",
        scales.fastest_period_s, scales.slowest_period_s, scales.forcing_time_s, scales.ratio
    );
    print_model(response);
    print_contact(response);
    if let Some(last) = response.samples.last() {
        let degrees: Vec<String> = last.angles.iter().map(|a| format!("{:.3}°", a.to_degrees())).collect();
        println!("  angles at t = {:.6e} s: {}", last.time, degrees.join(", "));
    }
    print_released(&scene, simulation);
    if let Some(report) = &simulation.network {
        if report.meeting_at_contact.len() > 1 {
            let pairs: Vec<String> = report
                .meeting_at_contact
                .iter()
                .map(|[a, b]| format!("{a} | {b}"))
                .collect();
            println!("  meeting at that moment (to 1e-6): {}", pairs.join("; "));
        }
        println!(
            "  max vertex closure residual along the run: {:.3e} rad; energy balance (kinetic + hinges − work + dissipation) held to {}",
            report.max_closure_residual,
            report
                .energy_balance_error
                .map_or("— (quasi-static: no work tracked)".to_string(), |e| format!("{e:.2e} of the largest energy"))
        );
        if let Some(reduced) = &report.reduced {
            println!(
                "  on fitted curves of edge {} over [{:.3}°, {:.3}°], degree {}: fit error {:.2e} rad, the curves close their loops to {:.2e} rad; reduced balance {:.4}°, {:.6e} Hz",
                reduced.driver_edge,
                reduced.domain_deg[0],
                reduced.domain_deg[1],
                reduced.degree,
                reduced.max_fit_error_rad,
                reduced.curves_closure_residual_rad,
                reduced.balance_driver_rad.to_degrees(),
                reduced.balance_frequency_hz
            );
        }
    }
    if let Some(closed) = &simulation.closed {
        println!(
            "  torque magnification η = {:.4}: the driving hinge ({:.1} µm wide) would need {:.1} µm to hold the target (T5.24-5.25)",
            closed.torque_magnification, closed.driving_hinge_width_um, closed.required_hinge_width_um
        );
        println!(
            "  max loop-closure residual along the run: {:.3e} rad",
            closed.max_closure_residual
        );
    }
    print_written(&dir, &files);
    Ok(())
}

/// Library settings and the flags that set them, per command.
const UNFOLD_FLAGS: &[(&str, &str)] = &[
    ("p", "--p"),
    ("flat_tol", "--flat-tol"),
    ("bending_metric", "--bending-metric"),
    ("max_iterations", "--max-iterations"),
    ("restarts", "--restarts"),
    ("closure_tol", "--closure-tol"),
];
const CONSTRAINT_FLAGS: &[(&str, &str)] = &[
    ("drive", "--drive"),
    ("lock", "--lock"),
    ("range", "--range"),
    ("samples", "--samples"),
    ("degree", "--degree"),
    ("tolerance", "--tol"),
    ("source", "--source"),
    ("free", "--free"),
    ("check", "--check"),
    ("tol", "--tol"),
    ("closure_tol", "--closure-tol"),
];
const SIMULATE_FLAGS: &[(&str, &str)] = &[("rtol", "--rtol"), ("t_end", "--t-end"), ("max_steps", "--max-steps")];

/// Library errors name library fields: an invalid field that a flag sets gets the flag and
/// its value in front ("invalid --p -1: invalid `p`: …"); a run that a flag can rescue gets
/// the flags to try.
fn with_flags(error: nanofold::prelude::NanofoldError, flags: &[(&str, &str)]) -> anyhow::Error {
    use nanofold::prelude::NanofoldError;
    use nanofold::prelude::NumericalError;
    let context = match &error {
        // A field or a part of it: `free[1].bounds` is set by --free, `noise.default` by --noise.
        NanofoldError::InvalidField { field, value, .. } => flags
            .iter()
            .find(|(name, _)| {
                field
                    .strip_prefix(name)
                    .is_some_and(|rest| rest.is_empty() || rest.starts_with(['[', '.']))
            })
            .map(|(_, flag)| format!("invalid {flag} {value}")),
        NanofoldError::Unreachable { .. } if flags.iter().any(|(name, _)| *name == "range") => {
            Some("sweeping --drive over --range with every --lock held".to_string())
        }
        NanofoldError::Numerical(
            NumericalError::StepBudget { .. } | NumericalError::NewtonFailures { .. } | NumericalError::Strayed { .. },
        ) => Some("simulate (flags that help: --method, --model, --rtol, --max-steps)".to_string()),
        _ => None,
    };
    match context {
        Some(context) => anyhow::Error::new(error).context(context),
        None => anyhow::Error::new(error),
    }
}

fn constraints_flags(error: nanofold::prelude::NanofoldError) -> anyhow::Error {
    with_flags(error, CONSTRAINT_FLAGS)
}

fn simulate_flags(error: nanofold::prelude::NanofoldError) -> anyhow::Error {
    with_flags(error, SIMULATE_FLAGS)
}

fn run_export(format: &ExportKind) -> Result<()> {
    let ExportKind::Mujoco {
        scene,
        out,
        timestep,
        closure,
    } = format;
    let built = load_scene(scene)?;
    let settings = nanofold::commands::MujocoSettings {
        timestep: *timestep,
        closure: match closure {
            ClosureArg::Connect => nanofold::commands::LoopClosure::Connect,
            ClosureArg::Poly => nanofold::commands::LoopClosure::Polycoef,
        },
    };
    let export = nanofold::commands::export_mujoco(&built, &settings)
        .map_err(|e| with_flags(e, &[("timestep", "--timestep")]))?;
    let (text, fastest_period_s) = (export.mjcf, export.fastest_period_s);
    let out = out.clone().unwrap_or_else(|| {
        PathBuf::from("output")
            .join(&built.name)
            .join(format!("{}.xml", built.name))
    });
    if out.extension().and_then(|e| e.to_str()) != Some("xml") {
        anyhow::bail!("--out {}: the file name must end in .xml", out.display());
    }
    nanofold::commands::outputs::write_atomic(&out, text.as_bytes())
        .with_context(|| format!("writing {}", out.display()))?;
    println!(
        "{}: wrote {} (MJCF, units µm, pg, µs; RK4 step {:e} s, a {:.0}th of the fastest period {:.3e} s)",
        built.name,
        out.display(),
        timestep,
        fastest_period_s / timestep,
        fastest_period_s
    );
    Ok(())
}

fn run_modes(path: &Path, json: bool, out: Option<&Path>) -> Result<()> {
    let scene = load_scene(path)?;
    let dir = out
        .map(Path::to_path_buf)
        .unwrap_or_else(|| default_output_folder(&scene.name, path));
    let report = nanofold::commands::modes(&scene)?;
    let files = nanofold::commands::modes_files(&scene, &report)?;
    write_outputs(&dir, path, &files)?;
    if json {
        let mut value = report.to_json();
        value["out"] = serde_json::json!(dir.display().to_string());
        println!("{value}");
        return Ok(());
    }
    let result = match &report.detail {
        ModesDetail::Closed(..) => {
            print_modes_closed(&scene, &report);
            print_written(&dir, &files);
            return Ok(());
        }
        ModesDetail::Network(..) => {
            print_modes_network(&scene, &report);
            print_written(&dir, &files);
            return Ok(());
        }
        ModesDetail::Strip(result) => result,
    };
    let degrees: Vec<String> = result
        .equilibrium
        .iter()
        .map(|a| format!("{:.3}°", a.to_degrees()))
        .collect();
    println!(
        "{}: modes at the folded equilibrium θ* = ({})",
        scene.name,
        degrees.join(", ")
    );
    println!(
        "  {:>4} {:>14} {:>14}  mode shape (unit max-norm)",
        "mode", "λ (rad²/s²)", "f (Hz)"
    );
    for k in 0..result.eigenvalues.len() {
        let shape: Vec<String> = result
            .mode_shapes
            .column(k)
            .iter()
            .map(|v| format!("{v:+.4}"))
            .collect();
        println!(
            "  {:>4} {:>14.6e} {:>14.3} ({})",
            k,
            result.eigenvalues[k],
            result.frequencies_hz[k],
            shape.join(", ")
        );
    }
    println!(
        "  {}",
        if result.stable {
            "stable: K is positive definite, every eigenvalue > 0"
        } else {
            "NOT stable: some hinge stiffness or eigenvalue is not positive"
        }
    );
    print_written(&dir, &files);
    Ok(())
}

fn print_modes_network(scene: &Scene, report: &nanofold::commands::ModesReport) {
    let (System::Network(model), ModesDetail::Network(result)) = (&scene.system, &report.detail) else {
        unreachable!("a network's modes")
    };
    let name = &scene.name;
    let modes = &result.modes;
    let eq = &modes.equilibrium;
    println!(
        "{}: modes of the network ({} panels, {} creases, face {} anchored) at its folded equilibrium: {} degree(s) of freedom",
        name,
        model.panels(),
        model.columns(),
        model.anchored_face,
        modes.basis.ncols()
    );
    if !result.released.is_empty() {
        let list: Vec<String> = result
            .released
            .iter()
            .map(|&(c, a)| format!("{} at {:.3}°", model.labels[c], a.to_degrees()))
            .collect();
        println!("  locks released (springs at rest there): {}", list.join(", "));
    }
    println!(
        "  equilibrium: {} Newton steps at the full drive, residual torque {:.1e} N·m, closure {:.1e} rad",
        eq.iterations, eq.residual_torque, eq.closure_residual
    );
    let shown = model.columns().min(12);
    println!(
        "  {:>4} {:>14} {:>12} {:>16}  shape (unit max-norm; the {} creases that move most)",
        "mode", "λ (rad²/s²)", "f (Hz)", "f, ZᵀKZ only", shown
    );
    for k in 0..modes.modes.eigenvalues.len() {
        let column = modes.crease_shapes.column(k);
        let mut order: Vec<usize> = (0..model.columns()).collect();
        order.sort_by(|&a, &b| column[b].abs().total_cmp(&column[a].abs()));
        let shape: Vec<String> = order[..shown]
            .iter()
            .map(|&c| format!("{} {:+.4}", model.labels[c], column[c]))
            .collect();
        println!(
            "  {:>4} {:>14.6e} {:>12.3} {:>16.3}  ({})",
            k,
            modes.modes.eigenvalues[k],
            modes.modes.frequencies_hz[k],
            modes.frequencies_without_load_hz[k],
            shape.join(", ")
        );
    }
    println!(
        "  {}",
        if modes.modes.stable {
            "stable: the stiffness on the manifold is positive definite, every eigenvalue > 0"
        } else {
            "NOT stable: some eigenvalue of the stiffness on the manifold is not positive"
        }
    );
    if let Some(reduction) = &model.reduction {
        let r = &reduction.report;
        println!(
            "  the scene's fitted curves (edge {} driving, degree {}, fit error {:.2e} rad) give {:.6e} Hz at {:.6}°: {:.1e} of the exact mode",
            r.driver_edge,
            r.degree,
            r.max_fit_error_rad,
            r.balance_frequency_hz,
            r.balance_driver_rad.to_degrees(),
            modes.modes.frequencies_hz.first().map_or(f64::NAN, |f| (r.balance_frequency_hz - f).abs() / f)
        );
    }
}

use nanofold::commands::ModesDetail;

fn print_modes_closed(scene: &Scene, report: &nanofold::commands::ModesReport) {
    let (System::Closed(chain), ModesDetail::Closed(result, eta)) = (&scene.system, &report.detail) else {
        unreachable!("a closed chain's modes")
    };
    let (name, eta) = (&scene.name, *eta);
    let degrees = |angles: &[f64]| {
        angles
            .iter()
            .map(|a| format!("{:.3}°", a.to_degrees()))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let coordinates: Vec<String> = result
        .coordinates
        .iter()
        .map(|&c| format!("edges[{}]", chain.crease_user_indices[c]))
        .collect();
    println!(
        "{}: modes of the closed chain (cut at edges[{}], face {} anchored, f = {}), locks released: coordinates {}",
        name,
        chain.crease_user_indices[chain.cut_crease],
        chain.anchored_face,
        chain.source.name(),
        coordinates.join(", ")
    );
    println!("  folded pose  θ = ({})", degrees(&result.folded_pose));
    println!(
        "  equilibrium  θ* = ({})  [{} Newton steps, residual torque {:.1e} N·m, closure {:.1e} rad]",
        degrees(&result.equilibrium),
        result.newton_iterations,
        result.residual_torque,
        result.closure_residual
    );
    for &c in &result.folded_through {
        println!(
            "  warning: edges[{}] is past ±180° at the free equilibrium: the plates touch before it",
            chain.crease_user_indices[c]
        );
    }
    println!(
        "  {:>4} {:>14} {:>12} {:>16}  shape over every crease (unit max-norm in the coordinates)",
        "mode", "λ (rad²/s²)", "f (Hz)", "f, ΓᵀKΓ only"
    );
    for k in 0..result.modes.eigenvalues.len() {
        let shape: Vec<String> = result
            .crease_shapes
            .column(k)
            .iter()
            .map(|v| format!("{v:+.4}"))
            .collect();
        println!(
            "  {:>4} {:>14.6e} {:>12.3} {:>16.3}  ({})",
            k,
            result.modes.eigenvalues[k],
            result.modes.frequencies_hz[k],
            result.frequencies_without_load_hz[k],
            shape.join(", ")
        );
    }
    println!("  torque magnification η = {eta:.4}");
    println!(
        "  {}",
        if result.modes.stable {
            "stable: the reduced stiffness is positive definite, every eigenvalue > 0"
        } else {
            "NOT stable: some eigenvalue of the reduced stiffness is not positive"
        }
    );
}

/// Runs the parsed command; Ok(false) means "finished, but exit non-zero".
pub fn run(cli: Cli) -> Result<bool> {
    FORCE.store(cli.force, std::sync::atomic::Ordering::Relaxed);
    match cli.command {
        Command::Unfold {
            patterns,
            solver,
            out,
            json,
            parallel,
        } => run_unfold(&patterns, &solver, out, json, &parallel),
        Command::Check {
            patterns,
            solver,
            json,
            parallel,
        } => run_check(&patterns, &solver, json, &parallel),
        Command::Constraints(args) => run_constraints(&args).map(|_| true),
        Command::Fold(args) => folding::run_fold(&args).map(|_| true),
        Command::View(args) => folding::run_view(&args).map(|_| true),
        Command::Generate { kind } => folding::run_generate(&kind).map(|_| true),
        Command::Simulate(args) => run_simulate(&args).map(|_| true),
        Command::Fit(args) => run_fit(&args).map(|_| true),
        Command::Nets(args) => run_nets(&args).map(|_| true),
        Command::Modes { scene, json, out } => run_modes(&scene, json, out.as_deref()).map(|_| true),
        Command::Export { format } => run_export(&format).map(|_| true),
    }
}
