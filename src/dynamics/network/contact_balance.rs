//! One step of the quasi-static balance with contact (`docs/model.md#contact-forces`): the
//! hinge energy Σ ½ Kᵢ (θᵢ − rᵢ)² is quadratic in the fold angles, so with the closures and
//! the contacts linearised at θ the step d is the QP
//!
//!   min ½ dᵀ (K + W) d + (K (θ − r))ᵀ d   s.t.  E d = −e,  G d ≥ −g,  |d|∞ ≤ τ,
//!
//! where W is the rows' own curvature weighted by their forces (the Lagrangian's Hessian
//! less K: without it a balance held by contacts converges only linearly, or cycles),
//! solved directly or by Clarabel; repeated from the new θ it is a sequential QP. Its
//! multipliers on the contact rows are the contact forces (the energy in J, the gaps in m:
//! newtons).

use crate::error::{NumericalError, Result};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use nalgebra::{DMatrix, DVector};

/// Clarabel's tolerances for a step with friction cones whose solve stalls at 1e-12
/// (relative to the step's scale).
const FRICTION_TOLERANCE: f64 = 1e-10;
/// The trust box's half-width in units of the step's own scale at most.
const SCALED_TRUST: f64 = 1e3;

/// A step's data, all in the fold angles' columns.
#[derive(Debug, Clone)]
pub struct BalanceStep<'a> {
    /// Hinge stiffnesses, N·m/rad.
    pub stiffness: &'a [f64],
    /// W, the rows' curvature weighted by their multipliers, N·m/rad² (symmetric, with
    /// K + W positive definite); `None` for none.
    pub curvature: Option<&'a DMatrix<f64>>,
    /// θ − r, rad.
    pub offset: &'a [f64],
    /// The closure rows E (held to −e), over the size (dimensionless).
    pub closures: (&'a DMatrix<f64>, &'a DVector<f64>),
    /// The contact rows G and gaps g, m.
    pub contacts: (&'a DMatrix<f64>, &'a DVector<f64>),
    /// The largest turn of one step, rad.
    pub trust: f64,
    /// The length that scales gaps (the size), m.
    pub size: f64,
    /// Coulomb friction at the contacts, if any.
    pub friction: Option<FrictionRows<'a>>,
}

/// Coulomb friction at the pressing contacts, the normal forces lagged from the last
/// iterate: each contact k dissipates μ Nₖ ‖Tₖ (θ − θ₀)‖ over the step from θ₀, Tₖ its two
/// slip rows (the relative motion of its points across its normal, m/rad). Its share of
/// the QP is μ Nₖ sₖ with (sₖ, Tₖ d + oₖ) in a second-order cone, oₖ = Tₖ (θ − θ₀) the slip
/// so far, so the step's stationarity has friction opposing the slip, at most μ Nₖ.
#[derive(Debug, Clone)]
pub struct FrictionRows<'a> {
    /// Two rows per contact, m/rad.
    pub slip_rows: &'a DMatrix<f64>,
    /// The slip since the step's start, two per contact, m.
    pub slip: &'a DVector<f64>,
    /// μ Nₖ per contact, N.
    pub bounds: &'a DVector<f64>,
}

/// A solved step.
#[derive(Debug, Clone)]
pub struct BalanceSolution {
    /// The change of the fold angles, rad.
    pub step: DVector<f64>,
    /// The contact forces, N (one per contact row, non-negative).
    pub forces: DVector<f64>,
    /// The closure rows' multipliers μ, N·m (K (θ − r) = −Eᵀμ + Gᵀf at the balance).
    pub closure_multipliers: DVector<f64>,
    /// Whether a trust bound was reached (the step is not yet the balance's).
    pub at_trust: bool,
    /// Each friction contact's force across its normal, N (two components along its slip
    /// rows' directions; empty without friction).
    pub friction_forces: DVector<f64>,
}

