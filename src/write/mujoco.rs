//! MuJoCo scenes (`docs/model.md#mujoco-scenes`): a dynamics [`Scene`] written as one complete
//! MJCF model — a body per plate with its mass and inertia, a hinge per crease with its
//! stiffness, the step torque as an actuator, the substrate, and a closed loop closed by
//! `connect` equalities — in scaled units (µm, pg, µs) that keep MuJoCo's numbers near 1.

use crate::dynamics::closed::ClosedChain;
use crate::dynamics::forcing::{Actuation, Forcing};
use crate::dynamics::model::{Model, Plate};
use crate::dynamics::network::start::leave_flat;
use crate::dynamics::network::NetworkModel;
use crate::dynamics::scene::{Scene, System};
use crate::dynamics::strip::StripChain;
use crate::error::{NanofoldError, Result};
use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};
use std::fmt::Write as _;

/// Length unit of the MJCF, m (1 µm).
pub const LENGTH_UNIT: f64 = 1e-6;
/// Mass unit of the MJCF, kg (1 pg).
pub const MASS_UNIT: f64 = 1e-12;
/// Time unit of the MJCF, s (1 µs).
pub const TIME_UNIT: f64 = 1e-6;
/// Torque (and hinge stiffness per rad) unit, N·m: MASS · LENGTH² / TIME².
pub const TORQUE_UNIT: f64 = MASS_UNIT * LENGTH_UNIT * LENGTH_UNIT / (TIME_UNIT * TIME_UNIT);

/// The mass of the auxiliary body that carries a closed loop's cut crease, as a share of the
/// lightest plate's (its inertia likewise).
pub const CUT_BODY_SHARE: f64 = 1e-6;

/// How a closed loop is closed in MuJoCo.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoopClosure {
    /// Geometric `connect` equalities on a light body carrying the cut crease: exact, every
    /// crease a hinge with its stiffness.
    Connect,
    /// Fitted quartic `polycoef` equalities, each dependent crease a polynomial of the
    /// driver's angle; the cut crease has no joint (and so no stiffness).
    Polycoef,
}

/// How to write a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MujocoSettings {
    /// Integrator time step, s (RK4).
    pub timestep: f64,
    /// How a closed chain's loop is closed.
    pub closure: LoopClosure,
}

impl Default for MujocoSettings {
    fn default() -> Self {
        MujocoSettings {
            timestep: 1e-9,
            closure: LoopClosure::Connect,
        }
    }
}

/// A quartic y = Σ a_k x^k (x the driver's angle, rad) for every dependent crease of a closed
/// chain, least squares over 64 Chebyshev points of the constraint's domain, and the largest
/// error at 400 points of it, rad.
pub struct QuarticCurves {
    /// (crease, coefficients a_0..a_4) per dependent crease.
    pub curves: Vec<(usize, [f64; 5])>,
    /// Largest |fit − constraint| over the domain, rad.
    pub max_error: f64,
}

/// The closed chain's dependent creases as quartics of the driver (MuJoCo's `polycoef`).
pub fn quartic_curves(chain: &ClosedChain) -> Result<QuarticCurves> {
    let [lo, hi] = chain.source.domain();
    let mut ws = chain.workspace();
    let nodes: Vec<f64> = (0..64)
        .map(|k| {
            let c = (std::f64::consts::PI * (k as f64 + 0.5) / 64.0).cos();
            0.5 * (lo + hi) + 0.5 * (hi - lo) * c
        })
        .collect();
    let mut values = Vec::new();
    for &q in &nodes {
        chain.update_creases(q, &mut ws)?;
        values.push(ws.crease_angles.clone());
    }
    let design = nalgebra::DMatrix::from_fn(nodes.len(), 5, |i, k| nodes[i].powi(k as i32));
    let svd = design.svd(true, true);
    let mut curves = Vec::new();
    for &c in &chain.dependents {
        let rhs = nalgebra::DVector::from_iterator(nodes.len(), values.iter().map(|v| v[c]));
        let solution = svd
            .solve(&rhs, 1e-14)
            .map_err(|e| NanofoldError::invalid("constraint", e, "the quartic fit failed"))?;
        curves.push((c, [solution[0], solution[1], solution[2], solution[3], solution[4]]));
    }
    let mut max_error: f64 = 0.0;
    for k in 0..=400 {
        let q = lo + (hi - lo) * k as f64 / 400.0;
        chain.update_creases(q, &mut ws)?;
        for (c, a) in &curves {
            let fit = a.iter().rev().fold(0.0, |acc, x| acc * q + x);
            max_error = max_error.max((fit - ws.crease_angles[*c]).abs());
        }
    }
    Ok(QuarticCurves { curves, max_error })
}

impl MujocoSettings {
    /// Checks the time step against the scene's fastest natural period: RK4 needs it well
    /// below, and MuJoCo's equality constraints relax over two steps.
    pub fn validate(&self, fastest_period: f64) -> Result<()> {
        let limit = fastest_period / 20.0;
        if !(self.timestep > 0.0 && self.timestep <= limit) {
            return Err(NanofoldError::invalid(
                "timestep",
                format!("{:e} s", self.timestep),
                format!(
                    "must lie in (0, {limit:.3e}] s, a twentieth of the fastest natural period {fastest_period:.3e} s"
                ),
            ));
        }
        Ok(())
    }
}

/// One body of the MJCF tree: a plate and the joint that carries it.
struct BodySpec {
    name: String,
    pose: Isometry3<f64>,
    parent: Option<usize>,
    joint: Option<JointSpec>,
    mass: f64,
    /// Inertia at the centre of mass in body axes, kg·m².
    inertia: [f64; 6],
    /// Outline in the body frame, m (None: no geometry, the cut crease's body).
    outline: Option<Vec<Point3<f64>>>,
    thickness: f64,
    drag_area: f64,
    collide: bool,
}

struct JointSpec {
    name: String,
    axis: Vector3<f64>,
    point: Point3<f64>,
    stiffness: f64,
    /// Its stressed layer's drive (None: passive).
    drive: Option<StressDrive>,
}

