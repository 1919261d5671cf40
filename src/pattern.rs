//! The crease-pattern model (`docs/model.md#the-vertex`): a validated single vertex — its rays, sectors and
//! creases — that every algorithm reads. Built from numbers with [`VertexBuilder`], or from
//! files by the readers ([`crate::read`]). Patterns of many vertices are [`crease_pattern`].

pub mod crease_pattern;
pub mod generate;
pub mod net;

use crate::error::{NanofoldError, Result};
use crate::geometry::kinematics;
use serde::Serialize;
use std::f64::consts::{PI, TAU};

/// Smallest sector angle accepted, rad: 100 times below the hard case of `docs/model.md`
/// (1e-4 rad), where two nodes are still far apart compared with rounding.
pub const MIN_SECTOR_RAD: f64 = 1e-6;

/// Most rays (creases, split rays and boundary rays) one vertex may have; an unfold
/// iteration costs O(n²) in the energy (512 rays unfold in seconds: docs/guide/limits.md),
/// and a 1000-ray vertex stalled short of flat.
pub const MAX_RAYS: usize = 512;

/// Mountain / valley / flat / unassigned assignment of a crease (FOLD's letters).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Assignment {
    /// Folds away from the viewer: fold angle ≤ 0.
    Mountain,
    /// Folds towards the viewer: fold angle ≥ 0.
    Valley,
    /// A crease held flat (`docs/model.md#the-vertex`: a "virtual" crease, fold angle constrained to 0).
    Flat,
    /// Either way.
    Unassigned,
}

impl Assignment {
    /// Parses FOLD's one-letter code; `field` names the value in errors.
    pub fn from_letter(letter: &str, field: &str) -> Result<Self> {
        match letter {
            "M" | "m" => Ok(Assignment::Mountain),
            "V" | "v" => Ok(Assignment::Valley),
            "F" | "f" => Ok(Assignment::Flat),
            "U" | "u" => Ok(Assignment::Unassigned),
            "C" | "c" | "J" | "j" => Err(NanofoldError::invalid(
                field,
                format!("\"{letter}\""),
                "cut (C) and join (J) edges are not supported yet: the paper must be one disc",
            )),
            other => Err(NanofoldError::invalid(
                field,
                format!("\"{other}\""),
                "expected one of M, V, F, U, B",
            )),
        }
    }

    /// FOLD's letter for this assignment.
    pub fn letter(self) -> &'static str {
        match self {
            Assignment::Mountain => "M",
            Assignment::Valley => "V",
            Assignment::Flat => "F",
            Assignment::Unassigned => "U",
        }
    }
}

/// Whether the sectors form a cycle (interior vertex) or an open fan (boundary vertex).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Chain {
    /// An interior vertex: the sectors go all the way round.
    Closed,
    /// A vertex on the sheet's edge: the sectors end at two boundary rays.
    Open,
}

/// What a ray of the (split) vertex is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RayRole {
    /// A user crease; the index is into [`VertexPattern::creases`].
    Crease(usize),
    /// An end of the sheet at a boundary vertex.
    Boundary,
    /// A flat ray added to split a sector of π or more (`docs/model.md#the-sphere`).
    Virtual,
}

/// A crease as the user wrote it.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, Serialize)]
pub struct Crease {
    /// How errors and outputs name it (`edges[3]`, `creases[1]`).
    pub label: String,
    /// Mountain, valley, flat or unassigned.
    pub assignment: Assignment,
    /// Fold angle of the given folded state, radians, valley positive.
    pub folded_angle: f64,
    /// Held at `folded_angle` while unfolding.
    pub locked: bool,
    /// Index of this crease's ray in [`VertexPattern::rays`].
    pub ray: usize,
    /// FOLD edge index, for FOLD input.
    pub fold_edge: Option<usize>,
}

/// The original FOLD geometry, kept so outputs can be written back on the same mesh.
#[derive(Debug, Clone)]
pub struct FlatMesh {
    /// Vertex positions in the flat pattern.
    pub vertices_coords: Vec<[f64; 2]>,
    /// Edges as vertex pairs.
    pub edges_vertices: Vec<[usize; 2]>,
    /// Every edge's FOLD letter.
    pub edges_assignment: Vec<String>,
    /// Faces as vertex cycles, when given.
    pub faces_vertices: Option<Vec<Vec<usize>>>,
    /// The vertex where the creases meet.
    pub center: usize,
    /// Polar angle of ray 0 in the crease pattern's xy-plane.
    pub ray0_direction: f64,
    /// The file's `frame_unit`, written back on the outputs.
    pub unit: Option<String>,
}

