//! Single-vertex crease patterns (SPEC §2): the validated description every other module
//! reads, built from a FOLD file ([`fold`]) or the native JSON schema ([`native`]).

pub mod fold;
pub mod native;

use crate::error::{NanofoldError, Result};
use crate::kinematics;
use serde::Serialize;
use std::f64::consts::{PI, TAU};
use std::path::Path;

/// Mountain / valley / flat / unassigned assignment of a crease (FOLD's letters).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Assignment {
    Mountain,
    Valley,
    /// A crease held flat (SPEC §2: a "virtual" crease, fold angle constrained to 0).
    Flat,
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
                "cut (C) and join (J) edges are not supported by a single-vertex model",
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
    Closed,
    Open,
}

/// What a ray of the (split) vertex is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RayRole {
    /// A user crease; the index is into [`Pattern::creases`].
    Crease(usize),
    /// An end of the sheet at a boundary vertex.
    Boundary,
    /// A flat ray added to split a sector of π or more (SPEC §3).
    Virtual,
}

/// A crease as the user wrote it.
#[derive(Debug, Clone, Serialize)]
pub struct Crease {
    /// How errors and outputs name it ("edges[3]", "creases[1]").
    pub label: String,
    pub assignment: Assignment,
    /// Fold angle of the given folded state, radians, valley positive.
    pub folded_angle: f64,
    /// Held at `folded_angle` while unfolding.
    pub locked: bool,
    /// Index of this crease's ray in [`Pattern::rays`].
    pub ray: usize,
    /// FOLD edge index, for FOLD input.
    pub fold_edge: Option<usize>,
}

/// The original FOLD geometry, kept so outputs can be written back on the same mesh.
#[derive(Debug, Clone)]
pub struct FoldMesh {
    pub vertices_coords: Vec<[f64; 2]>,
    pub edges_vertices: Vec<[usize; 2]>,
    pub edges_assignment: Vec<String>,
    pub faces_vertices: Option<Vec<Vec<usize>>>,
    pub center: usize,
    /// Polar angle of ray 0 in the crease pattern's xy-plane.
    pub ray0_direction: f64,
}

/// A validated single vertex.
#[derive(Debug, Clone)]
pub struct Pattern {
    pub name: String,
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
    pub mesh: Option<FoldMesh>,
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

/// A ray as an importer sees it, before validation and splitting.
#[derive(Debug, Clone)]
pub(crate) enum RawRay {
    Crease(RawCrease),
    Boundary,
}

#[derive(Debug, Clone)]
pub(crate) struct RawCrease {
    pub label: String,
    pub assignment: Assignment,
    pub folded_angle: f64,
    pub locked: bool,
    pub fold_edge: Option<usize>,
    /// Position in the file's crease order.
    pub order: usize,
    /// Name of the fold-angle field, for errors.
    pub angle_field: String,
}

/// What an importer hands to [`Pattern::build`].
pub(crate) struct RawVertex {
    pub name: String,
    pub chain: Chain,
    /// Rays CCW; for an open chain the first and last are `Boundary`.
    pub rays: Vec<RawRay>,
    /// Sector k between ray k and k+1; `sector_fields[k]` names it in errors.
    pub sector_angles: Vec<f64>,
    pub sector_fields: Vec<String>,
    pub mesh: Option<FoldMesh>,
}

/// Is this a pattern file (a FOLD file or a native vertex, not a scene)?
pub fn is_pattern_file(path: &Path) -> bool {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    (name.ends_with(".fold") || name.ends_with(".json")) && !name.ends_with(".scene.json")
}

/// A pattern's name: its file name without `.fold` or `.json` (names output folders).
pub fn pattern_name(path: &Path) -> String {
    path.file_name()
        .and_then(|s| s.to_str())
        .map(|s| s.trim_end_matches(".json").trim_end_matches(".fold").to_string())
        .unwrap_or_else(|| "pattern".to_string())
}

impl Pattern {
    /// Loads a `.fold` file or a native `.json` vertex (decided by content: a FOLD file has
    /// `vertices_coords`).
    pub fn load(path: &Path, options: &LoadOptions) -> Result<Pattern> {
        let text = std::fs::read_to_string(path).map_err(|error| NanofoldError::Io {
            path: path.display().to_string(),
            error,
        })?;
        let name = pattern_name(path);
        Self::from_str(&text, &name, &path.display().to_string(), options)
    }

    /// Parses pattern text; `origin` names it in error messages.
    pub fn from_str(text: &str, name: &str, origin: &str, options: &LoadOptions) -> Result<Pattern> {
        let value: serde_json::Value = serde_json::from_str(text).map_err(|e| NanofoldError::Json {
            path: origin.to_string(),
            message: e.to_string(),
        })?;
        let raw = if value.get("vertices_coords").is_some() {
            fold::read_fold(&value, name)?
        } else {
            native::read_native(&value, name)?
        };
        Pattern::build(raw, options)
    }

    /// Validates and splits an importer's vertex (SPEC §2, §3).
    pub(crate) fn build(raw: RawVertex, options: &LoadOptions) -> Result<Pattern> {
        let RawVertex {
            name,
            chain,
            rays: raw_rays,
            mut sector_angles,
            sector_fields,
            mesh,
        } = raw;
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
        let creases_given = raw_rays.iter().filter(|r| matches!(r, RawRay::Crease(_))).count();
        if creases_given == 0 {
            return Err(NanofoldError::invalid("creases", 0, "the vertex has no crease"));
        }
        for ray in &raw_rays {
            if let RawRay::Crease(c) = ray {
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

        // Split sectors of π or more with virtual flat rays (SPEC §3).
        let mut rays = Vec::new();
        let mut sectors = Vec::new();
        let mut creases: Vec<Option<Crease>> = vec![None; creases_given];
        for (k, raw_ray) in raw_rays.iter().enumerate() {
            let ray_index = rays.len();
            match raw_ray {
                RawRay::Boundary => rays.push(RayRole::Boundary),
                RawRay::Crease(c) => {
                    rays.push(RayRole::Crease(c.order));
                    creases[c.order] = Some(Crease {
                        label: c.label.clone(),
                        assignment: c.assignment,
                        folded_angle: c.folded_angle,
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

        let mut pattern = Pattern {
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

    /// The crease a user index names, if any (inverse of [`Pattern::user_index`]).
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

/// Range and sign checks of one crease's folded angle (SPEC §1).
fn check_crease_angle(c: &RawCrease) -> Result<()> {
    let rho = c.folded_angle;
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