/// What a hinge's stressed layer does, as MuJoCo will apply it.
#[derive(Debug, Clone, Copy, PartialEq)]
enum StressDrive {
    /// τ = K θ_target from the release time on: an actuator's constant bias.
    Step { torque: f64, release_time: f64 },
    /// τ = K θ_drive(t), θ_drive growing at `rate` (rad/s) up to `target` from the release
    /// time on: an integrator actuator whose activation is θ_drive (ctrl = the rate,
    /// activation clamped at the target).
    Ramp {
        stiffness: f64,
        rate: f64,
        target: f64,
        release_time: f64,
    },
}

fn stress_drives(forcing: &Forcing, stiffness: &[f64]) -> Vec<Option<StressDrive>> {
    forcing
        .hinges
        .iter()
        .zip(stiffness)
        .map(|(h, &k)| {
            h.actuated.then_some(match forcing.actuation {
                Actuation::Step => StressDrive::Step {
                    torque: k * h.target,
                    release_time: h.release_time,
                },
                Actuation::Ramp { etch_rate } => StressDrive::Ramp {
                    stiffness: k,
                    rate: (etch_rate / h.radius_of_curvature).copysign(h.target),
                    target: h.target,
                    release_time: h.release_time,
                },
            })
        })
        .collect()
}

fn inertia6(plate: &Plate) -> [f64; 6] {
    let i = &plate.inertia;
    [i[(0, 0)], i[(1, 1)], i[(2, 2)], i[(0, 1)], i[(0, 2)], i[(1, 2)]]
}

fn plate_body(model: &Model, j: usize, name: String, joint: JointSpec, collide: bool) -> BodySpec {
    let plate = &model.plates()[j];
    BodySpec {
        name,
        pose: plate.reference_pose,
        parent: model.parent(j),
        joint: Some(joint),
        mass: plate.mass,
        inertia: inertia6(plate),
        outline: Some(plate.outline.clone()),
        thickness: plate.thickness,
        drag_area: plate.area,
        collide,
    }
}

/// A strip's bodies, and a note for each plate whose off-axis moments had to move.
fn strip_bodies(chain: &StripChain) -> Result<(Vec<BodySpec>, Vec<String>)> {
    let model = &chain.model;
    let stiffness: Vec<f64> = model.joints().iter().map(|j| j.stiffness).collect();
    let torques = stress_drives(&chain.forcing, &stiffness);
    let mut notes = Vec::new();
    let bodies = (0..model.dof())
        .map(|j| {
            let joint = &model.joints()[j];
            let mut body = plate_body(
                model,
                j,
                format!("plate_{j}"),
                JointSpec {
                    name: format!("hinge_{j}"),
                    axis: joint.axis.into_inner(),
                    point: joint.point,
                    stiffness: joint.stiffness,
                    drive: torques[j],
                },
                true,
            );
            if let Some(note) = satisfy_triangle_inequality(&mut body.inertia) {
                notes.push(format!("plate_{j}: {note}"));
            }
            body
        })
        .collect();
    Ok((bodies, notes))
}

/// MuJoCo refuses moments that break the triangle inequality, as a stated
/// `moment_about_crease_kg_m2` can. Every hinge of a strip turns about x, so only I_xx enters
/// its motion: I_yy or I_zz is raised to the least value MuJoCo accepts, and the change named.
fn satisfy_triangle_inequality(inertia: &mut [f64; 6]) -> Option<String> {
    // Both I_zz ≤ I_xx + I_yy and I_xx ≤ I_yy + I_zz hold exactly when I_yy ≥ |I_xx − I_zz|.
    let [ixx, iyy, izz, ..] = *inertia;
    let least = (ixx - izz).abs();
    (iyy < least).then(|| {
        inertia[1] = least;
        format!("I_yy raised from {iyy:.4e} to {least:.4e} kg·m² to meet the triangle inequality (it does not enter motion about x)")
    })
}

/// A closed chain's bodies: the sector plates on their tree, and a light body that turns
/// about the cut crease from one neighbour and is joined to the other by two `connect`
/// equalities, so the cut crease is a hinge with its own stiffness.
/// A closed chain's bodies, the body the cut body must meet, and the two connect anchors.
type ClosedBodies = (Vec<BodySpec>, Vec<String>, Vec<Point3<f64>>);

