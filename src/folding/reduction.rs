//! Exact reductions of the closure Jacobian before its rank count
//! (`docs/model.md#rigid-folding`): creases a star ties in fixed proportion merged into one
//! column, each star's rows replaced by its row space, and a crease only one star holds
//! eliminated with one of that star's rows. None changes the null space's dimension.

use super::closure::ClosureJacobian;
use nalgebra::DMatrix;

/// A star whose block has a singular value in (t/AMBIGUITY, AMBIGUITY·t] for the count's
/// threshold t ties nothing: whether it has a null direction there is the count's to judge.
const AMBIGUITY: f64 = 1e3;

/// A class is tied only where the star leaves it clearly free (its row of the star's null
/// projector at least this long): a crease a star nearly forces to zero is left to the count.
const FREE_LENGTH: f64 = 1e-3;

/// A crease held by one row is eliminated with it only where its entry is at least this
/// fraction of the row's largest (a small pivot could hide a small singular value).
const PIVOT_FRACTION: f64 = 0.1;

/// Passes over the stars merging ties; later merges can reveal new ties at earlier stars.
const MAX_PASSES: usize = 8;

/// What the reductions leave for the rank count.
#[derive(Debug, Clone)]
pub struct Reduction {
    /// The rows and merged columns that remain, every column with an entry.
    pub remainder: ClosureJacobian,
    /// Merged columns left without any entry: each is a null direction by itself.
    pub free_columns: usize,
    /// Columns of the input that the reductions removed (merged or eliminated).
    pub removed_columns: usize,
}

/// Creases as classes of proportional fold rates: ρ_c = factor_c · ρ_parent.
struct Ties {
    parent: Vec<usize>,
    factor: Vec<f64>,
}

impl Ties {
    fn new(columns: usize) -> Self {
        Ties {
            parent: (0..columns).collect(),
            factor: vec![1.0; columns],
        }
    }

    /// The class's root and ρ_c / ρ_root.
    fn find(&mut self, c: usize) -> (usize, f64) {
        let mut root = c;
        let mut factor = 1.0;
        while self.parent[root] != root {
            factor *= self.factor[root];
            root = self.parent[root];
        }
        // Compress: point every crease on the way straight at the root.
        let mut node = c;
        let mut remaining = factor;
        while self.parent[node] != root && node != root {
            let next = self.parent[node];
            let own = self.factor[node];
            self.parent[node] = root;
            self.factor[node] = remaining;
            remaining /= own;
            node = next;
        }
        (root, factor)
    }
}

/// A star's block over the current classes: one column (3 entries) per distinct root.
fn star_block(entries: &[(usize, usize, f64)], ties: &mut Ties) -> (Vec<usize>, DMatrix<f64>) {
    let mut roots: Vec<usize> = Vec::new();
    let mut columns: Vec<[f64; 3]> = Vec::new();
    for &(local_row, c, v) in entries {
        let (root, factor) = ties.find(c);
        let k = match roots.iter().position(|&r| r == root) {
            Some(k) => k,
            None => {
                roots.push(root);
                columns.push([0.0; 3]);
                roots.len() - 1
            }
        };
        columns[k][local_row] += factor * v;
    }
    let block = DMatrix::from_fn(3, roots.len(), |i, k| columns[k][i]);
    (roots, block)
}

/// The star's row space as rows σ_k v_kᵀ with σ_k above `threshold`, and whether any
/// singular value lies in the ambiguous band above it.
fn row_space(block: &DMatrix<f64>, threshold: f64) -> (Vec<Vec<f64>>, bool) {
    let svd = block.clone().svd(false, true);
    let v_t = svd.v_t.expect("requested");
    let mut rows = Vec::new();
    let mut ambiguous = false;
    for (k, &sigma) in svd.singular_values.iter().enumerate() {
        ambiguous |= sigma > threshold / AMBIGUITY && sigma <= AMBIGUITY * threshold;
        if sigma > threshold {
            rows.push(v_t.row(k).iter().map(|x| x * sigma).collect());
        }
    }
    (rows, ambiguous)
}