/// Solves one step: first directly by active sets ([`held_step`]: the rows held as
/// equalities have non-negative forces and the others hold), which satisfies all the QP's
/// optimality conditions and, the energy being strictly convex, is the QP's one solution. Otherwise with Clarabel; a status other
/// than solved (or almost solved) is an error naming it.
pub fn solve_step(step: &BalanceStep) -> Result<BalanceSolution> {
    if step.friction.is_some() {
        // The cones are Clarabel's: the direct path has equalities and bounds only.
        return solve_step_with_clarabel(step);
    }
    match held_step(step) {
        HeldStep::Solved(solution) => Ok(solution),
        HeldStep::Infeasible => Err(NumericalError::QpStatus {
            status: "PrimalInfeasible (by the dual active-set method)".into(),
        }
        .into()),
        HeldStep::Unsure => solve_step_with_clarabel(step),
    }
}

/// A row whose direction, projected off the held rows through H⁻¹, keeps less than this
/// share of its own H⁻¹-norm depends on them.
const DEPENDENT_ROW: f64 = 1e-12;
/// A dependent row crossed by less than this share of the step's scale may be feasible
/// within rounding: the direct path does not call it infeasible.
const NEAR_FEASIBLE: f64 = 1e-5;
/// A held row must hold to this share of the step's own scale.
const HELD_RESIDUAL: f64 = 1e-9;

/// What the direct path found.
pub(crate) enum HeldStep {
    /// The QP's solution.
    Solved(BalanceSolution),
    /// A row crossed that the held rows cannot let hold: the linearised rows have no common
    /// point (the dual method's proof of it).
    Infeasible,
    /// Rounding left the answer unproven: Clarabel decides.
    Unsure,
}

