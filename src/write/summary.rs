//! The summaries `check`, `fold` and `unfold` print with `--json`, as types that derive
//! `Serialize`: each is built once from an engine's report and the pattern it answers, and
//! its serialisation is the JSON (`docs/guide/unfolding.md` names the keys).

use crate::folding::{
    closure_jacobian, jacobian_rank, panel_poses, vertex_positions, CheckReport, FoldPath, FoldingModel,
};
use crate::pattern::crease_pattern::FoldedFormFit;
use crate::pattern::VertexPattern;
use crate::unfold::network::NetworkUnfoldReport;
use crate::unfold::{UnfoldReport, Verdict};
use serde::{Serialize, Serializer};

/// A number for JSON, which has no infinity or NaN: those are written as the strings
/// "inf", "-inf" and "nan" (serde_json would write `null`, the mark of an absent value).
pub fn number<S: Serializer>(x: &f64, serializer: S) -> Result<S::Ok, S::Error> {
    if x.is_finite() {
        serializer.serialize_f64(*x)
    } else if x.is_nan() {
        serializer.serialize_str("nan")
    } else if *x > 0.0 {
        serializer.serialize_str("inf")
    } else {
        serializer.serialize_str("-inf")
    }
}

/// [`number`] of a value that may be absent (absent: `null`).
pub fn optional_number<S: Serializer>(x: &Option<f64>, serializer: S) -> Result<S::Ok, S::Error> {
    match x {
        Some(x) => number(x, serializer),
        None => serializer.serialize_none(),
    }
}

/// The summary of one answer, whichever command and engine gave it.
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum Summary {
    /// A single vertex's unfolding (its `check` and `unfold`).
    VertexUnfold(Box<VertexUnfoldSummary>),
    /// A crease pattern's unfolding.
    NetworkUnfold(Box<NetworkUnfoldSummary>),
    /// A crease pattern's check.
    Check(Box<CheckSummary>),
    /// A fold.
    Fold(Box<FoldSummary>),
}

/// How far `--project` moved a state to make it rigid.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProjectionFigures {
    /// Largest change of a fold angle, rad.
    pub max_change_rad: f64,
    /// RMS change of the fold angles, rad.
    pub rms_change_rad: f64,
    /// Worst vertex closure before, rad.
    pub residual_before_rad: f64,
    /// Newton iterations taken.
    pub newton_iterations: usize,
    /// What was moved: `fold_angles` (least-norm Newton, damped least squares where Newton
    /// stalls near a branch point) or `vertex_positions` (a folded form's vertices, onto
    /// planar faces, flat facets and developable vertices).
    pub moved: &'static str,
    /// Largest distance a folded form's vertex moved, in the file's length unit (None: the
    /// fold angles were moved).
    pub max_vertex_move: Option<f64>,
    /// How far a folded form's facets were from rigid (None: the file gave fold angles).
    pub folded_form: Option<FoldedFormBend>,
}

/// A folded form's facets, bent, as read.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FoldedFormBend {
    /// Largest angle across a facet (F) edge, rad.
    pub max_facet_angle_rad: f64,
    /// Mismatch of the faces' development.
    pub development_error: f64,
    /// Largest out-of-plane distance of a face's corners.
    pub face_nonplanarity: f64,
}

impl From<&FoldedFormFit> for FoldedFormBend {
    fn from(fit: &FoldedFormFit) -> FoldedFormBend {
        FoldedFormBend {
            max_facet_angle_rad: fit.max_facet_angle,
            development_error: fit.development_error,
            face_nonplanarity: fit.face_nonplanarity,
        }
    }
}

