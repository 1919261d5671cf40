//! Crease patterns built from parameters (`docs/model.md#pattern-generators`): Miura-ori
//! with its folded state in closed form.

use super::crease_pattern::{CreasePatternBuilder, EdgeKind, MAX_EDGES};
use super::Assignment;
use crate::error::{NanofoldError, Result};

/// A Miura-ori: rows × cols parallelogram panels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MiuraSpec {
    /// Panels along y.
    pub rows: usize,
    /// Panels along x.
    pub cols: usize,
    /// The panels' acute angle γ, rad, in (0, π/2).
    pub sector_angle: f64,
    /// Length of the panels' straight (horizontal) sides.
    pub width: f64,
    /// Length of the panels' slanted (zigzag) sides.
    pub slant: f64,
    /// Fold angle of the zigzag creases, rad, in [0, π); 0 is the flat sheet.
    pub zigzag_fold_angle: f64,
}

impl Default for MiuraSpec {
    fn default() -> Self {
        MiuraSpec {
            rows: 4,
            cols: 4,
            sector_angle: 60f64.to_radians(),
            width: 1.0,
            slant: 1.0,
            zigzag_fold_angle: 0.0,
        }
    }
}

impl MiuraSpec {
    /// Checks every parameter.
    pub fn validate(&self) -> Result<()> {
        let edges = 3 * (self.rows + 1) * (self.cols + 1);
        if self.rows < 1 || self.cols < 1 || edges > MAX_EDGES {
            return Err(NanofoldError::invalid(
                "rows, cols",
                format!("{} × {}", self.rows, self.cols),
                format!("at least 1 × 1, and at most {MAX_EDGES} edges (about 3 per vertex)"),
            ));
        }
        let gamma = self.sector_angle;
        if !(gamma >= 1f64.to_radians() && gamma <= 89f64.to_radians()) {
            return Err(NanofoldError::invalid(
                "sector_angle",
                gamma.to_degrees(),
                "must lie in [1°, 89°]",
            ));
        }
        for (field, value) in [("width", self.width), ("slant", self.slant)] {
            if !(value.is_finite() && value > 0.0 && value <= 1e6) {
                return Err(NanofoldError::invalid(field, value, "must lie in (0, 1e6]"));
            }
        }
        let rho = self.zigzag_fold_angle;
        if !(rho.is_finite() && (0.0..std::f64::consts::PI).contains(&rho)) {
            return Err(NanofoldError::invalid(
                "zigzag_fold_angle",
                rho.to_degrees(),
                "must lie in [0°, 180°)",
            ));
        }
        Ok(())
    }

    /// The horizontal creases' fold-angle magnitude for the zigzag one: at every vertex
    /// tan(ρ_h/2) = cos γ · tan(ρ_z/2).
    pub fn straight_fold_angle(&self) -> f64 {
        2.0 * (self.sector_angle.cos() * (self.zigzag_fold_angle / 2.0).tan()).atan()
    }

    /// The pattern: vertex (i, j) at (j·width + δ_i, i·h) with h = slant·sin γ and the rows
    /// shifted alternately by slant·cos γ. Zigzag lines (fixed j) are valleys for even j,
    /// mountains for odd j; the straight lines' segments alternate, so that every vertex
    /// has three creases of one kind (Maekawa).
    pub fn build(&self) -> Result<CreasePatternBuilder> {
        self.validate()?;
        let (rows, cols) = (self.rows, self.cols);
        let (height, shift) = (
            self.slant * self.sector_angle.sin(),
            self.slant * self.sector_angle.cos(),
        );
        let index = |i: usize, j: usize| i * (cols + 1) + j;
        let vertices: Vec<[f64; 2]> = (0..=rows)
            .flat_map(|i| (0..=cols).map(move |j| (i, j)))
            .map(|(i, j)| {
                [
                    j as f64 * self.width + if i % 2 == 1 { shift } else { 0.0 },
                    i as f64 * height,
                ]
            })
            .collect();
        let (rho_z, rho_h) = (self.zigzag_fold_angle, self.straight_fold_angle());
        let zigzag_sign = |j: usize| if j.is_multiple_of(2) { 1.0 } else { -1.0 };
        let mut builder = CreasePatternBuilder {
            name: format!("miura_{rows}x{cols}"),
            vertices,
            angle_field: "edges_foldAngle".into(),
            ..Default::default()
        };
        let mut push = |edge: [usize; 2], kind: EdgeKind, angle: f64| {
            builder.edges.push(edge);
            builder.kinds.push(kind);
            builder.fold_angles.push(angle);
        };
        let crease = |sign: f64| {
            EdgeKind::Crease(if sign > 0.0 {
                Assignment::Valley
            } else {
                Assignment::Mountain
            })
        };
        for i in 0..=rows {
            for j in 0..cols {
                let edge = [index(i, j), index(i, j + 1)];
                if i == 0 || i == rows {
                    push(edge, EdgeKind::Boundary, 0.0);
                } else {
                    // Seen from (i, j) the segment points +x; the zigzag there leans +x on
                    // even rows, and the segment on the side it leans to folds against it.
                    let leans_right = i.is_multiple_of(2);
                    let sign = zigzag_sign(j) * if leans_right { -1.0 } else { 1.0 };
                    push(edge, crease(sign), sign * rho_h);
                }
            }
        }
        for i in 0..rows {
            for j in 0..=cols {
                let edge = [index(i, j), index(i + 1, j)];
                if j == 0 || j == cols {
                    push(edge, EdgeKind::Boundary, 0.0);
                } else {
                    push(edge, crease(zigzag_sign(j)), zigzag_sign(j) * rho_z);
                }
            }
        }
        Ok(builder)
    }
}
