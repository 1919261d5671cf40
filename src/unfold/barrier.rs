//! The barrier between panels that share no vertex
//! (`docs/model.md#energy-unfolding-of-many-vertices`): IPC's log barrier
//! b(x) = −(x − 1)² ln x, x = d / d̂, on every vertex–triangle and edge–edge distance d below
//! the activation distance d̂, with its gradient in fold angles through the panels' poses.

use crate::error::{NanofoldError, Result};
use crate::folding::contact::{closest_point_on_triangle, median_panel_size, share_vertex};
use crate::folding::{FoldingModel, Pose};
use crate::geometry::broad_phase::overlapping_pairs;
use nalgebra::Vector3;

type Point = Vector3<f64>;

/// How the barrier acts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BarrierSettings {
    /// d̂ as a share of the median panel size.
    pub activation: f64,
    /// κ, in the energy's units.
    pub stiffness: f64,
}

impl Default for BarrierSettings {
    fn default() -> Self {
        BarrierSettings {
            activation: 0.01,
            stiffness: 1.0,
        }
    }
}

impl BarrierSettings {
    /// Checks both numbers.
    pub fn validate(&self) -> Result<()> {
        if !(self.activation > 0.0 && self.activation <= 1.0) {
            return Err(NanofoldError::invalid(
                "barrier.activation",
                self.activation,
                "a share of the median panel size in (0, 1]",
            ));
        }
        if !(self.stiffness > 0.0 && self.stiffness.is_finite()) {
            return Err(NanofoldError::invalid(
                "barrier.stiffness",
                self.stiffness,
                "a positive finite number",
            ));
        }
        Ok(())
    }
}

/// b(x) and db/dx for x in (0, 1); 0 from 1 on. Value, slope and curvature vanish at x = 1,
/// so the barrier is C² there; it grows without bound as x → 0.
pub fn barrier_function(x: f64) -> (f64, f64) {
    if x >= 1.0 {
        return (0.0, 0.0);
    }
    if x <= 0.0 {
        return (f64::INFINITY, f64::NEG_INFINITY);
    }
    let (m, l) = (x - 1.0, x.ln());
    (-m * m * l, -2.0 * m * l - m * m / x)
}

/// The barrier of a folding model: its activation distance, stiffness, the panel pairs left
/// out and each panel's edges (its gradient goes up the model's tree of panels).
pub struct PanelBarrier {
    activation: f64,
    stiffness: f64,
    /// Panel pairs left out: layers already touching at the start (a flat-folded state).
    excluded: std::collections::HashSet<(usize, usize)>,
    /// Each panel's distinct triangle edges (vertex pairs).
    edges: Vec<Vec<[usize; 2]>>,
}

/// A close pair of points, one on each panel.
struct Close {
    distance: f64,
    on_first: Point,
    on_second: Point,
}

