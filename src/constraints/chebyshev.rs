//! Chebyshev series on an interval [a, b]: least-squares fits on the scaled variable
//! t = (2x − a − b)/(b − a) ∈ [−1, 1] for conditioning (`docs/model.md#constraint-curves`), evaluation with first and
//! second derivatives, and conversion to monomial coefficients in x; and [`FittedCurves`],
//! a set of them on one driving angle's domain: the one form in which both dynamics models
//! move on fitted constraint curves (a closed chain's `poly` source and a panel network
//! reduced to one coordinate).

use crate::error::{NanofoldError, NumericalError, Result};
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// f(x) = Σ_k c_k T_k(t(x)) on `domain`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Chebyshev {
    /// [a, b], a < b.
    pub domain: [f64; 2],
    /// c_0 … c_D.
    pub coeffs: Vec<f64>,
}

/// Fold angles fitted against one driving angle: one series per dependent crease, all on the
/// driver's fitted domain. Evaluation extrapolates outside it; whether a state may lie there
/// is the caller's decision ([`FittedCurves::covers`]).
#[derive(Debug, Clone, PartialEq)]
pub struct FittedCurves {
    /// The driver's fitted interval [a, b], rad.
    pub domain: [f64; 2],
    /// One series per dependent crease, in the caller's order.
    pub curves: Vec<Chebyshev>,
}

impl FittedCurves {
    /// The common degree (0 for no curves).
    pub fn degree(&self) -> usize {
        self.curves.first().map_or(0, Chebyshev::degree)
    }

    /// Is q within the domain widened by `margin` on each side?
    pub fn covers(&self, q: f64, margin: f64) -> bool {
        q >= self.domain[0] - margin && q <= self.domain[1] + margin
    }

    /// Curve k's value, slope and curvature at q: (f, f′, f″).
    pub fn at(&self, k: usize, q: f64) -> (f64, f64, f64) {
        self.curves[k].eval_with_derivatives(q)
    }

    /// Every curve's value, slope and curvature at q, written in curve order.
    pub fn evaluate(&self, q: f64, values: &mut [f64], slopes: &mut [f64], curvatures: &mut [f64]) {
        for (k, curve) in self.curves.iter().enumerate() {
            (values[k], slopes[k], curvatures[k]) = curve.eval_with_derivatives(q);
        }
    }
}

impl Chebyshev {
    /// Degree D (number of coefficients − 1).
    pub fn degree(&self) -> usize {
        self.coeffs.len().saturating_sub(1)
    }

    fn scale(&self) -> f64 {
        2.0 / (self.domain[1] - self.domain[0])
    }

    fn unit(&self, x: f64) -> f64 {
        (2.0 * x - self.domain[0] - self.domain[1]) / (self.domain[1] - self.domain[0])
    }

    /// f(x) by Clenshaw's recurrence.
    pub fn eval(&self, x: f64) -> f64 {
        let t = self.unit(x);
        let (mut b1, mut b2) = (0.0, 0.0);
        for &c in self.coeffs.iter().skip(1).rev() {
            let b0 = 2.0 * t * b1 - b2 + c;
            b2 = b1;
            b1 = b0;
        }
        t * b1 - b2 + self.coeffs.first().copied().unwrap_or(0.0)
    }

    /// (f, f′, f″) at x, derivatives with respect to x. Uses the three-term recurrences of
    /// T_k, T_k′ and T_k″; allocation-free.
    pub fn eval_with_derivatives(&self, x: f64) -> (f64, f64, f64) {
        let t = self.unit(x);
        let s = self.scale();
        // (T_{k−1}, T_k) and their first and second derivatives in t.
        let (mut p0, mut p1) = (1.0, t);
        let (mut d0, mut d1) = (0.0, 1.0);
        let (mut e0, mut e1) = (0.0, 0.0);
        let mut value = 0.0;
        let mut first = 0.0;
        let mut second = 0.0;
        for (k, &c) in self.coeffs.iter().enumerate() {
            let (p, d, e) = if k == 0 { (p0, d0, e0) } else { (p1, d1, e1) };
            value += c * p;
            first += c * d;
            second += c * e;
            if k >= 1 {
                let p2 = 2.0 * t * p1 - p0;
                let d2 = 2.0 * p1 + 2.0 * t * d1 - d0;
                let e2 = 4.0 * d1 + 2.0 * t * e1 - e0;
                (p0, p1, d0, d1, e0, e1) = (p1, p2, d1, d2, e1, e2);
            }
        }
        (value, first * s, second * s * s)
    }

