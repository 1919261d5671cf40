//! The immutable description of a vertex for the solver ([`UnfoldModel`]: nodes, arcs,
//! held creases, the gauge, the exact flat layout), the constraint rows restored after
//! every step, and the fold angles measured from node positions.

use crate::geometry::kinematics;
use crate::geometry::sphere::{fold_angle, geodesic, Vec3};
use crate::pattern::{Assignment, Chain, RayRole, VertexPattern};
use crate::unfold::energy::Arc;
use serde::Serialize;

/// A crease held at a fixed fold angle: virtual and flat creases (0) and locked ones.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct HeldFold {
    /// The ray.
    pub ray: usize,
    /// Its fold angle, rad.
    pub target: f64,
}

/// The immutable description of a vertex for the solver.
#[derive(Debug, Clone)]
pub struct UnfoldModel {
    /// Closed (interior vertex) or open (boundary vertex).
    pub chain: Chain,
    /// Nodes: one per ray.
    pub node_count: usize,
    /// One great-circle arc per sector.
    pub arcs: Vec<Arc>,
    /// Rays with a fold angle (all but boundary rays).
    pub fold_rays: Vec<usize>,
    /// Ray of each user crease, in file order.
    pub crease_rays: Vec<usize>,
    /// Rays held at a fold angle: virtual, flat and locked creases.
    pub held: Vec<HeldFold>,
    /// Nodes 0 and 1 are fixed (gauge: sector 0 stays in the xy-plane); the rest are free.
    pub free: Vec<usize>,
    /// Exact flat layout: nodes at cumulative sector angles on the equator.
    pub flat_layout: Vec<Vec3>,
    /// Fold angles of the given folded state, per ray.
    pub folded_ray_angles: Vec<f64>,
    /// Sector angles after splitting, rad.
    pub sector_angles: Vec<f64>,
}

/// Constraints restored by Newton projection, one row each.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum ConstraintRow {
    Arc(usize),
    Held(usize),
    /// The fold angle at this ray is zero (only while the Newton finish runs).
    Flat(usize),
    /// Component `k` (of the tangent plane at x_v) of x_v + x_w = 0: an antipodal pair held
    /// at its kink (see the solver's antipodal pins).
    Antipodal {
        v: usize,
        w: usize,
        k: usize,
    },
}

impl UnfoldModel {
    /// The solver's view of a pattern.
    pub fn new(pattern: &VertexPattern) -> UnfoldModel {
        let n = pattern.ray_count();
        let arcs: Vec<Arc> = pattern
            .sector_angles
            .iter()
            .enumerate()
            .map(|(k, &length)| Arc {
                a: k,
                b: (k + 1) % n,
                length,
            })
            .collect();
        let fold_rays: Vec<usize> = (0..n).filter(|&k| pattern.rays[k] != RayRole::Boundary).collect();
        let mut held = Vec::new();
        for (k, role) in pattern.rays.iter().enumerate() {
            match role {
                RayRole::Virtual => held.push(HeldFold { ray: k, target: 0.0 }),
                RayRole::Crease(i) => {
                    let c = &pattern.creases[*i];
                    if c.assignment == Assignment::Flat {
                        held.push(HeldFold { ray: k, target: 0.0 });
                    } else if c.locked {
                        held.push(HeldFold {
                            ray: k,
                            target: c.folded_angle,
                        });
                    }
                }
                RayRole::Boundary => {}
            }
        }
        let flat_layout = kinematics::forward(&pattern.sector_angles, &vec![0.0; n]);
        UnfoldModel {
            chain: pattern.chain,
            node_count: n,
            arcs,
            fold_rays,
            crease_rays: pattern.creases.iter().map(|c| c.ray).collect(),
            held,
            free: (2..n).collect(),
            flat_layout,
            folded_ray_angles: pattern.folded_ray_angles(),
            sector_angles: pattern.sector_angles.clone(),
        }
    }

