//! The direction subproblem of the projected gradient step (SPEC §5):
//! min_y ½‖y‖² + qᵀy  s.t.  A y = 0, solved by Clarabel (the general path) or by a direct
//! projection onto the null space of A (the equality-only closed form).

mod row_space;

pub use row_space::{ConstraintJacobian, JacobianRow, RowSpace, RANK_TOL};

use crate::error::{NanofoldError, Result};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use nalgebra::DVector;
use serde::Serialize;

/// Which solver computes the direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum QpMethod {
    /// Clarabel interior-point QP (handles inequalities; the reference path).
    Clarabel,
    /// Closed-form projection y = −(I − A⁺A) q through the chain factorisation of A
    /// (equality constraints only).
    Direct,
}

/// Problem data: the linearised constraints A (rows) and the energy gradient q, both in the
/// tangent coordinates of the free nodes.
#[derive(Debug, Clone)]
pub struct DirectionProblem {
    pub q: DVector<f64>,
    pub a: ConstraintJacobian,
}

/// Outcome of a direction solve, Clarabel-style.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum QpStatus {
    Solved,
    /// Clarabel's reduced-accuracy success.
    AlmostSolved,
}

/// The direction and how it was obtained.
#[derive(Debug, Clone)]
pub struct DirectionSolution {
    pub y: DVector<f64>,
    pub status: QpStatus,
    /// Interior-point iterations (0 for the direct projection).
    pub iterations: u32,
}

/// Solves the direction QP with Clarabel. Any status other than `Solved` or `AlmostSolved`
/// is an error naming the status, never silently used.
pub fn solve_clarabel(problem: &DirectionProblem) -> Result<DirectionSolution> {
    let n = problem.q.len();
    let rows = problem.a.rows.len();
    let p = CscMatrix::identity(n);
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
        .map_err(|e| NanofoldError::Numerical {
            stage: "QP settings".into(),
            message: format!("{e:?}"),
        })?;
    let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings).map_err(|e| NanofoldError::Numerical {
        stage: "QP setup".into(),
        message: e.to_string(),
    })?;
    solver.solve();
    let status = match solver.solution.status {
        SolverStatus::Solved => QpStatus::Solved,
        SolverStatus::AlmostSolved => QpStatus::AlmostSolved,
        other => {
            return Err(NanofoldError::Numerical {
                stage: "direction QP (Clarabel)".into(),
                message: format!("status {other:?}"),
            })
        }
    };
    Ok(DirectionSolution {
        y: DVector::from_vec(solver.solution.x.clone()),
        status,
        iterations: solver.solution.iterations,
    })
}

/// The direct path: y = −(I − A⁺A) q.
pub fn solve_direct(problem: &DirectionProblem) -> Result<DirectionSolution> {
    Ok(solve_direct_with(problem, &RowSpace::new(&problem.a)?))
}

/// The direct path with A already factorised (the unfolder reuses it for the restoration).
pub fn solve_direct_with(problem: &DirectionProblem, row_space: &RowSpace) -> DirectionSolution {
    DirectionSolution {
        y: -row_space.project_to_null(&problem.q),
        status: QpStatus::Solved,
        iterations: 0,
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
        let problem = DirectionProblem { q, a: a.clone() };
        let direct = solve_direct(&problem).unwrap();
        let clarabel = solve_clarabel(&problem).unwrap();
        assert!((&direct.y - &clarabel.y).amax() < 1e-10);
        assert!((&dense * &direct.y).amax() < 1e-14);
        // Optimality: y + q lies in the row space of A, so it is orthogonal to null(A).
        let rs = RowSpace::dense(&a).unwrap();
        assert!(rs.project_to_null(&(&direct.y + &problem.q)).amax() < 1e-14);
    }

    #[test]
    fn dependent_rows_do_not_break_either_path() {
        // The third row (closing) is the sum of the first two: rank 2.
        let dense = DMatrix::from_row_slice(3, 4, &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0]);
        let a = ConstraintJacobian::from_dense(&dense, &[false, false, true]);
        let q = DVector::from_vec(vec![1.0, 2.0, 3.0, -1.0]);
        let problem = DirectionProblem { q, a };
        let expected = DVector::from_vec(vec![0.0, 0.0, -3.0, 1.0]);
        let direct = solve_direct(&problem).unwrap();
        assert!((direct.y - &expected).amax() < 1e-14);
        let clarabel = solve_clarabel(&problem).unwrap();
        assert!((clarabel.y - expected).amax() < 1e-9);
    }
}
