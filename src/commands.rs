//! The library's front door: one [`Pattern`] (a single vertex is a pattern with one interior
//! vertex), one [`check`], [`fold`] and [`unfold`] that take any pattern, each with its own
//! verdict type ([`CheckVerdict`], [`FoldVerdict`], [`UnfoldVerdict`]), and one report shape
//! ([`Report`]) that serialises as the command's `--json`. Behind it the two engines
//! stay as they are: the single vertex's unfolding on the sphere
//! (`docs/model.md#unfolding`) and the many-vertex folding layer
//! (`docs/model.md#rigid-folding`); a pattern goes to the single-vertex engine whenever that
//! engine reads it, as the command line does.
//!
//! ```
//! use nanofold::prelude::*;
//! let options = LoadOptions::default();
//! let settings = Settings::default();
//! // A single vertex and a crease pattern of many, through the same calls.
//! let vertex = Pattern::open("patterns/miura_vertex.fold".as_ref(), &options)?;
//! let sheet = Pattern::open("patterns/many/miura_4x4_folded.fold".as_ref(), &options)?;
//! assert_eq!((vertex.engine(), sheet.engine()), (Engine::Vertex, Engine::Network));
//! for pattern in [&vertex, &sheet] {
//!     let report = unfold(pattern, &settings)?;
//!     assert_eq!(report.verdict, UnfoldVerdict::Flat);
//!     assert!(report.final_fold_angles_rad.iter().all(|a| a.abs() <= 1e-6));
//! }
//! // The flat Miura-ori's assignment folds rigidly; folding it reaches 100%.
//! let flat = Pattern::open("patterns/many/miura_4x4.fold".as_ref(), &options)?;
//! assert_eq!(check(&flat, &settings)?.verdict, PatternVerdict::RigidlyFoldable);
//! assert_eq!(fold(&flat, &settings)?.verdict, FoldVerdict::Reached);
//! # Ok::<(), NanofoldError>(())
//! ```

use crate::error::{NanofoldError, Result};
use crate::folding::PatternVerdict;
use crate::folding::{check_pattern, fold_path, CheckReport, CheckSettings, FoldPath, FoldSettings, FoldingModel};
use crate::names::{Answer, Named};
use crate::pattern::crease_pattern::{CreasePattern, CreasePatternBuilder, EdgeKind};
use crate::pattern::{Assignment, Chain, LoadOptions, RayRole};
use crate::unfold::network::{unfold_network, unfold_network_observed, NetworkUnfoldReport, NetworkUnfoldSettings};
use crate::unfold::{UnfoldProgress, UnfoldReport, UnfoldSettings};
use crate::write::summary::crease_labels;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

mod constraints;
mod fit;
mod generate;
pub mod nets;
pub mod options;
pub mod outputs;
mod scene;
#[cfg(feature = "plot")]
mod view;
mod witness;

pub use crate::constraints::network::NetworkCurves;
pub use crate::constraints::ConstraintReport;
pub use crate::write::folding_output::MAX_TRAJECTORY_ANGLES;
pub use crate::write::mujoco::{LoopClosure, MujocoSettings};
pub use crate::write::summary::{
    CheckSummary, FlatFoldabilitySummary, FoldSummary, FoldedFormBend, FoldedFormSummary, NetworkUnfoldSummary,
    ProjectionFigures, Summary, UnfoldBrief, VertexResidual, VertexUnfoldSummary, WitnessSummary,
};
#[cfg(feature = "plot")]
pub use constraints::constraints_files;
pub use constraints::{constraints, ConstraintSettings, Constraints, CurveSource, Degree};
#[cfg(feature = "plot")]
pub use fit::fit_files;
pub use fit::{
    fit, fit_table_csv, open_measurement, open_scene_document, parse_measurement, ColumnResiduals, Combination,
    FitOptions, FitReport, FitSettings, FitStatus, FitTable, FittedParameter, FreeOption, FreeParameter, Measurement,
    Noise, NoiseOption, Observed, SceneDocument,
};
pub use generate::{Generated, Generator};
pub use options::{
    options_from_json, AutoDegree, CheckOptions, ConstraintOptions, CurveFormat, DegreeOption, FoldOptions, FromJson,
    ReadOptions, SimulateOptions, UnfoldOptions,
};
pub use scene::{
    export_mujoco, modes, open_scene, parse_scene, scene_kind, simulate, ModesDetail, ModesReport, MujocoExport,
    SimulationReport, MODE_AMPLITUDE,
};
#[cfg(feature = "plot")]
pub use scene::{modes_files, simulation_files};
#[cfg(feature = "plot")]
pub use view::{view_page, MAX_VIEW_BYTES};

/// The single-vertex pattern type of the engine behind the door.
pub use crate::pattern::VertexPattern;

/// Which engine answers for a pattern.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Engine {
    /// The single vertex on the sphere.
    Vertex,
    /// The crease pattern of many vertices (panels, stars, closures).
    Network,
}

impl crate::names::Named for Engine {}

/// Any crease pattern nanofold reads, decided once from its input: a single vertex (the
/// single-vertex engine's, with its sheet when its sectors close one) or a crease pattern of
/// many vertices.
#[derive(Debug, Clone)]
pub enum Pattern {
    /// One interior or boundary vertex.
    Vertex {
        /// The vertex.
        vertex: Box<VertexPattern>,
        /// Its sheet of panels (None: sectors that close no flat sheet, a cone).
        sheet: Option<Box<FoldingModel>>,
        /// Where it came from.
        origin: Origin,
    },
    /// A crease pattern of many vertices (or of creases that meet at no vertex).
    Sheet {
        /// Its panels, stars and closures.
        model: Box<FoldingModel>,
        /// Where it came from.
        origin: Origin,
    },
}

