//! Edge unfoldings of a solid (`docs/model.md#nets-of-polyhedra`): the spanning trees of its
//! dual graph, enumerated as sets of dual edges (bit k: dual edge k is a fold), and their
//! classes under the solid's symmetry group (the distinct nets).

use super::polyhedron::{Polyhedron, Symmetry};
use crate::error::{NanofoldError, Result};

/// A spanning tree of the dual graph: bit k set when dual edge k is a fold (a hinge).
pub type Tree = u64;

/// Most dual edges for enumeration (a tree is one 64-bit word).
pub const MAX_DUAL_EDGES: usize = 64;

/// Every spanning tree of the solid's dual graph, or an error naming the count when there
/// are more than `limit` (the caller samples instead).
pub fn spanning_trees(solid: &Polyhedron, limit: usize) -> Result<Vec<Tree>> {
    let edges: Vec<[usize; 2]> = solid.dual_edges().iter().map(|e| e.faces).collect();
    if edges.len() > MAX_DUAL_EDGES {
        return Err(NanofoldError::invalid(
            "faces",
            format!("{} edges", edges.len()),
            format!("trees are enumerated for solids of at most {MAX_DUAL_EDGES} edges"),
        ));
    }
    let count = solid.spanning_tree_count();
    if count > limit as f64 {
        return Err(NanofoldError::invalid(
            "limit",
            limit,
            format!("the solid has {count} spanning trees: sample them instead"),
        ));
    }
    let faces = solid.faces.len();
    let mut trees = Vec::with_capacity(count as usize);
    let mut search = Search {
        edges: &edges,
        faces,
        trees: &mut trees,
    };
    search.extend(0, 0, &mut (0..faces).collect::<Vec<_>>(), faces - 1);
    Ok(trees)
}

/// Depth-first choice of each dual edge in turn: in (when it joins two components) or out
/// (when the edges left can still connect everything).
struct Search<'a> {
    edges: &'a [[usize; 2]],
    faces: usize,
    trees: &'a mut Vec<Tree>,
}

impl Search<'_> {
    fn extend(&mut self, next: usize, chosen: Tree, component: &mut Vec<usize>, missing: usize) {
        if missing == 0 {
            self.trees.push(chosen);
            return;
        }
        if next == self.edges.len() || self.edges.len() - next < missing {
            return;
        }
        let [a, b] = self.edges[next];
        let (ca, cb) = (component[a], component[b]);
        if ca != cb {
            let saved = component.clone();
            for c in component.iter_mut() {
                if *c == cb {
                    *c = ca;
                }
            }
            self.extend(next + 1, chosen | 1 << next, component, missing - 1);
            *component = saved;
        }
        if self.still_connectable(next + 1, component) {
            self.extend(next + 1, chosen, component, missing);
        }
    }

    /// Whether the components joined by the edges from `from` on make one.
    fn still_connectable(&self, from: usize, component: &[usize]) -> bool {
        let find = |parent: &mut Vec<usize>, mut x: usize| {
            while parent[x] != x {
                parent[x] = parent[parent[x]];
                x = parent[x];
            }
            x
        };
        // Components are labelled by a member face; union them along the remaining edges.
        let mut parent: Vec<usize> = (0..self.faces).collect();
        for (f, &root) in component.iter().enumerate() {
            let (rf, rr) = (find(&mut parent, f), find(&mut parent, root));
            parent[rf] = rr;
        }
        for &[a, b] in &self.edges[from..] {
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
            parent[ra] = rb;
        }
        let root = find(&mut parent, 0);
        (0..self.faces).all(|f| find(&mut parent, f) == root)
    }
}

/// Where each dual edge goes under a symmetry.
pub fn edge_map(solid: &Polyhedron, symmetry: &Symmetry) -> Vec<usize> {
    let edges = solid.dual_edges();
    let key = |a: usize, b: usize| if a < b { [a, b] } else { [b, a] };
    edges
        .iter()
        .map(|e| {
            let image = key(symmetry.vertex_map[e.vertices[0]], symmetry.vertex_map[e.vertices[1]]);
            edges
                .iter()
                .position(|f| key(f.vertices[0], f.vertices[1]) == image)
                .expect("a symmetry maps edges onto edges")
        })
        .collect()
}

/// A tree's image under a symmetry's edge map.
pub fn image(tree: Tree, map: &[usize]) -> Tree {
    let mut rest = tree;
    let mut image: Tree = 0;
    while rest != 0 {
        let k = rest.trailing_zeros() as usize;
        image |= 1 << map[k];
        rest &= rest - 1;
    }
    image
}