/// `unfold --json` (and `check --json`) of a single vertex.
#[derive(Debug, Clone, Serialize)]
pub struct VertexUnfoldSummary {
    /// The pattern's name.
    pub pattern: String,
    /// The input's path (or the name, for a pattern built in code).
    pub file: String,
    /// The answer.
    pub verdict: Verdict,
    /// Why.
    pub evidence: String,
    /// Descent steps.
    pub iterations: usize,
    /// Wall time, s.
    pub seconds: f64,
    /// Energy at the start.
    pub energy_initial: f64,
    /// Energy at the end.
    pub energy_final: f64,
    /// Fold angles at the start, rad.
    pub initial_fold_angles_rad: Vec<f64>,
    /// Fold angles at the end, rad.
    pub final_fold_angles_rad: Vec<f64>,
    /// The creases' labels, in the order of the angles.
    pub crease_labels: Vec<String>,
    /// Largest arc-length residual over the run, rad.
    pub max_arc_residual: f64,
    /// Largest distance of a ray from the plane at the end.
    pub planarity_residual: f64,
    /// Distance of the end from the flat layout.
    pub flat_layout_error: f64,
    /// Restarts from perturbed states.
    pub restarts_used: usize,
    /// Steps refused for carrying a node through an arc.
    pub crossings_refused: usize,
    /// How the input was read or moved.
    pub adjustments: Vec<String>,
}

impl VertexUnfoldSummary {
    /// The summary of `report` on `pattern`, read from `file`.
    pub fn new(pattern: &VertexPattern, file: &str, report: &UnfoldReport) -> VertexUnfoldSummary {
        VertexUnfoldSummary {
            pattern: pattern.name.clone(),
            file: file.to_string(),
            verdict: report.verdict,
            evidence: report.evidence.clone(),
            iterations: report.iterations,
            seconds: report.seconds,
            energy_initial: report.energy_initial,
            energy_final: report.energy_final,
            initial_fold_angles_rad: report.initial_fold_angles_rad.clone(),
            final_fold_angles_rad: report.final_fold_angles_rad.clone(),
            crease_labels: pattern.creases.iter().map(|c| c.label.clone()).collect(),
            max_arc_residual: report.max_arc_residual,
            planarity_residual: report.planarity_residual,
            flat_layout_error: report.flat_layout_error,
            restarts_used: report.restarts_used,
            crossings_refused: report.crossings_refused,
            adjustments: report.adjustments.clone(),
        }
    }
}

/// `unfold --json` of a crease pattern of many vertices: the single vertex's keys where
/// they apply, with the end's distance from the flat crease pattern (`flat_layout_error`)
/// and from the plane.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, Serialize)]
pub struct NetworkUnfoldSummary {
    /// The pattern's name.
    pub pattern: String,
    /// The input's path.
    pub file: String,
    /// The answer.
    pub verdict: Verdict,
    /// Why.
    pub evidence: String,
    /// Descent steps.
    pub iterations: usize,
    /// Wall time, s.
    pub seconds: f64,
    /// Energy at the start (None: a start that is not rigid is no state on the closures).
    #[serde(serialize_with = "optional_number")]
    pub energy_initial: Option<f64>,
    /// Energy at the end (None as at the start).
    #[serde(serialize_with = "optional_number")]
    pub energy_final: Option<f64>,
    /// Fold angles at the start, rad.
    pub initial_fold_angles_rad: Vec<f64>,
    /// Fold angles at the end, rad.
    pub final_fold_angles_rad: Vec<f64>,
    /// The creases' labels (`edges[e]`).
    pub crease_labels: Vec<String>,
    /// The single vertex's arc residual: none here.
    pub max_arc_residual: Option<f64>,
    /// Largest distance of a vertex from the plane at the end.
    pub planarity_residual: f64,
    /// Largest distance of a vertex from its place in the flat crease pattern.
    pub flat_layout_error: f64,
    /// Restarts from perturbed states.
    pub restarts_used: usize,
    /// Steps refused for putting panels through each other.
    pub crossings_refused: usize,
    /// Steps taken along the ray to flat.
    pub radial_steps: usize,
    /// How the input was read or moved.
    pub adjustments: Vec<String>,
    /// `--project`'s figures (None: not projected).
    pub projection: Option<ProjectionFigures>,
    /// Worst vertex closure over the path, rad.
    pub max_closure_residual_rad: f64,
}