/// Where a pattern came from, and what its reading left out.
#[derive(Debug, Clone, Default)]
pub struct Origin {
    /// The file it was read from (None: built in code).
    pub source: Option<String>,
    /// What was ignored of a FOLD animation's frames.
    pub frames_note: Option<String>,
    /// How far its state was moved to make it rigid (None: not moved).
    pub projection: Option<Projection>,
}

impl Pattern {
    /// Reads a FOLD file or a native vertex file: the single-vertex engine takes it when it
    /// reads it, the many-vertex reader otherwise (its errors are then the ones returned).
    pub fn open(path: &Path, options: &LoadOptions) -> Result<Pattern> {
        let text = crate::read::input::read_text(path, crate::read::input::MAX_PATTERN_BYTES)?;
        let origin = path.display().to_string();
        Ok(Pattern::parse(&text, &crate::read::pattern_name(path), &origin, options)?.with_source(origin))
    }

    /// Reads pattern text (FOLD or a native vertex) as [`Pattern::open`] reads a file;
    /// `name` names the pattern when the text has no title, `origin` names it in errors. The
    /// text is parsed once; both readers read the one value.
    pub fn parse(text: &str, name: &str, origin: &str, options: &LoadOptions) -> Result<Pattern> {
        let value = crate::read::input::parse_json(text, origin)?;
        let origin_of = || Origin {
            source: None,
            frames_note: crate::read::frames_note(&value),
            projection: None,
        };
        // A FOLD object is a crease pattern too; a native vertex is not.
        let as_sheet = || crate::read::crease_pattern_of_value(&value, name, origin);
        match crate::read::pattern_of_value(&value, name, origin, options) {
            Ok(vertex) => {
                let sheet = match crate::read::is_fold_object(&value) {
                    true => as_sheet().ok().and_then(|p| FoldingModel::new(p).ok()),
                    false => None,
                }
                .or_else(|| sheet_of_vertex(&vertex).ok());
                Ok(Pattern::Vertex {
                    vertex: Box::new(vertex),
                    sheet: sheet.map(Box::new),
                    origin: origin_of(),
                })
            }
            Err(refusal) => {
                let sheet = as_sheet();
                if !refused_as_vertex(&refusal, sheet.is_ok()) {
                    return Err(refusal);
                }
                let pattern = Pattern::Sheet {
                    model: Box::new(FoldingModel::new(sheet?)?),
                    origin: origin_of(),
                };
                Ok(pattern.settled(&value, name, origin))
            }
        }
    }

    /// A sheet whose state is off rigid within [`NOISY_STATE_BOUND`] moved onto the nearest
    /// rigid state ([`Pattern::projected`]); anything else, or a sheet the projection cannot
    /// move, as it is (its check then says how far from rigid it is).
    fn settled(self, value: &serde_json::Value, name: &str, source: &str) -> Pattern {
        let off = match &self {
            Pattern::Sheet { model, .. } => off_rigid(model),
            Pattern::Vertex { .. } => return self,
        };
        if !(off > RIGID_WITHIN && off <= NOISY_STATE_BOUND) {
            return self;
        }
        let Pattern::Sheet { model, origin } = self else {
            unreachable!("matched above")
        };
        if model.pattern.folded_form.is_some() {
            if let Some(moved) = rigid_form_of(&model, value, name, source) {
                let (model, mut projection) = moved;
                projection.note = format!(
                    "off rigid by {off:.2e} (within {NOISY_STATE_BOUND:.0e}: an exporter's noise), {}",
                    projection.note
                );
                return Pattern::Sheet {
                    model: Box::new(model),
                    origin: Origin {
                        projection: Some(projection),
                        ..origin
                    },
                };
            }
        }
        let kept = (model.clone(), origin.clone());
        match (Pattern::Sheet { model, origin }).projected() {
            Ok(Pattern::Sheet { model, mut origin }) => {
                if let Some(projection) = origin.projection.as_mut() {
                    projection.note = format!(
                        "off rigid by {off:.2e} (within {NOISY_STATE_BOUND:.0e}: an exporter's noise), {}",
                        projection.note
                    );
                }
                Pattern::Sheet { model, origin }
            }
            _ => Pattern::Sheet {
                model: kept.0,
                origin: kept.1,
            },
        }
    }

    /// A crease pattern of any number of vertices (validated, its stars and panels found).
    pub fn from_crease_pattern(pattern: CreasePattern) -> Result<Pattern> {
        Ok(Pattern::Sheet {
            model: Box::new(FoldingModel::new(pattern)?),
            origin: Origin::default(),
        })
    }

    fn origin(&self) -> &Origin {
        match self {
            Pattern::Vertex { origin, .. } | Pattern::Sheet { origin, .. } => origin,
        }
    }

    /// The same pattern, read from `source` (the file its reports name).
    pub fn with_source(mut self, source: impl Into<String>) -> Pattern {
        match &mut self {
            Pattern::Vertex { origin, .. } | Pattern::Sheet { origin, .. } => origin.source = Some(source.into()),
        }
        self
    }

    /// The file it was read from (None: built in code).
    pub fn source(&self) -> Option<&str> {
        self.origin().source.as_deref()
    }

    /// The pattern's name.
    pub fn name(&self) -> &str {
        match self {
            Pattern::Vertex { vertex, .. } => &vertex.name,
            Pattern::Sheet { model, .. } => &model.pattern.name,
        }
    }

