//! The closed-chain pipeline: a validated [`ClosedSpec`] → the constraint's exact sweep →
//! its fit (or the exact source) → the tree of sector plates rooted at the anchored face
//! (`docs/model.md#closed-chains`). Loaders never call this; building a scene does.

use super::{ClosedChain, ConstraintSource};
use crate::constraints::exact::ExactConstraint;
use crate::constraints::{sweep_samples, ConstraintPoly, Setup};
use crate::dynamics::forcing::{Actuation, Forcing, HingeDrive};
use crate::dynamics::model::{Joint, Model, Plate};
use crate::dynamics::spec::{actuation, drag_law, hinge_stiffness};
use crate::error::{NanofoldError, Result};
use crate::pattern::{Chain, FlatMesh, RayRole, VertexPattern};
use crate::read::scene_spec::{
    count_within, finite, limits, material, validate_materials, within, ClosedSpec, CreaseHingeSpec, HingeSpec,
    SourceKind, MICROMETRE,
};
use nalgebra::{Point3, Unit, Vector3};
use std::f64::consts::TAU;

/// The flat geometry of the sectors in SI units, centred at the vertex.
struct SectorGeometry {
    /// Polar angle of every ray.
    ray_direction: Vec<f64>,
    /// The far end of every crease (file order), m.
    crease_ends: Vec<Point3<f64>>,
    /// The face covering every sector, counter-clockwise outline in m, and its FOLD index.
    outlines: Vec<Option<(Vec<[f64; 2]>, usize)>>,
}

/// The hinges of every crease: stiffness and spec, one per crease (file order).
struct Hinges {
    stiffness: Vec<f64>,
    spec: Vec<HingeSpec>,
    of_crease: Vec<usize>,
}

/// What one step of the closed chain does: the driver and its target, the cut, the locks
/// as a constraint setup, the start and the swept domain.
struct Step {
    driver: usize,
    target: f64,
    cut: usize,
    setup: Setup,
    start: f64,
    domain: [f64; 2],
}

/// Assembles the closed chain a scene describes: validates the pattern and the hinges,
/// sets up the step, sweeps and fits the constraint, and builds the tree of sector plates.
pub fn closed_chain(spec: &ClosedSpec<VertexPattern>) -> Result<ClosedChain> {
    validate_materials(&spec.materials)?;
    let pattern = &spec.pattern;
    let mesh = check_pattern(pattern)?;
    let unit = within("length_unit_um", spec.length_unit_um, limits::LENGTH_UNIT_UM, "µm")? * MICROMETRE;
    let geometry = sector_geometry(pattern, mesh, unit)?;
    let hinges = crease_hinges(spec, &geometry)?;
    let step = step_of(spec, &hinges)?;
    let source = constraint_source(spec, &step)?;
    let ground_sector = anchored_sector(spec, &geometry, &step)?;
    let (model, joint_creases, joint_sectors) = sector_tree(spec, &geometry, &hinges, &step, ground_sector)?;
    let outline = outline_of(pattern, &geometry, ground_sector)?;
    let ground = outline.iter().map(|&[x, y]| Point3::new(x, y, 0.0)).collect();
    let actuation = actuation(&spec.actuation)?;
    let driver_hinge = &hinges.spec[hinges.of_crease[step.driver]];
    let mut drives = vec![HingeDrive::PASSIVE; pattern.creases.len()];
    drives[step.driver] = HingeDrive {
        target: step.target,
        radius_of_curvature: match actuation {
            Actuation::Step => f64::INFINITY,
            Actuation::Ramp { .. } => {
                let field = "hinges[driver].radius_of_curvature_um";
                within(
                    field,
                    driver_hinge
                        .radius_of_curvature_um
                        .ok_or_else(|| NanofoldError::missing(field))?,
                    limits::LENGTH_UM,
                    "µm",
                )? * MICROMETRE
            }
        },
        actuated: true,
        release_time: 0.0,
    };
    let anchored_face = geometry.outlines[ground_sector]
        .as_ref()
        .map(|(_, f)| *f)
        .expect("the anchored sector has a face");
    Ok(ClosedChain {
        model,
        joint_creases,
        joint_sectors,
        ground_sector,
        ground,
        cut_crease: step.cut,
        crease_stiffness: hinges.stiffness,
        crease_labels: pattern.creases.iter().map(|c| c.label.clone()).collect(),
        crease_ends: geometry.crease_ends,
        driver: step.driver,
        locked: step.setup.locked.clone(),
        dependents: step.setup.dependents.clone(),
        source,
        sector_angles: pattern.sector_angles.clone(),
        crease_rays: pattern.creases.iter().map(|c| c.ray).collect(),
        start: step.start,
        crease_user_indices: pattern.user_indices(),
        anchored_face,
        sector_faces: geometry.outlines.iter().map(|o| o.as_ref().map(|(_, f)| *f)).collect(),
        vertex: {
            let [x, y] = mesh.vertices_coords[mesh.center];
            [x * unit, y * unit]
        },
        forcing: Forcing {
            actuation,
            hinges: drives,
        },
    })
}