/// A validated single vertex.
#[derive(Debug, Clone)]
pub struct VertexPattern {
    /// Names the pattern (and its output folder).
    pub name: String,
    /// Interior (closed) or boundary (open) vertex.
    pub chain: Chain,
    /// Rays in counter-clockwise order, sectors of π or more already split.
    pub rays: Vec<RayRole>,
    /// Sector k lies between ray k and ray k+1 (cyclically for a closed chain).
    pub sector_angles: Vec<f64>,
    /// User creases in the file's order (FOLD edge order for FOLD input).
    pub creases: Vec<Crease>,
    /// Σα as given, before any adjustment.
    pub angle_sum: f64,
    /// Whether a flat state exists: false for a closed chain with Σα ≠ 2π (a cone).
    pub flat_foldable: bool,
    /// Rules applied to the input (sector rescaling, splits), for the report.
    pub adjustments: Vec<String>,
    /// Loop-closure residual of the given folded state (0 for an open chain).
    pub closure_residual: f64,
    /// The FOLD mesh when the input was a FOLD file.
    pub mesh: Option<FlatMesh>,
}

/// Tolerances applied while loading.
#[derive(Debug, Clone, Copy)]
pub struct LoadOptions {
    /// Largest accepted loop-closure residual of the folded state, radians.
    pub closure_tol: f64,
    /// |Σα − 2π| below which a closed chain is treated as exactly 2π (sectors rescaled).
    pub angle_sum_tol: f64,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            closure_tol: 1e-6,
            angle_sum_tol: 1e-8,
        }
    }
}

impl LoadOptions {
    /// Both tolerances in range: `closure_tol` in (0, 0.1] rad, `angle_sum_tol` in
    /// [0, 1e-3] rad.
    pub fn validate(&self) -> Result<()> {
        if !(self.closure_tol.is_finite() && self.closure_tol > 0.0 && self.closure_tol <= 0.1) {
            return Err(NanofoldError::invalid(
                "closure_tol",
                self.closure_tol,
                "must lie in (0, 0.1] rad",
            ));
        }
        if !(self.angle_sum_tol.is_finite() && (0.0..=1e-3).contains(&self.angle_sum_tol)) {
            return Err(NanofoldError::invalid(
                "angle_sum_tol",
                self.angle_sum_tol,
                "must lie in [0, 1e-3] rad",
            ));
        }
        Ok(())
    }
}

/// One ray handed to a [`VertexBuilder`], counter-clockwise.
#[derive(Debug, Clone)]
pub enum RaySpec {
    /// A crease.
    Crease(CreaseSpec),
    /// An edge of the sheet (the first and last ray of an open chain).
    Boundary,
}

/// A crease as given, before validation.
#[derive(Debug, Clone)]
pub struct CreaseSpec {
    /// How errors and outputs name it (`edges[3]`, `creases[1]`).
    pub label: String,
    /// Mountain, valley, flat or unassigned.
    pub assignment: Assignment,
    /// Fold angle of the given folded state, radians, valley positive.
    pub fold_angle: f64,
    /// Held at `fold_angle` while unfolding.
    pub locked: bool,
    /// FOLD edge index, for FOLD input.
    pub fold_edge: Option<usize>,
    /// Position in the caller's crease order (the order of [`VertexPattern::creases`]).
    pub order: usize,
    /// Name of the fold-angle field, for errors.
    pub angle_field: String,
}

/// Builds a [`VertexPattern`] from numbers: sector angles and creases counter-clockwise.
///
/// ```
/// use nanofold::pattern::{Assignment, VertexBuilder};
/// use std::f64::consts::FRAC_PI_2;
/// // A plus-shaped vertex folded along one straight crease line.
/// let pattern = VertexBuilder::closed("plus")
///     .sector_angles([FRAC_PI_2; 4])
///     .crease(Assignment::Valley, 1.0)
///     .crease(Assignment::Flat, 0.0)
///     .crease(Assignment::Valley, 1.0)
///     .crease(Assignment::Flat, 0.0)
///     .build()?;
/// assert_eq!(pattern.creases.len(), 4);
/// assert!(pattern.closure_residual < 1e-14);
/// # Ok::<(), nanofold::NanofoldError>(())
/// ```
#[derive(Debug, Clone)]
pub struct VertexBuilder {
    /// Names the pattern (and its output folder).
    pub name: String,
    /// Interior (closed) or boundary (open) vertex.
    pub chain: Chain,
    /// Rays counter-clockwise; for an open chain the first and last are [`RaySpec::Boundary`].
    pub rays: Vec<RaySpec>,
    /// Sector k lies between ray k and ray k+1, radians.
    pub sector_angles: Vec<f64>,
    /// `sector_fields[k]` names sector k in errors (defaults to `sector_angles[k]`).
    pub sector_fields: Vec<String>,
    /// The flat mesh the pattern came from, if any (outputs are written on it).
    pub mesh: Option<FlatMesh>,
}

