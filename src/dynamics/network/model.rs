//! The immutable panel network (`docs/model.md#panel-networks`): a crease pattern's panels as
//! rigid laminae on a spanning tree rooted at the anchored panel, every crease a hinge with
//! its stiffness and drive, and the vertex stars whose closure ties the other creases back.

use crate::dynamics::forcing::Forcing;
use crate::dynamics::model::Drag;
use crate::error::{NanofoldError, Result};
use crate::folding::FoldingModel;
use nalgebra::{Matrix3, Vector3};
use std::collections::VecDeque;

/// One panel's rigid-body properties in the flat reference (SI units).
#[derive(Debug, Clone, PartialEq)]
pub struct PanelBody {
    /// Mass of the structural layer, kg.
    pub mass: f64,
    /// Centre of mass in the flat sheet (z = 0), m.
    pub centre: Vector3<f64>,
    /// Inertia tensor about the centre of mass, flat-sheet axes, kg·m².
    pub inertia: Matrix3<f64>,
    /// Area of one face (drag), m².
    pub area: f64,
}

impl PanelBody {
    /// A uniform lamina of thickness `thickness` and density `density` over the triangles
    /// `triangles` (flat coordinates in m): in-plane second moments plus m t²/12 about the
    /// in-plane axes (`docs/model.md#plates`).
    pub fn lamina(triangles: &[[[f64; 2]; 3]], thickness: f64, density: f64) -> PanelBody {
        let (mut area, mut first) = (0.0, [0.0; 2]);
        let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
        for [p, q, r] in triangles {
            let a = 0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]));
            let (sx, sy) = (p[0] + q[0] + r[0], p[1] + q[1] + r[1]);
            area += a;
            first[0] += a * sx / 3.0;
            first[1] += a * sy / 3.0;
            // ∫x x dA = A/12 (Σ x_k x_k + (Σ x_k)²), and likewise for y and xy.
            sxx += a / 12.0 * (p[0] * p[0] + q[0] * q[0] + r[0] * r[0] + sx * sx);
            syy += a / 12.0 * (p[1] * p[1] + q[1] * q[1] + r[1] * r[1] + sy * sy);
            sxy += a / 12.0 * (p[0] * p[1] + q[0] * q[1] + r[0] * r[1] + sx * sy);
        }
        let (cx, cy) = (first[0] / area, first[1] / area);
        let (xx, yy, xy) = (sxx - area * cx * cx, syy - area * cy * cy, sxy - area * cx * cy);
        let sigma = density * thickness;
        let mass = sigma * area;
        let through = mass * thickness * thickness / 12.0;
        let inertia = Matrix3::new(
            sigma * yy + through,
            -sigma * xy,
            0.0,
            -sigma * xy,
            sigma * xx + through,
            0.0,
            0.0,
            0.0,
            sigma * (xx + yy),
        );
        PanelBody {
            mass,
            centre: Vector3::new(cx, cy, 0.0),
            inertia,
            area,
        }
    }
}

/// The hinge of one crease column, in the flat sheet.
#[derive(Debug, Clone, PartialEq)]
pub struct Hinge {
    /// Unit vector along the crease from its first vertex to its second.
    pub direction: Vector3<f64>,
    /// Its first vertex, m.
    pub point: Vector3<f64>,
    /// Crease length, m.
    pub length: f64,
    /// Hinge stiffness K, N·m/rad.
    pub stiffness: f64,
}