impl NetworkUnfoldSummary {
    /// The summary of `report` on `model` from `start`, read from `file`; `adjustments`:
    /// how the input was read or moved.
    pub fn new(
        model: &FoldingModel,
        file: &str,
        report: &NetworkUnfoldReport,
        start: &[f64],
        seconds: f64,
        adjustments: Vec<String>,
        projection: Option<ProjectionFigures>,
    ) -> NetworkUnfoldSummary {
        let last = report.steps.last().expect("the start is recorded");
        let mut poses = Vec::new();
        panel_poses(model, &last.fold_angles, &mut poses);
        let placed = vertex_positions(model, &poses);
        let flat_layout_error = placed
            .iter()
            .zip(&model.pattern.vertices)
            .map(|(p, q)| ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + p[2] * p[2]).sqrt())
            .fold(0.0, f64::max);
        let planarity_residual = placed.iter().map(|p| p[2].abs()).fold(0.0, f64::max);
        let energy = |u: f64| (report.verdict != Verdict::NotRigid).then_some(u);
        NetworkUnfoldSummary {
            pattern: model.pattern.name.clone(),
            file: file.to_string(),
            verdict: report.verdict,
            evidence: report.evidence.clone(),
            iterations: report.iterations,
            seconds,
            energy_initial: energy(report.steps[0].energy),
            energy_final: energy(last.energy),
            initial_fold_angles_rad: start.to_vec(),
            final_fold_angles_rad: last.fold_angles.clone(),
            crease_labels: crease_labels(model),
            max_arc_residual: None,
            planarity_residual,
            flat_layout_error,
            restarts_used: report.restarts_used,
            crossings_refused: report.crossings_refused,
            radial_steps: report.radial_steps,
            adjustments,
            projection,
            max_closure_residual_rad: report.max_closure_residual,
        }
    }
}

/// A crease pattern's crease labels, `edges[e]` in column order.
pub fn crease_labels(model: &FoldingModel) -> Vec<String> {
    model.pattern.creases.iter().map(|e| format!("edges[{e}]")).collect()
}

/// `check --json` of a crease pattern of many vertices.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, Serialize)]
pub struct CheckSummary {
    /// The pattern's name.
    pub pattern: String,
    /// The input's path.
    pub file: String,
    /// The answer.
    pub verdict: crate::folding::PatternVerdict,
    /// Why.
    pub evidence: String,
    /// "given" or "flat (assignment only)".
    pub state: &'static str,
    /// Degrees of freedom at the state judged.
    pub dof: usize,
    /// Rank of the closure Jacobian there.
    pub rank: usize,
    /// The threshold the rank was read with.
    pub rank_threshold: f64,
    /// Creases.
    pub creases: usize,
    /// Interior vertices.
    pub vertices: usize,
    /// Panels.
    pub panels: usize,
    /// Worst vertex closure, rad.
    pub max_vertex_residual_rad: f64,
    /// The vertices that close worst.
    pub worst_vertices: Vec<VertexResidual>,
    /// Pairs of panels that pass through each other.
    pub intersecting_pairs: Vec<[usize; 2]>,
    /// Pairs of panels in contact.
    pub contacts: usize,
    /// Smallest clearance between panels (None: none within the search range).
    #[serde(serialize_with = "optional_number")]
    pub min_panel_clearance: Option<f64>,
    /// Mismatch between the spanning tree's placement and the closures.
    pub tree_mismatch: f64,
    /// The witness path of a foldable assignment (or the try that failed).
    pub witness: Option<WitnessSummary>,
    /// What was tried, in words.
    pub tried: Vec<String>,
    /// The flat state's Kawasaki and Maekawa figures.
    pub flat_foldability: FlatFoldabilitySummary,
    /// How a folded form was read (None: the file gave fold angles).
    pub folded_form: Option<FoldedFormSummary>,
    /// How the file was read.
    pub reading: Vec<String>,
    /// The file's angles read as targets, per crease (None: the file gave a state or none).
    pub target_angles_rad: Option<Vec<f64>>,
    /// Wall time, s.
    pub seconds: f64,
    /// A rigid folded state's unfolding by energy (absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unfold: Option<UnfoldBrief>,
    /// `--project`'s figures (absent: not projected).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub projection: Option<ProjectionFigures>,
}

/// One vertex's closure residual.
#[derive(Debug, Clone, Serialize)]
pub struct VertexResidual {
    /// The vertex.
    pub vertex: usize,
    /// Its closure residual, rad.
    #[serde(serialize_with = "number")]
    pub residual_rad: f64,
}

/// A witness path, in brief.
#[derive(Debug, Clone, Serialize)]
pub struct WitnessSummary {
    /// Why it stopped.
    pub stop_reason: &'static str,
    /// Why, in words.
    pub evidence: String,
    /// States on the path.
    pub steps: usize,
    /// Progress at its end.
    pub progress: f64,
    /// Worst vertex closure along it, rad.
    pub max_closure_residual_rad: f64,
}