impl VertexBuilder {
    fn new(name: &str, chain: Chain) -> Self {
        VertexBuilder {
            name: name.to_string(),
            chain,
            rays: Vec::new(),
            sector_angles: Vec::new(),
            sector_fields: Vec::new(),
            mesh: None,
        }
    }

    /// An interior vertex: one sector after each crease, summing to 2π.
    pub fn closed(name: &str) -> Self {
        Self::new(name, Chain::Closed)
    }

    /// A boundary vertex: the sheet's edge, the creases, the other edge; one sector more
    /// than creases.
    pub fn open(name: &str) -> Self {
        Self::new(name, Chain::Open)
    }

    /// Sets the sector angles (radians), counter-clockwise from the first ray.
    pub fn sector_angles(mut self, angles: impl IntoIterator<Item = f64>) -> Self {
        self.sector_angles = angles.into_iter().collect();
        self.sector_fields = (0..self.sector_angles.len())
            .map(|k| format!("sector_angles[{k}]"))
            .collect();
        self
    }

    /// Adds the next crease counter-clockwise with its folded angle (radians).
    pub fn crease(self, assignment: Assignment, fold_angle: f64) -> Self {
        self.push_crease(assignment, fold_angle, false)
    }

    /// Adds the next crease, held at its folded angle while unfolding.
    pub fn locked_crease(self, assignment: Assignment, fold_angle: f64) -> Self {
        self.push_crease(assignment, fold_angle, true)
    }

    fn push_crease(mut self, assignment: Assignment, fold_angle: f64, locked: bool) -> Self {
        let order = self.rays.iter().filter(|r| matches!(r, RaySpec::Crease(_))).count();
        self.rays.push(RaySpec::Crease(CreaseSpec {
            label: format!("creases[{order}]"),
            assignment,
            fold_angle,
            locked,
            fold_edge: None,
            order,
            angle_field: format!("creases[{order}].fold_angle"),
        }));
        self
    }

    /// Validates with the default [`LoadOptions`] (`docs/model.md#the-vertex`).
    pub fn build(self) -> Result<VertexPattern> {
        self.build_with(&LoadOptions::default())
    }

    /// Validates and splits sectors of π or more (`docs/model.md#the-vertex`). An open chain built with
    /// [`VertexBuilder::crease`] gets its two boundary rays here.
    pub fn build_with(mut self, options: &LoadOptions) -> Result<VertexPattern> {
        options.validate()?;
        if self.chain == Chain::Open && !matches!(self.rays.first(), Some(RaySpec::Boundary)) {
            self.rays.insert(0, RaySpec::Boundary);
            self.rays.push(RaySpec::Boundary);
        }
        if self.sector_fields.len() != self.sector_angles.len() {
            self.sector_fields = (0..self.sector_angles.len())
                .map(|k| format!("sector_angles[{k}]"))
                .collect();
        }
        VertexPattern::build(self, options)
    }
}

