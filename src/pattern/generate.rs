//! Crease patterns built from parameters (`docs/model.md#pattern-generators`): Miura-ori
//! with its folded state in closed form, and flat-foldable single vertices folded flat.

use super::crease_pattern::{CreasePatternBuilder, EdgeKind, MAX_EDGES, MAX_INTERIOR_VERTICES};

/// The shortest length a generator takes: the crease-pattern reader's planarity tolerances
/// are fixed fractions of 1, so patterns far smaller lose their faces to rounding.
pub const MIN_LENGTH: f64 = 1e-6;
/// The longest.
pub const MAX_LENGTH: f64 = 1e6;
const LENGTH_RANGE: &str = "a length in [1e-6, 1e6]";
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
        // Horizontal segments (rows + 1 lines of cols) and zigzag ones (cols + 1 of rows).
        let edges = (self.rows + 1).saturating_mul(self.cols) + self.rows.saturating_mul(self.cols + 1);
        if self.rows < 1 || self.cols < 1 || edges > MAX_EDGES {
            return Err(NanofoldError::invalid(
                "rows, cols",
                format!("{} × {} ({edges} edges)", self.rows, self.cols),
                format!("at least 1 × 1, and at most {MAX_EDGES} edges ((rows + 1)·cols + rows·(cols + 1))"),
            ));
        }
        let interior = (self.rows - 1).saturating_mul(self.cols - 1);
        if interior > MAX_INTERIOR_VERTICES {
            return Err(NanofoldError::invalid(
                "rows, cols",
                format!("{} × {} ({interior} interior vertices)", self.rows, self.cols),
                format!("at most {MAX_INTERIOR_VERTICES} interior vertices ((rows − 1)·(cols − 1); 174 × 174 at most for a square sheet)"),
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
            if !(value.is_finite() && (MIN_LENGTH..=MAX_LENGTH).contains(&value)) {
                return Err(NanofoldError::invalid(field, format!("{value:e}"), LENGTH_RANGE));
            }
        }
        let ratio = self.width / self.slant;
        if !(1e-3..=1e3).contains(&ratio) {
            return Err(NanofoldError::invalid(
                "width",
                self.width,
                format!("width / slant = {ratio:.3e}: must lie in [1e-3, 1e3] (thinner panels have no room for the folding tolerances)"),
            ));
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
        self.build_with_column_angles(&vec![self.sector_angle; self.cols + 1])
    }

    /// A Miura-ori whose zigzag line j has its own sector angle γ_j (`cols + 1` of them):
    /// row height h = slant·sin γ as before, line j shifted on odd rows by h / tan γ_j, so the
    /// panels are trapezoids. Every vertex keeps sectors (γ_j, π − γ_j, π − γ_j, γ_j), and the
    /// pattern folds rigidly with one straight fold angle ρ_h for every horizontal crease and
    /// tan(ρ_z,j / 2) = tan(ρ_h / 2) / cos γ_j on line j; the state written is the one whose
    /// ρ_h is [`Self::straight_fold_angle`].
    pub fn build_with_column_angles(&self, column_angles: &[f64]) -> Result<CreasePatternBuilder> {
        self.validate()?;
        let (rows, cols) = (self.rows, self.cols);
        if column_angles.len() != cols + 1 {
            return Err(NanofoldError::invalid(
                "column_angles",
                format!("{} angles", column_angles.len()),
                format!("one per zigzag line ({})", cols + 1),
            ));
        }
        if let Some(j) = column_angles
            .iter()
            .position(|g| !(*g >= 1f64.to_radians() && *g <= 89f64.to_radians()))
        {
            return Err(NanofoldError::invalid(
                format!("column_angles[{j}]"),
                column_angles[j].to_degrees(),
                "must lie in [1°, 89°]",
            ));
        }
        let height = self.slant * self.sector_angle.sin();
        let shifts: Vec<f64> = column_angles.iter().map(|g| height / g.tan()).collect();
        if let Some(j) = (0..cols).find(|&j| self.width + shifts[j + 1] - shifts[j] < 0.2 * self.width) {
            return Err(NanofoldError::invalid(
                format!("column_angles[{}]", j + 1),
                column_angles[j + 1].to_degrees(),
                "the odd rows' panel between lines j and j + 1 would be narrower than 0.2 width",
            ));
        }
        let index = |i: usize, j: usize| i * (cols + 1) + j;
        let vertices: Vec<[f64; 2]> = (0..=rows)
            .flat_map(|i| (0..=cols).map(move |j| (i, j)))
            .map(|(i, j)| {
                [
                    j as f64 * self.width + if i % 2 == 1 { shifts[j] } else { 0.0 },
                    i as f64 * height,
                ]
            })
            .collect();
        let rho_h = self.straight_fold_angle();
        let rho_z: Vec<f64> = column_angles
            .iter()
            .map(|g| 2.0 * ((rho_h / 2.0).tan() / g.cos()).atan())
            .collect();
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
            for (j, rho) in rho_z.iter().enumerate() {
                let edge = [index(i, j), index(i + 1, j)];
                if j == 0 || j == cols {
                    push(edge, EdgeKind::Boundary, 0.0);
                } else {
                    push(edge, crease(zigzag_sign(j)), zigzag_sign(j) * rho);
                }
            }
        }
        Ok(builder)
    }
}