/// The flat state's Kawasaki and Maekawa figures.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, Serialize)]
pub struct FlatFoldabilitySummary {
    /// The vertex furthest from Kawasaki's theorem.
    pub worst_kawasaki: Option<VertexResidual>,
    /// Vertices of odd degree.
    pub odd_degree_vertices: Vec<usize>,
    /// Vertices whose mountains and valleys break Maekawa's theorem.
    pub maekawa_failures: Vec<usize>,
}

/// How a folded form was read into fold angles.
#[derive(Debug, Clone, Serialize)]
pub struct FoldedFormSummary {
    /// Mismatch of the faces' development.
    pub development_error: f64,
    /// Largest out-of-plane distance of a face's corners.
    pub face_nonplanarity: f64,
    /// Largest angle across a facet edge, rad.
    pub max_facet_angle_rad: f64,
    /// Whether the form was read mirrored.
    pub mirrored: bool,
    /// Creases whose folded sign contradicts their assignment.
    pub assignment_conflicts: usize,
    /// Creases folded flat.
    pub folded_flat_creases: usize,
}

/// An unfolding, in brief.
#[derive(Debug, Clone, Serialize)]
pub struct UnfoldBrief {
    /// Its answer.
    pub verdict: Verdict,
    /// Why.
    pub evidence: String,
    /// Descent steps.
    pub iterations: usize,
    /// Worst vertex closure over it, rad.
    pub max_closure_residual_rad: f64,
}

impl CheckSummary {
    /// The summary of `report` on `model`, read from `file` (`unfolding`: the unfolding by
    /// energy a rigid folded state also gets).
    pub fn new(
        model: &FoldingModel,
        file: &str,
        report: &CheckReport,
        unfolding: Option<&NetworkUnfoldReport>,
        seconds: f64,
        projection: Option<ProjectionFigures>,
    ) -> CheckSummary {
        let residual = |&(vertex, residual_rad): &(usize, f64)| VertexResidual { vertex, residual_rad };
        let flat = &report.flat_foldability;
        CheckSummary {
            pattern: model.pattern.name.clone(),
            file: file.to_string(),
            verdict: report.verdict,
            evidence: report.evidence.clone(),
            state: if report.has_state {
                "given"
            } else {
                "flat (assignment only)"
            },
            dof: report.rank.dof,
            rank: report.rank.rank,
            rank_threshold: report.rank.threshold,
            creases: model.crease_count(),
            vertices: model.stars.len(),
            panels: model.pattern.panel_count,
            max_vertex_residual_rad: report.max_vertex_residual_rad,
            worst_vertices: report.worst_vertices.iter().map(residual).collect(),
            intersecting_pairs: report.intersecting_pairs.clone(),
            contacts: report.contacts,
            min_panel_clearance: report.min_panel_clearance,
            tree_mismatch: report.tree_mismatch,
            witness: report.witness.as_ref().map(|w| WitnessSummary {
                stop_reason: crate::names::variant_name(&w.stop),
                evidence: w.evidence.clone(),
                steps: w.steps.len(),
                progress: w.steps.last().map_or(0.0, |s| s.progress),
                max_closure_residual_rad: w.max_closure_residual,
            }),
            tried: report.tried.clone(),
            flat_foldability: FlatFoldabilitySummary {
                worst_kawasaki: flat.worst_kawasaki.as_ref().map(residual),
                odd_degree_vertices: flat.odd_degree.clone(),
                maekawa_failures: flat.maekawa_failures.clone(),
            },
            folded_form: report.folded_form.map(|f| FoldedFormSummary {
                development_error: f.development_error,
                face_nonplanarity: f.face_nonplanarity,
                max_facet_angle_rad: f.max_facet_angle,
                mirrored: f.mirrored,
                assignment_conflicts: f.assignment_conflicts,
                folded_flat_creases: f.folded_flat,
            }),
            reading: model.pattern.reading.clone(),
            target_angles_rad: target_angles(model),
            seconds,
            unfold: unfolding.map(|u| UnfoldBrief {
                verdict: u.verdict,
                evidence: u.evidence.clone(),
                iterations: u.iterations,
                max_closure_residual_rad: u.max_closure_residual,
            }),
            projection,
        }
    }
}