/// A crease pattern's panels and hinges for dynamics (`docs/model.md#panel-networks`).
#[derive(Debug, Clone)]
pub struct NetworkModel {
    /// The crease pattern with its stars, columns and locks.
    pub folding: FoldingModel,
    /// Metres per pattern unit.
    pub unit: f64,
    /// The panel on the substrate (the tree's root, fixed).
    pub anchored_panel: usize,
    /// Its FOLD face index (the panel's first face in the file's `faces_vertices`).
    pub anchored_face: usize,
    /// Panels in placement order, the anchored one first.
    pub order: Vec<usize>,
    /// Each panel's parent in the tree (None for the anchored panel).
    pub parent: Vec<Option<usize>>,
    /// Each panel's tree crease column (the hinge to its parent).
    pub parent_column: Vec<Option<usize>>,
    /// Each column's carried panel when it is a tree crease.
    pub carried: Vec<Option<usize>>,
    /// Each tree column's axis for its carried panel: the crease direction, turned when the
    /// panel lies right of it, so a positive fold angle is a right-handed turn (valley lifts).
    pub joint_axis: Vec<Vector3<f64>>,
    /// Every column's hinge.
    pub hinges: Vec<Hinge>,
    /// Every panel's body.
    pub bodies: Vec<PanelBody>,
    /// Each panel's structural thickness, m.
    pub thickness: f64,
    /// What drives every column.
    pub forcing: Forcing,
    /// Air drag, when modelled.
    pub drag: Option<Drag>,
    /// Fold angles at rest at t = 0, rad (one per column; locked columns at their angles).
    pub start: Vec<f64>,
    /// Every column's name in reports: `edges[E]`.
    pub labels: Vec<String>,
    /// Every panel's name in reports: `face F` by its file face (`panel of faces F+G` when
    /// facets join several).
    pub panel_names: Vec<String>,
    /// Whether the substrate (z = 0 outside the etched pit) is a contact.
    pub substrate_contact: bool,
    /// The mass matrix's entries (row, column), column by column of the tree creases in
    /// placement order: (c, c), then each tree crease above c towards the root.
    pub mass_pattern: Vec<(usize, usize)>,
    /// The fitted curves a one-DOF network moves on instead of its exact closures, when the
    /// scene chooses them (`constraint.source` "poly").
    pub reduction: Option<super::fitted::FittedReduction>,
    /// The seams a tree of panels latches as it closes (a scene's `seams`; None: faces
    /// only push on each other).
    pub seams: Option<crate::pattern::net::SeamGluing>,
    /// Coulomb's coefficient of friction between touching faces (a scene's
    /// `friction_coefficient`; 0: frictionless).
    pub friction_coefficient: f64,
}

/// The inputs of [`NetworkModel::new`], in SI units.
#[derive(Debug, Clone)]
pub struct NetworkParts {
    /// The pattern (its `locked_columns` are the scene's locks).
    pub folding: FoldingModel,
    /// Metres per pattern unit.
    pub unit: f64,
    /// The anchored panel.
    pub anchored_panel: usize,
    /// Structural thickness of every panel, m.
    pub thickness: f64,
    /// Density of the structural layer, kg/m³.
    pub density: f64,
    /// Hinge stiffness per column, N·m/rad.
    pub stiffness: Vec<f64>,
    /// Drives per column.
    pub forcing: Forcing,
    /// Drag.
    pub drag: Option<Drag>,
    /// Start fold angles per column, rad.
    pub start: Vec<f64>,
    /// Substrate contact on.
    pub substrate_contact: bool,
}