/// The step by the dual active-set method (Goldfarb & Idnani 1983): from the energy's
/// minimum on the closures alone, the most crossed row is added by raising its multiplier
/// t, the held rows' multipliers moving so they stay held (H d + c = Aᵀy, A = the held
/// rows); a contact (or trust-box face) whose multiplier reaches zero first is let go.
/// Each addition lowers no held row's hold and raises the energy, so it ends: every row
/// holds with non-negative multipliers (the QP's one solution, the energy being strictly
/// convex), or a crossed row depends on held rows whose multipliers cannot make room for
/// it, which proves the rows infeasible. Rows are taken over their own norms, so rows in
/// m/rad and dimensionless ones weigh alike.
pub(crate) fn held_step(step: &BalanceStep) -> HeldStep {
    let n = step.stiffness.len();
    let (e_rows, e_values) = step.closures;
    let (g_rows, g_values) = step.contacts;
    let (m_e, m_g) = (e_rows.nrows(), g_rows.nrows());
    if step.stiffness.iter().any(|&k| !(k > 0.0 && k.is_finite())) {
        return HeldStep::Unsure;
    }
    let sigma = step_scale(step);
    let bound = step.trust.min(SCALED_TRUST * sigma);
    // Rows a·d ≥ b (closures a·d = b), each over its norm; the trust box's faces
    // ±d_c ≥ −bound after the contacts.
    let m = m_e + m_g + 2 * n;
    let mut a = DMatrix::zeros(m, n);
    let mut b = DVector::zeros(m);
    let mut scale = vec![0.0; m];
    scale[m_e + m_g..].fill(1.0);
    for i in 0..m_e + m_g {
        let (row, value) = if i < m_e {
            (e_rows.row(i), -e_values[i])
        } else {
            (g_rows.row(i - m_e), -g_values[i - m_e])
        };
        let norm = row.norm();
        if i >= m_e && value == f64::NEG_INFINITY {
            // A contact that cannot measure its gap here (two edges turned parallel: no
            // crossing to measure) asks nothing of this step.
            continue;
        }
        if !(norm.is_finite() && value.is_finite()) {
            return HeldStep::Unsure;
        }
        if norm == 0.0 {
            // A row no turn moves (the faces' meeting fixed by the anchor or the closures):
            // it holds as it is, or never.
            if value > 0.0 || (i < m_e && value < 0.0) {
                return HeldStep::Infeasible;
            }
            continue;
        }
        scale[i] = norm;
        a.row_mut(i).copy_from(&(row / norm));
        b[i] = value / norm;
    }
    for c in 0..n {
        a[(m_e + m_g + c, c)] = 1.0;
        a[(m_e + m_g + n + c, c)] = -1.0;
        b[m_e + m_g + c] = -bound;
        b[m_e + m_g + n + c] = -bound;
    }
    // H⁻¹ with H = K + W.
    let compliance: DMatrix<f64> = match step.curvature {
        None => DMatrix::from_diagonal(&DVector::from_iterator(n, step.stiffness.iter().map(|k| 1.0 / k))),
        Some(curvature) => {
            let hessian = curvature + DMatrix::from_diagonal(&DVector::from_column_slice(step.stiffness));
            match hessian.cholesky() {
                Some(factor) => factor.inverse(),
                None => return HeldStep::Unsure,
            }
        }
    };
    let gradient = DVector::from_iterator(n, (0..n).map(|c| step.stiffness[c] * step.offset[c]));
    // The held rows' product M = A H⁻¹ Aᵀ and the multipliers that hold them at t = 0.
    let held_solve = |held: &[usize], right: &DVector<f64>| -> Option<DVector<f64>> {
        let k = held.len();
        if k == 0 {
            return Some(DVector::zeros(0));
        }
        let through = DMatrix::from_fn(n, k, |r, p| (compliance.row(r) * a.row(held[p]).transpose())[0]);
        let product = DMatrix::from_fn(k, k, |p, q| a.row(held[p]).dot(&through.column(q).transpose()));
        product.cholesky().map(|factor| factor.solve(right))
    };
    // d(y) = H⁻¹ (Aᵀ y − c); held rows: A H⁻¹ Aᵀ y = b + A H⁻¹ c.
    let step_of = |held: &[usize], y: &DVector<f64>| -> DVector<f64> {
        let mut pushed = -&gradient;
        for (p, &i) in held.iter().enumerate() {
            pushed += a.row(i).transpose() * y[p];
        }
        &compliance * pushed
    };
    let free_gradient = &compliance * &gradient;
    let mut held: Vec<usize> = Vec::new();
    let mut y = DVector::zeros(0);
    if m_e > 0 {
        held = (0..m_e).filter(|&i| scale[i] > 0.0).collect();
        let right = DVector::from_iterator(
            held.len(),
            held.iter().map(|&i| b[i] + a.row(i).dot(&free_gradient.transpose())),
        );
        match held_solve(&held, &right) {
            Some(multipliers) => y = multipliers,
            None => return HeldStep::Unsure,
        }
    }
    let mut d = step_of(&held, &y);
    let tolerance = HELD_RESIDUAL * sigma;
    for _ in 0..4 * m + 8 {
        // The most crossed row not held.
        let crossed = (m_e..m)
            .filter(|i| !held.contains(i) && scale[*i] > 0.0)
            .map(|i| (i, a.row(i).dot(&d.transpose()) - b[i]))
            .filter(|&(_, over)| over < -tolerance)
            .min_by(|x, z| x.1.total_cmp(&z.1));
        let Some((entering, _)) = crossed else {
            // Rounding in nearly dependent held rows shows here: each must still hold.
            if held
                .iter()
                .any(|&i| (a.row(i).dot(&d.transpose()) - b[i]).abs() > tolerance)
            {
                return HeldStep::Unsure;
            }
            return finish(step, &held, &y, d, &scale, m_e, m_g);
        };
        let row = a.row(entering).transpose();
        // Raising the entering row's multiplier t moves the held ones by −t r and the step
        // by t z, z = H⁻¹(a − Aᵀ r), with A H⁻¹ Aᵀ r = A H⁻¹ a (held rows stay held).
        let mut t_total = 0.0;
        loop {
            let through = &compliance * &row;
            let r = if held.is_empty() {
                DVector::zeros(0)
            } else {
                let right =
                    DVector::from_iterator(held.len(), held.iter().map(|&i| a.row(i).dot(&through.transpose())));
                match held_solve(&held, &right) {
                    Some(r) => r,
                    None => return HeldStep::Unsure,
                }
            };
            let mut z = through.clone();
            for (p, &i) in held.iter().enumerate() {
                z -= &compliance * a.row(i).transpose() * r[p];
            }
            let reach = row.dot(&z);
            let full = if reach > DEPENDENT_ROW * row.dot(&through) {
                Some(-(row.dot(&d) - b[entering]) / reach)
            } else {
                None
            };
            // The first held inequality whose multiplier the rise brings to zero.
            let partial = held
                .iter()
                .enumerate()
                .filter(|&(p, &i)| i >= m_e && r[p] > 0.0)
                .map(|(p, _)| (p, y[p] / r[p]))
                .min_by(|x, z| x.1.total_cmp(&z.1));
            let t = match (full, partial) {
                (None, None) => {
                    // A row crossed by little that depends on the held rows: rounding in
                    // the linearisation may be all that keeps it off (Clarabel decides).
                    let crossing = -(row.dot(&d) - b[entering]);
                    return if crossing < NEAR_FEASIBLE * sigma {
                        HeldStep::Unsure
                    } else {
                        HeldStep::Infeasible
                    };
                }
                (Some(f), None) => f,
                (None, Some((_, q))) => q,
                (Some(f), Some((_, q))) => f.min(q),
            };
            if !t.is_finite() {
                return HeldStep::Unsure;
            }
            let t = t.max(0.0);
            d += &z * t;
            for p in 0..held.len() {
                y[p] -= t * r[p];
            }
            t_total += t;
            match (full, partial) {
                (Some(f), partial) if partial.is_none_or(|(_, q)| f <= q) => {
                    held.push(entering);
                    y = y.push(t_total);
                    break;
                }
                (_, Some((p, _))) => {
                    held.remove(p);
                    y = y.remove_row(p);
                }
                _ => return HeldStep::Unsure,
            }
            if !d.iter().all(|x| x.is_finite()) {
                return HeldStep::Unsure;
            }
        }
    }
    HeldStep::Unsure
}