    /// The engine that checks and unfolds it.
    pub fn engine(&self) -> Engine {
        match self {
            Pattern::Vertex { .. } => Engine::Vertex,
            Pattern::Sheet { .. } => Engine::Network,
        }
    }

    /// Its single vertex, when the single-vertex engine takes it.
    pub fn vertex(&self) -> Option<&VertexPattern> {
        match self {
            Pattern::Vertex { vertex, .. } => Some(vertex),
            Pattern::Sheet { .. } => None,
        }
    }

    /// Its sheet of panels (None: a vertex whose sectors do not close a flat sheet, a cone).
    pub fn sheet(&self) -> Option<&FoldingModel> {
        match self {
            Pattern::Vertex { sheet, .. } => sheet.as_deref(),
            Pattern::Sheet { model, .. } => Some(model),
        }
    }

    /// Crease labels in the order of every fold-angle vector the reports give.
    pub fn crease_labels(&self) -> Vec<String> {
        match self {
            Pattern::Vertex { vertex, .. } => vertex.creases.iter().map(|c| c.label.clone()).collect(),
            Pattern::Sheet { model, .. } => crease_labels(model),
        }
    }

    /// The state the pattern carries, rad (file order of the creases).
    pub fn fold_angles(&self) -> Vec<f64> {
        match self {
            Pattern::Vertex { vertex, .. } => vertex.creases.iter().map(|c| c.folded_angle).collect(),
            Pattern::Sheet { model, .. } => model.given_fold_angles(),
        }
    }
}

pub use crate::folding::NOISY_STATE_BOUND;

/// Off rigid by at most this, a state is rigid already (`check`'s closure tolerance).
const RIGID_WITHIN: f64 = 1e-6;

/// A folded form's file moved onto the nearest rigid folded form
/// ([`crate::geometry::rigid_form::rigidify`]) and read again: the model and the move. None
/// where the file's key frame lacks what that needs or the move fails.
fn rigid_form_of(
    model: &FoldingModel,
    value: &serde_json::Value,
    name: &str,
    source: &str,
) -> Option<(FoldingModel, Projection)> {
    let fit = model.pattern.folded_form?;
    let coords: Vec<[f64; 3]> = serde_json::from_value(value.get("vertices_coords")?.clone()).ok()?;
    let faces: Vec<Vec<usize>> = serde_json::from_value(value.get("faces_vertices")?.clone()).ok()?;
    let edges: Vec<[usize; 2]> = serde_json::from_value(value.get("edges_vertices")?.clone()).ok()?;
    let letters: Vec<String> = serde_json::from_value(value.get("edges_assignment")?.clone()).ok()?;
    let flat_edges: Vec<[usize; 2]> = edges
        .iter()
        .zip(&letters)
        .filter(|(_, a)| a.eq_ignore_ascii_case("F"))
        .map(|(e, _)| *e)
        .collect();
    let form = crate::geometry::rigid_form::rigidify(&coords, &faces, &flat_edges, 1e-13).ok()?;
    let mut moved_file = value.clone();
    moved_file["vertices_coords"] = serde_json::to_value(&form.coords).ok()?;
    let moved = FoldingModel::new(crate::read::crease_pattern_of_value(&moved_file, name, source).ok()?).ok()?;
    let (before, after) = (model.given_fold_angles(), moved.given_fold_angles());
    if before.len() != after.len() || off_rigid(&moved) > RIGID_WITHIN {
        return None;
    }
    let changes: Vec<f64> = before.iter().zip(&after).map(|(a, b)| (a - b).abs()).collect();
    let max_change = changes.iter().copied().fold(0.0, f64::max);
    let rms_change = (changes.iter().map(|c| c * c).sum::<f64>() / changes.len().max(1) as f64).sqrt();
    let residual_before = crate::folding::vertex_residuals(model, &before)
        .into_iter()
        .fold(0.0, f64::max);
    let note = format!(
        "moved onto the nearest rigid folded form (planar faces, flat facets, developable vertices, flat-foldable ones kept so): vertices moved by up to {:.3e} ({:.1e} of the sheet's size), fold angles by up to {max_change:.3e} rad (RMS {rms_change:.3e}); before, worst vertex closure {residual_before:.3e} rad, facets bent by up to {:.3e} rad, faces developing with a mismatch of {:.3e}",
        form.max_move,
        form.max_move / model.size,
        fit.max_facet_angle,
        fit.development_error
    );
    let figures = ProjectionFigures {
        max_change_rad: max_change,
        rms_change_rad: rms_change,
        residual_before_rad: residual_before,
        newton_iterations: form.iterations,
        moved: "vertex_positions",
        max_vertex_move: Some(form.max_move),
        folded_form: Some(FoldedFormBend::from(&fit)),
    };
    Some((moved, Projection { note, figures }))
}

/// How far a sheet's state is from rigid, in the measures of [`NOISY_STATE_BOUND`].
fn off_rigid(model: &FoldingModel) -> f64 {
    let closure = crate::folding::vertex_residuals(model, &model.given_fold_angles())
        .into_iter()
        .fold(0.0, f64::max);
    let form = model.pattern.folded_form.map_or(0.0, |fit| {
        fit.max_facet_angle
            .max(fit.development_error / model.size)
            .max(fit.face_nonplanarity / model.size)
    });
    closure.max(form)
}

/// How far a crease pattern's state was moved to make it rigid ([`Pattern::projected`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Projection {
    /// The move and the state before it, in words.
    pub note: String,
    /// The same in figures (`projection` in the reports).
    pub figures: ProjectionFigures,
}

impl Pattern {
    /// What a FOLD animation's frames the reading left out (None: nothing).
    pub fn frames_note(&self) -> Option<&str> {
        self.origin().frames_note.as_deref()
    }