fn closed_bodies(chain: &ClosedChain, closure: LoopClosure) -> Result<ClosedBodies> {
    let model = &chain.model;
    let torques = stress_drives(&chain.forcing, &chain.crease_stiffness);
    let label = |c: usize| format!("crease_{}", chain.crease_user_indices[c]);
    let mut bodies: Vec<BodySpec> = (0..model.dof())
        .map(|j| {
            let c = chain.joint_creases[j];
            let joint = &model.joints()[j];
            plate_body(
                model,
                j,
                format!("sector_{}", chain.joint_sectors[j]),
                JointSpec {
                    name: label(c),
                    axis: joint.axis.into_inner(),
                    point: joint.point,
                    stiffness: chain.crease_stiffness[c],
                    drive: torques[c],
                },
                false,
            )
        })
        .collect();
    if closure == LoopClosure::Polycoef {
        return Ok((bodies, Vec::new(), Vec::new()));
    }
    // The cut crease: between sector ray−1 (the clockwise side) and sector ray.
    let cut = chain.cut_crease;
    let rays = chain.sector_angles.len();
    let ray = chain.crease_rays[cut];
    let (before, after) = ((ray + rays - 1) % rays, ray);
    let body_of = |s: usize| chain.body_of_sector(s);
    // The light body hangs from the sector before the cut and turns about +r̂; `after` is
    // the sector it must coincide with. If that sector is the ground, swap roles.
    let (carrier, target, sign) = match (body_of(before), body_of(after)) {
        (Some(b), a) => (Some(b), a, 1.0),
        (None, a) => (a, None, -1.0),
    };
    let end = chain.crease_ends[cut];
    let axis = end.coords.normalize() * sign;
    let lightest = model.plates().iter().map(|p| p.mass).fold(f64::INFINITY, f64::min);
    let smallest = model
        .plates()
        .iter()
        .map(|p| p.inertia[(2, 2)])
        .fold(f64::INFINITY, f64::min);
    let target_pose = target.map_or(Isometry3::identity(), |b| bodies[b].pose);
    let share = CUT_BODY_SHARE;
    bodies.push(BodySpec {
        name: format!("cut_{}", label(cut)),
        pose: target_pose,
        parent: carrier,
        joint: Some(JointSpec {
            name: label(cut),
            axis,
            point: Point3::origin(),
            stiffness: chain.crease_stiffness[cut],
            drive: torques[cut],
        }),
        mass: share * lightest,
        inertia: [share * smallest, share * smallest, share * smallest, 0.0, 0.0, 0.0],
        outline: None,
        thickness: 0.0,
        drag_area: 0.0,
        collide: false,
    });
    let target_name = target.map_or("world".to_string(), |b| bodies[b].name.clone());
    // Anchors (world, flat): the target's centroid moved onto the plane normal to the cut
    // crease through the vertex, and the crease's far end.
    let centroid = match target {
        Some(b) => bodies[b].pose.translation.vector,
        None => chain.ground.iter().map(|p| p.coords).sum::<Vector3<f64>>() / chain.ground.len() as f64,
    };
    let unit = end.coords.normalize();
    let mut off_axis = centroid - unit * unit.dot(&centroid);
    if off_axis.norm() < 1e-6 * end.coords.norm() {
        off_axis = unit.cross(&Vector3::z()) * end.coords.norm();
    }
    let anchors = vec![Point3::from(off_axis), end];
    Ok((bodies, vec![target_name], anchors))
}

/// A network's bodies, its anchored panel's outline and the loops' connect equalities.
type NetworkBodies = (Vec<BodySpec>, Vec<Point3<f64>>, Vec<ConnectSpec>);

/// One `connect` equality: a point of `body1` (given in the world's flat frame) held on
/// `body2` (a body name, or "world").
struct ConnectSpec {
    body1: usize,
    body2: String,
    anchor: Point3<f64>,
    name: String,
}

/// A network's bodies (every panel but the anchored one, on the spanning tree; a light body
/// per crease off the tree, turning about it from one side), its anchored panel's outline
/// (world, flat) and the `connect` equalities that close each loop: three points of each light
/// body (its crease's ends and the far side's centroid) held on the panel it stands for.
fn network_bodies(model: &NetworkModel) -> Result<NetworkBodies> {
    let pattern = &model.folding.pattern;
    let unit = model.unit;
    let flat = |v: usize| Point3::new(pattern.vertices[v][0] * unit, pattern.vertices[v][1] * unit, 0.0);
    let stiffness = model.stiffness();
    let torques = stress_drives(&model.forcing, &stiffness);
    let crease_name = |c: usize| format!("crease_{}", pattern.creases[c]);
    let face_of = |p: usize| {
        (0..pattern.faces.len())
            .filter(|&f| pattern.panel_of_face[f] == p)
            .map(|f| pattern.file_face[f])
            .min()
            .expect("every panel has a face")
    };
    // Each off-tree crease's light body moves with the panel it stands for once its loop is
    // closed, so it carries an equal share of that panel's mass and inertia (the panel keeps
    // the rest): the totals are the panel's own, and no body is so light that MuJoCo's soft
    // equalities must hold back a large acceleration.
    let off_tree: Vec<(usize, usize, usize)> = (0..model.columns())
        .filter(|&c| model.carried[c].is_none())
        .filter_map(|c| {
            let [Some(left), Some(right)] = pattern.edge_faces[pattern.creases[c]] else {
                return None;
            };
            let (pl, pr) = (pattern.panel_of_face[left], pattern.panel_of_face[right]);
            Some(if pl == model.anchored_panel {
                (c, pr, pl)
            } else {
                (c, pl, pr)
            })
        })
        .collect();
    let mut pieces = vec![1.0; model.panels()];
    for &(_, _, target) in &off_tree {
        pieces[target] += 1.0;
    }
    let inertia_entries = |p: usize| {
        let i = model.bodies[p].inertia / pieces[p];
        [i[(0, 0)], i[(1, 1)], i[(2, 2)], i[(0, 1)], i[(0, 2)], i[(1, 2)]]
    };
    let mut body_of = vec![None; model.panels()];
    let mut bodies = Vec::new();
    for &p in &model.order[1..] {
        let c = model.parent_column[p].expect("placed panels hang from a crease");
        let parent = model.parent[p].expect("and from a parent");
        let body = &model.bodies[p];
        let centre = body.centre;
        let outline = model.folding.panel_vertices[p]
            .iter()
            .map(|&v| Point3::from(flat(v).coords - centre))
            .collect();
        body_of[p] = Some(bodies.len());
        bodies.push(BodySpec {
            name: format!("face_{}", face_of(p)),
            pose: Isometry3::translation(centre.x, centre.y, centre.z),
            parent: body_of[parent],
            joint: Some(JointSpec {
                name: crease_name(c),
                axis: model.joint_axis[c],
                point: Point3::from(model.hinges[c].point),
                stiffness: stiffness[c],
                drive: torques[c],
            }),
            mass: body.mass / pieces[p],
            inertia: inertia_entries(p),
            outline: Some(outline),
            thickness: model.thickness,
            drag_area: body.area,
            collide: false,
        });
    }
    let mut connects = Vec::new();
    for &(c, carrier, target) in &off_tree {
        let e = pattern.creases[c];
        let [Some(left), _] = pattern.edge_faces[e] else {
            unreachable!("off-tree creases have two sides");
        };
        let pl = pattern.panel_of_face[left];
        let target_on_left = target == pl;
        let direction = model.hinges[c].direction * if target_on_left { 1.0 } else { -1.0 };
        let target_centre = model.bodies[target].centre;
        let index = bodies.len();
        bodies.push(BodySpec {
            name: format!("loop_{}", crease_name(c)),
            pose: Isometry3::translation(target_centre.x, target_centre.y, target_centre.z),
            parent: body_of[carrier],
            joint: Some(JointSpec {
                name: crease_name(c),
                axis: direction,
                point: Point3::from(model.hinges[c].point),
                stiffness: stiffness[c],
                drive: torques[c],
            }),
            mass: model.bodies[target].mass / pieces[target],
            inertia: inertia_entries(target),
            outline: None,
            thickness: 0.0,
            drag_area: 0.0,
            collide: false,
        });
        let target_name = body_of[target].map_or("world".to_string(), |b| bodies[b].name.clone());
        let [a, b] = pattern.edges[e];
        for (k, anchor) in [flat(a), flat(b), Point3::from(target_centre)].into_iter().enumerate() {
            connects.push(ConnectSpec {
                body1: index,
                body2: target_name.clone(),
                anchor,
                name: format!("close_{}_{}", crease_name(c), ["a", "b", "c"][k]),
            });
        }
    }
    let ground = model.folding.panel_vertices[model.anchored_panel]
        .iter()
        .map(|&v| flat(v))
        .collect();
    Ok((bodies, ground, connects))
}

