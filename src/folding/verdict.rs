//! What `check` says of a crease pattern (`docs/model.md#pattern-verdicts`): for a folded
//! state, rigid / not rigid / self-intersecting with the evidence; for an assignment alone,
//! rigidly foldable (with a witness path), not rigidly foldable (a vertex whose assignment
//! matches none of its folding modes) or unknown.

use super::closure::{closure_jacobian, vertex_residuals};
use super::contact::{panel_contacts, ContactSettings};
use super::model::{FoldingModel, Star};
use super::path::NOISY_STATE_BOUND;
use super::path::{fold_path, Drive, FoldPath, FoldSettings, StopReason};
use super::poses::{panel_poses, tree_mismatch};
use super::rank::{jacobian_rank, RankReport};
use super::second_order::{second_order, SecondOrder, CERTIFICATE};
use crate::error::Result;
use crate::names::Named;
use crate::pattern::crease_pattern::EdgeKind;
use crate::pattern::Assignment;
use nalgebra::Matrix2;

/// The verdict on a crease pattern.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PatternVerdict {
    /// The given state closes at every vertex and no two panels cross.
    Rigid,
    /// Some vertex does not close: the state needs the panels to bend.
    NotRigid,
    /// The state closes but panels pass through each other.
    SelfIntersecting,
    /// The assignment folds rigidly from flat: a witness path was found.
    RigidlyFoldable,
    /// The assignment cannot fold rigidly from flat.
    NotRigidlyFoldable,
    /// Neither could be shown.
    Unknown,
}

impl crate::names::Named for PatternVerdict {}

/// Tolerances of a check.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckSettings {
    /// Largest vertex closure residual of a rigid state, rad.
    pub closure_tol: f64,
    /// Panel contact test.
    pub contact: ContactSettings,
    /// The witness path's settings (for assignment-only patterns).
    pub path: FoldSettings,
}

impl Default for CheckSettings {
    fn default() -> Self {
        CheckSettings {
            closure_tol: 1e-6,
            contact: ContactSettings::default(),
            path: FoldSettings::default(),
        }
    }
}

impl CheckSettings {
    /// Refuses a closure tolerance outside (0, 0.1] rad by name (the contact and path
    /// settings check themselves where they are used).
    pub fn validate(&self) -> crate::error::Result<()> {
        if !(self.closure_tol > 0.0 && self.closure_tol <= 0.1) {
            return Err(crate::error::NanofoldError::invalid(
                "closure_tol",
                self.closure_tol,
                "a closure tolerance lies in (0, 0.1] rad",
            ));
        }
        Ok(())
    }
}

/// A check's verdict with its evidence.
#[derive(Debug, Clone)]
pub struct CheckReport {
    /// The verdict.
    pub verdict: PatternVerdict,
    /// Why, in words.
    pub evidence: String,
    /// Whether the pattern carried a folded state (else its assignment was judged).
    pub has_state: bool,
    /// Rank of J at the state checked (the flat state for an assignment).
    pub rank: RankReport,
    /// Largest vertex closure residual, rad.
    pub max_vertex_residual_rad: f64,
    /// The worst vertices (vertex index, residual rad), at most 8, largest first.
    pub worst_vertices: Vec<(usize, f64)>,
    /// Pairs of panels that pass through each other.
    pub intersecting_pairs: Vec<[usize; 2]>,
    /// Pairs closer than the clearance (crossing ones included).
    pub contacts: usize,
    /// Smallest clearance between panels sharing no vertex, within the search range.
    pub min_panel_clearance: Option<f64>,
    /// Tree mismatch of the panel poses (a length), 0 to rounding for a rigid state.
    pub tree_mismatch: f64,
    /// The witness path tried for an assignment.
    pub witness: Option<FoldPath>,
    /// What was tried, for an `unknown`.
    pub tried: Vec<String>,
    /// For a 3D folded form: how far its faces were from a developable, rigid sheet.
    pub folded_form: Option<crate::pattern::crease_pattern::FoldedFormFit>,
    /// The local flat-foldability conditions at every interior vertex.
    pub flat_foldability: FlatFoldability,
}