/// A square twist: a central square whose four corners are degree-4 vertices, each sending
/// two creases 90° apart to the edge of a square sheet; adjacent corners' creases pair up
/// into four parallel pleats turned by the twist angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SquareTwistSpec {
    /// Side of the central square.
    pub side: f64,
    /// Half the side of the sheet (centred on the square).
    pub half_sheet: f64,
    /// Twist angle θ, rad, in (0, π/4]: the pleats' turn from the square's sides.
    pub twist: f64,
    /// Flip each corner's crease after its smallest sector: the classic assignment (square
    /// mountain, each pleat a mountain–valley pair; flat-foldable) turned into one that breaks
    /// big-little-big at every corner.
    pub flip_pleats: bool,
}

impl Default for SquareTwistSpec {
    fn default() -> Self {
        SquareTwistSpec {
            side: 1.0,
            half_sheet: 1.5,
            twist: 30f64.to_radians(),
            flip_pleats: false,
        }
    }
}

impl SquareTwistSpec {
    /// Checks every parameter.
    pub fn validate(&self) -> Result<()> {
        if !(self.side.is_finite() && (MIN_LENGTH..=MAX_LENGTH).contains(&self.side)) {
            return Err(NanofoldError::invalid("side", format!("{:e}", self.side), LENGTH_RANGE));
        }
        if !(self.half_sheet.is_finite() && self.half_sheet >= self.side && self.half_sheet <= MAX_LENGTH) {
            return Err(NanofoldError::invalid(
                "half_sheet",
                self.half_sheet,
                "must lie in [side, 1e6]",
            ));
        }
        if !(self.twist >= 1f64.to_radians() && self.twist <= 45f64.to_radians()) {
            return Err(NanofoldError::invalid(
                "twist",
                self.twist.to_degrees(),
                "must lie in [1°, 45°]",
            ));
        }
        Ok(())
    }

    /// The pattern (flat, assignment only). Corner k of the square sits at angle 45° + 90°k;
    /// its outgoing creases leave at θ + 90°k and 90° + θ + 90°k, so the sectors around it
    /// are 90° + θ, 90°, 90° − θ and 90° (the square's corner): Kawasaki holds. In the classic
    /// assignment the creases bounding the smallest sector (90° − θ) differ, so the crease at
    /// 90° + θ + 90°k is the valley of its corner.
    pub fn build(&self) -> Result<CreasePatternBuilder> {
        self.validate()?;
        let h = self.side / 2.0;
        let corners = [[h, h], [-h, h], [-h, -h], [h, -h]];
        let mut vertices: Vec<[f64; 2]> = corners.to_vec();
        let mut segments: Vec<([usize; 2], EdgeKind)> = Vec::new();
        let mountain = EdgeKind::Crease(Assignment::Mountain);
        let valley = EdgeKind::Crease(Assignment::Valley);
        for k in 0..4 {
            segments.push(([k, (k + 1) % 4], mountain));
        }
        let mut rim: Vec<usize> = Vec::new();
        for (k, corner) in corners.iter().enumerate() {
            let turn = std::f64::consts::FRAC_PI_2 * k as f64;
            for (j, direction) in [self.twist + turn, std::f64::consts::FRAC_PI_2 + self.twist + turn]
                .into_iter()
                .enumerate()
            {
                let end = to_sheet_edge(*corner, direction, self.half_sheet);
                vertices.push(end);
                rim.push(vertices.len() - 1);
                let odd_one = j == 1;
                let kind = if odd_one != self.flip_pleats { valley } else { mountain };
                segments.push(([k, vertices.len() - 1], kind));
            }
        }
        Ok(on_rectangle(
            format!("square_twist_{:.0}deg", self.twist.to_degrees()),
            vertices,
            segments,
            rim,
            [-self.half_sheet, -self.half_sheet],
            [self.half_sheet, self.half_sheet],
        ))
    }
}