impl VertexPattern {
    /// Validates and splits a builder's vertex (`docs/model.md#the-vertex`).
    fn build(raw: VertexBuilder, options: &LoadOptions) -> Result<VertexPattern> {
        let VertexBuilder {
            name,
            chain,
            rays: raw_rays,
            mut sector_angles,
            sector_fields,
            mesh,
        } = raw;
        if raw_rays.is_empty() {
            return Err(NanofoldError::invalid("creases", 0, "the vertex has no crease"));
        }
        if raw_rays.len() > MAX_RAYS {
            return Err(NanofoldError::invalid(
                "creases",
                format!("{} rays", raw_rays.len()),
                format!("a vertex has at most {MAX_RAYS} rays (an unfold iteration costs O(n²) in the energy)"),
            ));
        }
        let expected_sectors = match chain {
            Chain::Closed => raw_rays.len(),
            Chain::Open => raw_rays.len() - 1,
        };
        if sector_angles.len() != expected_sectors {
            return Err(NanofoldError::invalid(
                "sector_angles",
                format!("{} values", sector_angles.len()),
                format!("expected {expected_sectors} for {} rays", raw_rays.len()),
            ));
        }
        for (alpha, field) in sector_angles.iter().zip(&sector_fields) {
            if !alpha.is_finite() {
                return Err(NanofoldError::invalid(field, alpha, "sector angle must be finite"));
            }
            if *alpha <= 0.0 {
                return Err(NanofoldError::invalid(
                    field,
                    format!("{:.6}°", alpha.to_degrees()),
                    "sector angle must be positive",
                ));
            }
            if *alpha < MIN_SECTOR_RAD {
                return Err(NanofoldError::invalid(
                    field,
                    format!("{alpha:.3e} rad"),
                    format!(
                        "sector angle below {MIN_SECTOR_RAD:.0e} rad: its two creases are one crease to this model (their nodes closer than the energy resolves); merge them"
                    ),
                ));
            }
            // A sector of a full turn or more would overlap itself (and splitting it into
            // quarter turns would need arbitrarily many virtual rays).
            if *alpha >= TAU {
                return Err(NanofoldError::invalid(
                    field,
                    format!("{:.6}°", alpha.to_degrees()),
                    "sector angle must be less than 360°",
                ));
            }
        }
        let creases_given = raw_rays.iter().filter(|r| matches!(r, RaySpec::Crease(_))).count();
        if creases_given == 0 {
            return Err(NanofoldError::invalid("creases", 0, "the vertex has no crease"));
        }
        for ray in &raw_rays {
            if let RaySpec::Crease(c) = ray {
                check_crease_angle(c)?;
            }
        }
        let angle_sum: f64 = sector_angles.iter().sum();
        let mut adjustments = Vec::new();
        let mut flat_foldable = true;
        match chain {
            Chain::Closed => {
                let excess = angle_sum - TAU;
                if excess.abs() <= options.angle_sum_tol {
                    if excess != 0.0 {
                        let scale = TAU / angle_sum;
                        sector_angles.iter_mut().for_each(|a| *a *= scale);
                        adjustments.push(format!(
                            "sector angles sum to 2π{excess:+.3e} rad; rescaled by {scale:.15} to sum to 2π exactly"
                        ));
                    }
                } else {
                    flat_foldable = false;
                }
            }
            Chain::Open => {
                if angle_sum > TAU + 1e-12 {
                    return Err(NanofoldError::invalid(
                        "sector_angles",
                        format!("sum {:.9}°", angle_sum.to_degrees()),
                        "a boundary vertex cannot have more than 360° of paper",
                    ));
                }
            }
        }

        // Split sectors of π or more with virtual flat rays (`docs/model.md#the-sphere`).
        let mut rays = Vec::new();
        let mut sectors = Vec::new();
        let mut creases: Vec<Option<Crease>> = vec![None; creases_given];
        for (k, raw_ray) in raw_rays.iter().enumerate() {
            let ray_index = rays.len();
            match raw_ray {
                RaySpec::Boundary => rays.push(RayRole::Boundary),
                RaySpec::Crease(c) => {
                    rays.push(RayRole::Crease(c.order));
                    creases[c.order] = Some(Crease {
                        label: c.label.clone(),
                        assignment: c.assignment,
                        folded_angle: c.fold_angle,
                        locked: c.locked,
                        ray: ray_index,
                        fold_edge: c.fold_edge,
                    });
                }
            }
            if k < sector_angles.len() {
                let alpha = sector_angles[k];
                let pieces = if alpha >= PI {
                    (alpha / (PI / 2.0)).ceil() as usize
                } else {
                    1
                };
                if pieces > 1 {
                    adjustments.push(format!(
                        "sector {k} ({:.3}°) split into {pieces} by virtual flat rays",
                        alpha.to_degrees()
                    ));
                }
                for piece in 0..pieces {
                    if piece > 0 {
                        rays.push(RayRole::Virtual);
                    }
                    sectors.push(alpha / pieces as f64);
                }
            }
        }
        let creases: Vec<Crease> = creases
            .into_iter()
            .enumerate()
            .map(|(i, c)| c.ok_or_else(|| NanofoldError::invalid("creases", i, "crease order has a gap")))
            .collect::<Result<_>>()?;

        let mut pattern = VertexPattern {
            name,
            chain,
            rays,
            sector_angles: sectors,
            creases,
            angle_sum,
            flat_foldable,
            adjustments,
            closure_residual: 0.0,
            mesh,
        };
        if chain == Chain::Closed {
            let residual = kinematics::closure_residual(&pattern.sector_angles, &pattern.folded_ray_angles());
            pattern.closure_residual = residual;
            if residual.is_nan() || residual > options.closure_tol {
                let field = if pattern.mesh.is_some() {
                    "edges_foldAngle"
                } else {
                    "creases[].fold_angle"
                };
                return Err(NanofoldError::ClosureViolated {
                    field: field.to_string(),
                    residual,
                    tolerance: options.closure_tol,
                });
            }
        }
        Ok(pattern)
    }

