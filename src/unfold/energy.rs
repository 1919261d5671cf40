//! Repulsive energies on the sphere (`docs/model.md#energy`, T3.1–3.2), behind one trait so another
//! reading can be added without touching the solver.

use crate::geometry::sphere::{geodesic_with_gradient, Vec3};
use serde::{Deserialize, Serialize};

/// A great-circle arc (one sector) between nodes `a` and `b`, of length `length`.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Arc {
    /// The node at the start of the arc.
    pub a: usize,
    /// The node at its end.
    pub b: usize,
    /// Its length (the sector angle), rad.
    pub length: f64,
}

/// Scratch buffers reused across evaluations, so the solver's hot loop allocates nothing.
#[derive(Debug, Default, Clone)]
pub struct EnergyWorkspace {
    /// Pairwise geodesics γ(v, w), row-major n × n.
    gamma: Vec<f64>,
    /// ∂γ(v, w)/∂x_v for v < w stored at [v·n + w], and ∂γ/∂x_w at [w·n + v].
    gamma_grad: Vec<Vec3>,
    /// dU/dγ(v, w), accumulated before the chain rule.
    coefficient: Vec<f64>,
}

/// A repulsive energy U(x) of the node positions, with its gradient.
pub trait Energy: Send + Sync {
    /// The CLI name (`--energy`).
    fn name(&self) -> &'static str;
    /// The exponent p.
    fn exponent(&self) -> f64;
    /// U(x); `f64::INFINITY` when charges touch (a node on an arc for the separable
    /// energy, a node on a midpoint for the midpoint energy).
    fn value(&self, nodes: &[Vec3], arcs: &[Arc], ws: &mut EnergyWorkspace) -> f64;
    /// U(x) and ∇U (overwrites `gradient`, one entry per node).
    fn value_and_gradient(&self, nodes: &[Vec3], arcs: &[Arc], ws: &mut EnergyWorkspace, gradient: &mut [Vec3]) -> f64;
}

/// Which energy to use, as named on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EnergyKind {
    /// U_s = Σ_e Σ_{v∉e} (γ(v,a_e) + γ(v,b_e) − α_e)^(−p), default p = 2: a barrier
    /// wherever a node touches an arc.
    Separable,
    /// U_m = Σ_e Σ_{v∉e} γ(v, m_e)^(−p), default p = 4: no barrier away from midpoints.
    #[serde(alias = "non_separable")]
    NonSeparable,
}

impl EnergyKind {
    /// The default exponent of this energy.
    pub fn default_exponent(self) -> f64 {
        match self {
            EnergyKind::Separable => 2.0,
            EnergyKind::NonSeparable => 4.0,
        }
    }

    /// Builds the energy with exponent `p` (the default when `None`).
    pub fn build(self, p: Option<f64>) -> Box<dyn Energy> {
        let p = p.unwrap_or_else(|| self.default_exponent());
        match self {
            EnergyKind::Separable => Box::new(SeparableEnergy { p }),
            EnergyKind::NonSeparable => Box::new(MidpointEnergy { p }),
        }
    }
}

/// s^(−p) and its derivative −p s^(−p−1), with integer powers where p allows.
#[inline]
fn inverse_power(s: f64, p: f64) -> (f64, f64) {
    let value = if p == 2.0 {
        1.0 / (s * s)
    } else if p == 4.0 {
        let s2 = s * s;
        1.0 / (s2 * s2)
    } else {
        s.powf(-p)
    };
    (value, -p * value / s)
}

/// The separable, admissible energy (`docs/model.md#energy`, default p = 2).
#[derive(Debug, Clone, Copy)]
pub struct SeparableEnergy {
    /// The exponent p.
    pub p: f64,
}

impl SeparableEnergy {
    fn fill_pairs(nodes: &[Vec3], ws: &mut EnergyWorkspace, with_gradient: bool) {
        let n = nodes.len();
        ws.gamma.resize(n * n, 0.0);
        if with_gradient {
            ws.gamma_grad.resize(n * n, Vec3::zeros());
            ws.coefficient.clear();
            ws.coefficient.resize(n * n, 0.0);
        }
        for v in 0..n {
            for w in v + 1..n {
                if with_gradient {
                    let (g, dv, dw) = geodesic_with_gradient(&nodes[v], &nodes[w]);
                    ws.gamma[v * n + w] = g;
                    ws.gamma[w * n + v] = g;
                    ws.gamma_grad[v * n + w] = dv;
                    ws.gamma_grad[w * n + v] = dw;
                } else {
                    let g = crate::geometry::sphere::geodesic(&nodes[v], &nodes[w]);
                    ws.gamma[v * n + w] = g;
                    ws.gamma[w * n + v] = g;
                }
            }
        }
    }