/// The direct path's answer checked (every held row holds, every row is on its side,
/// multipliers of inequalities non-negative) and in the rows' own units.
fn finish(
    step: &BalanceStep,
    held: &[usize],
    y: &DVector<f64>,
    d: DVector<f64>,
    scale: &[f64],
    m_e: usize,
    m_g: usize,
) -> HeldStep {
    let n = step.stiffness.len();
    if !d.iter().all(|x| x.is_finite()) || held.iter().enumerate().any(|(p, &i)| i >= m_e && y[p] < 0.0) {
        return HeldStep::Unsure;
    }
    let at_trust = held.iter().any(|&i| i >= m_e + m_g);
    let mut forces = DVector::zeros(m_g);
    let mut closure_multipliers = DVector::zeros(m_e);
    for (p, &i) in held.iter().enumerate() {
        // Back to the rows' own units: y over its row's norm. K d + c = Eᵀy_E + Gᵀf, and
        // the closures' multipliers are reported as μ = −y_E.
        if i < m_e {
            closure_multipliers[i] = -y[p] / scale[i];
        } else if i < m_e + m_g {
            forces[i - m_e] = y[p] / scale[i];
        }
    }
    debug_assert_eq!(d.len(), n);
    HeldStep::Solved(BalanceSolution {
        friction_forces: DVector::zeros(0),
        step: d,
        forces,
        closure_multipliers,
        at_trust,
    })
}

/// The step's own scale σ: the largest turn the offsets or any row's residual ask for,
/// capped by the trust.
fn step_scale(step: &BalanceStep) -> f64 {
    let (e_rows, e_values) = step.closures;
    let (g_rows, g_values) = step.contacts;
    let row_turn = |norm: f64, value: f64| if norm > 0.0 { value.abs() / norm } else { 0.0 };
    (0..e_rows.nrows())
        .map(|i| row_turn(e_rows.row(i).norm(), e_values[i]))
        .chain((0..g_rows.nrows()).map(|i| row_turn(g_rows.row(i).norm(), g_values[i])))
        .chain(step.offset.iter().map(|o| o.abs()))
        .fold(0.0_f64, f64::max)
        .min(step.trust)
}