/// Merge the classes one star ties: classes whose rows of the star's null projector are
/// parallel (to `tolerance`) have fold rates in fixed proportion. Returns merges made.
fn merge_star(entries: &[(usize, usize, f64)], ties: &mut Ties, threshold: f64, tolerance: f64) -> usize {
    let (roots, block) = star_block(entries, ties);
    let d = roots.len();
    if d < 2 {
        return 0;
    }
    let (rows, ambiguous) = row_space(&block, threshold);
    if ambiguous || rows.len() >= d {
        return 0;
    }
    // Orthonormal row-space basis, then the null projector's rows p_i = e_i − Vᵀ V e_i.
    let basis: Vec<Vec<f64>> = rows
        .iter()
        .map(|r| {
            let n = r.iter().map(|x| x * x).sum::<f64>().sqrt();
            r.iter().map(|x| x / n).collect()
        })
        .collect();
    let projector_row = |i: usize| -> Vec<f64> {
        let mut p = vec![0.0; d];
        p[i] = 1.0;
        for b in &basis {
            for (j, pj) in p.iter_mut().enumerate() {
                *pj -= b[i] * b[j];
            }
        }
        p
    };
    let norm = |p: &[f64]| p.iter().map(|x| x * x).sum::<f64>().sqrt();
    // Greedy grouping by parallel projector rows; each group merges onto its first class.
    let mut representatives: Vec<(usize, Vec<f64>)> = Vec::new();
    let mut merges = 0;
    for i in 0..d {
        let p_i = projector_row(i);
        if norm(&p_i) < FREE_LENGTH {
            continue;
        }
        let tie = representatives.iter().find_map(|(k, p_k)| {
            let lambda = p_i.iter().zip(p_k).map(|(a, b)| a * b).sum::<f64>() / p_k.iter().map(|x| x * x).sum::<f64>();
            // The tie row (e_i − λ e_k)/√(1+λ²) lies this far from the star's row space.
            let distance = p_i
                .iter()
                .zip(p_k)
                .map(|(a, b)| (a - lambda * b).powi(2))
                .sum::<f64>()
                .sqrt()
                / (1.0 + lambda * lambda).sqrt();
            (distance <= tolerance && lambda.abs() >= FREE_LENGTH && lambda.abs() <= 1.0 / FREE_LENGTH)
                .then_some((*k, lambda))
        });
        match tie {
            Some((k, lambda)) => {
                // ρ_i = λ ρ_k: root i under root k.
                ties.parent[roots[i]] = roots[k];
                ties.factor[roots[i]] = lambda;
                merges += 1;
            }
            None => representatives.push((i, p_i)),
        }
    }
    merges
}

/// Reduce J (every column with an entry, none held) for its rank count at relative
/// threshold `tolerance` (of J's largest column norm, `scale`).
pub fn reduce(jacobian: &ClosureJacobian, tolerance: f64, scale: f64) -> Reduction {
    let threshold = tolerance * scale;
    let stars = jacobian.rows.div_ceil(3);
    let mut by_star: Vec<Vec<(usize, usize, f64)>> = vec![Vec::new(); stars];
    for &(r, c, v) in &jacobian.entries {
        if v != 0.0 {
            by_star[r / 3].push((r % 3, c, v));
        }
    }
    let mut ties = Ties::new(jacobian.cols);
    for _ in 0..MAX_PASSES {
        let merges: usize = by_star
            .iter()
            .map(|e| merge_star(e, &mut ties, threshold, tolerance))
            .sum();
        if merges == 0 {
            break;
        }
    }
    // Each star's rows over the final classes (roots), truncated at the threshold.
    let mut star_rows: Vec<StarRows> = by_star
        .iter()
        .map(|entries| {
            let (classes, block) = star_block(entries, &mut ties);
            let rows = compress(&block, threshold);
            StarRows { classes, rows }
        })
        .collect();
    let roots = (0..jacobian.cols).filter(|&c| ties.find(c).0 == c).count();
    let eliminated = eliminate_held_columns(&mut star_rows, jacobian.cols, threshold);
    let mut position = vec![usize::MAX; jacobian.cols];
    let (mut rows, mut columns) = (0, 0);
    let mut entries = Vec::new();
    for star in &star_rows {
        for row in &star.rows {
            for (k, &v) in row.iter().enumerate() {
                if v != 0.0 {
                    let column = &mut position[star.classes[k]];
                    if *column == usize::MAX {
                        *column = columns;
                        columns += 1;
                    }
                    entries.push((rows, *column, v));
                }
            }
            rows += 1;
        }
    }
    let remainder = ClosureJacobian {
        residual: vec![0.0; rows],
        rows,
        cols: columns,
        entries,
        held: 0,
        angle_precision: jacobian.angle_precision,
    };
    Reduction {
        remainder,
        // Roots that lost every entry (to truncation, or as their rows were eliminated).
        free_columns: roots - columns - eliminated,
        removed_columns: jacobian.cols - columns,
    }
}

/// A star's remaining rows, dense over its classes.
struct StarRows {
    classes: Vec<usize>,
    rows: Vec<Vec<f64>>,
}

impl StarRows {
    fn holds(&self, k: usize) -> bool {
        self.rows.iter().any(|row| row[k] != 0.0)
    }
}

