//! Closed-chain scenes (`*.scene.json` with a `pattern`): a single-vertex FOLD pattern whose
//! faces are the plates, which crease is cut, which one drives, which are locked, the
//! hinges, and where f comes from (SPEC §6–8). Builds a [`ClosedChain`] in SI units.

use super::{
    drag_law, finite, hinge_stiffness, material, positive, validate_materials, ActuationSpec, EnvironmentSpec,
    HingeSpec, LayerSpec, MaterialSpec, OutputSpec, TimeSpec, MICROMETRE,
};
use crate::constraints::exact::ExactConstraint;
use crate::constraints::{sweep_samples, ConstraintPoly, Setup};
use crate::dynamics::closed::{ClosedChain, ConstraintSource};
use crate::dynamics::{Joint, Model, Plate};
use crate::error::{NanofoldError, Result};
use crate::pattern::{Chain, LoadOptions, Pattern, RayRole};
use crate::scene::Actuation;
use nalgebra::{Point3, Unit, Vector3};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::f64::consts::TAU;
use std::path::Path;

/// Every sector plate: one structural layer.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SectorPlateSpec {
    pub thickness_um: f64,
    pub material: String,
}

/// The hinge of one crease (`crease`: the FOLD edge index); the other fields as in a strip
/// scene's hinge, the width being the crease's length.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CreaseHingeSpec {
    pub crease: usize,
    pub hinge_length_um: f64,
    pub layers: Vec<LayerSpec>,
    pub actuated: bool,
    #[serde(default)]
    pub target_angle_deg: Option<f64>,
    #[serde(default)]
    pub radius_of_curvature_um: Option<f64>,
}

impl CreaseHingeSpec {
    fn hinge(&self) -> HingeSpec {
        HingeSpec {
            hinge_length_um: self.hinge_length_um,
            layers: self.layers.clone(),
            actuated: self.actuated,
            target_angle_deg: self.target_angle_deg,
            radius_of_curvature_um: self.radius_of_curvature_um,
        }
    }
}

/// A crease held at an angle during this step.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LockSpec {
    pub crease: usize,
    pub angle_deg: f64,
}

/// Where f comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SourceKind {
    Poly,
    Exact,
}

fn default_constraint_samples() -> usize {
    401
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstraintSpec {
    pub source: SourceKind,
    /// Polynomial degree (poly only).
    #[serde(default)]
    pub degree: Option<usize>,
    /// Exact sweep samples the fit (and the exact source's branch) use.
    #[serde(default = "default_constraint_samples")]
    pub samples: usize,
    /// Driving-angle range [a, b] in degrees; default from the start to the target.
    #[serde(default)]
    pub range_deg: Option<[f64; 2]>,
}

/// A closed-chain scene file as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClosedSceneFile {
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub description: Option<String>,
    /// A FOLD file (relative to the scene file) with `faces_vertices`: its faces are the plates.
    pub pattern: String,
    /// One FOLD coordinate unit in µm.
    pub length_unit_um: f64,
    pub materials: BTreeMap<String, MaterialSpec>,
    pub plates: SectorPlateSpec,
    /// One hinge per crease.
    pub hinges: Vec<CreaseHingeSpec>,
    /// The unactuated crease where the loop is cut (FOLD edge index); the sector after it
    /// (counter-clockwise) is anchored.
    pub cut_crease: usize,
    #[serde(default)]
    pub locks: Vec<LockSpec>,
    /// The driving crease's angle at rest at t = 0, degrees.
    #[serde(default)]
    pub start_angle_deg: f64,
    pub constraint: ConstraintSpec,
    pub actuation: ActuationSpec,
    pub environment: EnvironmentSpec,
    pub time: TimeSpec,
    #[serde(default)]
    pub outputs: OutputSpec,
}

/// A loaded closed-chain scene.
#[derive(Debug, Clone)]
pub struct ClosedScene {
    pub name: String,
    pub pattern: Pattern,
    pub chain: ClosedChain,
    pub t_end: f64,
    pub outputs: OutputSpec,
    /// Largest |f − exact| of the fit over the sweep samples, rad (0 for `exact`).
    pub fit_error: f64,
    /// Largest |f′ − G| of the fit over the regular sweep samples, G by the implicit function
    /// theorem (0 for `exact`).
    pub slope_error: f64,
}

/// Whether a scene file's text describes a closed chain (it names a `pattern`).
pub fn is_closed_scene(text: &str) -> bool {
    serde_json::from_str::<serde_json::Value>(text).is_ok_and(|v| v.get("pattern").is_some())
}