/// How far along its branch a closed chain that starts flat is started, degrees of the driver.
pub const BRANCH_START_DEG: f64 = 1.0;

/// The driver's angle in the keyframe: the scene's start, or, when that is the flat state (a
/// branch point), [`BRANCH_START_DEG`] towards the target.
pub fn keyframe_driver_angle(chain: &ClosedChain) -> f64 {
    if chain.start.abs() > 1e-9 {
        return chain.start;
    }
    BRANCH_START_DEG.to_radians().copysign(chain.target() - chain.start)
}

fn fmt(x: f64) -> String {
    let s = format!("{x:.12e}");
    // Trim the mantissa's trailing zeros: 1.000000000000e0 → 1e0.
    if let Some((mantissa, exponent)) = s.split_once('e') {
        let mantissa = if mantissa.contains('.') {
            mantissa.trim_end_matches('0').trim_end_matches('.')
        } else {
            mantissa
        };
        if exponent == "0" {
            return mantissa.to_string();
        }
        return format!("{mantissa}e{exponent}");
    }
    s
}

fn vec3(v: &Vector3<f64>, scale: f64) -> String {
    format!("{} {} {}", fmt(v.x * scale), fmt(v.y * scale), fmt(v.z * scale))
}

fn quat(q: &UnitQuaternion<f64>) -> String {
    format!("{} {} {} {}", fmt(q.w), fmt(q.i), fmt(q.j), fmt(q.k))
}

/// The MJCF text of `scene`.
pub fn scene_mjcf(scene: &Scene, settings: &MujocoSettings) -> Result<String> {
    let parts = scene_parts(scene, settings)?;
    let dt = settings.timestep / TIME_UNIT;
    let mut x = String::new();
    let w = &mut x;
    write_header(w, &scene.name, &parts.description, dt);
    write_assets(w, scene, &parts);
    write_custom(w, scene, &parts);
    let joint_order = write_worldbody(w, scene, &parts);
    let quartics = match (&scene.system, settings.closure) {
        (System::Closed(chain), LoopClosure::Polycoef) => Some(quartic_curves(chain)?),
        _ => None,
    };
    write_equalities(w, scene, &parts, quartics.as_ref(), dt);
    // A network that starts flat starts in MuJoCo where nanofold leaves the branch point: its
    // angles, rates and time (MuJoCo's constraint forces would hold the panels still there).
    let branch = match &scene.system {
        System::Network(model) => leave_flat(model)?,
        _ => None,
    };
    let key_time = branch.as_ref().map_or(0.0, |b| b.time);
    let actuators = write_actuators(w, &parts.bodies, key_time);
    write_keyframe(
        w,
        scene,
        &joint_order,
        quartics.as_ref(),
        branch.as_ref(),
        key_time,
        &actuators,
    )?;
    writeln!(w, "</mujoco>").unwrap();
    Ok(x)
}

/// What a scene puts into its MJCF: its bodies (a tree), a closed chain's connect targets and
/// anchors, a strip's substrate edge, the drag, the description for the header, and a
/// network's anchored panel and connect equalities.
struct MjcfParts {
    bodies: Vec<BodySpec>,
    connect_targets: Vec<String>,
    connect_anchors: Vec<Point3<f64>>,
    substrate_edge: Option<f64>,
    drag: Option<crate::dynamics::model::Drag>,
    description: String,
    network_parts: Option<(Vec<Point3<f64>>, Vec<ConnectSpec>)>,
}

/// The scene's bodies and what closes its loops (a network refuses fitted curves).
fn scene_parts(scene: &Scene, settings: &MujocoSettings) -> Result<MjcfParts> {
    let mut network_parts = None;
    let (bodies, connect_targets, connect_anchors, substrate_edge, drag, description) = match &scene.system {
        System::Network(model) => {
            if settings.closure == LoopClosure::Polycoef {
                return Err(NanofoldError::invalid(
                    "closure",
                    "poly",
                    "a network's loops are closed by connect equalities (fitted curves are for a single closed vertex)",
                ));
            }
            let (bodies, ground, connects) = network_bodies(model)?;
            let description = format!(
                "a network of {} panels: the anchored panel (face {}) is the world's geom `ground`, the others a tree of bodies; each of its {} creases off the tree is a hinge on a light body closed onto its panel by three connect equalities",
                model.panels(),
                model.anchored_face,
                model.columns() - (model.panels() - 1)
            );
            network_parts = Some((ground, connects));
            (bodies, Vec::new(), Vec::new(), None, model.drag, description)
        }
        System::Strip(chain) => {
            let (bodies, notes) = strip_bodies(chain)?;
            let mut description = "a strip: plate i hangs from plate i − 1 by hinge i; the substrate is the box under z = 0 for y ≤ the edge"
                .to_string();
            for note in notes {
                description.push_str(&format!(";\n       {note}"));
            }
            (
                bodies,
                Vec::new(),
                Vec::new(),
                Some(chain.substrate_edge_y),
                chain.model.drag(),
                description,
            )
        }
        System::Closed(chain) => {
            let (bodies, targets, anchors) = closed_bodies(chain, settings.closure)?;
            (
                bodies,
                targets,
                anchors,
                None,
                chain.model.drag(),
                format!(
                    "a closed vertex: the anchored sector is the world's geom `ground`; the loop is cut at crease_{} and closed by {}",
                    chain.crease_user_indices[chain.cut_crease],
                    match settings.closure {
                        LoopClosure::Connect => "two connect equalities on a light body that keeps the cut crease a hinge",
                        LoopClosure::Polycoef => "fitted quartic polycoef equalities (the cut crease has no joint and no stiffness)",
                    }
                ),
            )
        }
    };
    Ok(MjcfParts {
        bodies,
        connect_targets,
        connect_anchors,
        substrate_edge,
        drag,
        description,
        network_parts,
    })
}