impl PanelBarrier {
    /// The barrier for `model`.
    pub fn new(model: &FoldingModel, settings: &BarrierSettings) -> Result<PanelBarrier> {
        settings.validate()?;
        let edges = model
            .panel_triangles
            .iter()
            .map(|triangles| {
                let mut list: Vec<[usize; 2]> = triangles
                    .iter()
                    .flat_map(|t| (0..3).map(move |k| [t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])]))
                    .collect();
                list.sort_unstable();
                list.dedup();
                list
            })
            .collect();
        Ok(PanelBarrier {
            activation: settings.activation * median_panel_size(model),
            stiffness: settings.stiffness,
            edges,
            excluded: Default::default(),
        })
    }

    /// Leaves out the panel pairs that touch (within 1e-9 of the pattern's size) at `poses`:
    /// the layers of a flat-folded start lie on each other, and would make the barrier
    /// infinite before the first step. Crossings of those pairs are still refused.
    pub fn exclude_touching(&mut self, model: &FoldingModel, poses: &[Pose]) -> usize {
        let settings = crate::folding::ContactSettings {
            search: 0.0,
            ..crate::folding::ContactSettings::default()
        };
        let report = crate::folding::panel_contacts(model, poses, &settings);
        for contact in &report.contacts {
            if contact.distance <= 1e-9 * model.size {
                self.excluded.insert((contact.panels[0], contact.panels[1]));
            }
        }
        self.excluded.len()
    }

    /// The activation distance d̂, in the pattern's length unit.
    pub fn activation(&self) -> f64 {
        self.activation
    }

    /// B(ρ) at the panel poses of `fold_angles`, and ∂B/∂ρ added into `gradient`. Infinite
    /// when two panels touch.
    pub fn value_and_gradient(&self, model: &FoldingModel, poses: &[Pose], gradient: &mut [f64]) -> f64 {
        let pattern = &model.pattern;
        let place = |panel: usize, v: usize| poses[panel].place(pattern.vertices[v]);
        let half = self.activation / 2.0;
        let boxes: Vec<([f64; 3], [f64; 3])> = (0..pattern.panel_count)
            .map(|p| {
                let mut lo = [f64::INFINITY; 3];
                let mut hi = [f64::NEG_INFINITY; 3];
                for &v in &model.panel_vertices[p] {
                    let x = place(p, v);
                    for k in 0..3 {
                        lo[k] = lo[k].min(x[k] - half);
                        hi[k] = hi[k].max(x[k] + half);
                    }
                }
                (lo, hi)
            })
            .collect();
        let mut total = 0.0;
        // Each panel's barrier force and its moment about the origin; turned into ∂B/∂ρ
        // once, up the tree, below.
        let mut wrench = vec![(Point::zeros(), Point::zeros()); pattern.panel_count];
        let mut push = |panel: usize, point: &Point, force: Point| {
            wrench[panel].0 += force;
            wrench[panel].1 += point.cross(&force);
        };
        for (a, b) in overlapping_pairs(&boxes) {
            if share_vertex(&model.panel_vertices[a], &model.panel_vertices[b]) || self.excluded.contains(&(a, b)) {
                continue;
            }
            let mut close = Vec::new();
            for (first, second) in [(a, b), (b, a)] {
                for &v in &model.panel_vertices[first] {
                    let p = place(first, v);
                    for t in &model.panel_triangles[second] {
                        let triangle = t.map(|w| place(second, w));
                        let q = closest_point_on_triangle(&p, &triangle);
                        let distance = (p - q).norm();
                        if distance < self.activation {
                            let (on_first, on_second) = if first == a { (p, q) } else { (q, p) };
                            close.push(Close {
                                distance,
                                on_first,
                                on_second,
                            });
                        }
                    }
                }
            }
            for e in &self.edges[a] {
                let (p1, q1) = (place(a, e[0]), place(a, e[1]));
                for f in &self.edges[b] {
                    let (p2, q2) = (place(b, f[0]), place(b, f[1]));
                    let (x, y) = closest_between_segments(&p1, &q1, &p2, &q2);
                    let distance = (x - y).norm();
                    if distance < self.activation {
                        close.push(Close {
                            distance,
                            on_first: x,
                            on_second: y,
                        });
                    }
                }
            }
            for c in close {
                let (value, slope) = barrier_function(c.distance / self.activation);
                if !value.is_finite() {
                    return f64::INFINITY;
                }
                total += self.stiffness * value;
                // dB/dd along n = (p_a − p_b)/d, through both panels' point velocities.
                let coefficient = self.stiffness * slope / self.activation;
                let n = (c.on_first - c.on_second) / c.distance;
                push(a, &c.on_first, n * coefficient);
                push(b, &c.on_second, -n * coefficient);
            }
        }
        self.add_wrench_gradient(model, poses, &mut wrench, gradient);
        total
    }

    /// Adds Σ force·∂p/∂ρ over every point p that carries a force: a tree step turns the
    /// points of every panel below it about its crease's current axis u through q,
    /// ∂p/∂ρ = ±u × (p − q), so its column gains ±u · (τ − q × F) for the subtree's total
    /// force F and moment τ about the origin. One sweep from the leaves sums the subtrees
    /// (`wrench` is spent doing so): linear in the panels, where walking each point's path
    /// to the root was quadratic in a long strip's length.
    fn add_wrench_gradient(
        &self,
        model: &FoldingModel,
        poses: &[Pose],
        wrench: &mut [(Point, Point)],
        gradient: &mut [f64],
    ) {
        for step in model.tree.iter().rev() {
            let (force, moment) = wrench[step.panel];
            if force == Point::zeros() && moment == Point::zeros() {
                continue;
            }
            let [i, j] = model.pattern.edges[step.edge];
            let parent = &poses[step.parent];
            let (from, to) = (
                parent.place(model.pattern.vertices[i]),
                parent.place(model.pattern.vertices[j]),
            );
            let axis = (to - from).normalize();
            let sign = if step.panel_on_left { 1.0 } else { -1.0 };
            gradient[step.column] += sign * axis.dot(&(moment - from.cross(&force)));
            wrench[step.parent].0 += force;
            wrench[step.parent].1 += moment;
        }
    }
}

/// The nearest points of segments p1q1 and p2q2 (parameters clamped to the segments).
fn closest_between_segments(p1: &Point, q1: &Point, p2: &Point, q2: &Point) -> (Point, Point) {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.dot(&d1), d2.dot(&d2), d2.dot(&r));
    let c = d1.dot(&r);
    let b = d1.dot(&d2);
    let denominator = a * e - b * b;
    let mut s = if denominator > 1e-14 * a * e {
        ((b * f - c * e) / denominator).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = (b * s + f) / e;
    if t < 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
    }
    (p1 + d1 * s, p2 + d2 * t)
}