/// A block's row space as rows σ_k v_kᵀ with σ_k above `threshold`; a column whose norm is
/// at or below the threshold is taken as zero (its entries exactly 0).
fn compress(block: &DMatrix<f64>, threshold: f64) -> Vec<Vec<f64>> {
    if block.nrows() == 0 || block.ncols() == 0 {
        return Vec::new();
    }
    let small: Vec<bool> = block.column_iter().map(|c| c.norm() <= threshold).collect();
    let mut block = block.clone();
    for (k, &s) in small.iter().enumerate() {
        if s {
            block.column_mut(k).fill(0.0);
        }
    }
    let (mut rows, _) = row_space(&block, threshold);
    for row in &mut rows {
        for (k, &s) in small.iter().enumerate() {
            if s {
                row[k] = 0.0;
            }
        }
    }
    rows
}

/// Eliminate, while any is left, a column only one star's rows hold: a Householder
/// reflection of that star's rows puts the column in one row, and where its entry there is
/// at least [`PIVOT_FRACTION`] of that row's largest, row and column go together (rank and
/// columns fall by one, so the null space keeps its dimension); the star's other rows are
/// compressed again. Returns the number of columns eliminated.
fn eliminate_held_columns(stars: &mut [StarRows], columns: usize, threshold: f64) -> usize {
    let mut stars_of: Vec<Vec<usize>> = vec![Vec::new(); columns];
    let mut count = vec![0usize; columns];
    for (s, star) in stars.iter().enumerate() {
        for (k, &class) in star.classes.iter().enumerate() {
            stars_of[class].push(s);
            if star.holds(k) {
                count[class] += 1;
            }
        }
    }
    let mut eliminated = 0;
    let mut queue: Vec<usize> = (0..columns).filter(|&c| count[c] == 1).collect();
    while let Some(c) = queue.pop() {
        if count[c] != 1 {
            continue;
        }
        let Some((s, k)) = stars_of[c].iter().find_map(|&s| {
            let k = stars[s].classes.iter().position(|&x| x == c)?;
            stars[s].holds(k).then_some((s, k))
        }) else {
            continue;
        };
        let star = &mut stars[s];
        let Some(pivot_row) = reflect_onto_first_row(&star.rows, k) else {
            continue;
        };
        let largest = pivot_row.iter().fold(0.0_f64, |a, &b| a.max(b.abs()));
        if pivot_row[k].abs() < PIVOT_FRACTION * largest {
            continue;
        }
        let held_before: Vec<bool> = (0..star.classes.len()).map(|j| star.holds(j)).collect();
        let others = reflected_rest(&star.rows, k);
        star.rows = if others.is_empty() {
            Vec::new()
        } else {
            let d = star.classes.len();
            let block = DMatrix::from_fn(others.len(), d, |i, j| if j == k { 0.0 } else { others[i][j] });
            compress(&block, threshold)
        };
        eliminated += 1;
        for (j, &was) in held_before.iter().enumerate() {
            if was && !star.holds(j) {
                let class = star.classes[j];
                count[class] -= 1;
                if count[class] == 1 {
                    queue.push(class);
                }
            }
        }
    }
    eliminated
}

/// The Householder reflection H with H a = ‖a‖e₀ for a = column k of `rows`, and H's first
/// row applied to `rows` (None when the column is zero).
fn reflect_onto_first_row(rows: &[Vec<f64>], k: usize) -> Option<Vec<f64>> {
    let h = householder(rows, k)?;
    let d = rows[0].len();
    Some(
        (0..d)
            .map(|j| (0..rows.len()).map(|i| h[0][i] * rows[i][j]).sum())
            .collect(),
    )
}

/// H's other rows applied to `rows` (their entries at column k are zero).
fn reflected_rest(rows: &[Vec<f64>], k: usize) -> Vec<Vec<f64>> {
    let Some(h) = householder(rows, k) else {
        return rows.to_vec();
    };
    let d = rows[0].len();
    (1..rows.len())
        .map(|r| {
            (0..d)
                .map(|j| (0..rows.len()).map(|i| h[r][i] * rows[i][j]).sum())
                .collect()
        })
        .collect()
}

/// The reflection I − 2 v vᵀ / vᵀv, v = a + sign(a₀)‖a‖e₀, as a dense matrix.
fn householder(rows: &[Vec<f64>], k: usize) -> Option<Vec<Vec<f64>>> {
    let m = rows.len();
    let a: Vec<f64> = rows.iter().map(|r| r[k]).collect();
    let norm = a.iter().map(|x| x * x).sum::<f64>().sqrt();
    if norm == 0.0 {
        return None;
    }
    let mut v = a;
    v[0] += norm.copysign(v[0]);
    let vv: f64 = v.iter().map(|x| x * x).sum();
    Some(
        (0..m)
            .map(|i| {
                (0..m)
                    .map(|j| f64::from(u8::from(i == j)) - 2.0 * v[i] * v[j] / vv)
                    .collect()
            })
            .collect(),
    )
}