/// The file's angles read as targets, per crease (None: the file gave a state or none).
fn target_angles(model: &FoldingModel) -> Option<Vec<f64>> {
    let targets = model.pattern.target_angles.as_ref()?;
    Some(model.pattern.creases.iter().map(|&e| targets[e]).collect())
}

/// `fold --json` (`frames` and `out` are the command line's own keys).
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, Serialize)]
pub struct FoldSummary {
    /// The pattern's name.
    pub pattern: String,
    /// The input's path.
    pub file: String,
    /// Why the path stopped.
    pub stop_reason: &'static str,
    /// Why, in words.
    pub evidence: String,
    /// The branch followed, in words.
    pub branch: Option<String>,
    /// States on the path.
    pub steps: usize,
    /// Degrees of freedom at the end.
    pub dof: usize,
    /// Creases.
    pub creases: usize,
    /// Interior vertices.
    pub vertices: usize,
    /// Panels.
    pub panels: usize,
    /// Progress at the end.
    pub progress: f64,
    /// Worst vertex closure along the path, rad.
    pub max_closure_residual_rad: f64,
    /// Smallest clearance between panels (None: none within the search range).
    #[serde(serialize_with = "optional_number")]
    pub min_panel_clearance: Option<f64>,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// Factorisations of the closure Jacobian.
    pub factorisations: usize,
    /// Contact tests (one per trial state closed).
    pub contact_tests: usize,
    /// How the file was read.
    pub reading: Vec<String>,
    /// The file's angles read as targets, per crease.
    pub target_angles_rad: Option<Vec<f64>>,
    /// Wall time, s.
    pub seconds: f64,
}

impl FoldSummary {
    /// The summary of `path` on `model`, read from `file`; the degrees of freedom at its end
    /// are counted here.
    pub fn new(model: &FoldingModel, file: &str, path: &FoldPath, seconds: f64) -> FoldSummary {
        let last = path.steps.last().expect("a path has its start");
        let dof = jacobian_rank(&closure_jacobian(model, &last.fold_angles)).map_or(0, |r| r.dof);
        FoldSummary {
            pattern: model.pattern.name.clone(),
            file: file.to_string(),
            stop_reason: crate::names::variant_name(&path.stop),
            evidence: path.evidence.clone(),
            branch: path.branch.clone(),
            steps: path.steps.len(),
            dof,
            creases: model.crease_count(),
            vertices: model.stars.len(),
            panels: model.pattern.panel_count,
            progress: last.progress,
            max_closure_residual_rad: path.max_closure_residual,
            min_panel_clearance: path.min_panel_clearance,
            newton_iterations: path.newton_iterations,
            factorisations: path.factorisations,
            contact_tests: path.contact_tests,
            reading: model.pattern.reading.clone(),
            target_angles_rad: target_angles(model),
            seconds,
        }
    }
}

/// `simulate --json`, and the head of `response.json`: the model chosen and why, the
/// first contact, the end; a closed chain's or a network's own figures beside them (angles
/// are every crease's, in FOLD edge order).
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, Serialize)]
pub struct ResponseSummary {
    /// The scene's name.
    pub scene: String,
    /// The equations solved.
    pub model: crate::dynamics::simulate::ModelKind,
    /// The integrator (None: quasi-static).
    pub method: Option<crate::dynamics::integrate::Method>,
    /// Relative tolerance.
    pub rtol: f64,
    /// Forcing time over the slowest natural period.
    #[serde(serialize_with = "number")]
    pub time_scale_ratio: f64,
    /// The time scales the model was chosen from.
    pub time_scales: TimeScalesSummary,
    /// The quasi-static model's error bound, rad.
    #[serde(serialize_with = "number")]
    pub quasi_static_error_estimate_rad: f64,
    /// Its error measured against a dynamic window, rad.
    pub measured_quasi_static_error_rad: Option<f64>,
    /// That window, s.
    pub quasi_static_check_window_s: Option<f64>,
    /// Whether contacts were integrated through.
    pub ignore_collisions: bool,
    /// End of the run, s.
    pub t_end_s: f64,
    /// The first contact (None: none).
    pub collision: Option<CollisionSummary>,
    /// Angles at the end, rad.
    pub final_angles_rad: Vec<f64>,
    /// Every output angle's target, rad.
    pub target_angles_rad: Vec<f64>,
    /// Integrator steps.
    pub steps: usize,
    /// Right-hand-side evaluations.
    pub rhs_evaluations: usize,
    /// Wall time, s.
    pub seconds: f64,
    /// A closed chain's figures.
    #[serde(flatten)]
    pub closed: Option<ClosedRunSummary>,
    /// A network's figures.
    #[serde(flatten)]
    pub network: Option<NetworkRunSummary>,
    /// A tree of panels released slowly through its contacts: how it ended, its latches,
    /// contacts and forces, the frames at its events.
    pub released: Option<crate::dynamics::network::closing::ClosingReport>,
}

