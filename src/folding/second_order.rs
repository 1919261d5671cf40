//! The second-order test of a flat vertex's assignment (`docs/model.md#second-order-at-flat`):
//! whether any motion from flat with the assigned signs satisfies the vertex's closure to
//! second order. At flat the closure's first order is Σ aᵢ uᵢ = 0 in the plane, and its
//! out-of-plane part at second order is the quadratic form Q(a) = Σ_{i<j} aᵢ aⱼ sin(φⱼ − φᵢ).
//! A motion's leading coefficients a (at whatever order the vertex starts to move) lie in
//! the cone {sᵢ aᵢ ≥ 0, Σ aᵢ uᵢ = 0} of the signs s and must have Q(a) = 0; on the cone's
//! section Σ sᵢ aᵢ = 1 (a polytope) Q is continuous, so where its range there excludes 0 no
//! motion exists: a certificate.

use super::model::Star;
use nalgebra::{DMatrix, DVector};

/// |Q| above this on the whole section proves that no motion has the signs (Q is of order
/// 1/n² there).
pub const CERTIFICATE: f64 = 1e-9;

/// Largest degree tested (the test enumerates the 2ⁿ faces of the cone's section).
pub const MAX_DEGREE: usize = 12;

/// What the test found at one vertex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SecondOrder {
    /// Every crease has one sign. The vertex's folded image on the unit sphere is then a
    /// locally convex closed polygon of length 2π, which only a great circle or a lune has:
    /// the vertex folds only along a straight line through it, and its other creases stay
    /// flat.
    OneSign,
    /// No nonzero first-order motion has the assigned signs: the vertex cannot leave flat.
    NoFirstOrder,
    /// Q over the section of the first-order cone ranges over [min, max] (or, where Q was
    /// seen on both sides of ±`CERTIFICATE`, the part of it seen before the search stopped).
    Range {
        /// Smallest Q on the section.
        min: f64,
        /// Largest Q on the section.
        max: f64,
    },
}

impl SecondOrder {
    /// Whether this proves that no motion from flat has the assigned signs (|Q| above
    /// `tolerance` everywhere on the section, or no section at all); `tolerance` at least
    /// `CERTIFICATE`.
    pub fn excludes_motion(&self, tolerance: f64) -> bool {
        match *self {
            SecondOrder::OneSign | SecondOrder::NoFirstOrder => true,
            SecondOrder::Range { min, max } => min > tolerance || max < -tolerance,
        }
    }
}

/// Each ray's direction φ in the plane, ray 0 at 0, counter-clockwise.
fn ray_directions(sector_angles: &[f64]) -> Vec<f64> {
    let mut directions = vec![0.0; sector_angles.len()];
    for k in 1..sector_angles.len() {
        directions[k] = directions[k - 1] + sector_angles[k - 1];
    }
    directions
}

/// The quadratic form's matrix M (Q(a) = aᵀ M a) of a star with these sector angles.
pub fn quadratic_form(sector_angles: &[f64]) -> DMatrix<f64> {
    let n = sector_angles.len();
    let directions = ray_directions(sector_angles);
    DMatrix::from_fn(n, n, |i, j| {
        let (a, b) = (i.min(j), i.max(j));
        if a == b {
            0.0
        } else {
            0.5 * (directions[b] - directions[a]).sin()
        }
    })
}

/// The test at a flat star whose creases have the signs `signs` (±1, counter-clockwise as
/// the star's columns): [`SecondOrder::OneSign`] at degree 3 or more, else Q's range over
/// the first-order cone's section at degrees 5 to `MAX_DEGREE`; None where a sign is 0 (an
/// unassigned crease) or neither applies.
pub fn second_order(star: &Star, signs: &[f64]) -> Option<SecondOrder> {
    let n = star.sector_angles.len();
    if n > MAX_DEGREE || signs.len() != n || signs.contains(&0.0) {
        return None;
    }
    if n > 2 && signs.iter().all(|&s| s == signs[0]) {
        return Some(SecondOrder::OneSign);
    }
    cone_range(star, signs)
}

/// Q's range over the section of the first-order cone (the polytope part of
/// [`second_order`], without its one-sign rule); None as there, and below degree 5 (degree
/// 4 has its exact modes, and at lower degrees the sign row can depend on the closure rows).
pub fn cone_range(star: &Star, signs: &[f64]) -> Option<SecondOrder> {
    let n = star.sector_angles.len();
    if !(5..=MAX_DEGREE).contains(&n) || signs.len() != n || signs.contains(&0.0) {
        return None;
    }
    let directions = ray_directions(&star.sector_angles);
    let m = quadratic_form(&star.sector_angles);
    let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
    // Every face of the section: the creases in `zero` held at 0. Q's stationary point on
    // the face's affine hull (a KKT system), where it lies in the section, is a candidate
    // for its extremes; vertices are faces of dimension 0.
    // Most creases held first (vertices, then edges, …): they usually show both signs of Q
    // at once, and the search stops there, since no certificate is then possible. A vertex
    // with more than n − 3 creases at 0 is also the one solution for some n − 3 of them (its
    // active constraints have rank n, and the two closure rows and the sign row are
    // independent: a ±1 vector of the form α cos φ + β sin φ takes at most four directions),
    // so larger sets are not needed. Where a
    // face's system is singular, Q has no isolated stationary point inside it and its
    // extremes there lie on the face's boundary (a smaller face): it is skipped.
    let mut faces: Vec<u32> = (0u32..(1 << n)).filter(|z| z.count_ones() as usize + 3 <= n).collect();
    faces.sort_by_key(|z| std::cmp::Reverse(z.count_ones()));
    for zero in faces {
        if min < -CERTIFICATE && max > CERTIFICATE {
            break;
        }
        let held: Vec<usize> = (0..n).filter(|&i| zero & (1 << i) != 0).collect();
        let rows = 3 + held.len();
        let size = n + rows;
        let mut kkt = DMatrix::zeros(size, size);
        let mut rhs = DVector::zeros(size);
        kkt.view_mut((0, 0), (n, n)).copy_from(&(2.0 * &m));
        let mut constraint = DMatrix::zeros(rows, n);
        for i in 0..n {
            constraint[(0, i)] = directions[i].cos();
            constraint[(1, i)] = directions[i].sin();
            constraint[(2, i)] = signs[i];
        }
        for (r, &i) in held.iter().enumerate() {
            constraint[(3 + r, i)] = 1.0;
        }
        kkt.view_mut((0, n), (n, rows)).copy_from(&constraint.transpose());
        kkt.view_mut((n, 0), (rows, n)).copy_from(&constraint);
        rhs[n + 2] = 1.0;
        let lu = kkt.clone().full_piv_lu();
        let pivots = lu.u().diagonal().map(f64::abs);
        if pivots.min() <= 1e-10 * pivots.max() {
            continue;
        }
        let Some(solution) = lu.solve(&rhs) else { continue };
        if (&kkt * &solution - &rhs).amax() > 1e-9 {
            continue;
        }
        let a = solution.rows(0, n);
        if (0..n).any(|i| signs[i] * a[i] < -1e-10) {
            continue;
        }
        let q = (a.transpose() * &m * a)[(0, 0)];
        min = min.min(q);
        max = max.max(q);
    }
    Some(if min.is_finite() {
        SecondOrder::Range { min, max }
    } else {
        SecondOrder::NoFirstOrder
    })
}