/// Kawasaki's and Maekawa's conditions, necessary for a vertex to fold flat: alternate
/// sector angles sum to π, and mountains and valleys differ by two.
#[derive(Debug, Clone, PartialEq)]
pub struct FlatFoldability {
    /// The even-degree vertex farthest from Kawasaki's condition and its |Σ alternate
    /// sectors − π|, rad.
    pub worst_kawasaki: Option<(usize, f64)>,
    /// Vertices of odd degree: no flat folding exists there (Kawasaki's condition has no
    /// alternation to hold).
    pub odd_degree: Vec<usize>,
    /// Vertices whose assignment breaks Maekawa's condition (vertices with a U crease are
    /// not judged).
    pub maekawa_failures: Vec<usize>,
    /// The residual below which Kawasaki's condition holds, rad (1e-9, or the pattern's
    /// own angle precision where that is coarser).
    pub tolerance: f64,
}

impl FlatFoldability {
    /// The conditions at every star of the model.
    pub fn of(model: &FoldingModel) -> FlatFoldability {
        let mut worst_kawasaki: Option<(usize, f64)> = None;
        let mut odd_degree = Vec::new();
        let mut maekawa_failures = Vec::new();
        for star in &model.stars {
            if star.sector_angles.len() % 2 == 1 {
                odd_degree.push(star.vertex);
            } else {
                let alternating: f64 = star.sector_angles.iter().step_by(2).sum();
                let residual = (alternating - std::f64::consts::PI).abs();
                if worst_kawasaki.is_none_or(|(_, r)| residual > r) {
                    worst_kawasaki = Some((star.vertex, residual));
                }
            }
            let signs: Vec<f64> = star.columns.iter().map(|&c| sign_of(model, c)).collect();
            if signs.iter().all(|&x| x != 0.0) {
                let valleys = signs.iter().filter(|&&x| x > 0.0).count() as i64;
                let mountains = signs.len() as i64 - valleys;
                if (valleys - mountains).abs() != 2 {
                    maekawa_failures.push(star.vertex);
                }
            }
        }
        FlatFoldability {
            worst_kawasaki,
            odd_degree,
            maekawa_failures,
            tolerance: model.exact_angle_tolerance(),
        }
    }

    /// One line for the evidence.
    pub fn summary(&self, vertices: usize) -> String {
        let even = vertices - self.odd_degree.len();
        let mut kawasaki = match self.worst_kawasaki {
            None if self.odd_degree.is_empty() => "no interior vertex".to_string(),
            None => String::new(),
            Some((_, r)) if r <= self.tolerance && self.odd_degree.is_empty() => {
                format!("Kawasaki holds at all {vertices} vertices")
            }
            Some((_, r)) if r <= self.tolerance => format!("Kawasaki holds at the {even} of even degree"),
            Some((v, r)) => format!("Kawasaki fails by up to {r:.3e} rad (vertex {v})"),
        };
        if !self.odd_degree.is_empty() {
            let odd = format!(
                "odd degree at {} vertices (first {:?}): no flat folding there",
                self.odd_degree.len(),
                &self.odd_degree[..self.odd_degree.len().min(5)]
            );
            kawasaki = if kawasaki.is_empty() {
                odd
            } else {
                format!("{odd}; {kawasaki}")
            };
        }
        let maekawa = if self.maekawa_failures.is_empty() {
            "Maekawa holds".to_string()
        } else {
            format!(
                "Maekawa fails at {} vertices (first {:?})",
                self.maekawa_failures.len(),
                &self.maekawa_failures[..self.maekawa_failures.len().min(5)]
            )
        };
        format!("{kawasaki}; {maekawa}")
    }
}