/// Where the ray from `from` at `direction` leaves the square [−half, half]².
fn to_sheet_edge(from: [f64; 2], direction: f64, half: f64) -> [f64; 2] {
    let (dx, dy) = (direction.cos(), direction.sin());
    let mut t = f64::INFINITY;
    for (d, p) in [(dx, from[0]), (dy, from[1])] {
        if d > 1e-15 {
            t = t.min((half - p) / d);
        } else if d < -1e-15 {
            t = t.min((-half - p) / d);
        }
    }
    [from[0] + t * dx, from[1] + t * dy]
}

/// Closes a set of creases with the rectangle [lo, hi] as the sheet's edge: its corners
/// and the `rim` vertices that lie on it, joined in counter-clockwise order by boundary edges.
fn on_rectangle(
    name: String,
    mut vertices: Vec<[f64; 2]>,
    segments: Vec<([usize; 2], EdgeKind)>,
    mut rim: Vec<usize>,
    lo: [f64; 2],
    hi: [f64; 2],
) -> CreasePatternBuilder {
    for corner in [[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]] {
        let close = |p: &[f64; 2]| (p[0] - corner[0]).abs() < 1e-12 && (p[1] - corner[1]).abs() < 1e-12;
        if !rim.iter().any(|&v| close(&vertices[v])) {
            vertices.push(corner);
            rim.push(vertices.len() - 1);
        }
    }
    // Position along the outline, counter-clockwise from (lo, lo).
    let (w, h) = (hi[0] - lo[0], hi[1] - lo[1]);
    let along = |p: [f64; 2]| {
        let (x, y) = (p[0] - lo[0], p[1] - lo[1]);
        if y.abs() < 1e-9 * h {
            x
        } else if (x - w).abs() < 1e-9 * w {
            w + y
        } else if (y - h).abs() < 1e-9 * h {
            w + h + (w - x)
        } else {
            2.0 * w + h + (h - y)
        }
    };
    rim.sort_by(|&a, &b| along(vertices[a]).total_cmp(&along(vertices[b])));
    rim.dedup();
    let mut builder = CreasePatternBuilder {
        name,
        vertices,
        angle_field: "edges_foldAngle".into(),
        ..Default::default()
    };
    for k in 0..rim.len() {
        builder.edges.push([rim[k], rim[(k + 1) % rim.len()]]);
        builder.kinds.push(EdgeKind::Boundary);
        builder.fold_angles.push(0.0);
    }
    for (edge, kind) in segments {
        builder.edges.push(edge);
        builder.kinds.push(kind);
        builder.fold_angles.push(0.0);
    }
    builder
}

/// The waterbomb tessellation: rows of triangles between horizontal mountain lines,
/// degree-6 vertices where four valley diagonals meet a horizontal line, alternating rows
/// shifted by one unit. With row height 1 the triangles are isosceles right triangles
/// (sectors 45°, 90°, 45°, 45°, 90°, 45°); another row height stretches the cells into
/// rectangles (sectors θ, π − 2θ, θ, θ, π − 2θ, θ with tan θ = height), the Huffman-style
/// variant. Three straight lines cross at every vertex, so Kawasaki holds for any height.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WaterbombSpec {
    /// Rows of triangles (the sheet is `rows · row_height` high).
    pub rows: usize,
    /// Units across (the sheet is 2·cols wide).
    pub cols: usize,
    /// Height of a row, in units of the half-cell width; 1 for the square waterbomb.
    pub row_height: f64,
}