/// The model line, the units and conventions as comments, the compiler and the options.
fn write_header(w: &mut String, name: &str, description: &str, dt: f64) {
    writeln!(w, "<mujoco model=\"{}\">", xml_escape(name)).unwrap();
    writeln!(
        w,
        "  <!-- Written by nanofold export mujoco. Units: length µm, mass pg (1e-12 kg), time µs;"
    )
    .unwrap();
    writeln!(
        w,
        "       so force µN, torque and hinge stiffness 1e-12 N·m (per rad), density 1e6 kg/m³."
    )
    .unwrap();
    writeln!(w, "       {} -->", xml_escape(description)).unwrap();
    writeln!(
        w,
        "  <!-- Hinges: a positive angle folds valley, right-handed about the joint axis; springref 0 is flat."
    )
    .unwrap();
    writeln!(
        w,
        "       Drag (nanofold's F = -1/2 C_D rho A |v|^2 sgn(v.n) n at each plate's centre of mass, n its body z)"
    )
    .unwrap();
    writeln!(
        w,
        "       is not a MuJoCo force: its parameters are the custom numerics below, applied by a passive"
    )
    .unwrap();
    writeln!(
        w,
        "       callback (tests/mujoco/nanofold_mujoco.py). MuJoCo's own fluid model is off (density 0). -->"
    )
    .unwrap();
    writeln!(
        w,
        "  <compiler angle=\"radian\" inertiafromgeom=\"false\" autolimits=\"true\"/>"
    )
    .unwrap();
    writeln!(
        w,
        "  <option timestep=\"{}\" integrator=\"RK4\" gravity=\"0 0 0\" density=\"0\" viscosity=\"0\"/>",
        fmt(dt)
    )
    .unwrap();
}

/// Meshes: each plate a thin prism of its structural thickness, and the anchored sector or
/// panel.
fn write_assets(w: &mut String, scene: &Scene, parts: &MjcfParts) {
    let l = 1.0 / LENGTH_UNIT;
    let bodies = &parts.bodies;
    writeln!(w, "  <asset>").unwrap();
    // A prism of half-thickness `half` over an outline, µm.
    let prism = |w: &mut String, name: &str, outline: &[Point3<f64>], half: f64| {
        let mut vertex = Vec::new();
        for dz in [-half, half] {
            for p in outline {
                vertex.push(vec3(&Vector3::new(p.x, p.y, p.z + dz), l));
            }
        }
        writeln!(w, "    <mesh name=\"{name}\" vertex=\"{}\"/>", vertex.join("  ")).unwrap();
    };
    for body in bodies.iter() {
        if let Some(outline) = &body.outline {
            prism(w, &body.name, outline, 0.5 * body.thickness.max(1e-3 * LENGTH_UNIT));
        }
    }
    // The anchored sector or panel: as thick as the thickest plate.
    let ground_half = 0.5
        * bodies
            .iter()
            .map(|b| b.thickness)
            .fold(0.0, f64::max)
            .max(1e-3 * LENGTH_UNIT);
    if let System::Closed(chain) = &scene.system {
        prism(w, "ground", &chain.ground, ground_half);
    }
    if let Some((ground, _)) = &parts.network_parts {
        prism(w, "ground", ground, ground_half);
    }
    writeln!(w, "  </asset>").unwrap();
}

/// The custom numerics a client needs: units, drag, the substrate edge, etch-front release
/// times and rates.
fn write_custom(w: &mut String, scene: &Scene, parts: &MjcfParts) {
    let l = 1.0 / LENGTH_UNIT;
    let bodies = &parts.bodies;
    writeln!(w, "  <custom>").unwrap();
    writeln!(
        w,
        "    <text name=\"nanofold:units\" data=\"length um, mass pg, time us\"/>"
    )
    .unwrap();
    if let Some(drag) = parts.drag {
        writeln!(
            w,
            "    <numeric name=\"nanofold:drag_coefficient\" data=\"{}\"/>",
            fmt(drag.drag_coefficient)
        )
        .unwrap();
        writeln!(
            w,
            "    <numeric name=\"nanofold:air_density\" data=\"{}\"/>",
            fmt(drag.air_density * LENGTH_UNIT.powi(3) / MASS_UNIT)
        )
        .unwrap();
        for body in bodies.iter().filter(|b| b.drag_area > 0.0) {
            writeln!(
                w,
                "    <numeric name=\"nanofold:drag_area:{}\" data=\"{}\"/>",
                body.name,
                fmt(body.drag_area * l * l)
            )
            .unwrap();
        }
    }
    if let Some(edge) = parts.substrate_edge {
        writeln!(
            w,
            "    <numeric name=\"nanofold:substrate_edge_y\" data=\"{}\"/>",
            fmt(edge * l)
        )
        .unwrap();
    }
    if let System::Network(model) = &scene.system {
        for (c, hinge) in model.forcing.hinges.iter().enumerate() {
            if hinge.actuated && hinge.release_time > 0.0 {
                let e = model.folding.pattern.creases[c];
                writeln!(
                    w,
                    "    <numeric name=\"nanofold:release_time:crease_{e}\" data=\"{}\"/>",
                    fmt(hinge.release_time / TIME_UNIT)
                )
                .unwrap();
                if let Actuation::Ramp { etch_rate } = model.forcing.actuation {
                    writeln!(
                        w,
                        "    <numeric name=\"nanofold:release_rate:crease_{e}\" data=\"{}\"/>",
                        fmt((etch_rate / hinge.radius_of_curvature).copysign(hinge.target) * TIME_UNIT)
                    )
                    .unwrap();
                }
            }
        }
    }
    writeln!(w, "  </custom>").unwrap();
}