/// One tree of each distinct net among `trees` (all of a solid's): the orbits under the
/// symmetries' edge maps, each represented by its smallest member. The trees
/// are sorted once and each orbit's images struck off by binary search, so the work is one
/// orbit's images per net, not per tree.
pub fn distinct_nets(trees: &[Tree], maps: &[Vec<usize>]) -> Vec<Tree> {
    let mut sorted = trees.to_vec();
    sorted.sort_unstable();
    sorted.dedup();
    let mut seen = vec![false; sorted.len()];
    let mut representatives = Vec::new();
    for at in 0..sorted.len() {
        if seen[at] {
            continue;
        }
        let tree = sorted[at];
        representatives.push(tree);
        for map in maps {
            if let Ok(other) = sorted.binary_search(&image(tree, map)) {
                seen[other] = true;
            }
        }
    }
    representatives
}

/// Checks the nets against the orbit–stabiliser theorem before they are counted: each net's
/// orbit (its distinct images) has a size that divides the group's order, and the orbits of
/// all the nets together hold every tree once. A set of maps that is not a group breaks it.
pub fn check_orbits(trees: usize, nets: &[Tree], maps: &[Vec<usize>]) -> Result<()> {
    let mut total = 0usize;
    let mut images = Vec::with_capacity(maps.len());
    for &tree in nets {
        images.clear();
        images.extend(maps.iter().map(|m| image(tree, m)));
        images.sort_unstable();
        images.dedup();
        if !maps.len().is_multiple_of(images.len()) {
            return Err(NanofoldError::invalid(
                "symmetries",
                format!("an orbit of {} trees under {} maps", images.len(), maps.len()),
                "an orbit's size divides the group's order: the maps are not a group",
            ));
        }
        total += images.len();
    }
    if total != trees {
        return Err(NanofoldError::invalid(
            "symmetries",
            format!("orbits of {total} trees in all, of {trees}"),
            "the nets' orbits hold every tree once: the maps are not a group",
        ));
    }
    Ok(())
}

/// One tree of each distinct net among some of a solid's trees (a sample): each tree's
/// class is its smallest image, the classes in the order first met.
pub fn distinct_among(trees: &[Tree], maps: &[Vec<usize>]) -> Vec<Tree> {
    let mut seen = std::collections::HashSet::new();
    let mut representatives = Vec::new();
    for &tree in trees {
        let smallest = maps.iter().map(|m| image(tree, m)).min().unwrap_or(tree).min(tree);
        if seen.insert(smallest) {
            representatives.push(smallest);
        }
    }
    representatives
}

/// Burnside's count of the same orbits: the mean, over the group, of the trees each
/// symmetry fixes.
pub fn burnside_nets(trees: &[Tree], maps: &[Vec<usize>]) -> f64 {
    let fixed: usize = maps
        .iter()
        .map(|m| trees.iter().filter(|&&t| image(t, m) == t).count())
        .sum();
    fixed as f64 / maps.len() as f64
}

/// `count` spanning trees drawn uniformly at random (Wilson's algorithm: loop-erased random
/// walks on the dual graph, each step along a dual edge chosen uniformly, so parallel edges
/// count as they should), from `seed`: for solids with too many trees to enumerate.
pub fn sample_trees(solid: &Polyhedron, count: usize, seed: u64) -> Result<Vec<Tree>> {
    let edges: Vec<[usize; 2]> = solid.dual_edges().iter().map(|e| e.faces).collect();
    if edges.len() > MAX_DUAL_EDGES {
        return Err(NanofoldError::invalid(
            "faces",
            format!("{} edges", edges.len()),
            format!("trees are sampled for solids of at most {MAX_DUAL_EDGES} edges"),
        ));
    }
    let faces = solid.faces.len();
    let mut incident: Vec<Vec<usize>> = vec![Vec::new(); faces];
    for (k, &[a, b]) in edges.iter().enumerate() {
        incident[a].push(k);
        incident[b].push(k);
    }
    let mut state = seed;
    let mut draw = |n: usize| {
        // splitmix64
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) % n as u64) as usize
    };
    let mut trees = Vec::with_capacity(count);
    for _ in 0..count {
        let mut in_tree = vec![false; faces];
        let mut leave: Vec<usize> = vec![usize::MAX; faces];
        in_tree[0] = true;
        let mut tree: Tree = 0;
        for start in 1..faces {
            // Walk until the tree, remembering only the last exit from each face (which
            // erases the loops).
            let mut at = start;
            while !in_tree[at] {
                let k = incident[at][draw(incident[at].len())];
                leave[at] = k;
                let [a, b] = edges[k];
                at = if a == at { b } else { a };
            }
            let mut at = start;
            while !in_tree[at] {
                in_tree[at] = true;
                let k = leave[at];
                tree |= 1 << k;
                let [a, b] = edges[k];
                at = if a == at { b } else { a };
            }
        }
        trees.push(tree);
    }
    Ok(trees)
}
