//! Closed solids from the files mesh tools write: OFF, Wavefront OBJ (vertices and faces;
//! the rest ignored) and FOLD with 3D `vertices_coords` and `faces_vertices`
//! (`docs/model.md#nets-of-polyhedra`). Parsed here, validated by [`Polyhedron::new`].

use crate::error::{NanofoldError, Result};
use crate::geometry::polyhedron::{Polyhedron, MAX_VERTICES};
use nalgebra::Point3;
use std::path::Path;

/// The largest solid file read.
pub const MAX_SOLID_BYTES: u64 = 16 << 20;

/// Reads a solid from `path`, its format from the extension: `.off`, `.obj` or `.fold`.
pub fn load_solid(path: &Path) -> Result<Polyhedron> {
    let source = path.display().to_string();
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let parse: fn(&str, &str) -> Result<Polyhedron> = match extension.as_str() {
        "off" => parse_off,
        "obj" => parse_obj,
        "fold" | "json" => parse_fold_solid,
        _ => {
            return Err(NanofoldError::invalid(
                "solid",
                source,
                "a solid is read from .off, .obj or .fold (with 3D vertices_coords and faces_vertices)",
            ))
        }
    };
    let text = crate::read::input::read_text(path, MAX_SOLID_BYTES)?;
    parse(&text, &source)
}

/// A finite coordinate or index token, or an error naming where it is.
fn number<T: std::str::FromStr>(token: Option<&str>, at: impl Fn() -> String, what: &str) -> Result<T> {
    let token = token.ok_or_else(|| NanofoldError::invalid(at(), "missing", format!("expected {what}")))?;
    token
        .parse::<T>()
        .map_err(|_| NanofoldError::invalid(at(), token, format!("expected {what}")))
}

fn point(values: [f64; 3], at: impl Fn() -> String) -> Result<Point3<f64>> {
    if values.iter().all(|x| x.is_finite()) {
        Ok(Point3::from(values))
    } else {
        Err(NanofoldError::invalid(
            at(),
            format!("{values:?}"),
            "coordinates must be finite",
        ))
    }
}

/// More vertices or faces than a solid may have, refused before anything is stored.
fn check_counts(source: &str, vertices: usize, faces: usize) -> Result<()> {
    if vertices > MAX_VERTICES {
        return Err(NanofoldError::invalid(
            format!("{source}: vertices"),
            vertices,
            format!("a solid has at most {MAX_VERTICES} vertices"),
        ));
    }
    if faces > 2 * MAX_VERTICES {
        return Err(NanofoldError::invalid(
            format!("{source}: faces"),
            faces,
            format!(
                "a solid of at most {MAX_VERTICES} vertices has at most {} faces",
                2 * MAX_VERTICES
            ),
        ));
    }
    Ok(())
}

/// Object File Format: `OFF`, then the counts of vertices, faces (and edges), the vertices'
/// x y z, and each face as its corner count and 0-based indices (a colour after them is
/// ignored). `#` starts a comment.
pub fn parse_off(text: &str, source: &str) -> Result<Polyhedron> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.split('#').next().unwrap_or("").trim()))
        .filter(|(_, l)| !l.is_empty());
    let at_line = |line: usize| move || format!("{source}: line {line}");
    let (line, first) = lines
        .next()
        .ok_or_else(|| NanofoldError::invalid(source, "empty", "an OFF file starts with OFF"))?;
    // The counts may follow OFF on its own line.
    let counts_text = match first.strip_prefix("OFF") {
        Some(rest) if rest.trim().is_empty() => lines
            .next()
            .ok_or_else(|| NanofoldError::invalid(at_line(line)(), "no counts", "OFF is followed by the counts"))?,
        Some(rest) => (line, rest.trim()),
        None => {
            return Err(NanofoldError::invalid(
                at_line(line)(),
                first,
                "an OFF file starts with OFF",
            ))
        }
    };
    let mut counts = counts_text.1.split_whitespace();
    let vertex_count: usize = number(counts.next(), at_line(counts_text.0), "the number of vertices")?;
    let face_count: usize = number(counts.next(), at_line(counts_text.0), "the number of faces")?;
    check_counts(source, vertex_count, face_count)?;
    let mut vertices = Vec::with_capacity(vertex_count);
    for k in 0..vertex_count {
        let (line, text) = lines.next().ok_or_else(|| {
            NanofoldError::invalid(
                format!("{source}: vertices[{k}]"),
                "missing",
                format!("the counts say {vertex_count}"),
            )
        })?;
        let mut tokens = text.split_whitespace();
        let mut xyz = [0.0; 3];
        for x in &mut xyz {
            *x = number(tokens.next(), at_line(line), "three coordinates")?;
        }
        vertices.push(point(xyz, at_line(line))?);
    }
    let mut faces = Vec::with_capacity(face_count);
    for k in 0..face_count {
        let (line, text) = lines.next().ok_or_else(|| {
            NanofoldError::invalid(
                format!("{source}: faces[{k}]"),
                "missing",
                format!("the counts say {face_count}"),
            )
        })?;
        let mut tokens = text.split_whitespace();
        let corners: usize = number(tokens.next(), at_line(line), "the face's number of corners")?;
        if corners > MAX_VERTICES {
            return Err(NanofoldError::invalid(
                at_line(line)(),
                corners,
                "more corners than a solid has vertices",
            ));
        }
        let mut face = Vec::with_capacity(corners);
        for _ in 0..corners {
            face.push(number::<usize>(tokens.next(), at_line(line), "a vertex index")?);
        }
        faces.push(face);
    }
    Polyhedron::new(vertices, faces)
}

