//! The spherical model (`docs/model.md#the-sphere`): geodesic distance, its gradient, arc midpoints and the
//! fold angle of a ray measured from node positions.

use nalgebra::Vector3;

/// A point or direction in R³.
pub type Vec3 = Vector3<f64>;

/// Geodesic distance by the spherical cosine rule (T3.3), γ = arccos(x_a·x_b) for unit
/// vectors. Kept as the defining formula and as a test reference: it loses half its digits
/// near 0 and π, so the solver uses [`geodesic`].
pub fn geodesic_cosine_rule(a: &Vec3, b: &Vec3) -> f64 {
    let c = a.dot(b) / (a.norm() * b.norm());
    c.clamp(-1.0, 1.0).acos()
}

/// Geodesic distance between the directions of `a` and `b`, in the stable form
/// γ = atan2(|a×b|, a·b) (`docs/model.md#the-sphere`). Scale-invariant in both arguments.
#[inline]
pub fn geodesic(a: &Vec3, b: &Vec3) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// sin γ below which the geodesic's gradient is taken as zero (see [`geodesic_with_gradient`]).
pub const KINK_WINDOW: f64 = 1e-12;

/// Geodesic distance and its gradients with respect to `a` and `b`.
///
/// For unit vectors ∂γ/∂a = −(b − cos γ a)/sin γ; for general vectors the gradient is that of
/// the direction, divided by |a|. At sin γ = 0 (coincident or antipodal points) γ is not
/// differentiable and its gradient has unit length in a direction set by rounding; within
/// [`KINK_WINDOW`] of that the zero vector is returned, a valid subgradient of the V-shaped
/// minimum the energies have at antipodal pairs (`docs/model.md#hard-cases`), so that rounding noise does not
/// steer the search at the flat state.
#[inline]
pub fn geodesic_with_gradient(a: &Vec3, b: &Vec3) -> (f64, Vec3, Vec3) {
    let na = a.norm();
    let nb = b.norm();
    let ua = a / na;
    let ub = b / nb;
    let cross = ua.cross(&ub);
    let sin_gamma = cross.norm();
    let gamma = sin_gamma.atan2(ua.dot(&ub));
    if sin_gamma <= KINK_WINDOW {
        return (gamma, Vec3::zeros(), Vec3::zeros());
    }
    // (ua×ub)×ua = ub − cos γ ua, of length sin γ.
    let towards_b = cross.cross(&ua) / sin_gamma;
    let towards_a = ub.cross(&cross) / sin_gamma;
    (gamma, -towards_b / na, -towards_a / nb)
}

/// Midpoint of the great-circle arc from `a` to `b` (arc length < π), as a unit vector.
pub fn arc_midpoint(a: &Vec3, b: &Vec3) -> Vec3 {
    (a + b).normalize()
}

/// Signed fold angle at the ray `axis`, between the sector (prev, axis) and the sector
/// (axis, next), with the CCW order prev → axis → next of the flat pattern (`docs/model.md#conventions`):
/// 0 when flat, positive for a valley (the sector after the ray rotates by +ρ about the
/// outward ray, lifting it to +z from a flat pattern in the xy-plane).
///
/// With u, w the components of prev and next perpendicular to the axis,
/// ρ = atan2(−â·(u×w), −u·w) (flat: u and w antiparallel).
pub fn fold_angle(prev: &Vec3, axis: &Vec3, next: &Vec3) -> f64 {
    let (y, x) = fold_angle_terms(prev, axis, next);
    y.atan2(x)
}

#[inline]
fn fold_angle_terms(prev: &Vec3, axis: &Vec3, next: &Vec3) -> (f64, f64) {
    let a = axis.normalize();
    let y = -a.dot(&prev.cross(next));
    let x = -(prev.dot(next) - prev.dot(&a) * next.dot(&a));
    (y, x)
}

/// Fold angle and its gradients with respect to (prev, axis, next).
///
/// The gradient is exact for a unit `axis` (the solver keeps nodes on the sphere); the
/// component along the axis, which only rescales it, is removed by the tangent projection.
pub fn fold_angle_with_gradient(prev: &Vec3, axis: &Vec3, next: &Vec3) -> (f64, [Vec3; 3]) {
    let a = axis / axis.norm();
    let pa = prev.dot(&a);
    let qa = next.dot(&a);
    let y = -a.dot(&prev.cross(next));
    let x = -(prev.dot(next) - pa * qa);
    let r2 = x * x + y * y;
    // dρ = (x dy − y dx) / (x² + y²)
    let dy_dp = -next.cross(&a);
    let dy_dq = -a.cross(prev);
    let dy_da = -prev.cross(next);
    let dx_dp = -(next - qa * a);
    let dx_dq = -(prev - pa * a);
    let dx_da = pa * next + qa * prev;
    let g = |dy: Vec3, dx: Vec3| (x * dy - y * dx) / r2;
    (y.atan2(x), [g(dy_dp, dx_dp), g(dy_da, dx_da), g(dy_dq, dx_dq)])
}