/// The crease a scene field names by its FOLD edge index.
fn crease_of(pattern: &VertexPattern, field: &str, index: usize) -> Result<usize> {
    pattern.crease_from_user_index(index).ok_or_else(|| {
        NanofoldError::invalid(
            field,
            index,
            format!(
                "not a crease of {} (creases: {:?})",
                pattern.name,
                pattern.user_indices()
            ),
        )
    })
}

/// One hinge per crease, its stiffness from its layers and the crease's length.
fn crease_hinges(spec: &ClosedSpec<VertexPattern>, geometry: &SectorGeometry) -> Result<Hinges> {
    let pattern = &spec.pattern;
    let creases = pattern.creases.len();
    let mut of_crease: Vec<Option<usize>> = vec![None; creases];
    let mut stiffness = vec![0.0; creases];
    let spec_hinges: Vec<HingeSpec> = spec.hinges.iter().map(CreaseHingeSpec::hinge).collect();
    for (i, hinge) in spec.hinges.iter().enumerate() {
        let c = crease_of(pattern, &format!("hinges[{i}].crease"), hinge.crease)?;
        if of_crease[c].replace(i).is_some() {
            return Err(NanofoldError::invalid(
                format!("hinges[{i}].crease"),
                hinge.crease,
                "this crease already has a hinge",
            ));
        }
        let length = geometry.crease_ends[c].coords.norm();
        within(
            &format!("length_unit_um × the length of crease {}", hinge.crease),
            length / MICROMETRE,
            limits::LENGTH_UM,
            "µm",
        )?;
        stiffness[c] = hinge_stiffness(&spec.materials, i, &spec_hinges[i], length)?;
    }
    let of_crease = of_crease
        .iter()
        .enumerate()
        .map(|(c, h)| {
            h.ok_or_else(|| NanofoldError::missing(format!("hinges: an entry with crease {}", pattern.user_index(c))))
        })
        .collect::<Result<Vec<usize>>>()?;
    Ok(Hinges {
        stiffness,
        spec: spec_hinges,
        of_crease,
    })
}