impl ClosedScene {
    pub fn load(path: &Path) -> Result<ClosedScene> {
        let text = std::fs::read_to_string(path).map_err(|error| NanofoldError::Io {
            path: path.display().to_string(),
            error,
        })?;
        let stem = path.file_name().and_then(|n| n.to_str()).unwrap_or("scene");
        let fallback = stem.strip_suffix(".scene.json").unwrap_or(stem);
        let base = path.parent().unwrap_or(Path::new("."));
        Self::from_json(&text, &path.display().to_string(), fallback, base)
    }

    /// Parses a closed-chain scene; `base` is the scene file's directory (for `pattern`).
    pub fn from_json(text: &str, source: &str, fallback_name: &str, base: &Path) -> Result<ClosedScene> {
        let file: ClosedSceneFile = serde_json::from_str(text).map_err(|e| NanofoldError::Json {
            path: source.to_string(),
            message: e.to_string(),
        })?;
        Self::from_file(file, fallback_name, base)
    }

    pub fn from_file(file: ClosedSceneFile, fallback_name: &str, base: &Path) -> Result<ClosedScene> {
        validate_materials(&file.materials)?;
        let pattern = Pattern::load(&base.join(&file.pattern), &LoadOptions::default())?;
        if pattern.chain != Chain::Closed {
            return Err(NanofoldError::invalid(
                "pattern",
                &file.pattern,
                "a closed-chain scene needs an interior vertex (a closed loop of sectors)",
            ));
        }
        if pattern.rays.iter().any(|r| matches!(r, RayRole::Virtual)) {
            return Err(NanofoldError::invalid(
                "pattern",
                &file.pattern,
                "sectors of 180° or more are not supported as plates: add a crease that splits them",
            ));
        }
        let mesh = pattern.mesh.clone().ok_or_else(|| {
            NanofoldError::invalid(
                "pattern",
                &file.pattern,
                "must be a FOLD file (its faces are the plates)",
            )
        })?;
        let faces = mesh.faces_vertices.clone().ok_or_else(|| NanofoldError::MissingField {
            field: format!("{}: faces_vertices (the plate outlines)", file.pattern),
        })?;
        let unit = positive("length_unit_um", file.length_unit_um)? * MICROMETRE;
        let user = |field: &str, index: usize| {
            pattern.crease_from_user_index(index).ok_or_else(|| {
                NanofoldError::invalid(
                    field,
                    index,
                    format!(
                        "not a crease of {} (creases: {:?})",
                        file.pattern,
                        pattern.user_indices()
                    ),
                )
            })
        };
        let creases = pattern.creases.len();
        let rays = pattern.rays.len();

        // Geometry: ray directions in the pattern's plane, centred at the vertex.
        let centre = mesh.vertices_coords[mesh.center];
        let mut ray_direction = vec![mesh.ray0_direction; rays];
        for r in 1..rays {
            ray_direction[r] = ray_direction[r - 1] + pattern.sector_angles[r - 1];
        }
        let mut crease_ends = vec![Point3::origin(); creases];
        let mut crease_lengths = vec![0.0; creases];
        for (c, crease) in pattern.creases.iter().enumerate() {
            let edge = mesh.edges_vertices[crease.fold_edge.unwrap_or(c)];
            let other = if edge[0] == mesh.center { edge[1] } else { edge[0] };
            let [x, y] = mesh.vertices_coords[other];
            crease_ends[c] = Point3::new((x - centre[0]) * unit, (y - centre[1]) * unit, 0.0);
            crease_lengths[c] = crease_ends[c].coords.norm();
        }
        // Each face's sector: the one its centroid's direction falls in.
        let mut outlines: Vec<Option<Vec<[f64; 2]>>> = vec![None; rays];
        for (i, face) in faces.iter().enumerate() {
            let mut points: Vec<[f64; 2]> = face
                .iter()
                .map(|&v| {
                    let [x, y] = mesh.vertices_coords[v];
                    [(x - centre[0]) * unit, (y - centre[1]) * unit]
                })
                .collect();
            let signed_area: f64 = (0..points.len())
                .map(|k| {
                    let (a, b) = (points[k], points[(k + 1) % points.len()]);
                    a[0] * b[1] - b[0] * a[1]
                })
                .sum();
            if signed_area < 0.0 {
                points.reverse();
            }
            if !is_convex(&points) {
                return Err(NanofoldError::invalid(
                    format!("{}: faces_vertices[{i}]", file.pattern),
                    format!("{face:?}"),
                    "plates must be convex polygons",
                ));
            }
            let n = points.len() as f64;
            let (cx, cy) = points.iter().fold((0.0, 0.0), |(a, b), p| (a + p[0] / n, b + p[1] / n));
            let angle = (cy.atan2(cx) - mesh.ray0_direction).rem_euclid(TAU);
            let sector = (0..rays)
                .rev()
                .find(|&r| ray_direction[r] - mesh.ray0_direction <= angle)
                .unwrap_or(0);
            if outlines[sector].replace(points).is_some() {
                return Err(NanofoldError::invalid(
                    format!("{}: faces_vertices[{i}]", file.pattern),
                    format!("{face:?}"),
                    format!("a second face in sector {sector}: one face per sector"),
                ));
            }
        }

        // Hinges, one per crease.
        let hinges: Vec<HingeSpec> = file.hinges.iter().map(CreaseHingeSpec::hinge).collect();
        let mut hinge_of: Vec<Option<&HingeSpec>> = vec![None; creases];
        let mut stiffness = vec![0.0; creases];
        for (i, spec) in file.hinges.iter().enumerate() {
            let c = user(&format!("hinges[{i}].crease"), spec.crease)?;
            if hinge_of[c].replace(&hinges[i]).is_some() {
                return Err(NanofoldError::invalid(
                    format!("hinges[{i}].crease"),
                    spec.crease,
                    "this crease already has a hinge",
                ));
            }
            stiffness[c] = hinge_stiffness(&file.materials, i, &hinges[i], crease_lengths[c])?;
        }
        if let Some(c) = hinge_of.iter().position(Option::is_none) {
            return Err(NanofoldError::MissingField {
                field: format!("hinges: an entry with crease {}", pattern.user_index(c)),
            });
        }
        let actuated: Vec<usize> = (0..creases)
            .filter(|&c| hinge_of[c].is_some_and(|h| h.actuated))
            .collect();
        let [driver] = actuated[..] else {
            return Err(NanofoldError::invalid(
                "hinges[*].actuated",
                format!("{} actuated", actuated.len()),
                "a closed-chain step drives exactly one crease; lock the others",
            ));
        };
        let driver_hinge = hinge_of[driver].expect("every crease has a hinge");
        let target_field = "hinges[driver].target_angle_deg";
        let target_deg = driver_hinge
            .target_angle_deg
            .ok_or_else(|| NanofoldError::MissingField {
                field: target_field.into(),
            })?;
        finite(target_field, target_deg)?;
        let cut = user("cut_crease", file.cut_crease)?;
        if cut == driver {
            return Err(NanofoldError::invalid(
                "cut_crease",
                file.cut_crease,
                "cannot cut the actuated crease: its torque would have no hinge to act on (T4.16 cuts an unactuated one)",
            ));
        }
        let mut locks = Vec::new();
        for (i, lock) in file.locks.iter().enumerate() {
            let c = user(&format!("locks[{i}].crease"), lock.crease)?;
            locks.push((
                c,
                finite(&format!("locks[{i}].angle_deg"), lock.angle_deg)?.to_radians(),
            ));
        }
        let free = creases as i64 - locks.len() as i64 - 3;
        if free != 1 {
            return Err(NanofoldError::invalid(
                "locks",
                format!("{} lock(s)", locks.len()),
                format!(
                    "{creases} creases with {} locked leave {free} degree(s) of freedom (loop closure removes 3); a closed-chain step needs exactly 1",
                    locks.len()
                ),
            ));
        }
        let setup = Setup::new(&pattern, driver, &locks)?;
        let start = finite("start_angle_deg", file.start_angle_deg)?.to_radians();
        let target = target_deg.to_radians();
        let domain = match file.constraint.range_deg {
            Some([a, b]) => {
                let field = "constraint.range_deg";
                if !(a.is_finite() && b.is_finite() && a < b) {
                    return Err(NanofoldError::invalid(
                        field,
                        format!("[{a}, {b}]"),
                        "needs finite [A, B] with A < B",
                    ));
                }
                if a < -180.0 || b > 180.0 {
                    return Err(NanofoldError::invalid(
                        field,
                        format!("[{a}, {b}]"),
                        "fold angles lie in [−180°, 180°]",
                    ));
                }
                [a.to_radians(), b.to_radians()]
            }
            None => [start.min(target), start.max(target)],
        };
        let samples = sweep_samples(&pattern, &setup, domain, file.constraint.samples)?;
        let (source, fit_error, slope_error) = match (file.constraint.source, file.constraint.degree) {
            (SourceKind::Poly, Some(degree)) => {
                let poly = ConstraintPoly::fit(&pattern, &samples, degree)?;
                let largest = |errors: &[f64]| errors.iter().copied().fold(0.0, f64::max);
                let (error, slope) = (largest(&poly.max_fit_error), largest(&poly.max_slope_error));
                (ConstraintSource::Poly(poly), error, slope)
            }
            (SourceKind::Poly, None) => {
                return Err(NanofoldError::MissingField {
                    field: "constraint.degree (needed by source \"poly\")".into(),
                })
            }
            (SourceKind::Exact, Some(degree)) => {
                return Err(NanofoldError::invalid(
                    "constraint.degree",
                    degree,
                    "only the \"poly\" source has a degree",
                ))
            }
            (SourceKind::Exact, None) => (
                ConstraintSource::Exact(ExactConstraint::new(&pattern, &samples)),
                0.0,
                0.0,
            ),
        };
        if start < domain[0] - 1e-12 || start > domain[1] + 1e-12 {
            return Err(NanofoldError::invalid(
                "start_angle_deg",
                file.start_angle_deg,
                "must lie inside constraint.range_deg",
            ));
        }

        // The open chain: from the ray after the cut, counter-clockwise.
        let thickness = positive("plates.thickness_um", file.plates.thickness_um)? * MICROMETRE;
        let density = material(&file.materials, "plates.material", &file.plates.material)?.density_g_cm3 * 1e3;
        let cut_ray = pattern.creases[cut].ray;
        let ray_crease = |r: usize| match pattern.rays[r] {
            RayRole::Crease(c) => c,
            _ => unreachable!("closed chains without virtual rays have a crease on every ray"),
        };
        let outline = |r: usize| {
            outlines[r].clone().ok_or_else(|| {
                NanofoldError::invalid(
                    format!("{}: faces_vertices", file.pattern),
                    format!("sector {r}"),
                    "no face covers this sector",
                )
            })
        };
        let mut joints = Vec::new();
        let mut plates = Vec::new();
        let mut joint_creases = Vec::new();
        for step in 1..rays {
            let r = (cut_ray + step) % rays;
            let c = ray_crease(r);
            joints.push(Joint {
                axis: Unit::new_normalize(Vector3::new(ray_direction[r].cos(), ray_direction[r].sin(), 0.0)),
                point: Point3::origin(),
                stiffness: stiffness[c],
            });
            plates.push(Plate::lamina(&outline(r)?, thickness, density));
            joint_creases.push(c);
        }
        let ground = outline(cut_ray)?.iter().map(|&[x, y]| Point3::new(x, y, 0.0)).collect();
        let actuation = match file.actuation {
            ActuationSpec::Step => Actuation::Step,
            ActuationSpec::Ramp { etch_rate_um_per_min } => Actuation::Ramp {
                etch_rate: positive("actuation.etch_rate_um_per_min", etch_rate_um_per_min)? * MICROMETRE / 60.0,
                radius_of_curvature: Vec::new(),
            },
        };
        let radius_of_curvature = match actuation {
            Actuation::Step => f64::INFINITY,
            Actuation::Ramp { .. } => {
                let field = "hinges[driver].radius_of_curvature_um";
                positive(
                    field,
                    driver_hinge
                        .radius_of_curvature_um
                        .ok_or_else(|| NanofoldError::MissingField { field: field.into() })?,
                )? * MICROMETRE
            }
        };
        let t_end = positive("time.t_end_s", file.time.t_end_s)?;
        if file.outputs.samples < 2 {
            return Err(NanofoldError::invalid(
                "outputs.samples",
                file.outputs.samples,
                "need at least 2",
            ));
        }
        let chain = ClosedChain {
            model: Model {
                joints,
                plates,
                drag: drag_law(&file.environment)?,
            },
            joint_creases,
            ground,
            cut_crease: cut,
            crease_stiffness: stiffness,
            crease_labels: pattern.creases.iter().map(|c| c.label.clone()).collect(),
            crease_ends,
            driver,
            locked: setup.locked.clone(),
            dependents: setup.dependents.clone(),
            source,
            sector_angles: pattern.sector_angles.clone(),
            crease_rays: pattern.creases.iter().map(|c| c.ray).collect(),
            start,
            target,
            actuation,
            radius_of_curvature,
        };
        Ok(ClosedScene {
            name: file.name.clone().unwrap_or_else(|| fallback_name.to_string()),
            pattern,
            chain,
            t_end,
            outputs: file.outputs.clone(),
            fit_error,
            slope_error,
        })
    }
}

fn is_convex(points: &[[f64; 2]]) -> bool {
    let n = points.len();
    n >= 3
        && (0..n).all(|k| {
            let (a, b, c) = (points[k], points[(k + 1) % n], points[(k + 2) % n]);
            (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]) >= -1e-12 * (1.0 + a[0].abs() + a[1].abs())
        })
}
