//! The direction subproblem of the projected gradient step (SPEC §5):
//! min_y ½‖y‖² + qᵀy  s.t.  A y = 0, solved by Clarabel (the general path) or by a direct
//! projection onto the null space of A (the equality-only closed form).

use crate::error::{NanofoldError, Result};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// Which solver computes the direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum QpMethod {
    /// Clarabel interior-point QP (handles inequalities; the reference path).
    Clarabel,
    /// Closed-form projection y = −(I − A⁺A) q via the SVD of A (equality constraints only).
    Direct,
}

/// Problem data: the linearised constraints A (rows) and the energy gradient q, both in the
/// tangent coordinates of the free nodes.
#[derive(Debug, Clone)]
pub struct DirectionProblem {
    pub q: DVector<f64>,
    pub a: DMatrix<f64>,
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

/// Relative singular-value threshold below which a constraint direction is taken as
/// dependent (the rank drop at the flat state, SPEC §9).
pub const RANK_TOL: f64 = 1e-10;

/// Solves the direction QP with Clarabel. Any status other than `Solved` or `AlmostSolved`
/// is an error naming the status, never silently used.
pub fn solve_clarabel(problem: &DirectionProblem) -> Result<DirectionSolution> {
    let n = problem.q.len();
    let rows = problem.a.nrows();
    let p = CscMatrix::identity(n);
    let q: Vec<f64> = problem.q.iter().copied().collect();
    let a = dense_to_csc(&problem.a);
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

fn dense_to_csc(a: &DMatrix<f64>) -> CscMatrix<f64> {
    let (m, n) = a.shape();
    let mut colptr = Vec::with_capacity(n + 1);
    let mut rowval = Vec::new();
    let mut nzval = Vec::new();
    colptr.push(0);
    for j in 0..n {
        for i in 0..m {
            let v = a[(i, j)];
            if v != 0.0 {
                rowval.push(i);
                nzval.push(v);
            }
        }
        colptr.push(rowval.len());
    }
    CscMatrix::new(m, n, colptr, rowval, nzval)
}

/// The SVD-based projector onto the row space of A, reused for the direction and for the
/// Newton restoration of the constraints.
#[derive(Debug, Clone)]
pub struct RowSpace {
    /// Right singular vectors with σ > RANK_TOL·σ_max, as rows.
    v_t: DMatrix<f64>,
    /// Matching left singular vectors (columns) and singular values.
    u: DMatrix<f64>,
    sigma: DVector<f64>,
    /// Columns of A (tangent coordinates).
    pub dimension: usize,
}

impl RowSpace {
    /// Factorises A.
    pub fn new(a: &DMatrix<f64>) -> Result<RowSpace> {
        let dimension = a.ncols();
        if a.nrows() == 0 {
            return Ok(RowSpace {
                v_t: DMatrix::zeros(0, dimension),
                u: DMatrix::zeros(0, 0),
                sigma: DVector::zeros(0),
                dimension,
            });
        }
        let svd = a.clone().svd(true, true);
        let (u, v_t) = match (svd.u, svd.v_t) {
            (Some(u), Some(v_t)) => (u, v_t),
            _ => {
                return Err(NanofoldError::Numerical {
                    stage: "SVD".into(),
                    message: "no singular vectors".into(),
                })
            }
        };
        let sigma_max = svd.singular_values.max();
        let keep: Vec<usize> = (0..svd.singular_values.len())
            .filter(|&i| svd.singular_values[i] > RANK_TOL * sigma_max.max(f64::MIN_POSITIVE))
            .collect();
        let v_t = v_t.select_rows(keep.iter());
        let u = u.select_columns(keep.iter());
        let sigma = DVector::from_iterator(keep.len(), keep.iter().map(|&i| svd.singular_values[i]));
        if sigma.iter().any(|s| !s.is_finite()) {
            return Err(NanofoldError::Numerical {
                stage: "SVD".into(),
                message: "non-finite singular value".into(),
            });
        }
        Ok(RowSpace {
            v_t,
            u,
            sigma,
            dimension,
        })
    }

    /// Numerical rank of A.
    pub fn rank(&self) -> usize {
        self.sigma.len()
    }

    /// Dimension of the null space: the first-order degrees of freedom.
    pub fn null_dimension(&self) -> usize {
        self.dimension - self.rank()
    }

    /// (I − A⁺A) w: the component of `w` in the null space of A.
    pub fn project_to_null(&self, w: &DVector<f64>) -> DVector<f64> {
        let coefficients = &self.v_t * w;
        w - self.v_t.transpose() * coefficients
    }

    /// Minimum-norm z with A z = r (least squares if r is outside the range).
    pub fn solve_min_norm(&self, r: &DVector<f64>) -> DVector<f64> {
        let mut coefficients = self.u.transpose() * r;
        for (c, s) in coefficients.iter_mut().zip(self.sigma.iter()) {
            *c /= s;
        }
        self.v_t.transpose() * coefficients
    }
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

    #[test]
    fn projection_and_clarabel_agree_on_a_small_problem() {
        let a = DMatrix::from_row_slice(2, 4, &[1.0, 2.0, 0.0, -1.0, 0.0, 1.0, 1.0, 3.0]);
        let q = DVector::from_vec(vec![0.3, -1.0, 2.0, 0.5]);
        let problem = DirectionProblem { q, a: a.clone() };
        let direct = solve_direct(&problem).unwrap();
        let clarabel = solve_clarabel(&problem).unwrap();
        assert!((&direct.y - &clarabel.y).amax() < 1e-10);
        assert!((&a * &direct.y).amax() < 1e-14);
        // Optimality: y + q lies in the row space of A, so it is orthogonal to null(A).
        let rs = RowSpace::new(&a).unwrap();
        assert!(rs.project_to_null(&(&direct.y + &problem.q)).amax() < 1e-14);
    }

    #[test]
    fn dependent_rows_do_not_break_either_path() {
        // The third row is the sum of the first two: rank 2.
        let a = DMatrix::from_row_slice(3, 3, &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0]);
        let q = DVector::from_vec(vec![1.0, 2.0, 3.0]);
        let problem = DirectionProblem { q, a };
        let direct = solve_direct(&problem).unwrap();
        assert!((direct.y - DVector::from_vec(vec![0.0, 0.0, -3.0])).amax() < 1e-14);
        let clarabel = solve_clarabel(&problem).unwrap();
        assert!((clarabel.y - DVector::from_vec(vec![0.0, 0.0, -3.0])).amax() < 1e-9);
    }
}