/// Checks the state the pattern carries or, when it is flat, its assignment.
pub fn check_pattern(model: &FoldingModel, settings: &CheckSettings) -> Result<CheckReport> {
    let mut report = judge(model, settings)?;
    // How the file was read (a noisy flat sheet, angles taken as targets) is part of the
    // evidence: the verdict rests on it.
    for note in &model.pattern.reading {
        report.evidence.push_str(&format!("; read: {note}"));
    }
    Ok(report)
}

/// [`check_pattern`] before the reading's notes.
fn judge(model: &FoldingModel, settings: &CheckSettings) -> Result<CheckReport> {
    settings.contact.validate()?;
    let rho = model.given_fold_angles();
    let has_state = rho.iter().any(|&r| r != 0.0);
    let residuals = vertex_residuals(model, &rho);
    let mut worst: Vec<(usize, f64)> = model
        .stars
        .iter()
        .map(|s| s.vertex)
        .zip(residuals.iter().copied())
        .collect();
    worst.sort_by(|a, b| b.1.total_cmp(&a.1));
    let max_residual = worst.first().map_or(0.0, |w| w.1);
    worst.truncate(8);
    let rank = jacobian_rank(&closure_jacobian(model, &rho))?;
    let mut poses = Vec::new();
    panel_poses(model, &rho, &mut poses);
    let contacts = panel_contacts(model, &poses, &settings.contact);
    let mut report = CheckReport {
        verdict: PatternVerdict::Unknown,
        evidence: String::new(),
        has_state,
        rank,
        max_vertex_residual_rad: max_residual,
        worst_vertices: worst.clone(),
        intersecting_pairs: contacts.crossing().map(|c| c.panels).collect(),
        contacts: contacts.contacts.len(),
        min_panel_clearance: contacts.min_clearance,
        tree_mismatch: tree_mismatch(model, &rho, &poses),
        witness: None,
        tried: Vec::new(),
        folded_form: model.pattern.folded_form,
        flat_foldability: FlatFoldability::of(model),
    };
    // A folded form whose facets bend or whose faces do not develop into one flat sheet.
    let bent = model.pattern.folded_form.and_then(|fit| {
        let facets = (fit.max_facet_angle > settings.closure_tol)
            .then(|| format!("facets (F edges) bend by up to {:.3e} rad", fit.max_facet_angle));
        let development = (fit.development_error > settings.closure_tol * model.size).then(|| {
            format!(
                "the faces develop with a mismatch of {:.3e} (lengths)",
                fit.development_error
            )
        });
        let warped = (fit.face_nonplanarity > settings.closure_tol * model.size).then(|| {
            format!(
                "faces are warped out of their planes by up to {:.3e} (lengths)",
                fit.face_nonplanarity
            )
        });
        let parts: Vec<String> = facets.into_iter().chain(development).chain(warped).collect();
        (!parts.is_empty()).then(|| parts.join("; "))
    });
    if model.crease_count() == 0 && bent.is_none() {
        // No assignment to test: the flat sheet is the one state, and it is rigid.
        report.verdict = PatternVerdict::Rigid;
        report.evidence = "no creases: the paper is one rigid panel (0 DOF); nothing to fold".to_string();
        return Ok(report);
    }
    if has_state || bent.is_some() {
        (report.verdict, report.evidence) = state_verdict(&report, bent, &worst, contacts.overflow, settings);
        return Ok(report);
    }

    // An assignment alone: first the local test at each degree-4 vertex, then the modes'
    // agreement across shared creases, then a witness.
    let exact = model.exact_angle_tolerance();
    let chosen = match local_tests(model, exact) {
        Ok(local) => {
            report.tried.extend(local.tried);
            local.chosen
        }
        Err(evidence) => {
            report.verdict = PatternVerdict::NotRigidlyFoldable;
            report.evidence = evidence;
            return Ok(report);
        }
    };
    if let Some(conflict) = mode_conflict(model, &chosen, exact) {
        report.verdict = PatternVerdict::NotRigidlyFoldable;
        report.evidence = conflict;
        return Ok(report);
    }
    let path_settings = FoldSettings {
        drive: Drive::Assignment { to: 100.0 },
        ..settings.path.clone()
    };
    report.tried.push(format!(
        "flat-foldability at the vertices: {}",
        report.flat_foldability.summary(model.stars.len())
    ));
    let mut path = fold_path(model, &rho, &path_settings)?;
    // A file's targets drive a second path where the assignment's finds no witness.
    if let (false, Some(by_edge)) = (witnesses(&path), model.pattern.target_angles.as_ref()) {
        let targets = model.pattern.creases.iter().map(|&e| by_edge[e]).collect();
        let by_targets = FoldSettings {
            drive: Drive::Targets { targets, to: 100.0 },
            ..settings.path.clone()
        };
        if by_targets.validate(model).is_ok() {
            let towards = fold_path(model, &rho, &by_targets)?;
            report.tried.push(format!(
                "folding path from flat by the assignment: {} ({})",
                path.stop.as_str(),
                path.evidence
            ));
            path = towards;
        }
    }
    let reached = path.steps.last().map_or(0.0, |s| s.progress);
    let fully_assigned = model.pattern.creases.iter().all(|&e| {
        matches!(
            model.pattern.kinds[e],
            EdgeKind::Crease(Assignment::Mountain) | EdgeKind::Crease(Assignment::Valley)
        )
    });
    if witnesses(&path) {
        report.verdict = PatternVerdict::RigidlyFoldable;
        report.evidence = format!(
            "a rigid folding path from flat with the assigned signs reaches {:.1}% of {} ({} steps, closure ≤ {:.1e} rad, stop: {} — {})",
            100.0 * reached,
            match path.drive {
                Drive::Targets { .. } => "the way to the file's targets",
                _ => "full folding",
            },
            path.steps.len(),
            path.max_closure_residual,
            path.stop.as_str(),
            path.evidence
        );
    } else {
        report.tried.push(format!(
            "folding path from flat{}: {} ({}{})",
            match path.drive {
                Drive::Targets { .. } => " towards the file's targets",
                _ => "",
            },
            path.stop.as_str(),
            path.evidence,
            if path.left_flat_damped {
                format!(
                    "; it left flat by damped least squares and reached {:.2e} of the way, short of the {DAMPED_WITNESS_PROGRESS} a witness needs",
                    reached
                )
            } else {
                String::new()
            }
        ));
        let verdict_by_path = matches!(path.stop, StopReason::Locked) && fully_assigned && model.stars.is_empty();
        report.verdict = if verdict_by_path {
            PatternVerdict::NotRigidlyFoldable
        } else {
            PatternVerdict::Unknown
        };
        report.evidence = format!("no witness found; tried: {}", report.tried.join("; "));
    }
    report.witness = Some(path);
    Ok(report)
}