/// The world: the substrate or the anchored geom and the tree of bodies; a strip's first
/// plate excluded from contact with the world. Returns the joints in MJCF order.
fn write_worldbody(w: &mut String, scene: &Scene, parts: &MjcfParts) -> Vec<String> {
    let l = 1.0 / LENGTH_UNIT;
    let m = 1.0 / MASS_UNIT;
    let inertia_scale = 1.0 / (MASS_UNIT * LENGTH_UNIT * LENGTH_UNIT);
    let torque_scale = 1.0 / TORQUE_UNIT;
    let (bodies, substrate_edge) = (&parts.bodies, parts.substrate_edge);
    writeln!(w, "  <worldbody>").unwrap();
    // The substrate (strip) or the anchored sector (closed).
    let extent = bodies
        .iter()
        .filter_map(|b| b.outline.as_ref().map(|o| (b, o)))
        .flat_map(|(b, o)| o.iter().map(move |p| (b.pose * p).coords.norm()))
        .fold(0.0, f64::max);
    if let Some(edge) = substrate_edge {
        let depth = 10.0 * LENGTH_UNIT;
        writeln!(
            w,
            "    <geom name=\"substrate\" type=\"box\" pos=\"0 {} {}\" size=\"{} {} {}\" rgba=\"0.55 0.55 0.6 1\"/>",
            fmt((edge - extent) * l),
            fmt(-0.5 * depth * l),
            fmt(extent * l),
            fmt(extent * l),
            fmt(0.5 * depth * l)
        )
        .unwrap();
    }
    if matches!(scene.system, System::Closed(_) | System::Network(_)) {
        writeln!(w, "    <geom name=\"ground\" type=\"mesh\" mesh=\"ground\" contype=\"0\" conaffinity=\"0\" rgba=\"0.55 0.55 0.6 1\"/>").unwrap();
    }
    let mut joint_order = Vec::new();
    write_children(
        w,
        bodies,
        None,
        &Isometry3::identity(),
        2,
        l,
        m,
        inertia_scale,
        torque_scale,
        &mut joint_order,
    );
    writeln!(w, "  </worldbody>").unwrap();
    // The first plate of a strip lies on the substrate edge at its hinge.
    if substrate_edge.is_some() {
        writeln!(w, "  <contact>").unwrap();
        writeln!(w, "    <exclude body1=\"world\" body2=\"{}\"/>", bodies[0].name).unwrap();
        writeln!(w, "  </contact>").unwrap();
    }
    joint_order
}

/// Equalities: a closed chain's loop (connects or fitted quartics) and locks, a network's
/// connects and locks.
fn write_equalities(w: &mut String, scene: &Scene, parts: &MjcfParts, quartics: Option<&QuarticCurves>, dt: f64) {
    let l = 1.0 / LENGTH_UNIT;
    let (bodies, connect_targets, connect_anchors) = (&parts.bodies, &parts.connect_targets, &parts.connect_anchors);
    if let System::Closed(chain) = &scene.system {
        writeln!(w, "  <equality>").unwrap();
        // Two points of the cut body: one off its hinge axis, one on it away from the vertex
        // (the vertex itself is shared through the tree), so the three fix it to its target.
        for (k, anchor) in connect_anchors.iter().enumerate() {
            let cut = bodies.last().expect("the cut crease's body");
            let local = cut.pose.inverse_transform_point(anchor);
            writeln!(
                w,
                "    <connect name=\"close_{}_{}\" body1=\"{}\" body2=\"{}\" anchor=\"{}\" solref=\"{} 1\" solimp=\"0.9999 0.9999 0.001\"/>",
                cut.name,
                ["a", "b"][k],
                cut.name,
                connect_targets[0],
                vec3(&local.coords, l),
                fmt(2.0 * dt)
            )
            .unwrap();
        }
        {
            for &(c, value) in &chain.locked {
                writeln!(
                    w,
                    "    <joint name=\"lock_crease_{}\" joint1=\"crease_{}\" polycoef=\"{} 0 0 0 0\" solref=\"{} 1\" solimp=\"0.9999 0.9999 0.001\"/>",
                    chain.crease_user_indices[c],
                    chain.crease_user_indices[c],
                    fmt(value),
                    fmt(2.0 * dt)
                )
                .unwrap();
            }
        }
        if let Some(quartics) = quartics {
            let driver = chain.crease_user_indices[chain.driver];
            writeln!(
                w,
                "    <!-- Each dependent crease a quartic of crease_{driver} (rad), least squares over the constraint's domain; largest error {:.3e} rad. crease_{} is cut: no joint, no equality. -->",
                quartics.max_error,
                chain.crease_user_indices[chain.cut_crease]
            )
            .unwrap();
            for (c, a) in quartics.curves.iter().filter(|(c, _)| *c != chain.cut_crease) {
                let index = chain.crease_user_indices[*c];
                writeln!(
                    w,
                    "    <joint name=\"curve_crease_{index}\" joint1=\"crease_{index}\" joint2=\"crease_{driver}\" polycoef=\"{}\" solref=\"{} 1\" solimp=\"0.9999 0.9999 0.001\"/>",
                    a.iter().map(|&x| fmt(x)).collect::<Vec<_>>().join(" "),
                    fmt(2.0 * dt)
                )
                .unwrap();
            }
        }
        writeln!(w, "  </equality>").unwrap();
    }
    if let (Some((_, connects)), System::Network(model)) = (&parts.network_parts, &scene.system) {
        let any_lock = (0..model.columns()).any(|c| model.locked(c));
        if !connects.is_empty() || any_lock {
            writeln!(w, "  <equality>").unwrap();
        }
        for connect in connects {
            let body = &bodies[connect.body1];
            let local = body.pose.inverse_transform_point(&connect.anchor);
            writeln!(
                w,
                "    <connect name=\"{}\" body1=\"{}\" body2=\"{}\" anchor=\"{}\" solref=\"{} 1\" solimp=\"0.9999 0.9999 0.001\"/>",
                connect.name,
                body.name,
                connect.body2,
                vec3(&local.coords, l),
                fmt(2.0 * dt)
            )
            .unwrap();
        }
        for c in (0..model.columns()).filter(|&c| model.locked(c)) {
            let e = model.folding.pattern.creases[c];
            writeln!(
                w,
                "    <joint name=\"lock_crease_{e}\" joint1=\"crease_{e}\" polycoef=\"{} 0 0 0 0\" solref=\"{} 1\" solimp=\"0.9999 0.9999 0.001\"/>",
                fmt(model.start[c]),
                fmt(2.0 * dt)
            )
            .unwrap();
        }
        if !connects.is_empty() || any_lock {
            writeln!(w, "  </equality>").unwrap();
        }
    }
}