impl Default for WaterbombSpec {
    fn default() -> Self {
        WaterbombSpec {
            rows: 4,
            cols: 4,
            row_height: 1.0,
        }
    }
}

impl WaterbombSpec {
    /// The pattern (flat, assignment only). Vertex (x, y) at (x, y · row_height) for integer
    /// x in 0..=2·cols and y in 0..=rows; where x + y is even, diagonals run to
    /// (x ± 1, y ± 1); every horizontal line inside the sheet is a mountain crease, every
    /// diagonal a valley.
    pub fn build(&self) -> Result<CreasePatternBuilder> {
        let (rows, cols) = (self.rows, self.cols);
        if rows < 1 || cols < 1 || 6 * (rows + 1) * (2 * cols + 1) > MAX_EDGES {
            return Err(NanofoldError::invalid(
                "rows, cols",
                format!("{rows} × {cols}"),
                format!("at least 1 × 1, and at most {MAX_EDGES} edges"),
            ));
        }
        let interior = (rows - 1) * (2 * cols - 1);
        if interior > MAX_INTERIOR_VERTICES {
            return Err(NanofoldError::invalid(
                "rows, cols",
                format!("{rows} × {cols} ({interior} interior vertices)"),
                format!("at most {MAX_INTERIOR_VERTICES} interior vertices ((rows − 1)·(2·cols − 1))"),
            ));
        }
        let height = self.row_height;
        if !(0.1..=10.0).contains(&height) {
            return Err(NanofoldError::invalid(
                "row_height",
                height,
                "a number in [0.1, 10] (units of the half-cell width)",
            ));
        }
        let width = 2 * cols;
        let index = |x: usize, y: usize| y * (width + 1) + x;
        let vertices: Vec<[f64; 2]> = (0..=rows)
            .flat_map(|y| (0..=width).map(move |x| [x as f64, y as f64 * height]))
            .collect();
        let mut segments = Vec::new();
        for y in 1..rows {
            for x in 0..width {
                segments.push(([index(x, y), index(x + 1, y)], EdgeKind::Crease(Assignment::Mountain)));
            }
        }
        for y in 0..rows {
            for x in 0..=width {
                if (x + y) % 2 == 0 {
                    if x < width {
                        segments.push(([index(x, y), index(x + 1, y + 1)], EdgeKind::Crease(Assignment::Valley)));
                    }
                    if x > 0 {
                        segments.push(([index(x, y), index(x - 1, y + 1)], EdgeKind::Crease(Assignment::Valley)));
                    }
                }
            }
        }
        // The sheet's edge: bottom and top rows and the two sides, through every vertex on them.
        let mut rim: Vec<usize> = (0..=width).map(|x| index(x, 0)).collect();
        rim.extend((0..=width).map(|x| index(x, rows)));
        rim.extend((1..rows).flat_map(|y| [index(0, y), index(width, y)]));
        // Horizontal lines end on the sides: drop their segments' duplicates with the rim.
        Ok(on_rectangle(
            if height == 1.0 {
                format!("waterbomb_{rows}x{cols}")
            } else {
                format!("waterbomb_{rows}x{cols}_h{height}")
            },
            vertices,
            segments,
            rim,
            [0.0, 0.0],
            [width as f64, rows as f64 * height],
        ))
    }
}

/// The bird base as a flat-foldable crease pattern on the square [−s, s]²: the four
/// midlines (mountain from the centre to the four petal points at (2 − √2)·s, valley beyond),
/// eight kite creases (mountain) from the petal points to the corners beside them, and the
/// diagonal through (−s, s) and (s, −s) (valley). The other diagonal and the petal folds'
/// horizontal guide creases are flat in the finished base, so they are not creases here.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BirdBaseSpec {
    /// Half the side s of the square sheet.
    pub half_side: f64,
}

impl Default for BirdBaseSpec {
    fn default() -> Self {
        BirdBaseSpec { half_side: 1.0 }
    }
}