/// The progress a path that left flat by damped least squares must make to witness a
/// rigid folding: its start is the rigid state nearest a kick, not a branch followed.
const DAMPED_WITNESS_PROGRESS: f64 = 0.01;

/// Whether a path from flat witnesses a rigid folding with the assigned signs: states past
/// the one it left flat to, some progress, and where it left flat by damped least squares,
/// [`DAMPED_WITNESS_PROGRESS`] of it.
fn witnesses(path: &crate::folding::FoldPath) -> bool {
    let reached = path.steps.last().map_or(0.0, |s| s.progress);
    path.steps.len() > 2 && reached > 0.0 && (!path.left_flat_damped || reached >= DAMPED_WITNESS_PROGRESS)
}

/// The verdict of a folded state (or a folded form whose facets bend, `bent`): not rigid,
/// undecided where the contact budget overflows, self-intersecting, or rigid.
fn state_verdict(
    report: &CheckReport,
    bent: Option<String>,
    worst: &[(usize, f64)],
    overflow: Option<usize>,
    settings: &CheckSettings,
) -> (PatternVerdict, String) {
    let max_residual = report.max_vertex_residual_rad;
    if let Some(bent) = bent {
        (
            PatternVerdict::NotRigid,
            format!("the folded form is not rigid: {bent}; worst vertex closure {max_residual:.3e} rad (beyond the {NOISY_STATE_BOUND:.0e} an exporter's noise explains, so not moved onto a rigid form; `project` moves it anyway)"),
        )
    } else if max_residual > settings.closure_tol {
        let list: Vec<String> = worst
            .iter()
            .filter(|w| w.1 > settings.closure_tol)
            .map(|(v, r)| format!("vertex {v}: {r:.3e} rad"))
            .collect();
        (
            PatternVerdict::NotRigid,
            format!(
                "closure fails above {:.0e} rad at {}",
                settings.closure_tol,
                list.join(", ")
            ),
        )
    } else if let Some(found) = overflow {
        (
            PatternVerdict::Unknown,
            format!(
                "every vertex closes within {max_residual:.1e} rad, but more than {} pairs of panels overlap (layers stacked deep), the contact test's budget: whether panels cross is not decided ({} DOF at this state)",
                found - 1,
                report.rank.dof
            ),
        )
    } else if !report.intersecting_pairs.is_empty() {
        let list: Vec<String> = report
            .intersecting_pairs
            .iter()
            .take(8)
            .map(|p| format!("{p:?}"))
            .collect();
        (
            PatternVerdict::SelfIntersecting,
            format!(
                "{} panel pairs pass through each other: {}",
                report.intersecting_pairs.len(),
                list.join(", ")
            ),
        )
    } else {
        (
            PatternVerdict::Rigid,
            format!(
                "every vertex closes within {max_residual:.1e} rad, no panels cross ({} DOF at this state)",
                report.rank.dof
            ),
        )
    }
}