    fn accumulate(&self, nodes: &[Vec3], arcs: &[Arc], ws: &mut EnergyWorkspace, with_gradient: bool) -> f64 {
        let n = nodes.len();
        let mut total = 0.0;
        for arc in arcs {
            for v in 0..n {
                if v == arc.a || v == arc.b {
                    continue;
                }
                let s = ws.gamma[v * n + arc.a] + ws.gamma[v * n + arc.b] - arc.length;
                if s <= 0.0 {
                    return f64::INFINITY;
                }
                let (value, slope) = inverse_power(s, self.p);
                total += value;
                if with_gradient {
                    ws.coefficient[v * n + arc.a] += slope;
                    ws.coefficient[v * n + arc.b] += slope;
                }
            }
        }
        total
    }
}

impl Energy for SeparableEnergy {
    fn name(&self) -> &'static str {
        "separable"
    }
    fn exponent(&self) -> f64 {
        self.p
    }
    fn value(&self, nodes: &[Vec3], arcs: &[Arc], ws: &mut EnergyWorkspace) -> f64 {
        Self::fill_pairs(nodes, ws, false);
        self.accumulate(nodes, arcs, ws, false)
    }
    fn value_and_gradient(&self, nodes: &[Vec3], arcs: &[Arc], ws: &mut EnergyWorkspace, gradient: &mut [Vec3]) -> f64 {
        let n = nodes.len();
        Self::fill_pairs(nodes, ws, true);
        let total = self.accumulate(nodes, arcs, ws, true);
        gradient.iter_mut().for_each(|g| *g = Vec3::zeros());
        if !total.is_finite() {
            return total;
        }
        // Chain rule through every pair once: coefficient[v][w] multiplies γ(v, w).
        for v in 0..n {
            for w in v + 1..n {
                let c = ws.coefficient[v * n + w] + ws.coefficient[w * n + v];
                if c != 0.0 {
                    gradient[v] += c * ws.gamma_grad[v * n + w];
                    gradient[w] += c * ws.gamma_grad[w * n + v];
                }
            }
        }
        total
    }
}

/// The non-separable midpoint-charge energy (`docs/model.md#energy`, default p = 4). The midpoint m_e is
/// the direction of x_a + x_b, and γ is scale-invariant, so γ(v, m_e) = γ(v, x_a + x_b).
#[derive(Debug, Clone, Copy)]
pub struct MidpointEnergy {
    /// The exponent p.
    pub p: f64,
}

impl Energy for MidpointEnergy {
    fn name(&self) -> &'static str {
        "non-separable"
    }
    fn exponent(&self) -> f64 {
        self.p
    }
    fn value(&self, nodes: &[Vec3], arcs: &[Arc], _ws: &mut EnergyWorkspace) -> f64 {
        let mut total = 0.0;
        for arc in arcs {
            let mid = nodes[arc.a] + nodes[arc.b];
            for (v, x) in nodes.iter().enumerate() {
                if v == arc.a || v == arc.b {
                    continue;
                }
                let g = crate::geometry::sphere::geodesic(x, &mid);
                if g <= 0.0 {
                    return f64::INFINITY;
                }
                total += inverse_power(g, self.p).0;
            }
        }
        total
    }
    fn value_and_gradient(
        &self,
        nodes: &[Vec3],
        arcs: &[Arc],
        _ws: &mut EnergyWorkspace,
        gradient: &mut [Vec3],
    ) -> f64 {
        gradient.iter_mut().for_each(|g| *g = Vec3::zeros());
        let mut total = 0.0;
        for arc in arcs {
            let mid = nodes[arc.a] + nodes[arc.b];
            let mut mid_gradient = Vec3::zeros();
            for (v, x) in nodes.iter().enumerate() {
                if v == arc.a || v == arc.b {
                    continue;
                }
                let (g, dv, dm) = geodesic_with_gradient(x, &mid);
                if g <= 0.0 {
                    gradient.iter_mut().for_each(|g| *g = Vec3::zeros());
                    return f64::INFINITY;
                }
                let (value, slope) = inverse_power(g, self.p);
                total += value;
                gradient[v] += slope * dv;
                mid_gradient += slope * dm;
            }
            gradient[arc.a] += mid_gradient;
            gradient[arc.b] += mid_gradient;
        }
        total
    }
}