    /// How far [`Pattern::projected`] moved its state (None: not moved).
    pub fn projection(&self) -> Option<&Projection> {
        self.origin().projection.as_ref()
    }

    /// The input's path as reports name it (the name, for a pattern built in code).
    pub fn file(&self) -> &str {
        self.source().unwrap_or(self.name())
    }

    /// How the input was read or moved, in words: the projection, the frames left out and
    /// the reader's notes, in that order.
    pub fn adjustments(&self) -> Vec<String> {
        let origin = self.origin();
        let reading = match self {
            Pattern::Sheet { model, .. } => model.pattern.reading.clone(),
            Pattern::Vertex { .. } => Vec::new(),
        };
        origin
            .projection
            .iter()
            .map(|p| p.note.clone())
            .chain(origin.frames_note.clone())
            .chain(reading)
            .collect()
    }

    /// The pattern with its state moved to the nearest rigid state (a crease pattern whose
    /// state does not close at some vertex, or a folded form whose facets bend, as a
    /// compliant simulator exports it), and how far it moved. A single vertex is its own
    /// engine's input and is returned as it is, with no projection. The move is the
    /// pattern's [`Pattern::projection`], and its reports state it.
    pub fn projected(self) -> Result<Pattern> {
        let (model, origin) = match self {
            Pattern::Sheet { model, origin } => (model, origin),
            vertex => return Ok(vertex),
        };
        let rho = model.given_fold_angles();
        let projection = crate::folding::project_to_rigid(&model, &rho, 1e-11)?;
        let moved = model.with_fold_angles(&projection.fold_angles);
        let fit = model.pattern.folded_form;
        let mut note = format!(
            "projected onto the rigid states: fold angles moved by up to {:.3e} rad (RMS {:.3e}), worst vertex closure {:.3e} rad before",
            projection.max_change, projection.rms_change, projection.residual_before
        );
        if let Some(fit) = fit {
            note.push_str(&format!(
                ", folded form with facets bent by up to {:.3e} rad and faces developing with a mismatch of {:.3e}",
                fit.max_facet_angle, fit.development_error
            ));
        }
        let figures = ProjectionFigures {
            max_change_rad: projection.max_change,
            rms_change_rad: projection.rms_change,
            residual_before_rad: projection.residual_before,
            newton_iterations: projection.iterations,
            moved: "fold_angles",
            max_vertex_move: None,
            folded_form: fit.as_ref().map(FoldedFormBend::from),
        };
        Ok(Pattern::Sheet {
            model: Box::new(moved),
            origin: Origin {
                projection: Some(Projection { note, figures }),
                ..origin
            },
        })
    }
}

impl From<VertexPattern> for Pattern {
    /// A single vertex, with its sheet when its sectors close one (unit rays about the
    /// origin, ray 0 along its mesh's direction or +x).
    fn from(vertex: VertexPattern) -> Pattern {
        let sheet = sheet_of_vertex(&vertex).ok().map(Box::new);
        Pattern::Vertex {
            vertex: Box::new(vertex),
            sheet,
            origin: Origin::default(),
        }
    }
}

/// The sheet of a single vertex: the vertex at the origin, a unit ray per crease (virtual
/// rays as flat facet lines, an open chain's end rays as boundary), the rays' tips joined
/// by the paper's outline.
pub(crate) fn sheet_of_vertex(vertex: &VertexPattern) -> Result<FoldingModel> {
    if !vertex.flat_foldable {
        return Err(NanofoldError::invalid(
            "sector_angles",
            format!("Σα = {:.6}°", vertex.angle_sum.to_degrees()),
            "a closed vertex whose sectors do not sum to 360° (a cone) has no flat sheet",
        ));
    }
    let n = vertex.rays.len();
    let start = vertex.mesh.as_ref().map_or(0.0, |m| m.ray0_direction);
    let mut vertices = vec![[0.0, 0.0]];
    let mut direction = start;
    for k in 0..n {
        vertices.push([direction.cos(), direction.sin()]);
        if let Some(alpha) = vertex.sector_angles.get(k) {
            direction += alpha;
        }
    }
    let mut builder = CreasePatternBuilder {
        name: vertex.name.clone(),
        vertices,
        angle_field: "creases[*].folded_angle".into(),
        ..CreasePatternBuilder::default()
    };
    let mut locked = Vec::new();
    for (k, role) in vertex.rays.iter().enumerate() {
        let (kind, angle, lock) = match *role {
            RayRole::Crease(i) => {
                let crease = &vertex.creases[i];
                let kind = match crease.assignment {
                    Assignment::Flat if crease.folded_angle == 0.0 => EdgeKind::Facet,
                    Assignment::Flat => EdgeKind::Crease(Assignment::Unassigned),
                    a => EdgeKind::Crease(a),
                };
                (kind, crease.folded_angle, crease.locked)
            }
            RayRole::Virtual => (EdgeKind::Facet, 0.0, false),
            RayRole::Boundary => (EdgeKind::Boundary, 0.0, false),
        };
        builder.edges.push([0, k + 1]);
        builder.kinds.push(kind);
        builder
            .fold_angles
            .push(if kind == EdgeKind::Facet { 0.0 } else { angle });
        locked.push(lock);
    }
    let outline = match vertex.chain {
        Chain::Closed => n,
        Chain::Open => n - 1,
    };
    for k in 0..outline {
        builder.edges.push([k + 1, (k + 1) % n + 1]);
        builder.kinds.push(EdgeKind::Boundary);
        builder.fold_angles.push(0.0);
        locked.push(false);
    }
    if locked.iter().any(|&l| l) {
        builder.locked = locked;
    }
    FoldingModel::new(builder.build()?)
}