/// The time scales a run's model was chosen from, s.
#[derive(Debug, Clone, Serialize)]
pub struct TimeScalesSummary {
    /// Fastest natural period.
    #[serde(serialize_with = "number")]
    pub fastest_period_s: f64,
    /// Slowest natural period.
    #[serde(serialize_with = "number")]
    pub slowest_period_s: f64,
    /// Forcing time.
    #[serde(serialize_with = "number")]
    pub forcing_time_s: f64,
    /// Forcing time over the slowest period.
    #[serde(serialize_with = "number")]
    pub ratio: f64,
}

/// A first contact.
#[derive(Debug, Clone, Serialize)]
pub struct CollisionSummary {
    /// When, s.
    pub time_s: f64,
    /// The two bodies that meet.
    pub pair: [String; 2],
    /// Where, m.
    pub point: [f64; 3],
    /// Where, µm.
    pub point_um: [f64; 3],
}

/// A closed chain's figures of a run.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, Serialize)]
pub struct ClosedRunSummary {
    /// The cut crease (FOLD edge).
    pub cut_crease: usize,
    /// The face on the substrate.
    pub anchored_face: usize,
    /// The driving crease.
    pub driving_crease: usize,
    /// "poly" or "exact".
    pub constraint_source: &'static str,
    /// The fit's degree (poly only).
    pub constraint_degree: Option<usize>,
    /// The fit's largest error, rad.
    pub constraint_fit_error_rad: f64,
    /// The fit's largest slope error.
    pub constraint_slope_error: f64,
    /// Σ K ρ g over K θ_target at the target.
    #[serde(serialize_with = "number")]
    pub torque_magnification: f64,
    /// The driving hinge's width, µm.
    #[serde(serialize_with = "number")]
    pub driving_hinge_width_um: f64,
    /// The width the magnification asks for, µm.
    #[serde(serialize_with = "number")]
    pub required_hinge_width_um: f64,
    /// Worst loop closure over the run, rad.
    pub max_closure_residual: f64,
    /// Every crease's FOLD edge.
    pub crease_edges: Vec<usize>,
}

/// A network's figures of a run: the run's own report, and where its creases are.
#[derive(Debug, Clone, Serialize)]
pub struct NetworkRunSummary {
    /// What the run reported beside its response.
    #[serde(flatten)]
    pub run: crate::dynamics::network::NetworkRunReport,
    /// Every crease's FOLD edge.
    pub crease_edges: Vec<usize>,
    /// Each hinge's release time, s.
    pub release_times_s: Vec<f64>,
}

/// `modes --json`, whichever kind of scene.
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum ModesSummary {
    /// A strip's.
    Strip(Box<StripModesSummary>),
    /// A closed chain's.
    Closed(Box<ClosedModesSummary>),
    /// A network's.
    Network(Box<NetworkModesSummary>),
}

/// The modes themselves, as every kind of scene states them.
#[derive(Debug, Clone, Serialize)]
pub struct ModeSet {
    /// λ, rad²/s².
    pub eigenvalues: Vec<f64>,
    /// f, Hz.
    pub frequencies_hz: Vec<f64>,
    /// One shape per mode.
    pub mode_shapes: Vec<Vec<f64>>,
    /// Whether every λ > 0.
    pub stable: bool,
}

/// A strip's modes about its folded equilibrium.
#[derive(Debug, Clone, Serialize)]
pub struct StripModesSummary {
    /// The scene's name.
    pub scene: String,
    /// θ*, rad.
    pub equilibrium_rad: Vec<f64>,
    /// How θ* was found, in words.
    pub equilibrium: &'static str,
    /// The modes.
    #[serde(flatten)]
    pub modes: ModeSet,
    /// Each hinge's stiffness, N·m/rad.
    pub stiffness_n_m_per_rad: Vec<f64>,
}