/// [`solve_step`] by Clarabel.
pub(crate) fn solve_step_with_clarabel(step: &BalanceStep) -> Result<BalanceSolution> {
    let n = step.stiffness.len();
    // Scaled: the energy by the largest stiffness, the gaps by the size, so the solver's
    // tolerances mean the same for a 1 µm hinge and a 1 m one.
    let largest = step
        .stiffness
        .iter()
        .fold(0.0_f64, |m, &k| m.max(k))
        .max(f64::MIN_POSITIVE);
    let stiff: Vec<f64> = step.stiffness.iter().map(|k| k / largest).collect();
    let m_f = step.friction.as_ref().map_or(0, |f| f.bounds.len());
    let p = match step.curvature {
        None if m_f == 0 => CscMatrix::new(n, n, (0..=n).collect(), (0..n).collect(), stiff.clone()),
        _ => {
            // The upper triangle of (K + W) / largest; a friction contact's cone height
            // carries no energy of its own (zero columns).
            let mut hessian = DMatrix::zeros(n + m_f, n + m_f);
            if let Some(curvature) = step.curvature {
                hessian.view_mut((0, 0), (n, n)).copy_from(&(curvature / largest));
            }
            for c in 0..n {
                hessian[(c, c)] += stiff[c];
            }
            dense_to_csc(&hessian.upper_triangle())
        }
    };
    let (e_rows, e_values) = step.closures;
    let (g_rows, g_values) = step.contacts;
    let (m_e, m_g) = (e_rows.nrows(), g_rows.nrows());
    // The step's own scale σ (the largest turn the offsets or any row's residual ask for):
    // the QP is solved for d/σ with every row over its own size, so its tolerances are
    // relative to the step however small it is (a contact met 1e-13 m deep asks a turn of
    // 1e-9 rad, far below absolute tolerances on an O(1) problem).
    let sigma = step_scale(step);
    if sigma == 0.0 {
        // At the balance already, every row held: no step, and the forces are those that
        // balance a zero offset.
        return Ok(BalanceSolution {
            step: DVector::zeros(n),
            forces: DVector::zeros(m_g),
            closure_multipliers: DVector::zeros(m_e),
            at_trust: false,
            friction_forces: DVector::zeros(2 * m_f),
        });
    }
    // The variables: the step d/σ, then one cone height sₖ per friction contact (its slip
    // over the size), costing μ Nₖ size / (largest σ²) each in the objective scaled by
    // largest σ².
    let columns = n + m_f;
    let mut q: Vec<f64> = (0..n).map(|c| stiff[c] * step.offset[c] / sigma).collect();
    if let Some(friction) = &step.friction {
        q.extend(
            friction
                .bounds
                .iter()
                .map(|b| b * step.size / (largest * sigma * sigma)),
        );
    }
    let rows = m_e + m_g + 2 * n + 3 * m_f;
    let mut a = DMatrix::zeros(rows, columns);
    let mut b = vec![0.0; rows];
    // Each row over β, its size in the scaled variables.
    let mut beta = vec![1.0; rows];
    for i in 0..m_e {
        let row = e_rows.row(i) * sigma;
        beta[i] = row.norm().max(e_values[i].abs()).max(f64::MIN_POSITIVE);
        a.view_mut((i, 0), (1, n)).copy_from(&(row / beta[i]));
        b[i] = -e_values[i] / beta[i];
    }
    for i in 0..m_g {
        let row = g_rows.row(i) * (sigma / step.size);
        let r = m_e + i;
        beta[r] = row.norm().max(g_values[i].abs() / step.size).max(f64::MIN_POSITIVE);
        for c in 0..n {
            a[(r, c)] = -row[c] / beta[r];
        }
        b[r] = g_values[i] / step.size / beta[r];
    }
    // The trust box in the scaled variables, at most a few decades of σ (a bound far out
    // of scale stalls the interior point); a step that reaches it is not yet the balance's.
    let bound = (step.trust / sigma).min(SCALED_TRUST);
    for c in 0..n {
        a[(m_e + m_g + c, c)] = 1.0;
        a[(m_e + m_g + n + c, c)] = -1.0;
        b[m_e + m_g + c] = bound;
        b[m_e + m_g + n + c] = bound;
    }
    // Each friction contact's cone: (sₖ, (Tₖ σx + oₖ)/size) ∈ SOC(3), as z = b − A x.
    let cone_start = m_e + m_g + 2 * n;
    if let Some(friction) = &step.friction {
        for k in 0..m_f {
            let r = cone_start + 3 * k;
            a[(r, n + k)] = -1.0;
            for j in 0..2 {
                for c in 0..n {
                    a[(r + 1 + j, c)] = -friction.slip_rows[(2 * k + j, c)] * sigma / step.size;
                }
                b[r + 1 + j] = friction.slip[2 * k + j] / step.size;
            }
        }
    }
    let a = dense_to_csc(&a);
    let mut cones = Vec::new();
    if m_e > 0 {
        cones.push(SupportedConeT::ZeroConeT(m_e));
    }
    cones.push(SupportedConeT::NonnegativeConeT(m_g + 2 * n));
    for _ in 0..m_f {
        cones.push(SupportedConeT::SecondOrderConeT(3));
    }
    // With cones, a contact that sticks sits at a cone's apex, where the interior point's
    // progress may stall short of 1e-12 (of the step's own scale): then it is solved again
    // to 1e-10.
    let tolerances: &[f64] = if m_f > 0 {
        &[1e-12, FRICTION_TOLERANCE]
    } else {
        &[1e-12]
    };
    let mut solved = None;
    for &tolerance in tolerances {
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .tol_gap_abs(tolerance)
            .tol_gap_rel(tolerance)
            .tol_feas(tolerance)
            .build()
            .map_err(|e| NumericalError::QpSetup {
                message: format!("{e:?}"),
            })?;
        let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings)
            .map_err(|e| NumericalError::QpSetup { message: e.to_string() })?;
        solver.solve();
        match solver.solution.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => {
                solved = Some(solver);
                break;
            }
            SolverStatus::InsufficientProgress | SolverStatus::MaxIterations if tolerance < FRICTION_TOLERANCE => {}
            other => {
                return Err(NumericalError::QpStatus {
                    status: format!("{other:?}"),
                }
                .into())
            }
        }
    }
    let solver = solved.ok_or_else(|| NumericalError::QpStatus {
        status: "InsufficientProgress".into(),
    })?;
    let x = DVector::from_column_slice(&solver.solution.x[..n]) * sigma;
    // A cone's multiplier across it is the slip's force on the scaled row: back in newtons
    // (K (θ − r + d) = Gᵀf + Tᵀφ, as the contacts' forces; |φₖ| ≤ μ Nₖ).
    let friction_forces = DVector::from_iterator(
        2 * m_f,
        (0..m_f).flat_map(|k| {
            let z = &solver.solution.z;
            [1, 2].map(|j| z[cone_start + 3 * k + j] * largest * sigma * sigma / step.size)
        }),
    );
    // Back to the unscaled rows: z = σ² z' / β (the objective was divided by σ²: P d + q +
    // Aᵀz = 0 with d = σ x and each row over β), then the energy's and the gaps' units.
    let z: Vec<f64> = (0..m_e + m_g)
        .map(|i| solver.solution.z[i] * sigma * sigma / beta[i])
        .collect();
    let forces = DVector::from_iterator(m_g, (0..m_g).map(|i| z[m_e + i].max(0.0) * largest / step.size));
    let at_trust = x.amax() >= bound * sigma * (1.0 - 1e-9);
    let closure_multipliers = DVector::from_iterator(m_e, (0..m_e).map(|i| z[i] * largest));
    Ok(BalanceSolution {
        step: x,
        forces,
        closure_multipliers,
        at_trust,
        friction_forces,
    })
}

