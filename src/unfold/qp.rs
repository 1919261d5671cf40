//! The direction subproblem of the projected gradient step (`docs/model.md#projected-gradient`):
//! min_y ½ yᵀMy + qᵀy  s.t.  A y = 0, with M = I (the plain QP) or the bending metric
//! M = I + SᵀS, solved by Clarabel (the general path) or by a direct projection onto the
//! null space of A (the equality-only closed form).

mod row_space;

pub use row_space::{ConstraintJacobian, JacobianRow, RowSpace};

use crate::error::{NumericalError, Result};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Which solver computes the direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum QpMethod {
    /// Clarabel interior-point QP (handles inequalities; the reference path).
    Clarabel,
    /// Closed-form projection y = −(I − A⁺A) q through the chain factorisation of A
    /// (equality constraints only).
    Direct,
}

/// Problem data: the linearised constraints A (rows) and the energy gradient q, both in the
/// tangent coordinates of the free nodes, and the rows of S when the metric is
/// M = I + SᵀS (None: M = I).
#[derive(Debug, Clone)]
pub struct DirectionProblem {
    /// ∇U in the tangent coordinates of the free nodes.
    pub q: DVector<f64>,
    /// The constraint rows A.
    pub a: ConstraintJacobian,
    /// S of the metric M = I + SᵀS (None: M = I).
    pub metric: Option<ConstraintJacobian>,
}

impl DirectionProblem {
    /// ½ yᵀMy's gradient My.
    pub fn metric_times(&self, y: &DVector<f64>) -> DVector<f64> {
        match &self.metric {
            None => y.clone(),
            Some(s) => y + s.mul_transpose(&s.mul(y)),
        }
    }
}

/// Outcome of a direction solve, Clarabel-style.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum QpStatus {
    /// Solved to the requested accuracy.
    Solved,
    /// Clarabel's reduced-accuracy success.
    AlmostSolved,
}

/// The direction and how it was obtained.
#[derive(Debug, Clone)]
pub struct DirectionSolution {
    /// The direction, in tangent coordinates.
    pub y: DVector<f64>,
    /// How well it was solved.
    pub status: QpStatus,
    /// Interior-point iterations (0 for the direct projection).
    pub iterations: u32,
}

/// Solves the direction QP with Clarabel. Any status other than `Solved` or `AlmostSolved`
/// is an error naming the status, never silently used.
pub fn solve_clarabel(problem: &DirectionProblem) -> Result<DirectionSolution> {
    let n = problem.q.len();
    let rows = problem.a.rows.len();
    let p = match &problem.metric {
        None => CscMatrix::identity(n),
        Some(s) => upper_triangle_csc(&(DMatrix::identity(n, n) + s.to_dense().transpose() * s.to_dense())),
    };
    let q: Vec<f64> = problem.q.iter().copied().collect();
    let a = problem.a.to_csc();
    let b = vec![0.0; rows];
    let cones = [SupportedConeT::ZeroConeT(rows)];
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .tol_gap_abs(1e-13)
        .tol_gap_rel(1e-13)
        .tol_feas(1e-13)
        .presolve_enable(false)
        .build()
        .map_err(|e| NumericalError::QpSetup {
            message: format!("{e:?}"),
        })?;
    let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings)
        .map_err(|e| NumericalError::QpSetup { message: e.to_string() })?;
    solver.solve();
    let status = match solver.solution.status {
        SolverStatus::Solved => QpStatus::Solved,
        SolverStatus::AlmostSolved => QpStatus::AlmostSolved,
        other => {
            return Err(NumericalError::QpStatus {
                status: format!("{other:?}"),
            }
            .into())
        }
    };
    Ok(DirectionSolution {
        y: DVector::from_vec(solver.solution.x.clone()),
        status,
        iterations: solver.solution.iterations,
    })
}

/// The upper triangle of a symmetric matrix (what Clarabel reads of P).
fn upper_triangle_csc(p: &DMatrix<f64>) -> CscMatrix<f64> {
    let n = p.ncols();
    let (mut colptr, mut rowval, mut nzval) = (vec![0], Vec::new(), Vec::new());
    for j in 0..n {
        for i in 0..=j {
            if p[(i, j)] != 0.0 {
                rowval.push(i);
                nzval.push(p[(i, j)]);
            }
        }
        colptr.push(rowval.len());
    }
    CscMatrix::new(n, n, colptr, rowval, nzval)
}

/// The direct path: y = −(I − A⁺A) q, or with the metric M = I + SᵀS the same projection
/// in the variables (y, e) under A y = 0, S y − e = 0 (so ½‖y‖² + ½‖e‖² = ½ yᵀMy).
pub fn solve_direct(problem: &DirectionProblem) -> Result<DirectionSolution> {
    let mut row_space = RowSpace::new(&problem.a)?;
    solve_direct_with(problem, &mut row_space)
}

/// The direct path with A already factorised (the unfolder reuses it for the restoration).
pub fn solve_direct_with(problem: &DirectionProblem, row_space: &mut RowSpace) -> Result<DirectionSolution> {
    let mut workspace = DirectWorkspace::default();
    let mut y = DVector::zeros(problem.q.len());
    workspace.solve(
        &problem.a,
        problem.q.as_slice(),
        problem.metric.as_ref(),
        row_space,
        y.as_mut_slice(),
    )?;
    Ok(DirectionSolution {
        y,
        status: QpStatus::Solved,
        iterations: 0,
    })
}