/// The actuators' keyframe values: ctrl per actuator, act per integrator actuator (None for
/// a step's), and how many an etch front still holds off.
struct ActuatorKeys {
    controls: Vec<f64>,
    activations: Vec<Option<f64>>,
    held_back: usize,
}

/// The stress actuators (a step's affine bias, a ramp's integrator) and their keyframe
/// values at `key_time`.
fn write_actuators(w: &mut String, bodies: &[BodySpec], key_time: f64) -> ActuatorKeys {
    let torque_scale = 1.0 / TORQUE_UNIT;
    writeln!(w, "  <actuator>").unwrap();
    // The keyframe's ctrl: a ramp actuator's rate, 0 for a step's (its ctrl adds torque); an
    // actuator not yet released by an etch front is held off (ctrl 0 for a ramp, minus its
    // bias for a step). The keyframe's act: each ramp's drive angle at the key's time.
    let mut controls = Vec::new();
    let mut activations = Vec::new();
    let mut held_back = 0;
    for body in bodies.iter() {
        let Some(joint) = body.joint.as_ref() else { continue };
        match joint.drive {
            Some(StressDrive::Step { torque, release_time }) => {
                writeln!(
                    w,
                    "    <general name=\"stress_{}\" joint=\"{}\" gainprm=\"1\" biastype=\"affine\" biasprm=\"{} 0 0\"/>",
                    joint.name,
                    joint.name,
                    fmt(torque * torque_scale)
                )
                .unwrap();
                let held = release_time > key_time;
                held_back += usize::from(held);
                controls.push(if held { -torque * torque_scale } else { 0.0 });
                activations.push(None);
            }
            Some(StressDrive::Ramp {
                stiffness,
                rate,
                target,
                release_time,
            }) => {
                let (lo, hi) = if target >= 0.0 { (0.0, target) } else { (target, 0.0) };
                writeln!(
                    w,
                    "    <general name=\"stress_{}\" joint=\"{}\" dyntype=\"integrator\" gainprm=\"{}\" actlimited=\"true\" actrange=\"{} {}\"/>",
                    joint.name,
                    joint.name,
                    fmt(stiffness * torque_scale),
                    fmt(lo),
                    fmt(hi)
                )
                .unwrap();
                let held = release_time > key_time;
                held_back += usize::from(held);
                controls.push(if held { 0.0 } else { rate * TIME_UNIT });
                let drive = (rate * (key_time - release_time).max(0.0)).clamp(lo, hi);
                activations.push(Some(drive));
            }
            None => {}
        }
    }
    writeln!(w, "  </actuator>").unwrap();
    ActuatorKeys {
        controls,
        activations,
        held_back,
    }
}