/// A dense matrix in Clarabel's compressed columns, zeros left out.
fn dense_to_csc(m: &DMatrix<f64>) -> CscMatrix<f64> {
    let (mut colptr, mut rowval, mut nzval) = (vec![0], Vec::new(), Vec::new());
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            if m[(i, j)] != 0.0 {
                rowval.push(i);
                nzval.push(m[(i, j)]);
            }
        }
        colptr.push(rowval.len());
    }
    CscMatrix::new(m.nrows(), m.ncols(), colptr, rowval, nzval)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One hinge driven to 1 rad against a stop at 0.4 rad (a gap row of lever 2 m): the
    /// step lands on the stop and the force is the torque over the lever arm.
    #[test]
    fn a_hinge_driven_into_a_stop_rests_on_it_with_the_torque_over_the_lever() {
        let stiffness = [3.0];
        let offset = [-1.0];
        let closures = (DMatrix::zeros(0, 1), DVector::zeros(0));
        // gap = 2 (0.4 − θ): row −2, gap 0.8 at θ = 0.
        let contacts = (DMatrix::from_element(1, 1, -2.0), DVector::from_element(1, 0.8));
        let solution = solve_step(&BalanceStep {
            stiffness: &stiffness,
            curvature: None,
            offset: &offset,
            closures: (&closures.0, &closures.1),
            contacts: (&contacts.0, &contacts.1),
            trust: 10.0,
            size: 1.0,
            friction: None,
        })
        .unwrap();
        assert!((solution.step[0] - 0.4).abs() < 1e-9, "{}", solution.step[0]);
        // K (r − θ) = 3 · 0.6 N·m over 2 m.
        assert!((solution.forces[0] - 0.9).abs() < 1e-8, "{}", solution.forces[0]);
        assert!(!solution.at_trust);
    }

    /// One hinge of 3 N·m/rad driven 1 rad on, its contact sliding 2 m per radian against
    /// a friction of at most F: past 3 N·m > 2F it slides until K (r − θ) = 2F (θ = 1 − 2F/3),
    /// below it sticks (no step), and the cone's multiplier is the friction that holds.
    #[test]
    fn friction_lets_a_hinge_slide_past_its_bound_and_holds_it_below() {
        let stiffness = [3.0];
        let offset = [-1.0];
        let closures = (DMatrix::zeros(0, 1), DVector::zeros(0));
        let contacts = (DMatrix::zeros(0, 1), DVector::zeros(0));
        let slip_rows = DMatrix::from_row_slice(2, 1, &[2.0, 0.0]);
        let slip = DVector::zeros(2);
        for (bound, step, friction) in [(0.9, 0.4, -0.9), (2.0, 0.0, -1.5)] {
            let bounds = DVector::from_element(1, bound);
            let solution = solve_step(&BalanceStep {
                stiffness: &stiffness,
                curvature: None,
                offset: &offset,
                closures: (&closures.0, &closures.1),
                contacts: (&contacts.0, &contacts.1),
                trust: 10.0,
                size: 1.0,
                friction: Some(FrictionRows {
                    slip_rows: &slip_rows,
                    slip: &slip,
                    bounds: &bounds,
                }),
            })
            .unwrap();
            assert!(
                (solution.step[0] - step).abs() < 1e-8,
                "F {bound}: step {}",
                solution.step[0]
            );
            // K (θ − r + d) = Tᵀφ: the friction on the slip row.
            assert!(
                (solution.friction_forces[0] - friction).abs() < 1e-7 && solution.friction_forces[1].abs() < 1e-7,
                "F {bound}: friction {:?}",
                solution.friction_forces
            );
        }
    }

    /// The same stop met 1e-13 deep at a hinge of 1e-9 N·m/rad: the step is the 5e-14 rad
    /// that lifts it out (relative, not an absolute tolerance's worth), and the force the
    /// torque that turn costs over the lever.
    #[test]
    fn a_contact_met_a_hair_deep_is_lifted_by_exactly_that_hair() {
        let stiffness = [1e-9];
        let offset = [0.0];
        let closures = (DMatrix::zeros(0, 1), DVector::zeros(0));
        let contacts = (DMatrix::from_element(1, 1, 2.0), DVector::from_element(1, -1e-13));
        let solution = solve_step(&BalanceStep {
            stiffness: &stiffness,
            curvature: None,
            offset: &offset,
            closures: (&closures.0, &closures.1),
            contacts: (&contacts.0, &contacts.1),
            trust: 0.3,
            size: 1e-4,
            friction: None,
        })
        .unwrap();
        assert!((solution.step[0] - 5e-14).abs() <= 1e-9 * 5e-14, "{}", solution.step[0]);
        let force = 1e-9 * 5e-14 / 2.0;
        assert!(
            (solution.forces[0] - force).abs() <= 1e-6 * force,
            "{} against {force}",
            solution.forces[0]
        );
    }

    /// The held-rows step against Clarabel on random steps (5 hinges, a closure row, three
    /// contacts, every other one with a curvature W, half in a trust box the step reaches):
    /// wherever the direct path accepts, the two agree on the step, the forces and the
    /// closure multipliers; where it proves the rows infeasible, Clarabel finds no step.
    #[test]
    fn the_held_rows_step_is_clarabels_step_where_it_is_taken() {
        let mut seed = 12345_u64;
        let mut uniform = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut taken, mut refused, mut pressing, mut free, mut curved, mut boxed) = (0, 0, 0, 0, 0, 0);
        let mut infeasible = 0;
        for trial in 0..400 {
            let n = 5;
            let stiffness: Vec<f64> = (0..n).map(|_| 1e-9 * (0.5 + uniform())).collect();
            // Every other step with a curvature, indefinite but with K + W ≥ 0.7 K.
            let spread = DMatrix::from_fn(n, n, |_, _| uniform() - 0.5);
            let mut curvature = &spread * spread.transpose() * 3e-10;
            for c in 0..n {
                curvature[(c, c)] -= 0.3 * stiffness[c];
            }
            let offset: Vec<f64> = (0..n).map(|_| 0.2 * (uniform() - 0.5)).collect();
            let e = DMatrix::from_fn(1, n, |_, _| uniform() - 0.5);
            let e_values = DVector::from_element(1, 0.01 * (uniform() - 0.5));
            let g = DMatrix::from_fn(3, n, |_, _| 1e-4 * (uniform() - 0.5));
            let g_values = DVector::from_fn(3, |_, _| 1e-6 * (uniform() - 0.7));
            let step = BalanceStep {
                stiffness: &stiffness,
                curvature: (trial % 2 == 1).then_some(&curvature),
                offset: &offset,
                closures: (&e, &e_values),
                contacts: (&g, &g_values),
                // Every other pair of steps in a box the free step leaves.
                trust: if trial % 4 >= 2 { 0.03 } else { 1.0 },
                size: 1e-4,
                friction: None,
            };
            let held = match held_step(&step) {
                HeldStep::Solved(held) => held,
                HeldStep::Infeasible => {
                    // The dual method's proof of infeasibility: Clarabel finds no step either.
                    infeasible += 1;
                    assert!(solve_step_with_clarabel(&step).is_err(), "trial {trial}");
                    continue;
                }
                HeldStep::Unsure => {
                    refused += 1;
                    continue;
                }
            };
            taken += 1;
            curved += trial % 2;
            boxed += usize::from(held.at_trust);
            pressing += held.forces.iter().filter(|&&f| f > 0.0).count();
            free += held.forces.iter().filter(|&&f| f == 0.0).count();
            let clarabel = solve_step_with_clarabel(&step).unwrap();
            let agree = |ours: &DVector<f64>, theirs: &DVector<f64>, tolerance: f64| {
                assert!(
                    (ours - theirs).amax() <= tolerance,
                    "trial {trial}: {ours} against {theirs}"
                );
            };
            agree(&held.step, &clarabel.step, 1e-7 * clarabel.step.amax());
            // Forces here are of order K·offset/lever = 1e-9·0.1/1e-4 = 1e-6 N; an inactive
            // contact's is zero on the direct path and an interior point's 1e-19.
            agree(&held.forces, &clarabel.forces, 1e-6 * clarabel.forces.amax().max(1e-6));
            agree(
                &held.closure_multipliers,
                &clarabel.closure_multipliers,
                1e-6 * clarabel.closure_multipliers.amax().max(1e-30),
            );
        }
        // Both kinds of contact are met, and the direct path answers nearly every step.
        assert!(
            taken > 300 && curved > 150 && boxed > 50 && pressing > 100 && free > 100 && infeasible > 0,
            "taken {taken} ({curved} curved, {boxed} at the box), refused {refused}, infeasible {infeasible}; {pressing} pressing, {free} free"
        );
    }
}