/// Does a pattern the single-vertex loader refused (with `error`) go to the many-vertex
/// reader? Yes when the refusal says it is not a single vertex (several vertices or none, a
/// 3D folded form, no fold angles, a mesh larger than a vertex's); otherwise (a vertex whose
/// folded state does not close, say) only if it reads as a crease pattern.
fn refused_as_vertex(error: &NanofoldError, reads_as_sheet: bool) -> bool {
    use NanofoldError::{ClosureViolated, InvalidField, MissingField, MultipleVertices};
    let not_a_vertex = match error {
        MultipleVertices { .. } => true,
        MissingField { field, .. } => field == "edges_foldAngle",
        InvalidField { value, reason, .. } => {
            value == "no vertex with two or more creases"
                || reason.contains("3D folded forms are read as crease patterns")
                || reason.contains("a single-vertex pattern (its outputs repeat the mesh")
        }
        _ => false,
    };
    not_a_vertex || (!matches!(error, ClosureViolated { .. }) && reads_as_sheet)
}

/// `unfold`'s answer: the unfolding engines' verdict (either engine).
pub use crate::unfold::Verdict as UnfoldVerdict;

/// `fold`'s answer: why the path stopped.
pub use crate::folding::StopReason as FoldVerdict;

/// `check`'s answer: a single vertex is judged by unfolding it, a crease pattern of many
/// vertices by its state or its assignment. It is named in outputs by the inner verdict's
/// name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(untagged)]
pub enum CheckVerdict {
    /// A single vertex's unfolding (flat, locked, a local minimum, …).
    Unfolding(UnfoldVerdict),
    /// A crease pattern's state or assignment (rigid, not rigid, rigidly foldable, …).
    Pattern(PatternVerdict),
}

impl Named for CheckVerdict {}

impl PartialEq<UnfoldVerdict> for CheckVerdict {
    fn eq(&self, other: &UnfoldVerdict) -> bool {
        *self == CheckVerdict::Unfolding(*other)
    }
}

impl PartialEq<PatternVerdict> for CheckVerdict {
    fn eq(&self, other: &PatternVerdict) -> bool {
        *self == CheckVerdict::Pattern(*other)
    }
}

/// Which command a report answers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CommandKind {
    /// [`check`].
    Check,
    /// [`fold`].
    Fold,
    /// [`unfold`].
    Unfold,
}

/// What the engine behind the door reported in full.
#[derive(Debug, Clone)]
pub enum Detail {
    /// The single-vertex unfolding (also `check` of a single vertex).
    VertexUnfold(Box<UnfoldReport>),
    /// The many-vertex unfolding.
    NetworkUnfold(Box<NetworkUnfoldReport>),
    /// The many-vertex check, with the unfolding by energy a rigid folded state also gets.
    NetworkCheck(Box<CheckReport>, Option<Box<NetworkUnfoldReport>>),
    /// A folding path.
    Fold(Box<FoldPath>),
}

/// One report shape for every command and engine; `V` is the command's verdict type. It
/// serialises as its `Summary` (`check`, `fold` and `unfold --json` print that), the
/// typed fields beside it being the library's view of the same answer.
#[derive(Debug, Clone, Serialize)]
pub struct Report<V> {
    /// The pattern's name.
    #[serde(skip)]
    pub pattern: String,
    /// The command answered.
    #[serde(skip)]
    pub command: CommandKind,
    /// The engine that answered.
    #[serde(skip)]
    pub engine: Engine,
    /// The answer.
    #[serde(skip)]
    pub verdict: V,
    /// Why, in words.
    #[serde(skip)]
    pub evidence: String,
    /// Steps the engine took (descent steps, path steps).
    #[serde(skip)]
    pub steps: usize,
    /// Wall time, s.
    #[serde(skip)]
    pub seconds: f64,
    /// Every crease's label, in the order of the angle vectors.
    #[serde(skip)]
    pub crease_labels: Vec<String>,
    /// Fold angles at the start, rad.
    #[serde(skip)]
    pub start_fold_angles_rad: Vec<f64>,
    /// Fold angles at the end (the state judged, for `check`), rad.
    #[serde(skip)]
    pub final_fold_angles_rad: Vec<f64>,
    /// Largest constraint residual over the run, rad (the sphere's arcs for a single
    /// vertex, the vertex closures for a network).
    #[serde(skip)]
    pub max_closure_residual_rad: f64,
    /// The engine's own report.
    #[serde(skip)]
    pub detail: Detail,
    /// The answer as `--json` prints it (less the command line's own keys, `out` and
    /// `frames`).
    #[serde(flatten)]
    pub summary: Summary,
}

impl<V: Named> Answer for Report<V> {
    fn verdict_name(&self) -> &'static str {
        self.verdict.as_str()
    }

    fn evidence(&self) -> &str {
        &self.evidence
    }
}

impl<V> Report<V> {
    /// The report as `--json` prints it: its own serialisation.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).expect("a summary is plain data")
    }

    /// The same report with its verdict in another command's vocabulary.
    fn map_verdict<W>(self, to: impl FnOnce(V) -> W) -> Report<W> {
        Report {
            pattern: self.pattern,
            command: self.command,
            engine: self.engine,
            verdict: to(self.verdict),
            evidence: self.evidence,
            steps: self.steps,
            seconds: self.seconds,
            crease_labels: self.crease_labels,
            start_fold_angles_rad: self.start_fold_angles_rad,
            final_fold_angles_rad: self.final_fold_angles_rad,
            max_closure_residual_rad: self.max_closure_residual_rad,
            detail: self.detail,
            summary: self.summary,
        }
    }
}