/// The keyframe: every joint's start (a closed chain's on its closure, a network's where it
/// leaves flat), its rates and time where it moves, the actuators' ctrl and act.
fn write_keyframe(
    w: &mut String,
    scene: &Scene,
    joint_order: &[String],
    quartics: Option<&QuarticCurves>,
    branch: Option<&crate::dynamics::network::start::BranchStart>,
    key_time: f64,
    actuators: &ActuatorKeys,
) -> Result<()> {
    let (controls, activations, held_back) = (&actuators.controls, &actuators.activations, actuators.held_back);
    // The state at t = 0: flat for a strip; for a closed chain the driver's start with the
    // locks and the dependents (the cut crease included) on the closure.
    let mut start = vec![0.0; joint_order.len()];
    let qpos = &mut start;
    if let System::Closed(chain) = &scene.system {
        let mut ws = chain.workspace();
        let q = keyframe_driver_angle(chain);
        chain.update_creases(q, &mut ws)?;
        // With polycoef equalities the keyframe lies on the fitted curves, so MuJoCo starts
        // with every equality satisfied.
        if let Some(quartics) = quartics {
            for (c, a) in &quartics.curves {
                ws.crease_angles[*c] = a.iter().rev().fold(0.0, |acc, x| acc * q + x);
            }
        }
        for (slot, name) in qpos.iter_mut().zip(joint_order) {
            if let Some(c) =
                (0..chain.crease_labels.len()).find(|&c| *name == format!("crease_{}", chain.crease_user_indices[c]))
            {
                *slot = ws.crease_angles[c];
            }
        }
    }
    let mut velocities = vec![0.0; joint_order.len()];
    let mut network_note = None;
    if let System::Network(model) = &scene.system {
        let (angles, rates) = match branch {
            Some(branch) => {
                network_note = Some(format!(
                    "The scene starts flat, a branch point where MuJoCo's constraint forces would hold the panels still: the keyframe is nanofold's state where it leaves the branch point, {:e} rad along, {:e} µs after the release.",
                    crate::dynamics::network::start::KICK,
                    branch.time / TIME_UNIT
                ));
                (branch.angles.clone(), branch.rates.clone())
            }
            None => (model.start.clone(), vec![0.0; model.columns()]),
        };
        for ((slot, rate), name) in qpos.iter_mut().zip(velocities.iter_mut()).zip(joint_order) {
            if let Some(c) =
                (0..model.columns()).find(|&c| *name == format!("crease_{}", model.folding.pattern.creases[c]))
            {
                *slot = angles[c];
                *rate = rates[c] * TIME_UNIT;
            }
        }
        if held_back > 0 {
            writeln!(
                w,
                "  <!-- An etch front: {held_back} actuator(s) are held off by the keyframe's ctrl until their hinge's release time (custom numeric nanofold:release_time:JOINT, µs), when a client sets ctrl to 0 for a step, or for a ramp to its rate (nanofold:release_rate:JOINT, rad/µs). -->"
            )
            .unwrap();
        }
    }
    if let Some(note) = &network_note {
        writeln!(w, "  <!-- {} -->", xml_escape(note)).unwrap();
    }
    if let System::Closed(chain) = &scene.system {
        if keyframe_driver_angle(chain) != chain.start {
            writeln!(
                w,
                "  <!-- The scene starts flat, a branch point where the loop's constraint forces hold the driver still in MuJoCo. The keyframe starts {}° along the branch nanofold follows, at rest. -->",
                BRANCH_START_DEG
            )
            .unwrap();
        }
    }
    writeln!(w, "  <keyframe>").unwrap();
    if controls.iter().any(|&c| c != 0.0) {
        writeln!(
            w,
            "  <!-- Ramp actuation: each stressed hinge's activation is its drive angle θ_drive(t), growing at the rate in ctrl (rad/µs, set by this keyframe) until it reaches its target; the actuator's force is K θ_drive. -->"
        )
        .unwrap();
    }
    let timing = if key_time > 0.0 {
        format!(
            " time=\"{}\" qvel=\"{}\"",
            fmt(key_time / TIME_UNIT),
            velocities.iter().map(|&v| fmt(v)).collect::<Vec<_>>().join(" ")
        )
    } else {
        String::new()
    };
    // MuJoCo's act holds only the integrator actuators' states.
    let act: Vec<String> = activations.iter().flatten().map(|&a| fmt(a)).collect();
    writeln!(
        w,
        "    <key name=\"start\"{timing} qpos=\"{}\"{}/>",
        start.iter().map(|&q| fmt(q)).collect::<Vec<_>>().join(" "),
        if controls.iter().any(|&c| c != 0.0) {
            format!(
                " ctrl=\"{}\"{}",
                controls.iter().map(|&c| fmt(c)).collect::<Vec<_>>().join(" "),
                if act.is_empty() {
                    String::new()
                } else {
                    format!(" act=\"{}\"", act.join(" "))
                }
            )
        } else {
            String::new()
        }
    )
    .unwrap();
    writeln!(w, "  </keyframe>").unwrap();
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn write_children(
    w: &mut String,
    bodies: &[BodySpec],
    parent: Option<usize>,
    parent_pose: &Isometry3<f64>,
    depth: usize,
    l: f64,
    m: f64,
    inertia_scale: f64,
    torque_scale: f64,
    joint_order: &mut Vec<String>,
) {
    let pad = "  ".repeat(depth);
    for (index, body) in bodies.iter().enumerate().filter(|(_, b)| b.parent == parent) {
        let relative = parent_pose.inverse() * body.pose;
        writeln!(
            w,
            "{pad}<body name=\"{}\" pos=\"{}\" quat=\"{}\">",
            body.name,
            vec3(&relative.translation.vector, l),
            quat(&relative.rotation)
        )
        .unwrap();
        let i = body.inertia;
        writeln!(
            w,
            "{pad}  <inertial pos=\"0 0 0\" mass=\"{}\" fullinertia=\"{} {} {} {} {} {}\"/>",
            fmt(body.mass * m),
            fmt(i[0] * inertia_scale),
            fmt(i[1] * inertia_scale),
            fmt(i[2] * inertia_scale),
            fmt(i[3] * inertia_scale),
            fmt(i[4] * inertia_scale),
            fmt(i[5] * inertia_scale)
        )
        .unwrap();
        if let Some(joint) = &body.joint {
            joint_order.push(joint.name.clone());
            let local_point = body.pose.inverse_transform_point(&joint.point);
            let local_axis = body.pose.rotation.inverse_transform_vector(&joint.axis);
            writeln!(
                w,
                "{pad}  <joint name=\"{}\" type=\"hinge\" pos=\"{}\" axis=\"{}\" stiffness=\"{}\" springref=\"0\"/>",
                joint.name,
                vec3(&local_point.coords, l),
                vec3(&local_axis, 1.0),
                fmt(joint.stiffness * torque_scale)
            )
            .unwrap();
        }
        if let Some(outline) = &body.outline {
            let collide = if body.collide {
                ""
            } else {
                " contype=\"0\" conaffinity=\"0\""
            };
            writeln!(
                w,
                "{pad}  <geom name=\"{}\" type=\"mesh\" mesh=\"{}\"{collide}/>",
                body.name, body.name
            )
            .unwrap();
            for (k, p) in outline.iter().enumerate() {
                writeln!(
                    w,
                    "{pad}  <site name=\"{}:corner_{k}\" pos=\"{}\" size=\"{}\"/>",
                    body.name,
                    vec3(&p.coords, l),
                    fmt(1.0)
                )
                .unwrap();
            }
        }
        write_children(
            w,
            bodies,
            Some(index),
            &body.pose,
            depth + 1,
            l,
            m,
            inertia_scale,
            torque_scale,
            joint_order,
        );
        writeln!(w, "{pad}</body>").unwrap();
    }
}

fn xml_escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace("--", "- -")
}