    /// Fold angle of every ray in the given folded state (0 for boundary and virtual rays).
    pub fn folded_ray_angles(&self) -> Vec<f64> {
        self.rays
            .iter()
            .map(|role| match role {
                RayRole::Crease(i) => self.creases[*i].folded_angle,
                _ => 0.0,
            })
            .collect()
    }

    /// Number of rays after splitting.
    pub fn ray_count(&self) -> usize {
        self.rays.len()
    }

    /// Polar angle of every ray in the flat pattern, ray 0 at 0.
    pub fn flat_ray_directions(&self) -> Vec<f64> {
        let mut directions = Vec::with_capacity(self.rays.len());
        let mut phi = 0.0;
        for k in 0..self.rays.len() {
            directions.push(phi);
            if k < self.sector_angles.len() {
                phi += self.sector_angles[k];
            }
        }
        directions
    }

    /// The index a user types for crease `i`: its FOLD edge index for FOLD input, its
    /// position in `creases` for the native schema.
    pub fn user_index(&self, crease: usize) -> usize {
        self.creases[crease].fold_edge.unwrap_or(crease)
    }

    /// The crease a user index names, if any (inverse of [`VertexPattern::user_index`]).
    pub fn crease_from_user_index(&self, index: usize) -> Option<usize> {
        (0..self.creases.len()).find(|&i| self.user_index(i) == index)
    }

    /// Every valid user index, for error messages.
    pub fn user_indices(&self) -> Vec<usize> {
        (0..self.creases.len()).map(|i| self.user_index(i)).collect()
    }

    /// Degrees of freedom of the folded vertex: n − 3 for a closed chain, n − 2 crease
    /// rays for an open one, less one per held crease (locked or flat).
    pub fn degrees_of_freedom(&self) -> i64 {
        let held = self
            .rays
            .iter()
            .filter(|r| match r {
                RayRole::Virtual => true,
                RayRole::Crease(i) => self.creases[*i].locked || self.creases[*i].assignment == Assignment::Flat,
                RayRole::Boundary => false,
            })
            .count() as i64;
        let folds = self.rays.iter().filter(|r| !matches!(r, RayRole::Boundary)).count() as i64;
        match self.chain {
            Chain::Closed => folds - 3 - held,
            Chain::Open => folds - held,
        }
    }
}

/// Range and sign checks of one crease's folded angle (`docs/model.md#conventions`).
fn check_crease_angle(c: &CreaseSpec) -> Result<()> {
    let rho = c.fold_angle;
    let shown = format!("{:.6}°", rho.to_degrees());
    if !rho.is_finite() {
        return Err(NanofoldError::invalid(&c.angle_field, rho, "fold angle must be finite"));
    }
    if rho.abs() > PI + 1e-12 {
        return Err(NanofoldError::invalid(
            &c.angle_field,
            shown,
            "fold angle must lie in [−180°, 180°]",
        ));
    }
    const SIGN_TOL: f64 = 1e-9;
    let contradiction = match c.assignment {
        Assignment::Mountain => rho > SIGN_TOL,
        Assignment::Valley => rho < -SIGN_TOL,
        Assignment::Flat => rho.abs() > SIGN_TOL,
        Assignment::Unassigned => false,
    };
    if contradiction {
        let rule = match c.assignment {
            Assignment::Mountain => "a mountain (M) crease needs a fold angle ≤ 0",
            Assignment::Valley => "a valley (V) crease needs a fold angle ≥ 0",
            _ => "a flat (F) crease needs fold angle 0",
        };
        return Err(NanofoldError::invalid(
            &c.angle_field,
            shown,
            format!("{rule} ({})", c.label),
        ));
    }
    Ok(())
}