impl NetworkModel {
    /// Builds the tree rooted at the anchored panel and every panel's and hinge's properties.
    pub fn new(parts: NetworkParts) -> Result<NetworkModel> {
        let NetworkParts {
            folding,
            unit,
            anchored_panel,
            thickness,
            density,
            stiffness,
            forcing,
            drag,
            start,
            substrate_contact,
        } = parts;
        let pattern = &folding.pattern;
        let columns = folding.crease_count();
        let np = pattern.panel_count;
        if anchored_panel >= np {
            return Err(NanofoldError::invalid(
                "anchored_face",
                anchored_panel,
                format!("the pattern has {np} panels"),
            ));
        }
        if stiffness.len() != columns || start.len() != columns || forcing.hinges.len() != columns {
            return Err(NanofoldError::invalid(
                "hinges",
                format!("{} stiffnesses, {} drives", stiffness.len(), forcing.hinges.len()),
                format!("one per crease ({columns})"),
            ));
        }
        let flat = |v: usize| Vector3::new(pattern.vertices[v][0] * unit, pattern.vertices[v][1] * unit, 0.0);
        let hinges: Vec<Hinge> = pattern
            .creases
            .iter()
            .zip(&stiffness)
            .map(|(&e, &k)| {
                let [a, b] = pattern.edges[e];
                let along = flat(b) - flat(a);
                Hinge {
                    direction: along.normalize(),
                    point: flat(a),
                    length: along.norm(),
                    stiffness: k,
                }
            })
            .collect();
        // Breadth-first from the anchored panel across creases (locked ones too: a lock is a
        // hinge held by a constraint, not a weld).
        let mut neighbours: Vec<Vec<(usize, usize, bool)>> = vec![Vec::new(); np];
        for (column, &e) in pattern.creases.iter().enumerate() {
            if let [Some(left), Some(right)] = pattern.edge_faces[e] {
                let (pl, pr) = (pattern.panel_of_face[left], pattern.panel_of_face[right]);
                if pl != pr {
                    neighbours[pl].push((pr, column, false));
                    neighbours[pr].push((pl, column, true));
                }
            }
        }
        let mut parent = vec![None; np];
        let mut parent_column = vec![None; np];
        let mut carried = vec![None; columns];
        let mut joint_axis = vec![Vector3::zeros(); columns];
        let mut placed = vec![false; np];
        let mut order = Vec::with_capacity(np);
        let mut queue = VecDeque::from([anchored_panel]);
        placed[anchored_panel] = true;
        while let Some(p) = queue.pop_front() {
            order.push(p);
            for &(child, column, child_on_left) in &neighbours[p] {
                if !placed[child] {
                    placed[child] = true;
                    parent[child] = Some(p);
                    parent_column[child] = Some(column);
                    carried[column] = Some(child);
                    let sign = if child_on_left { 1.0 } else { -1.0 };
                    joint_axis[column] = sign * hinges[column].direction;
                    queue.push_back(child);
                }
            }
        }
        if let Some(p) = placed.iter().position(|&done| !done) {
            return Err(NanofoldError::invalid(
                "pattern",
                format!("panel {p}"),
                "the panel is joined to the anchored one by no crease",
            ));
        }
        let bodies = (0..np)
            .map(|p| {
                let triangles: Vec<[[f64; 2]; 3]> = folding.panel_triangles[p]
                    .iter()
                    .map(|t| t.map(|v| [pattern.vertices[v][0] * unit, pattern.vertices[v][1] * unit]))
                    .collect();
                PanelBody::lamina(&triangles, thickness, density)
            })
            .collect();
        let anchored_face = (0..pattern.faces.len())
            .filter(|&f| pattern.panel_of_face[f] == anchored_panel)
            .map(|f| pattern.file_face[f])
            .min()
            .expect("every panel has a face");
        let labels = pattern.creases.iter().map(|e| format!("edges[{e}]")).collect();
        let panel_names = (0..np)
            .map(|panel| {
                let mut faces: Vec<usize> = (0..pattern.faces.len())
                    .filter(|&f| pattern.panel_of_face[f] == panel)
                    .map(|f| pattern.file_face[f])
                    .collect();
                faces.sort_unstable();
                let faces: Vec<String> = faces.iter().map(|f| f.to_string()).collect();
                if faces.len() == 1 {
                    format!("face {}", faces[0])
                } else {
                    format!("panel of faces {}", faces.join("+"))
                }
            })
            .collect();
        let mut model = NetworkModel {
            folding,
            unit,
            anchored_panel,
            anchored_face,
            order,
            parent,
            parent_column,
            carried,
            joint_axis,
            hinges,
            bodies,
            thickness,
            forcing,
            drag,
            start,
            labels,
            panel_names,
            substrate_contact,
            mass_pattern: Vec::new(),
            reduction: None,
            seams: None,
            friction_coefficient: 0.0,
        };
        let mut mass_pattern = Vec::new();
        for &p in &model.order[1..] {
            let c = model.parent_column[p].expect("placed panels have tree creases");
            mass_pattern.push((c, c));
            mass_pattern.extend(
                model
                    .path_columns(model.parent[p].expect("and parents"))
                    .map(|a| (a, c)),
            );
        }
        model.mass_pattern = mass_pattern;
        Ok(model)
    }

    /// Number of fold-angle coordinates (creases).
    pub fn columns(&self) -> usize {
        self.hinges.len()
    }

    /// Number of panels.
    pub fn panels(&self) -> usize {
        self.bodies.len()
    }

    /// Whether column `c` is held at its start angle.
    pub fn locked(&self, c: usize) -> bool {
        self.folding.locked_columns[c]
    }

    /// Hinge stiffness per column, N·m/rad.
    pub fn stiffness(&self) -> Vec<f64> {
        self.hinges.iter().map(|h| h.stiffness).collect()
    }

    /// The tree columns on the path from panel `p` to the anchored panel, nearest first.
    pub fn path_columns(&self, mut p: usize) -> impl Iterator<Item = usize> + '_ {
        std::iter::from_fn(move || {
            let column = self.parent_column[p]?;
            p = self.parent[p].expect("a panel with a tree crease has a parent");
            Some(column)
        })
    }

    /// The length scale of the pattern, m (its bounding-box diagonal).
    pub fn size(&self) -> f64 {
        self.folding.size * self.unit
    }
}