/// What the local tests at the flat vertices leave: each star's decided degree-4 mode (for
/// the cycle test) and what was tried.
struct LocalTests {
    chosen: Vec<Option<[f64; 4]>>,
    tried: Vec<String>,
}

/// The local tests of an assignment at each flat vertex: a degree-4 vertex against its
/// folding modes, another degree by the second-order test. Err(evidence) where a vertex
/// excludes the assignment.
fn local_tests(model: &FoldingModel, exact: f64) -> std::result::Result<LocalTests, String> {
    let mut tried = Vec::new();
    let mut local_checked = 0;
    let mut chosen: Vec<Option<[f64; 4]>> = Vec::with_capacity(model.stars.len());
    // Vertices of other degrees: the second-order test, once per shape and signs.
    let mut second_order_seen = std::collections::HashMap::new();
    let mut second_order_checked = 0;
    for star in &model.stars {
        // A locked crease stays flat: the vertex's modes from flat do not apply as computed.
        if star.columns.iter().any(|&c| model.locked_columns[c]) {
            chosen.push(None);
            continue;
        }
        let Some(modes) = degree4_modes_within(star, exact) else {
            chosen.push(None);
            let assigned: Vec<f64> = star.columns.iter().map(|&c| sign_of(model, c)).collect();
            let key = (
                star.sector_angles
                    .iter()
                    .map(|a| (a * 1e12).round() as i64)
                    .collect::<Vec<_>>(),
                assigned.iter().map(|&a| a as i8).collect::<Vec<_>>(),
            );
            let found = match second_order_seen.get(&key) {
                Some(found) => *found,
                None => {
                    let found = second_order(star, &assigned);
                    second_order_seen.insert(key, found);
                    found
                }
            };
            let Some(found) = found else { continue };
            second_order_checked += 1;
            if found.excludes_motion(CERTIFICATE) {
                let names: Vec<&str> = assigned.iter().map(|&a| letter(a)).collect();
                return Err(match found {
                    SecondOrder::OneSign => format!(
                        "vertex {} (degree {}): its assignment {} (creases counter-clockwise) has one sign: such a vertex folds only along a straight line through it (its image on the unit sphere, a locally convex polygon of length 2π, must be a great circle or a lune), so its other creases stay flat",
                        star.vertex,
                        assigned.len(),
                        names.concat()
                    ),
                    SecondOrder::NoFirstOrder => format!(
                        "vertex {} (degree {}): its assignment {} (creases counter-clockwise) admits no motion from flat: no velocities with these signs close it in the plane",
                        star.vertex,
                        assigned.len(),
                        names.concat()
                    ),
                    SecondOrder::Range { min, max } => format!(
                        "vertex {} (degree {}): its assignment {} (creases counter-clockwise) admits no motion from flat at second order: on the velocities with these signs that close it in the plane (scaled to Σ|ρ̇| = 1) the out-of-plane second-order closure Q ranges over [{min:.3e}, {max:.3e}], which excludes 0",
                        star.vertex,
                        assigned.len(),
                        names.concat()
                    ),
                });
            }
            continue;
        };
        local_checked += 1;
        let assigned: Vec<f64> = star.columns.iter().map(|&c| sign_of(model, c)).collect();
        // A mode's zero entry: at a flat-foldable vertex the branches keep exact ratios of
        // tan(ρ/2), so that crease stays flat and cannot be a mountain or valley; elsewhere
        // its sign is decided at higher order and matches anything.
        let alternating = star
            .sector_angles
            .iter()
            .enumerate()
            .map(|(k, a)| if k % 2 == 0 { *a } else { -a })
            .sum::<f64>();
        let flat_foldable = alternating.abs() < exact;
        let fits = |mode: &&[f64; 4]| {
            mode.iter()
                .zip(&assigned)
                .all(|(p, a)| *a == 0.0 || (*p == 0.0 && !flat_foldable) || p * a > 0.0)
        };
        let matching: Vec<&[f64; 4]> = modes.iter().filter(fits).collect();
        if matching.is_empty() {
            let names: Vec<&str> = assigned.iter().map(|&a| letter(a)).collect();
            let options: Vec<String> = modes.iter().map(|m| m.iter().map(|&a| letter(a)).collect()).collect();
            return Err(format!(
                "vertex {}: its assignment {} (creases counter-clockwise; 0 unassigned) matches none of the sign patterns of its folding modes from flat ({}; 0: the crease stays flat); a degree-4 vertex leaves flat only along these",
                star.vertex,
                names.concat(),
                if options.is_empty() { "none: the vertex cannot leave flat".to_string() } else { options.join(", ") }
            ));
        }
        let decided = matching.len() == 1 && matching[0].iter().all(|&m| m != 0.0);
        chosen.push(if decided { Some(*matching[0]) } else { None });
    }
    if local_checked > 0 {
        tried.push(format!(
            "{local_checked} degree-4 vertices: each assignment matches a folding mode"
        ));
    }
    if second_order_checked > 0 {
        tried.push(format!(
            "{second_order_checked} vertices of other degrees: each one's signs pass the second-order test at flat on their own (some velocity with those signs closes the vertex to second order); their conditions are not combined"
        ));
    }
    Ok(LocalTests { chosen, tried })
}