impl BirdBaseSpec {
    /// The pattern (flat, assignment only). Around the centre the sectors are 90°, 45°, 45°,
    /// 90°, 45°, 45° (four mountains, two valleys); around a petal point 67.5°, 112.5°,
    /// 112.5°, 67.5° (three mountains, one valley): Kawasaki and Maekawa hold at all five.
    pub fn build(&self) -> Result<CreasePatternBuilder> {
        let s = self.half_side;
        if !(s.is_finite() && (MIN_LENGTH..=MAX_LENGTH).contains(&s)) {
            return Err(NanofoldError::invalid("half_side", format!("{s:e}"), LENGTH_RANGE));
        }
        let d = (2.0 - std::f64::consts::SQRT_2) * s;
        let axes = [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]];
        // 0: centre; 1..=4 petal points; 5..=8 edge midpoints; 9..=12 corners, corner k
        // between axes k and k + 1.
        let mut vertices = vec![[0.0, 0.0]];
        vertices.extend(axes.iter().map(|a| [d * a[0], d * a[1]]));
        vertices.extend(axes.iter().map(|a| [s * a[0], s * a[1]]));
        vertices.extend((0..4).map(|k| {
            let (a, b) = (axes[k], axes[(k + 1) % 4]);
            [s * (a[0] + b[0]), s * (a[1] + b[1])]
        }));
        let mountain = EdgeKind::Crease(Assignment::Mountain);
        let valley = EdgeKind::Crease(Assignment::Valley);
        let mut segments = Vec::new();
        for k in 0..4 {
            let petal = 1 + k;
            segments.push(([0, petal], mountain));
            segments.push(([petal, 5 + k], valley));
            segments.push(([petal, 9 + k], mountain));
            segments.push(([petal, 9 + (k + 3) % 4], mountain));
        }
        // The valley diagonal: corners 1 (−s, s) and 3 (s, −s).
        segments.push(([0, 10], valley));
        segments.push(([0, 12], valley));
        Ok(on_rectangle(
            "bird_base".into(),
            vertices,
            segments,
            (5..=12).collect(),
            [-s, -s],
            [s, s],
        ))
    }
}

/// A flat-foldable vertex of even `degree` (at least 4) folded flat: seeded sectors whose
/// alternate sums are π, and an assignment made by crimping the smallest sector again and
/// again (Hull: its two creases fold opposite ways and the three sectors about it become
/// one; the last two creases fold alike), so a flat folding exists. Returns the sector
/// angles (sector k after crease k) and the fold angles, every one ±π.
pub fn flat_folded_vertex(degree: usize, seed: u64) -> crate::Result<(Vec<f64>, Vec<f64>)> {
    if degree < 4 || !degree.is_multiple_of(2) || degree > crate::pattern::MAX_RAYS {
        return Err(crate::NanofoldError::invalid(
            "degree",
            degree,
            format!(
                "a flat-foldable vertex has an even degree in [4, {}]",
                crate::pattern::MAX_RAYS
            ),
        ));
    }
    let mut state = seed | 1;
    let mut draw = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut halves: [Vec<f64>; 2] = [
        (0..degree / 2).map(|_| 0.3 + draw()).collect(),
        (0..degree / 2).map(|_| 0.3 + draw()).collect(),
    ];
    for half in &mut halves {
        let total: f64 = half.iter().sum();
        half.iter_mut().for_each(|x| *x *= std::f64::consts::PI / total);
    }
    let sectors: Vec<f64> = (0..degree).map(|k| halves[k % 2][k / 2]).collect();
    let (mut creases, mut after): (Vec<usize>, Vec<f64>) = ((0..degree).collect(), sectors.clone());
    let mut sign = vec![0.0; degree];
    let mut turn = if draw() < 0.5 { 1.0 } else { -1.0 };
    while creases.len() > 2 {
        let m = creases.len();
        let k = (0..m)
            .min_by(|&a, &b| after[a].total_cmp(&after[b]))
            .expect("creases left");
        let (previous, next) = ((k + m - 1) % m, (k + 1) % m);
        sign[creases[k]] = turn;
        sign[creases[next]] = -turn;
        turn = -turn;
        after[previous] += after[next] - after[k];
        let keep = |i: &usize| *i != k && *i != next;
        creases = (0..m).filter(keep).map(|i| creases[i]).collect();
        after = (0..m).filter(keep).map(|i| after[i]).collect();
    }
    let last = if draw() < 0.5 { 1.0 } else { -1.0 };
    sign[creases[0]] = last;
    sign[creases[1]] = last;
    Ok((sectors, sign.iter().map(|s| s * std::f64::consts::PI).collect()))
}