/// Scratch of the direct path with the bending metric: the augmented constraint rows
/// (A and S y − e = 0), their factorisation and the augmented vectors. Reused from one
/// direction to the next, so a direction allocates nothing once the buffers have grown.
#[derive(Debug, Default)]
pub struct DirectWorkspace {
    rows_at: Vec<usize>,
    used: Vec<usize>,
    node_slot: Vec<usize>,
    extra_first: Vec<usize>,
    augmented: ConstraintJacobian,
    augmented_space: RowSpace,
    q: Vec<f64>,
    projected: Vec<f64>,
}

impl DirectWorkspace {
    /// Writes the direction y (minimiser of ½ yᵀMy + qᵀy with A y = 0) into `y`; with no
    /// metric, `row_space` (A factorised) does it alone.
    pub fn solve(
        &mut self,
        a: &ConstraintJacobian,
        q: &[f64],
        metric: Option<&ConstraintJacobian>,
        row_space: &mut RowSpace,
        y: &mut [f64],
    ) -> Result<()> {
        match metric {
            None => {
                row_space.project_to_null_into(q, y);
                y.iter_mut().for_each(|v| *v = -*v);
                Ok(())
            }
            Some(s) => self.solve_with_metric(a, q, s, y),
        }
    }

    /// Each row of S gets its own variable e, placed right after the last node the row
    /// touches so the augmented rows keep the chain's band (and pivot on e: independent).
    fn solve_with_metric(
        &mut self,
        a: &ConstraintJacobian,
        q: &[f64],
        s: &ConstraintJacobian,
        y: &mut [f64],
    ) -> Result<()> {
        let nodes = a.columns / 2;
        self.rows_at.clear();
        self.rows_at.resize(nodes, 0);
        for row in &s.rows {
            if let Some(pivot) = row.entries().iter().map(|e| e.0).max() {
                self.rows_at[pivot] += 1;
            }
        }
        self.node_slot.clear();
        self.extra_first.clear();
        let mut cursor = 0;
        for k in 0..nodes {
            self.node_slot.push(cursor);
            self.extra_first.push(cursor + 1);
            cursor += 1 + self.rows_at[k].div_ceil(2);
        }
        self.augmented.columns = 2 * cursor;
        self.augmented.rows.clear();
        for row in &a.rows {
            let mut out = JacobianRow::default();
            out.clear(row.closing);
            for (slot, g) in row.entries() {
                out.add(self.node_slot[*slot], *g);
            }
            self.augmented.rows.push(out);
        }
        self.used.clear();
        self.used.resize(nodes, 0);
        for row in &s.rows {
            let Some(pivot) = row.entries().iter().map(|e| e.0).max() else {
                continue;
            };
            let mut out = JacobianRow::default();
            out.clear(false);
            for (slot, g) in row.entries() {
                out.add(self.node_slot[*slot], *g);
            }
            let k = self.used[pivot];
            self.used[pivot] += 1;
            out.add(
                self.extra_first[pivot] + k / 2,
                if k.is_multiple_of(2) { [-1.0, 0.0] } else { [0.0, -1.0] },
            );
            self.augmented.rows.push(out);
        }
        self.q.clear();
        self.q.resize(2 * cursor, 0.0);
        for k in 0..nodes {
            self.q[2 * self.node_slot[k]] = q[2 * k];
            self.q[2 * self.node_slot[k] + 1] = q[2 * k + 1];
        }
        self.projected.resize(2 * cursor, 0.0);
        self.augmented_space.factorise(&self.augmented)?;
        self.augmented_space.project_to_null_into(&self.q, &mut self.projected);
        for (c, out) in y.iter_mut().enumerate() {
            *out = -self.projected[2 * self.node_slot[c / 2] + c % 2];
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    #[test]
    fn projection_and_clarabel_agree_on_a_small_problem() {
        let dense = DMatrix::from_row_slice(2, 4, &[1.0, 2.0, 0.0, -1.0, 0.0, 1.0, 1.0, 3.0]);
        let a = ConstraintJacobian::from_dense(&dense, &[false, true]);
        let q = DVector::from_vec(vec![0.3, -1.0, 2.0, 0.5]);
        let problem = DirectionProblem {
            q,
            a: a.clone(),
            metric: None,
        };
        let direct = solve_direct(&problem).unwrap();
        let clarabel = solve_clarabel(&problem).unwrap();
        assert!((&direct.y - &clarabel.y).amax() < 1e-10);
        assert!((&dense * &direct.y).amax() < 1e-14);
        // Optimality: y + q lies in the row space of A, so it is orthogonal to null(A).
        let mut rs = RowSpace::dense(&a).unwrap();
        assert!(rs.project_to_null(&(&direct.y + &problem.q)).amax() < 1e-14);
    }

    #[test]
    fn dependent_rows_do_not_break_either_path() {
        // The third row (closing) is the sum of the first two: rank 2.
        let dense = DMatrix::from_row_slice(3, 4, &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0]);
        let a = ConstraintJacobian::from_dense(&dense, &[false, false, true]);
        let q = DVector::from_vec(vec![1.0, 2.0, 3.0, -1.0]);
        let problem = DirectionProblem { q, a, metric: None };
        let expected = DVector::from_vec(vec![0.0, 0.0, -3.0, 1.0]);
        let direct = solve_direct(&problem).unwrap();
        assert!((direct.y - &expected).amax() < 1e-14);
        let clarabel = solve_clarabel(&problem).unwrap();
        assert!((clarabel.y - expected).amax() < 1e-9);
    }
}