/// Settings of every command, each validated where it is used.
#[derive(Debug, Clone, Default)]
pub struct Settings {
    /// Unfolding (both engines: the network takes its energy, exponent, flat tolerance,
    /// iteration budget and restarts from here).
    pub unfold: UnfoldSettings,
    /// A many-vertex check.
    pub check: CheckSettings,
    /// A folding path.
    pub fold: FoldSettings,
}

impl Settings {
    fn network_unfold(&self) -> NetworkUnfoldSettings {
        let u = &self.unfold;
        NetworkUnfoldSettings {
            energy: u.energy,
            p: u.p,
            flat_tol: u.flat_tol,
            max_iterations: u.max_iterations,
            restarts: u.restarts,
            ..NetworkUnfoldSettings::default()
        }
    }
}

fn sheet_of<'p>(pattern: &'p Pattern, command: &str) -> Result<&'p FoldingModel> {
    pattern.sheet().ok_or_else(|| {
        NanofoldError::invalid(
            "pattern",
            pattern.name(),
            format!("a cone (a closed vertex whose sectors do not sum to 360°) has no flat sheet to {command}"),
        )
    })
}

/// Unfolds a folded pattern to flat: the single vertex by the sphere's energy descent, a
/// crease pattern of many vertices by descent on its closures.
pub fn unfold(pattern: &Pattern, settings: &Settings) -> Result<Report<UnfoldVerdict>> {
    unfold_observed(pattern, settings, None)
}

/// [`unfold`], with `progress` told of every step (recorded steps so far, max |ρ|, energy)
/// by whichever engine runs: both are argmin solvers under its executor.
///
/// ```
/// use nanofold::prelude::*;
/// use std::sync::{Arc, Mutex};
/// # fn main() -> nanofold::prelude::Result<()> {
/// let pattern = Pattern::open(std::path::Path::new("patterns/corner_cube.fold"), &LoadOptions::default())?;
/// let steps = Arc::new(Mutex::new(0));
/// let counter = steps.clone();
/// let progress = UnfoldProgress(Arc::new(move |_, _, _| *counter.lock().unwrap() += 1));
/// let report = unfold_observed(&pattern, &Settings::default(), Some(progress))?;
/// assert_eq!(report.verdict, UnfoldVerdict::Flat);
/// assert!(*steps.lock().unwrap() > 0);
/// # Ok(())
/// # }
/// ```
pub fn unfold_observed(
    pattern: &Pattern,
    settings: &Settings,
    progress: Option<UnfoldProgress>,
) -> Result<Report<UnfoldVerdict>> {
    match pattern.vertex() {
        Some(vertex) => vertex_report(pattern, vertex, CommandKind::Unfold, settings, progress),
        None => {
            let model = sheet_of(pattern, "unfold")?;
            let start = model.given_fold_angles();
            let clock = Instant::now();
            let report = unfold_network_observed(model, &start, &settings.network_unfold(), progress)?;
            let seconds = clock.elapsed().as_secs_f64();
            let last = report
                .steps
                .last()
                .map_or_else(|| start.clone(), |s| s.fold_angles.clone());
            let summary = NetworkUnfoldSummary::new(
                model,
                pattern.file(),
                &report,
                &start,
                seconds,
                pattern.adjustments(),
                pattern.projection().map(|p| p.figures.clone()),
            );
            Ok(Report {
                pattern: pattern.name().to_string(),
                command: CommandKind::Unfold,
                engine: Engine::Network,
                verdict: report.verdict,
                evidence: report.evidence.clone(),
                steps: report.iterations,
                seconds,
                crease_labels: pattern.crease_labels(),
                start_fold_angles_rad: start,
                final_fold_angles_rad: last,
                max_closure_residual_rad: report.max_closure_residual,
                detail: Detail::NetworkUnfold(Box::new(report)),
                summary: Summary::NetworkUnfold(Box::new(summary)),
            })
        }
    }
}

/// Judges a pattern: a single vertex by unfolding it (flat, locked, a local minimum, …), a
/// crease pattern of many vertices by its state (rigid, not rigid, self-intersecting) or,
/// flat, by its assignment (rigidly foldable or not, with a witness path).
pub fn check(pattern: &Pattern, settings: &Settings) -> Result<Report<CheckVerdict>> {
    settings.check.validate()?;
    match pattern.vertex() {
        Some(vertex) => Ok(
            vertex_report(pattern, vertex, CommandKind::Check, settings, None)?.map_verdict(CheckVerdict::Unfolding)
        ),
        None => {
            let model = sheet_of(pattern, "check")?;
            let clock = Instant::now();
            let (report, unfolding) = check_sheet(model, &settings.check)?;
            let seconds = clock.elapsed().as_secs_f64();
            let start = model.given_fold_angles();
            let judged = report
                .witness
                .as_ref()
                .and_then(|w| w.steps.last())
                .map_or_else(|| start.clone(), |s| s.fold_angles.clone());
            let summary = CheckSummary::new(
                model,
                pattern.file(),
                &report,
                unfolding.as_ref(),
                seconds,
                pattern.projection().map(|p| p.figures.clone()),
            );
            Ok(Report {
                pattern: pattern.name().to_string(),
                command: CommandKind::Check,
                engine: Engine::Network,
                verdict: CheckVerdict::Pattern(report.verdict),
                evidence: report.evidence.clone(),
                steps: report.witness.as_ref().map_or(0, |w| w.steps.len()),
                seconds,
                crease_labels: pattern.crease_labels(),
                start_fold_angles_rad: start,
                final_fold_angles_rad: judged,
                max_closure_residual_rad: report.max_vertex_residual_rad,
                detail: Detail::NetworkCheck(Box::new(report), unfolding.map(Box::new)),
                summary: Summary::Check(Box::new(summary)),
            })
        }
    }
}