/// Wavefront OBJ: `v x y z` and `f a b c …` (1-based, negative counting back from the last
/// vertex read, `a/t/n` forms taking the first number). Other statements are ignored.
pub fn parse_obj(text: &str, source: &str) -> Result<Polyhedron> {
    let mut vertices = Vec::new();
    let mut faces = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        let at = || format!("{source}: line {}", i + 1);
        let mut tokens = line.split_whitespace();
        match tokens.next() {
            Some("v") => {
                let mut xyz = [0.0; 3];
                for x in &mut xyz {
                    *x = number(tokens.next(), at, "three coordinates")?;
                }
                vertices.push(point(xyz, at)?);
            }
            Some("f") => {
                let mut face = Vec::new();
                for token in tokens {
                    let index: i64 = number(token.split('/').next(), at, "a vertex index")?;
                    let resolved = match index {
                        i if i > 0 && i as usize <= vertices.len() => (i - 1) as usize,
                        i if i < 0 && (-i) as usize <= vertices.len() => vertices.len() - (-i) as usize,
                        _ => {
                            return Err(NanofoldError::invalid(
                                at(),
                                token,
                                format!(
                                    "a vertex index from 1 (or back from -1) among the {} read so far",
                                    vertices.len()
                                ),
                            ))
                        }
                    };
                    face.push(resolved);
                }
                faces.push(face);
            }
            _ => {}
        }
        check_counts(source, vertices.len(), faces.len())?;
    }
    Polyhedron::new(vertices, faces)
}

/// A FOLD file with 3D `vertices_coords` and `faces_vertices` (a folded model's faces).
pub fn parse_fold_solid(text: &str, source: &str) -> Result<Polyhedron> {
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| NanofoldError::invalid(source, "not JSON", e.to_string()))?;
    let array = |key: &str| -> Result<&Vec<serde_json::Value>> {
        value.get(key).and_then(|v| v.as_array()).ok_or_else(|| {
            NanofoldError::invalid(
                format!("{source}: {key}"),
                "missing",
                "a solid's FOLD file gives vertices_coords and faces_vertices",
            )
        })
    };
    let (coords, face_lists) = (array("vertices_coords")?, array("faces_vertices")?);
    check_counts(source, coords.len(), face_lists.len())?;
    let mut vertices = Vec::with_capacity(coords.len());
    for (k, c) in coords.iter().enumerate() {
        let at = || format!("{source}: vertices_coords[{k}]");
        let xyz: Vec<f64> = c
            .as_array()
            .map(|a| a.iter().filter_map(|x| x.as_f64()).collect())
            .unwrap_or_default();
        if xyz.len() != 3 || c.as_array().map_or(0, |a| a.len()) != 3 {
            return Err(NanofoldError::invalid(
                at(),
                c.to_string(),
                "a solid's vertices have three coordinates",
            ));
        }
        vertices.push(point([xyz[0], xyz[1], xyz[2]], at)?);
    }
    let mut faces = Vec::with_capacity(face_lists.len());
    for (k, f) in face_lists.iter().enumerate() {
        let face: Option<Vec<usize>> = f
            .as_array()
            .and_then(|a| a.iter().map(|x| x.as_u64().map(|i| i as usize)).collect());
        faces.push(face.ok_or_else(|| {
            NanofoldError::invalid(
                format!("{source}: faces_vertices[{k}]"),
                f.to_string(),
                "a list of vertex indices",
            )
        })?);
    }
    Polyhedron::new(vertices, faces)
}