    /// Least-squares fit of degree `degree` to the points (x_i, y_i) on `domain`, solved by
    /// SVD of the Chebyshev–Vandermonde matrix.
    pub fn fit(x: &[f64], y: &[f64], degree: usize, domain: [f64; 2]) -> Result<Chebyshev> {
        if x.len() != y.len() {
            return Err(NumericalError::Fit {
                detail: format!("{} abscissae but {} values", x.len(), y.len()),
            }
            .into());
        }
        if x.len() < degree + 1 {
            return Err(NanofoldError::invalid(
                "samples",
                x.len(),
                format!("a degree-{degree} fit needs at least {} samples", degree + 1),
            ));
        }
        if !domain.iter().all(|v| v.is_finite()) || domain[0] >= domain[1] {
            return Err(NanofoldError::invalid(
                "range",
                format!("[{}, {}]", domain[0], domain[1]),
                "needs a finite interval with a < b",
            ));
        }
        let unit = |v: f64| (2.0 * v - domain[0] - domain[1]) / (domain[1] - domain[0]);
        let mut basis = DMatrix::zeros(x.len(), degree + 1);
        for (i, &xi) in x.iter().enumerate() {
            let t = unit(xi);
            let (mut p0, mut p1) = (1.0, t);
            for k in 0..=degree {
                basis[(i, k)] = if k == 0 { p0 } else { p1 };
                if k >= 1 {
                    let p2 = 2.0 * t * p1 - p0;
                    p0 = p1;
                    p1 = p2;
                }
            }
        }
        let rhs = DVector::from_column_slice(y);
        let svd = basis.svd(true, true);
        let largest = svd.singular_values.max();
        let coeffs = svd
            .solve(&rhs, largest * 1e-13)
            .map_err(|e| NumericalError::Fit { detail: e.to_string() })?;
        Ok(Chebyshev {
            domain,
            coeffs: coeffs.iter().copied().collect(),
        })
    }

    /// Monomial coefficients m_0 … m_D with f(x) = Σ m_k x^k (ascending powers).
    pub fn monomial_coefficients(&self) -> Vec<f64> {
        let degree = self.degree();
        // In t: q = Σ c_k T_k, building T_k's coefficients by T_{k+1} = 2t T_k − T_{k−1}.
        let mut q = vec![0.0; degree + 1];
        let mut previous = vec![0.0; degree + 2];
        let mut current = vec![0.0; degree + 2];
        previous[0] = 1.0; // T_0
        current[1] = 1.0; // T_1
        for (k, &c) in self.coeffs.iter().enumerate() {
            let tk = if k == 0 { &previous } else { &current };
            for j in 0..=degree {
                q[j] += c * tk[j];
            }
            if k >= 1 {
                let mut next = vec![0.0; degree + 2];
                for j in 0..=degree {
                    next[j + 1] += 2.0 * current[j];
                    next[j] -= previous[j];
                }
                previous = std::mem::replace(&mut current, next);
            }
        }
        // Substitute t = s·x + o by Horner on polynomials.
        let s = self.scale();
        let o = -(self.domain[0] + self.domain[1]) / (self.domain[1] - self.domain[0]);
        let mut result = vec![0.0; degree + 1];
        for &qj in q.iter().rev() {
            // result ← result·(s x + o) + q_j
            let mut next = vec![0.0; degree + 1];
            for (i, &r) in result.iter().enumerate() {
                next[i] += r * o;
                if i < degree {
                    next[i + 1] += r * s;
                }
            }
            next[0] += qj;
            result = next;
        }
        result
    }
}

/// Σ m_k x^k by Horner's rule.
pub fn eval_monomial(coeffs: &[f64], x: f64) -> f64 {
    coeffs.iter().rev().fold(0.0, |acc, &m| acc * x + m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivatives_match_finite_differences() {
        let series = Chebyshev {
            domain: [0.2, 2.9],
            coeffs: vec![0.3, -1.1, 0.7, 0.25, -0.4, 0.05],
        };
        for &x in &[0.2, 0.7, 1.5, 2.9] {
            let h = 1e-5;
            let (f, d1, d2) = series.eval_with_derivatives(x);
            assert!((f - series.eval(x)).abs() < 1e-14);
            let fd1 = (series.eval(x + h) - series.eval(x - h)) / (2.0 * h);
            let fd2 = (series.eval(x + h) - 2.0 * f + series.eval(x - h)) / (h * h);
            assert!((d1 - fd1).abs() < 1e-8 * (1.0 + d1.abs()), "{d1} vs {fd1}");
            assert!((d2 - fd2).abs() < 1e-4 * (1.0 + d2.abs()), "{d2} vs {fd2}");
        }
    }

    #[test]
    fn monomial_conversion_reproduces_the_series() {
        let series = Chebyshev {
            domain: [-0.5, 3.0],
            coeffs: vec![1.0, 0.5, -0.25, 0.125, 0.3],
        };
        let monomial = series.monomial_coefficients();
        for i in 0..=20 {
            let x = -0.5 + 3.5 * i as f64 / 20.0;
            assert!((eval_monomial(&monomial, x) - series.eval(x)).abs() < 1e-12);
        }
    }
}