/// When every star is a degree-4 vertex whose assignment picks exactly one mode (all four
/// creases moving), and the
/// stars are joined through shared creases: any rigid motion from flat starts (at its
/// lowest order) along each vertex's mode with a positive speed t_v, so a crease shared by
/// v and w needs t_v·m_v = t_w·m_w. The ratios are propagated over the stars; a cycle whose
/// ratios disagree leaves only t = 0, and the assignment cannot fold rigidly. Returns the
/// evidence of such a disagreement.
fn mode_conflict(model: &FoldingModel, chosen: &[Option<[f64; 4]>], exact: f64) -> Option<String> {
    if chosen.is_empty() || chosen.iter().any(Option::is_none) {
        return None;
    }
    let modes: Vec<[f64; 4]> = chosen.iter().map(|m| m.expect("checked above")).collect();
    // (star, slot) of each crease column.
    let mut owners: Vec<Vec<(usize, usize)>> = vec![Vec::new(); model.crease_count()];
    for (s, star) in model.stars.iter().enumerate() {
        for (slot, &c) in star.columns.iter().enumerate() {
            owners[c].push((s, slot));
        }
    }
    let mut speed: Vec<Option<f64>> = vec![None; modes.len()];
    let mut worst: Option<(f64, usize, usize, usize)> = None;
    for root in 0..modes.len() {
        if speed[root].is_some() {
            continue;
        }
        speed[root] = Some(1.0);
        let mut queue = std::collections::VecDeque::from([root]);
        while let Some(v) = queue.pop_front() {
            let tv = speed[v].expect("queued stars have a speed");
            for (slot, &c) in model.stars[v].columns.iter().enumerate() {
                for &(w, other) in &owners[c] {
                    if w == v {
                        continue;
                    }
                    let tw = tv * modes[v][slot] / modes[w][other];
                    match speed[w] {
                        None => {
                            speed[w] = Some(tw);
                            queue.push_back(w);
                        }
                        Some(existing) => {
                            let disagreement = (existing / tw).ln().abs();
                            if disagreement > exact && worst.is_none_or(|(d, ..)| disagreement > d) {
                                worst = Some((disagreement, c, v, w));
                            }
                        }
                    }
                }
            }
        }
    }
    let (disagreement, column, v, w) = worst?;
    Some(format!(
        "every vertex is degree 4 with one folding mode that fits its assignment, but the modes disagree: around a cycle of vertices through crease {} (vertices {} and {}) the speeds they ask for differ by a factor {:.6}, so no motion leaves flat with these signs (only degree-4 vertices, each moving along its mode at its lowest order)",
        model.pattern.creases[column],
        model.stars[v].vertex,
        model.stars[w].vertex,
        disagreement.exp()
    ))
}