/// The many-vertex check, and a rigid folded state's unfolding by energy beside it
/// (`docs/model.md#energy-unfolding-of-many-vertices`): what `check` answers for a sheet.
pub fn check_sheet(
    model: &FoldingModel,
    settings: &CheckSettings,
) -> Result<(CheckReport, Option<NetworkUnfoldReport>)> {
    let report = check_pattern(model, settings)?;
    let unfolding = if report.has_state && report.verdict == PatternVerdict::Rigid {
        Some(unfold_network(
            model,
            &model.given_fold_angles(),
            &NetworkUnfoldSettings::default(),
        )?)
    } else {
        None
    };
    Ok((report, unfolding))
}

/// Folds a pattern from its state (flat: along its assignment) by the many-vertex path
/// (a single vertex on its sheet), as `settings.fold` drives it.
pub fn fold(pattern: &Pattern, settings: &Settings) -> Result<Report<FoldVerdict>> {
    let model = sheet_of(pattern, "fold")?;
    let start = model.given_fold_angles();
    let clock = Instant::now();
    let path = fold_path(model, &start, &settings.fold)?;
    Ok(fold_report(pattern, model, start, path, clock))
}

/// A fold's report with what `fold` writes beside it: the FOLD animation of `frames`
/// frames (placed while the path goes on, on a large pattern) and the end state as FOLD.
#[derive(Debug, Clone)]
pub struct FoldRun {
    /// The report.
    pub report: Report<FoldVerdict>,
    /// The animation's frames, evenly spaced in progress.
    pub frames: Vec<crate::folding::PathFrame>,
    /// fold.fold: the crease pattern with one frame per snapshot.
    pub animation: serde_json::Value,
    /// folded.fold: the crease pattern carrying the end state.
    pub end_state: serde_json::Value,
}

/// Folds `pattern` with the front ends' options (`fold --to`, `--drive`, `--frames`, …).
pub fn fold_run(pattern: &Pattern, options: &options::FoldOptions) -> Result<FoldRun> {
    use crate::write::folding_output::{crease_pattern_fold, fold_path_fold};
    let model = sheet_of(pattern, "fold")?;
    let settings = options.settings(model)?;
    let start = options.start(model);
    let clock = Instant::now();
    let (path, frames) = crate::folding::fold_path_and_frames(model, &start, &settings, options.frames)?;
    let report = fold_report(pattern, model, start, path, clock);
    let animation = fold_path_fold(model, &frames);
    let end_state = crease_pattern_fold(
        &model.pattern,
        Some(&report.final_fold_angles_rad),
        "end state of nanofold fold (a crease pattern with its fold angles)",
    );
    Ok(FoldRun {
        report,
        frames,
        animation,
        end_state,
    })
}

/// The files `fold` writes for a run (rendered, not written): fold.fold (the animation),
/// folded.fold (the end state), trajectory.json (every step, thinned to 1000 and to
/// [`MAX_TRAJECTORY_ANGLES`] angles in all), fold.svg and
/// the 3D page fold.html.
#[cfg(feature = "plot")]
pub fn fold_files(pattern: &Pattern, run: &FoldRun) -> Result<Vec<(&'static str, String)>> {
    let model = sheet_of(pattern, "fold")?;
    let Detail::Fold(path) = &run.report.detail else {
        return Err(NanofoldError::invalid(
            "run",
            run.report.pattern.clone(),
            "is not a fold",
        ));
    };
    let title = format!(
        "{}: folding ({}, {} steps)",
        model.pattern.name,
        path.stop.as_str(),
        path.steps.len()
    );
    let states: Vec<(String, &[f64])> = run
        .frames
        .iter()
        .map(|f| (format!("progress {:.4}", f.progress), f.fold_angles.as_slice()))
        .collect();
    let json = |value: &serde_json::Value| {
        serde_json::to_string_pretty(value).map_err(|e| NanofoldError::invalid("fold.fold", "JSON", e.to_string()))
    };
    let trajectory = crate::write::folding_output::fold_trajectory_json(model, path, 1000);
    Ok(vec![
        ("fold.fold", json(&run.animation)?),
        ("folded.fold", json(&run.end_state)?),
        ("trajectory.json", trajectory.to_string()),
        ("fold.svg", crate::plot::folding::fold_svg(model, path, &title)?),
        ("fold.html", crate::plot::page::page_of_states(model, &title, &states)?),
    ])
}