/// A closed chain's modes: the strip's keys over the released coordinates, every crease's
/// angles and shapes, the reduced matrices and the closed chain's own keys (crease numbers
/// are FOLD edges).
#[derive(Debug, Clone, Serialize)]
pub struct ClosedModesSummary {
    /// The scene's name.
    pub scene: String,
    /// The cut crease.
    pub cut_crease: usize,
    /// The face on the substrate.
    pub anchored_face: usize,
    /// "poly" or "exact".
    pub constraint_source: &'static str,
    /// Σ K ρ g over K θ_target at the target.
    #[serde(serialize_with = "number")]
    pub torque_magnification: f64,
    /// Worst loop closure at the equilibrium, rad.
    pub max_closure_residual: f64,
    /// The released coordinates.
    pub coordinates: Vec<usize>,
    /// Every crease's FOLD edge.
    pub crease_edges: Vec<usize>,
    /// θ* over the coordinates, rad.
    pub equilibrium_rad: Vec<f64>,
    /// How θ* was found, in words.
    pub equilibrium: &'static str,
    /// θ* over every crease, rad.
    pub equilibrium_crease_angles_rad: Vec<f64>,
    /// The folded pose Newton started from, rad.
    pub folded_pose_rad: Vec<f64>,
    /// Every crease's rest angle, rad.
    pub rest_angles_rad: Vec<f64>,
    /// Residual torque at θ*, N·m.
    pub residual_torque_n_m: f64,
    /// Newton steps.
    pub newton_iterations: usize,
    /// Creases past ±180° at θ*.
    pub folded_through: Vec<usize>,
    /// The modes (shapes over the coordinates).
    #[serde(flatten)]
    pub modes: ModeSet,
    /// f without the load term, Hz.
    pub frequencies_without_load_hz: Vec<f64>,
    /// Shapes over every crease.
    pub crease_mode_shapes: Vec<Vec<f64>>,
    /// Each crease's stiffness, N·m/rad.
    pub stiffness_n_m_per_rad: Vec<f64>,
    /// Γᵀ M Γ, rows.
    pub reduced_mass_kg_m2: Vec<Vec<f64>>,
    /// Γᵀ K Γ plus the load term, rows.
    pub reduced_stiffness_n_m_per_rad: Vec<Vec<f64>>,
    /// The load term, rows.
    pub load_stiffness_n_m_per_rad: Vec<Vec<f64>>,
}

/// A network's modes: the equilibrium, the released locks, the frequencies (with and
/// without the constraints' load term) and the shapes over every crease.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, Serialize)]
pub struct NetworkModesSummary {
    /// The scene's name.
    pub scene: String,
    /// Panels.
    pub panels: usize,
    /// Creases.
    pub creases: usize,
    /// Every crease's FOLD edge.
    pub crease_edges: Vec<usize>,
    /// The face on the substrate.
    pub anchored_face: usize,
    /// Degrees of freedom at the equilibrium.
    pub degrees_of_freedom: usize,
    /// Locks released, with the angles they held.
    pub released_locks: Vec<ReleasedLock>,
    /// Every crease's rest angle, rad.
    pub rest_angles_rad: Vec<f64>,
    /// The equilibrium, rad.
    pub equilibrium_rad: Vec<f64>,
    /// Newton steps to it.
    pub equilibrium_newton_steps: usize,
    /// Residual torque there, N·m.
    pub residual_torque_n_m: f64,
    /// Worst closure there, rad.
    pub closure_residual_rad: f64,
    /// The modes (shapes over every crease).
    #[serde(flatten)]
    pub modes: ModeSet,
    /// f without the load term, Hz.
    pub frequencies_without_load_hz: Vec<f64>,
    /// The scene's fitted curves, when it has them.
    pub reduced: Option<crate::dynamics::network::ReducedReport>,
}

/// A lock released for the modes.
#[derive(Debug, Clone, Serialize)]
pub struct ReleasedLock {
    /// Its FOLD edge.
    pub edge: usize,
    /// The angle it held, rad.
    pub angle_rad: f64,
}