fn sign_of(model: &FoldingModel, column: usize) -> f64 {
    match model.pattern.kinds[model.pattern.creases[column]] {
        EdgeKind::Crease(Assignment::Valley) => 1.0,
        EdgeKind::Crease(Assignment::Mountain) => -1.0,
        _ => 0.0,
    }
}

/// M, V, or 0 for a crease that does not move (a U crease in an assignment).
fn letter(sign: f64) -> &'static str {
    if sign > 0.0 {
        "V"
    } else if sign < 0.0 {
        "M"
    } else {
        "0"
    }
}

/// The folding modes of a degree-4 vertex from flat, as velocities of its creases in ray
/// order (largest entry ±1), each line run both ways: the first-order
/// velocities keep the star closed in the plane (Σ ρ̇_j u_j = 0, a plane of velocities) and
/// the second-order term of the holonomy out of the plane vanishes,
/// Σ_{i<j} ρ̇_i ρ̇_j (u_i × u_j)·z = 0: two lines in that plane, each run both ways. None
/// when the vertex is not degree 4 or a mode has a crease that does not move to first
/// order (the signs would then be decided at higher order).
pub fn degree4_modes(star: &Star) -> Option<Vec<[f64; 4]>> {
    degree4_modes_within(star, 1e-9)
}