/// The files `unfold` writes for a report (rendered, not written): trajectory.json (the
/// recorded steps, thinned to 1000 and to [`MAX_TRAJECTORY_ANGLES`] angles in all),
/// unfold.fold (the FOLD animation), unfold.svg and the 3D
/// page unfold.html, for either engine.
#[cfg(feature = "plot")]
pub fn unfold_files(
    pattern: &Pattern,
    report: &Report<UnfoldVerdict>,
    settings: &Settings,
) -> Result<Vec<(&'static str, String)>> {
    use crate::plot::page::page_of_fold;
    use crate::write::folding_output::{evenly, states_fold, steps_to_write};
    let pretty = |value: &serde_json::Value| {
        serde_json::to_string_pretty(value).map_err(|e| NanofoldError::invalid("unfold.fold", "JSON", e.to_string()))
    };
    match (&report.detail, pattern.vertex(), pattern.sheet()) {
        (Detail::VertexUnfold(run), Some(vertex), _) => {
            let model = crate::unfold::UnfoldModel::new(vertex);
            let trajectory = crate::write::output::trajectory_json(vertex, &settings.unfold, run, 1000);
            let mut animation = crate::write::output::fold_animation(vertex, &model, run);
            // A file without faces: its sheet's own (the same vertices where none was
            // left out), so the page has faces to draw.
            if animation.get("faces_vertices").is_none() {
                if let Some(sheet) = pattern.sheet().filter(|s| s.pattern.ignored_vertices.is_empty()) {
                    animation["faces_vertices"] = serde_json::json!(sheet.pattern.faces);
                }
            }
            Ok(vec![
                ("trajectory.json", trajectory.to_string()),
                ("unfold.fold", pretty(&animation)?),
                ("unfold.svg", crate::plot::unfold_svg(vertex, run)?),
                ("unfold.html", page_of_fold(&animation, &vertex.name, &[], None)?),
            ])
        }
        (Detail::NetworkUnfold(run), _, Some(model)) => {
            let steps = &run.steps;
            // 11 snapshots in the animation, the trajectory thinned to 1000 steps.
            let frames: Vec<(String, &[f64])> = evenly(steps.len(), 11)
                .iter()
                .map(|&i| {
                    (
                        format!("step {i}, energy {:.6e}", steps[i].energy),
                        steps[i].fold_angles.as_slice(),
                    )
                })
                .collect();
            let animation = states_fold(
                model,
                Some(&report.start_fold_angles_rad),
                &frames,
                "unfolding written by nanofold unfold",
            );
            let written = evenly(steps.len(), steps_to_write(1000, model.crease_count()));
            let trajectory = serde_json::json!({
                "pattern": model.pattern.name,
                "units": {"angles": "rad"},
                "creases_edge_index": model.pattern.creases,
                "verdict": run.verdict.as_str(),
                "evidence": run.evidence,
                "recorded_steps": steps.len(),
                "steps_written": written.len(),
                "steps": written.iter().map(|&i| serde_json::json!({
                    "step": i,
                    "energy": crate::write::output::number(steps[i].energy),
                    "fold_angles_rad": steps[i].fold_angles,
                    "max_closure_residual_rad": steps[i].max_residual,
                })).collect::<Vec<_>>(),
            });
            let xs: Vec<f64> = (0..steps.len()).map(|i| i as f64).collect();
            let states: Vec<&[f64]> = steps.iter().map(|s| s.fold_angles.as_slice()).collect();
            let title = format!(
                "{}: fold angles while unfolding ({}, {} steps)",
                model.pattern.name,
                run.verdict.as_str(),
                run.iterations
            );
            Ok(vec![
                ("trajectory.json", trajectory.to_string()),
                ("unfold.fold", pretty(&animation)?),
                (
                    "unfold.svg",
                    crate::plot::folding::angles_svg(model, &xs, &states, "step", "step", &title)?,
                ),
                ("unfold.html", page_of_fold(&animation, &model.pattern.name, &[], None)?),
            ])
        }
        _ => Err(NanofoldError::invalid(
            "report",
            report.pattern.clone(),
            "is not an unfolding of this pattern",
        )),
    }
}

fn fold_report(
    pattern: &Pattern,
    model: &FoldingModel,
    start: Vec<f64>,
    path: FoldPath,
    clock: Instant,
) -> Report<FoldVerdict> {
    let seconds = clock.elapsed().as_secs_f64();
    let last = path
        .steps
        .last()
        .map_or_else(|| start.clone(), |s| s.fold_angles.clone());
    let summary = FoldSummary::new(model, pattern.file(), &path, seconds);
    Report {
        pattern: pattern.name().to_string(),
        command: CommandKind::Fold,
        engine: Engine::Network,
        verdict: path.stop.clone(),
        evidence: path.evidence.clone(),
        steps: path.steps.len().saturating_sub(1),
        seconds,
        crease_labels: crease_labels(model),
        start_fold_angles_rad: start,
        final_fold_angles_rad: last,
        max_closure_residual_rad: path.max_closure_residual,
        detail: Detail::Fold(Box::new(path)),
        summary: Summary::Fold(Box::new(summary)),
    }
}

fn vertex_report(
    pattern: &Pattern,
    vertex: &VertexPattern,
    command: CommandKind,
    settings: &Settings,
    progress: Option<UnfoldProgress>,
) -> Result<Report<UnfoldVerdict>> {
    let mut report = crate::unfold::unfold_observed(vertex, &settings.unfold, progress)?;
    if matches!(report.verdict, UnfoldVerdict::LocalMinimum | UnfoldVerdict::Stuck) {
        if let Ok(sheet) = sheet_of_vertex(vertex) {
            if let Some(witnessed) = witness::unfold_by_folding_path(vertex, &sheet, &report, &settings.unfold)? {
                report = witnessed;
            }
        }
    }
    let summary = VertexUnfoldSummary::new(vertex, pattern.file(), &report);
    Ok(Report {
        pattern: pattern.name().to_string(),
        command,
        engine: Engine::Vertex,
        verdict: report.verdict,
        evidence: report.evidence.clone(),
        steps: report.iterations,
        seconds: report.seconds,
        crease_labels: pattern.crease_labels(),
        start_fold_angles_rad: pattern.fold_angles(),
        final_fold_angles_rad: report.final_fold_angles_rad.clone(),
        max_closure_residual_rad: report.max_arc_residual,
        detail: Detail::VertexUnfold(Box::new(report)),
        summary: Summary::VertexUnfold(Box::new(summary)),
    })
}