    pub(crate) fn neighbours(&self, ray: usize) -> (usize, usize) {
        let n = self.node_count;
        ((ray + n - 1) % n, (ray + 1) % n)
    }

    /// Fold angle at `ray` measured from the nodes.
    pub fn fold_angle_at(&self, nodes: &[Vec3], ray: usize) -> f64 {
        let (prev, next) = self.neighbours(ray);
        fold_angle(&nodes[prev], &nodes[ray], &nodes[next])
    }

    /// Fold angle of every user crease, in file order.
    pub fn crease_angles(&self, nodes: &[Vec3]) -> Vec<f64> {
        let mut out = vec![0.0; self.crease_rays.len()];
        self.crease_angles_into(nodes, &mut out);
        out
    }

    /// [`UnfoldModel::crease_angles`] into a buffer.
    pub fn crease_angles_into(&self, nodes: &[Vec3], out: &mut [f64]) {
        for (o, &r) in out.iter_mut().zip(&self.crease_rays) {
            *o = self.fold_angle_at(nodes, r);
        }
    }

    /// Largest node distance from the exact flat layout.
    pub fn flat_layout_error(&self, nodes: &[Vec3]) -> f64 {
        nodes
            .iter()
            .zip(&self.flat_layout)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max)
    }

    /// Largest |ρ| over every ray that folds (creases and virtual rays).
    pub fn max_fold_angle(&self, nodes: &[Vec3]) -> f64 {
        self.fold_rays
            .iter()
            .map(|&r| self.fold_angle_at(nodes, r).abs())
            .fold(0.0, f64::max)
    }

    /// Largest |γ(x_a, x_b) − α| over all arcs.
    pub fn max_arc_residual(&self, nodes: &[Vec3]) -> f64 {
        self.arcs
            .iter()
            .map(|arc| (geodesic(&nodes[arc.a], &nodes[arc.b]) - arc.length).abs())
            .fold(0.0, f64::max)
    }

    /// Whether a row closes the loop (see [`crate::unfold::qp::JacobianRow::closing`]). The open
    /// chain is: arc (i−1, i) and the fold angle at ray i−1 for every free node i, both of
    /// which move x_i (along and across the arc) and nothing later. The arc back to node 0,
    /// fold angles at rays n−1 and 0, and antipodal pins close it.
    pub(crate) fn is_closing(&self, row: ConstraintRow) -> bool {
        match row {
            ConstraintRow::Arc(e) => self.arcs[e].b < self.arcs[e].a,
            ConstraintRow::Held(h) => self.closes_at_ray(self.held[h].ray),
            ConstraintRow::Flat(ray) => self.closes_at_ray(ray),
            ConstraintRow::Antipodal { .. } => true,
        }
    }

    fn closes_at_ray(&self, ray: usize) -> bool {
        ray == 0 || ray + 1 >= self.node_count
    }

    pub(crate) fn constraint_rows(&self) -> Vec<ConstraintRow> {
        let mut rows: Vec<ConstraintRow> = (0..self.arcs.len())
            .filter(|&e| self.arcs[e].a >= 2 || self.arcs[e].b >= 2)
            .map(ConstraintRow::Arc)
            .collect();
        rows.extend((0..self.held.len()).map(ConstraintRow::Held));
        rows
    }

    /// The restoration tolerance used for `requested`: no tighter than rounding allows,
    /// 4 ε per node, since residuals accumulate along the chain (`docs/model.md#projected-gradient`).
    pub fn restore_tolerance(&self, requested: f64) -> f64 {
        requested.max(4.0 * f64::EPSILON * self.node_count as f64)
    }

    /// Node positions of the given folded state (forward kinematics, `docs/model.md#loop-closure`).
    pub fn folded_nodes(&self) -> Vec<Vec3> {
        kinematics::forward(&self.sector_angles, &self.folded_ray_angles)
    }
}