/// [`degree4_modes`], with a crease whose velocity is below `zero_tolerance` of the
/// largest read as not moving (the pattern's own precision, where its numbers hold fewer
/// digits than 1e-9 rad).
pub fn degree4_modes_within(star: &Star, zero_tolerance: f64) -> Option<Vec<[f64; 4]>> {
    if star.columns.len() != 4 {
        return None;
    }
    let mut direction = 0.0_f64;
    let mut u = [[0.0; 2]; 4];
    for (j, slot) in u.iter_mut().enumerate() {
        *slot = [direction.cos(), direction.sin()];
        direction += star.sector_angles[j];
    }
    // The first-order velocities are the complement of the span of the rows (u_jx) and
    // (u_jy): Gram–Schmidt over those two rows, then over e_0 … e_3 for the complement.
    let mut span: Vec<[f64; 4]> = Vec::new();
    let mut basis: Vec<[f64; 4]> = Vec::new();
    let rows = [
        [u[0][0], u[1][0], u[2][0], u[3][0]],
        [u[0][1], u[1][1], u[2][1], u[3][1]],
    ];
    let unit = |k: usize| {
        let mut e = [0.0; 4];
        e[k] = 1.0;
        e
    };
    for (k, candidate) in rows.into_iter().chain((0..4).map(unit)).enumerate() {
        let mut e = candidate;
        for s in &span {
            let dot: f64 = (0..4).map(|i| s[i] * e[i]).sum();
            (0..4).for_each(|i| e[i] -= dot * s[i]);
        }
        let norm = e.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm > 1e-6 {
            let e = e.map(|x| x / norm);
            span.push(e);
            if k >= 2 {
                basis.push(e);
            }
        } else if k < 2 {
            return None;
        }
    }
    if basis.len() != 2 {
        return None;
    }
    let cross = |i: usize, j: usize| u[i][0] * u[j][1] - u[i][1] * u[j][0];
    let mut q = Matrix2::zeros();
    for a in 0..2 {
        for b in 0..2 {
            let mut sum = 0.0;
            for i in 0..4 {
                for j in (i + 1)..4 {
                    sum += 0.5 * (basis[a][i] * basis[b][j] + basis[b][i] * basis[a][j]) * cross(i, j);
                }
            }
            q[(a, b)] = sum;
        }
    }
    // Lines s·b1 + t·b2 with q = 0: q11 s² + 2 q12 s t + q22 t² = 0.
    let (q11, q12, q22) = (q[(0, 0)], q[(0, 1)], q[(1, 1)]);
    let discriminant = q12 * q12 - q11 * q22;
    let scale = q11.abs().max(q12.abs()).max(q22.abs());
    if discriminant <= 1e-12 * scale * scale {
        return Some(Vec::new());
    }
    // The form is indefinite (λ₁ > 0 > λ₂ with eigenvectors e₁, e₂); its null lines are
    // √(−λ₂) e₁ ± √λ₁ e₂. No division: the form may be 2 q12 s t with q11 = q22 = 0,
    // depending on which crease the star lists first.
    let (mean, radius) = ((q11 + q22) / 2.0, ((q11 - q22) / 2.0).hypot(q12));
    let (larger, smaller) = (mean + radius, mean - radius);
    let phi = 0.5 * (2.0 * q12).atan2(q11 - q22);
    let (e1, e2) = ((phi.cos(), phi.sin()), (-phi.sin(), phi.cos()));
    let (a, b) = ((-smaller).max(0.0).sqrt(), larger.max(0.0).sqrt());
    let directions: Vec<(f64, f64)> = [1.0, -1.0]
        .iter()
        .map(|sign| (a * e1.0 + sign * b * e2.0, a * e1.1 + sign * b * e2.1))
        .collect();
    let mut modes = Vec::new();
    for (s, t) in directions {
        let velocity: Vec<f64> = (0..4).map(|k| s * basis[0][k] + t * basis[1][k]).collect();
        let size = velocity.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        // A crease that does not move to first order (the straight fold through a pair of
        // collinear creases) gets 0: its sign is not decided here.
        let unit = [0, 1, 2, 3].map(|k| {
            if velocity[k].abs() < zero_tolerance * size {
                0.0
            } else {
                velocity[k] / size
            }
        });
        modes.push(unit);
        modes.push(unit.map(|x| -x));
    }
    Some(modes)
}

impl crate::names::Answer for CheckReport {
    fn verdict_name(&self) -> &'static str {
        crate::names::variant_name(&self.verdict)
    }

    fn evidence(&self) -> &str {
        &self.evidence
    }
}