/// The driver (the one actuated crease) and its target, the cut, the locks leaving one
/// freedom, the start and the domain the constraint is swept over.
fn step_of(spec: &ClosedSpec<VertexPattern>, hinges: &Hinges) -> Result<Step> {
    let pattern = &spec.pattern;
    let creases = pattern.creases.len();
    let actuated: Vec<usize> = (0..creases)
        .filter(|&c| hinges.spec[hinges.of_crease[c]].actuated)
        .collect();
    let [driver] = actuated[..] else {
        return Err(NanofoldError::invalid(
            "hinges[*].actuated",
            format!("{} actuated", actuated.len()),
            "a closed-chain step drives exactly one crease; lock the others",
        ));
    };
    let target_field = &format!("hinges[{}].target_angle_deg", hinges.of_crease[driver]);
    let target_deg = hinges.spec[hinges.of_crease[driver]]
        .target_angle_deg
        .ok_or_else(|| NanofoldError::missing(target_field))?;
    finite(target_field, target_deg)?;
    if target_deg.abs() > 180.0 {
        return Err(NanofoldError::invalid(
            target_field,
            target_deg,
            "must lie in [−180, 180]",
        ));
    }
    let cut = crease_of(pattern, "cut_crease", spec.cut_crease)?;
    if cut == driver {
        return Err(NanofoldError::invalid(
            "cut_crease",
            spec.cut_crease,
            "cannot cut the actuated crease: its torque would have no hinge to act on (the reduced equations cut an unactuated one)",
        ));
    }
    let mut locks = Vec::new();
    for (i, lock) in spec.locks.iter().enumerate() {
        let c = crease_of(pattern, &format!("locks[{i}].crease"), lock.crease)?;
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
    let setup = Setup::new(pattern, driver, &locks)?;
    let start = finite("start_angle_deg", spec.start_angle_deg)?.to_radians();
    let target = target_deg.to_radians();
    let domain = constraint_domain(spec.constraint.range_deg, start, target)?;
    if start < domain[0] - 1e-12 || start > domain[1] + 1e-12 {
        return Err(NanofoldError::invalid(
            "start_angle_deg",
            spec.start_angle_deg,
            "must lie inside constraint.range_deg",
        ));
    }
    Ok(Step {
        driver,
        target,
        cut,
        setup,
        start,
        domain,
    })
}

/// f: a Chebyshev fit of the exact sweep (`poly`), or Newton closure on the sweep's branch
/// (`exact`). The sweep runs here (the numerics of assembling, never of loading).
fn constraint_source(spec: &ClosedSpec<VertexPattern>, step: &Step) -> Result<ConstraintSource> {
    let pattern = &spec.pattern;
    count_within(
        "constraint.samples",
        spec.constraint.samples,
        limits::CONSTRAINT_SAMPLES,
    )?;
    let sweep = || sweep_samples(pattern, &step.setup, step.domain, spec.constraint.samples).map_err(scene_fields);
    Ok(match (spec.constraint.source, spec.constraint.degree) {
        (SourceKind::Poly, None) => {
            return Err(NanofoldError::missing_with(
                "constraint.degree",
                "needed by source \"poly\"",
            ))
        }
        (SourceKind::Exact, Some(degree)) => {
            return Err(NanofoldError::invalid(
                "constraint.degree",
                degree,
                "only the \"poly\" source has a degree",
            ))
        }
        (SourceKind::Poly, Some(degree)) => {
            ConstraintSource::Poly(ConstraintPoly::fit(pattern, &sweep()?, degree).map_err(scene_fields)?)
        }
        (SourceKind::Exact | SourceKind::Network, None) => {
            ConstraintSource::Exact(ExactConstraint::new(pattern, &sweep()?))
        }
        (SourceKind::Network, Some(degree)) => {
            return Err(NanofoldError::invalid(
                "constraint.degree",
                degree,
                "only the \"poly\" source has a degree",
            ))
        }
    })
}

/// The constraint layer's errors under the scene's names for its fields.
fn scene_fields(error: NanofoldError) -> NanofoldError {
    match error {
        NanofoldError::InvalidField { field, value, reason } => {
            let field = match field.as_str() {
                "samples" | "degree" | "source" => format!("constraint.{field}"),
                "range" => "constraint.range_deg".to_string(),
                "lock" => "locks".to_string(),
                _ => field,
            };
            NanofoldError::InvalidField { field, value, reason }
        }
        other => other,
    }
}

/// The sector on the substrate: the anchored face's, or the one after the cut.
fn anchored_sector(spec: &ClosedSpec<VertexPattern>, geometry: &SectorGeometry, step: &Step) -> Result<usize> {
    let pattern = &spec.pattern;
    match spec.anchored_face {
        None => Ok(pattern.creases[step.cut].ray),
        Some(face) => (0..pattern.rays.len())
            .find(|&s| geometry.outlines[s].as_ref().is_some_and(|(_, f)| *f == face))
            .ok_or_else(|| {
                NanofoldError::invalid(
                    "anchored_face",
                    face,
                    format!("not a face of {} that covers a sector", pattern.name),
                )
            }),
    }
}

/// The outline of the face covering `sector`, m.
fn outline_of(pattern: &VertexPattern, geometry: &SectorGeometry, sector: usize) -> Result<Vec<[f64; 2]>> {
    geometry.outlines[sector]
        .as_ref()
        .map(|(o, _)| o.clone())
        .ok_or_else(|| {
            NanofoldError::invalid(
                format!("{}: faces_vertices", pattern.name),
                format!("sector {sector}"),
                "no face covers this sector",
            )
        })
}

/// The sector plates on a tree rooted at the anchored sector, both ways round to the cut;
/// with the crease and the sector of every joint.
fn sector_tree(
    spec: &ClosedSpec<VertexPattern>,
    geometry: &SectorGeometry,
    hinges: &Hinges,
    step: &Step,
    ground_sector: usize,
) -> Result<(Model, Vec<usize>, Vec<usize>)> {
    let pattern = &spec.pattern;
    let thickness = within(
        "plates.thickness_um",
        spec.plates.thickness_um,
        limits::THICKNESS_UM,
        "µm",
    )? * MICROMETRE;
    let density = material(&spec.materials, "plates.material", &spec.plates.material)?.density_g_cm3 * 1e3;
    let rays = pattern.rays.len();
    let cut_ray = pattern.creases[step.cut].ray;
    let ray_crease = |r: usize| match pattern.rays[r] {
        RayRole::Crease(c) => c,
        _ => unreachable!("closed chains without virtual rays have a crease on every ray"),
    };
    let direction = |r: usize, sign: f64| {
        let phi = geometry.ray_direction[r];
        Unit::new_normalize(Vector3::new(sign * phi.cos(), sign * phi.sin(), 0.0))
    };
    let (mut joints, mut plates, mut parents) = (Vec::new(), Vec::new(), Vec::new());
    let (mut joint_creases, mut joint_sectors) = (Vec::new(), Vec::new());
    // Counter-clockwise from the anchored sector the crease at ray r turns sector r about
    // +ray_r relative to sector r − 1 (a valley lifts it); clockwise it turns sector r − 1
    // about −ray_r relative to sector r. Each branch stops at the cut.
    for clockwise in [false, true] {
        let mut parent = None;
        for step in 0..rays {
            let r = if clockwise {
                (ground_sector + rays - step) % rays
            } else {
                (ground_sector + step + 1) % rays
            };
            if r == cut_ray {
                break;
            }
            let (sector, sign) = if clockwise {
                ((r + rays - 1) % rays, -1.0)
            } else {
                (r, 1.0)
            };
            joints.push(Joint {
                axis: direction(r, sign),
                point: Point3::origin(),
                stiffness: hinges.stiffness[ray_crease(r)],
            });
            let plate = Plate::lamina(&outline_of(pattern, geometry, sector)?, thickness, density);
            let usable = |x: f64| x.is_finite() && x > 0.0;
            if !(usable(plate.mass) && (0..3).all(|k| usable(plate.inertia[(k, k)]))) {
                return Err(NanofoldError::invalid(
                    format!("{}: the face of sector {sector}", pattern.name),
                    format!("mass {:e} kg", plate.mass),
                    "the plate's mass or inertia overflows or vanishes in double precision: check length_unit_um against the FOLD coordinates",
                ));
            }
            plates.push(plate);
            parents.push(parent);
            parent = Some(joints.len() - 1);
            joint_creases.push(ray_crease(r));
            joint_sectors.push(sector);
        }
    }
    let model = Model::tree(joints, plates, parents, drag_law(&spec.environment)?)?;
    Ok((model, joint_creases, joint_sectors))
}

/// A closed vertex from a FOLD file with faces, and no sector split by a virtual ray.
fn check_pattern(pattern: &VertexPattern) -> Result<&FlatMesh> {
    if pattern.chain != Chain::Closed {
        return Err(NanofoldError::invalid(
            "pattern",
            &pattern.name,
            "a closed-chain scene needs an interior vertex (a closed loop of sectors)",
        ));
    }
    if pattern.rays.iter().any(|r| matches!(r, RayRole::Virtual)) {
        return Err(NanofoldError::invalid(
            "pattern",
            &pattern.name,
            "sectors of 180° or more are not supported as plates: add a crease that splits them",
        ));
    }
    let mesh = pattern.mesh.as_ref().ok_or_else(|| {
        NanofoldError::invalid(
            "pattern",
            &pattern.name,
            "must be a FOLD file (its faces are the plates)",
        )
    })?;
    if mesh.faces_vertices.is_none() {
        return Err(NanofoldError::missing_with(
            format!("{}: faces_vertices", pattern.name),
            "the plate outlines",
        ));
    }
    Ok(mesh)
}

/// Ray directions, crease ends and which face covers which sector (the one its centroid's
/// direction falls in), in m about the vertex.
fn sector_geometry(pattern: &VertexPattern, mesh: &FlatMesh, unit: f64) -> Result<SectorGeometry> {
    let rays = pattern.rays.len();
    let centre = mesh.vertices_coords[mesh.center];
    let mut ray_direction = vec![mesh.ray0_direction; rays];
    for r in 1..rays {
        ray_direction[r] = ray_direction[r - 1] + pattern.sector_angles[r - 1];
    }
    let crease_ends = pattern
        .creases
        .iter()
        .enumerate()
        .map(|(c, crease)| {
            let edge = mesh.edges_vertices[crease.fold_edge.unwrap_or(c)];
            let other = if edge[0] == mesh.center { edge[1] } else { edge[0] };
            let [x, y] = mesh.vertices_coords[other];
            Point3::new((x - centre[0]) * unit, (y - centre[1]) * unit, 0.0)
        })
        .collect();
    let faces = mesh.faces_vertices.as_ref().expect("checked by check_pattern");
    let mut outlines: Vec<Option<(Vec<[f64; 2]>, usize)>> = vec![None; rays];
    for (i, face) in faces.iter().enumerate() {
        let field = || format!("{}: faces_vertices[{i}]", pattern.name);
        check_face_indices(face, mesh.center)
            .map_err(|reason| NanofoldError::invalid(field(), format!("{face:?}"), reason))?;
        // In the pattern's units about the vertex, so the tolerances are relative to the face.
        let mut points: Vec<[f64; 2]> = face
            .iter()
            .map(|&v| {
                let [x, y] = mesh.vertices_coords[v];
                [x - centre[0], y - centre[1]]
            })
            .collect();
        let extent = points.iter().map(|p| p[0].hypot(p[1])).fold(0.0, f64::max);
        let twice_area: f64 = (0..points.len())
            .map(|k| {
                let (a, b) = (points[k], points[(k + 1) % points.len()]);
                a[0] * b[1] - b[0] * a[1]
            })
            .sum();
        if twice_area < 0.0 {
            points.reverse();
        }
        // Convexity first: a self-crossing face (a bow tie) can have zero signed area too.
        if !is_convex(&points, extent) {
            return Err(NanofoldError::invalid(
                field(),
                format!("{face:?}"),
                "plates must be convex polygons",
            ));
        }
        if twice_area.abs() <= 1e-9 * extent * extent {
            return Err(NanofoldError::invalid(
                field(),
                format!("{face:?}"),
                "the face has no area",
            ));
        }
        let n = points.len() as f64;
        let (cx, cy) = points.iter().fold((0.0, 0.0), |(a, b), p| (a + p[0] / n, b + p[1] / n));
        let angle = (cy.atan2(cx) - mesh.ray0_direction).rem_euclid(TAU);
        let sector = (0..rays)
            .rev()
            .find(|&r| ray_direction[r] - mesh.ray0_direction <= angle)
            .unwrap_or(0);
        // Every corner within the sector's wedge (the face is the sector's plate, not a
        // polygon reaching across a crease).
        let tolerance = 1e-6;
        for p in &points {
            if p[0].hypot(p[1]) <= 1e-9 * extent {
                continue;
            }
            let within = (p[1].atan2(p[0]) - ray_direction[sector]).rem_euclid(TAU);
            let within = if within > TAU - tolerance { within - TAU } else { within };
            if within > pattern.sector_angles[sector] + tolerance {
                return Err(NanofoldError::invalid(
                    field(),
                    format!("{face:?}"),
                    format!("the face reaches out of sector {sector} (between rays {sector} and {}): a plate lies between two neighbouring creases", (sector + 1) % rays),
                ));
            }
        }
        let points = points.iter().map(|p| [p[0] * unit, p[1] * unit]).collect();
        if outlines[sector].replace((points, i)).is_some() {
            return Err(NanofoldError::invalid(
                field(),
                format!("{face:?}"),
                format!("a second face in sector {sector}: one face per sector"),
            ));
        }
    }
    Ok(SectorGeometry {
        ray_direction,
        crease_ends,
        outlines,
    })
}

/// The swept interval of the driving angle: `range_deg`, or from the start to the target.
fn constraint_domain(range_deg: Option<[f64; 2]>, start: f64, target: f64) -> Result<[f64; 2]> {
    Ok(match range_deg {
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
    })
}

fn is_convex(points: &[[f64; 2]], extent: f64) -> bool {
    let n = points.len();
    n >= 3
        && (0..n).all(|k| {
            let (a, b, c) = (points[k], points[(k + 1) % n], points[(k + 2) % n]);
            (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]) >= -1e-9 * extent * extent
        })
}

/// A face's vertex list: at least three, none twice, the crease vertex among them.
fn check_face_indices(face: &[usize], center: usize) -> std::result::Result<(), String> {
    if face.len() < 3 {
        return Err("a face needs at least three vertices".into());
    }
    if let Some((k, v)) = face.iter().enumerate().find(|(k, v)| face[..*k].contains(v)) {
        return Err(format!("vertex {v} appears twice (again at position {k})"));
    }
    if !face.contains(&center) {
        return Err(format!(
            "the face does not touch the vertex {center} where the creases meet: each plate is a sector"
        ));
    }
    Ok(())
}