/// Signed volume det[a, b, c]: the side of the plane through the origin, a and b on which
/// c lies.
#[inline]
pub fn side_of_arc(a: &Vec3, b: &Vec3, c: &Vec3) -> f64 {
    a.cross(b).dot(c)
}

/// Does the point `p` (any length) lie inside the lune spanned by the arc from `a` to `b`
/// (arc length < π), i.e. would its projection onto the arc's great circle fall on the arc?
pub fn projects_onto_arc(a: &Vec3, b: &Vec3, p: &Vec3) -> bool {
    let normal = a.cross(b);
    // p projected onto the plane of the arc
    let q = p - normal * (normal.dot(p) / normal.norm_squared());
    normal.dot(&a.cross(&q)) >= 0.0 && normal.dot(&q.cross(b)) >= 0.0 && q.dot(&(a + b)) > 0.0
}

/// Geodesic distance from p to the arc from a to b (α < π): to the arc's great circle
/// when p projects inside the arc, else to the nearer end.
pub fn distance_to_arc(a: &Vec3, b: &Vec3, p: &Vec3) -> f64 {
    if projects_onto_arc(a, b, p) {
        let normal = a.cross(b).normalize();
        normal.dot(p).abs().min(1.0).asin()
    } else {
        geodesic(p, a).min(geodesic(p, b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(theta: f64, phi: f64) -> Vec3 {
        Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
    }

    #[test]
    fn cosine_rule_in_spherical_coordinates_matches_stable_form() {
        // T3.3 written in (θ, φ): cos γ = cos θa cos θb + sin θa sin θb cos(φb − φa)
        let (ta, pa, tb, pb) = (0.7_f64, 0.3_f64, 2.1_f64, -1.2_f64);
        let cos_gamma = ta.cos() * tb.cos() + ta.sin() * tb.sin() * (pb - pa).cos();
        let a = unit(ta, pa);
        let b = unit(tb, pb);
        assert!((cos_gamma.acos() - geodesic(&a, &b)).abs() < 1e-14);
        assert!((geodesic_cosine_rule(&a, &b) - geodesic(&a, &b)).abs() < 1e-14);
    }

    #[test]
    fn stable_form_keeps_digits_where_arccos_loses_them() {
        let a = Vec3::new(1.0, 0.0, 0.0);
        let eps = 1e-9_f64;
        let b = Vec3::new(eps.cos(), eps.sin(), 0.0);
        let stable = geodesic(&a, &b);
        let naive = geodesic_cosine_rule(&a, &b);
        assert!((stable - eps).abs() / eps < 1e-12);
        // arccos near 1 is off by far more than that: it is why the stable form exists.
        assert!((naive - eps).abs() / eps > 1e-3);
        let anti = Vec3::new(-(eps.cos()), eps.sin(), 0.0);
        assert!((geodesic(&a, &anti) - (std::f64::consts::PI - eps)).abs() < 1e-15);
    }

    #[test]
    fn fold_angle_of_a_valley_is_positive() {
        // prev at −90°, axis at 0°, next rotated about +x by +ρ from +90°
        let rho = 0.4_f64;
        let prev = Vec3::new(0.0, -1.0, 0.0);
        let axis = Vec3::new(1.0, 0.0, 0.0);
        let next = Vec3::new(0.0, rho.cos(), rho.sin());
        assert!((fold_angle(&prev, &axis, &next) - rho).abs() < 1e-15);
        let next_m = Vec3::new(0.0, rho.cos(), -rho.sin());
        assert!((fold_angle(&prev, &axis, &next_m) + rho).abs() < 1e-15);
    }

    #[test]
    fn midpoint_is_equidistant() {
        let a = unit(0.4, 0.1);
        let b = unit(1.3, 1.0);
        let m = arc_midpoint(&a, &b);
        assert!((geodesic(&a, &m) - geodesic(&m, &b)).abs() < 1e-14);
        assert!((2.0 * geodesic(&a, &m) - geodesic(&a, &b)).abs() < 1e-14);
    }

    #[test]
    fn distance_to_arc_matches_sampling_the_arc() {
        let a = unit(1.2, 0.1);
        let b = unit(1.6, 1.3);
        let alpha = geodesic(&a, &b);
        let axis = a.cross(&b).normalize();
        let tangent = axis.cross(&a);
        for (theta, phi) in [(0.3, 0.4), (1.5, 0.7), (2.8, -1.0), (1.4, 2.5), (1.0, 0.9), (2.0, 4.0)] {
            let p = unit(theta, phi);
            // Sample the arc finely; the closest sample is within half a sample spacing.
            let samples = 20_000;
            let sampled = (0..=samples)
                .map(|k| {
                    let t = alpha * k as f64 / samples as f64;
                    geodesic(&p, &(a * t.cos() + tangent * t.sin()))
                })
                .fold(f64::INFINITY, f64::min);
            let exact = distance_to_arc(&a, &b, &p);
            assert!(
                exact <= sampled + 1e-12 && sampled - exact < alpha / samples as f64,
                "{exact} vs {sampled}"
            );
        }
    }
}
