//! Closed solids from the files mesh tools write (`docs/model.md#solids-from-mesh-files`):
//! Wavefront OBJ (vertices and faces; texture coordinates, normals, groups, smoothing and
//! materials ignored), STL (ASCII and binary), PLY (ASCII and binary, by `ply-rs-bw`), OFF and
//! FOLD with 3D `vertices_coords` and `faces_vertices`. Each is parsed here with the precision
//! its numbers carry (their digits, or their float width), and built into a solid by
//! [`solid_from_mesh`] (welded, coplanar faces merged, validated).

use crate::error::{NanofoldError, Result};
use crate::geometry::mesh::{solid_from_mesh, MergeCoplanar, MeshReading};
use crate::geometry::polyhedron::{Polyhedron, MAX_VERTICES};
use crate::geometry::precision::DigitsSeen;
use nalgebra::Point3;
use std::path::Path;

/// The largest solid file read.
pub const MAX_SOLID_BYTES: u64 = 16 << 20;

/// The formats a solid is read from, by extension.
pub const SOLID_EXTENSIONS: [&str; 6] = ["off", "obj", "stl", "ply", "fold", "json"];

/// How a solid file is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SolidOptions {
    /// Whether faces in one plane are merged into one ([`MergeCoplanar`]).
    pub merge_coplanar: MergeCoplanar,
}

/// A mesh as a file gives it, before it is made a solid.
struct RawMesh {
    vertices: Vec<Point3<f64>>,
    faces: Vec<Vec<usize>>,
    digits: DigitsSeen,
    format: &'static str,
}

impl RawMesh {
    fn new(format: &'static str) -> Self {
        RawMesh {
            vertices: Vec::new(),
            faces: Vec::new(),
            digits: DigitsSeen::default(),
            format,
        }
    }

    fn build(self, options: &SolidOptions) -> Result<(Polyhedron, MeshReading)> {
        solid_from_mesh(
            self.vertices,
            self.faces,
            self.digits.precision(),
            options.merge_coplanar,
            self.format,
        )
    }
}

/// Whether a file's extension names a solid format.
pub fn is_solid_file(path: &Path) -> bool {
    extension(path).is_some_and(|e| SOLID_EXTENSIONS.contains(&e.as_str()))
}

fn extension(path: &Path) -> Option<String> {
    path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase)
}

/// Reads a solid from `path` with the default options ([`read_solid`]).
pub fn load_solid(path: &Path) -> Result<Polyhedron> {
    Ok(read_solid(path, &SolidOptions::default())?.0)
}

/// Reads a solid from `path`, its format from the extension (`.off`, `.obj`, `.stl`,
/// `.ply`, `.fold`), with what reading it did.
pub fn read_solid(path: &Path, options: &SolidOptions) -> Result<(Polyhedron, MeshReading)> {
    let source = path.display().to_string();
    let format = extension(path).unwrap_or_default();
    if !SOLID_EXTENSIONS.contains(&format.as_str()) {
        return Err(NanofoldError::invalid(
            "solid",
            source,
            "a solid is read from .off, .obj, .stl, .ply or .fold (with 3D vertices_coords and faces_vertices)",
        ));
    }
    let bytes = crate::read::input::read_bytes(path, MAX_SOLID_BYTES)?;
    parse_solid(&bytes, &format, &source, options)
}

/// A solid from a file's bytes in `format` (an extension: `off`, `obj`, `stl`, `ply`,
/// `fold`), `source` naming it in errors.
pub fn parse_solid(
    bytes: &[u8],
    format: &str,
    source: &str,
    options: &SolidOptions,
) -> Result<(Polyhedron, MeshReading)> {
    let text = || {
        std::str::from_utf8(bytes).map_err(|e| {
            NanofoldError::invalid(
                source,
                format!("byte {} is not UTF-8", e.valid_up_to()),
                format!("a {format} file is text"),
            )
        })
    };
    let raw = match format {
        "off" => off_mesh(text()?, source)?,
        "obj" => obj_mesh(text()?, source)?,
        "fold" | "json" => fold_mesh(text()?, source)?,
        "stl" => stl_mesh(bytes, source)?,
        "ply" => ply_mesh(bytes, source)?,
        other => {
            return Err(NanofoldError::invalid(
                "format",
                other,
                "a solid is read from off, obj, stl, ply or fold",
            ))
        }
    };
    raw.build(options)
}

/// A finite coordinate or index token, or an error naming where it is.
fn number<T: std::str::FromStr>(token: Option<&str>, at: impl Fn() -> String, what: &str) -> Result<T> {
    let token = token.ok_or_else(|| NanofoldError::invalid(at(), "missing", format!("expected {what}")))?;
    token
        .parse::<T>()
        .map_err(|_| NanofoldError::invalid(at(), token, format!("expected {what}")))
}

/// Three coordinates from text tokens, finite, their digits noted.
fn coordinates<'t>(
    tokens: &mut impl Iterator<Item = &'t str>,
    digits: &mut DigitsSeen,
    at: impl Fn() -> String,
) -> Result<Point3<f64>> {
    let mut xyz = [0.0f64; 3];
    for x in &mut xyz {
        let token = tokens.next();
        *x = number(token, &at, "three coordinates")?;
        if x.is_finite() {
            digits.text(token.unwrap_or_default());
        }
    }
    point(xyz, at)
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

/// More vertices or faces than a solid may have (before merging: a mesh's triangles),
/// refused before anything is stored.
fn check_counts(source: &str, vertices: usize, faces: usize) -> Result<()> {
    // A triangle mesh of the largest solid: its faces' corners, each written once per
    // triangle in an STL file.
    let most_vertices = 6 * MAX_VERTICES;
    if vertices > most_vertices {
        return Err(NanofoldError::invalid(
            format!("{source}: vertices"),
            vertices,
            format!("a solid's file has at most {most_vertices} vertices ({MAX_VERTICES} after welding)"),
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
fn off_mesh(text: &str, source: &str) -> Result<RawMesh> {
    let mut mesh = RawMesh::new("off");
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
    for k in 0..vertex_count {
        let (line, text) = lines.next().ok_or_else(|| {
            NanofoldError::invalid(
                format!("{source}: vertices[{k}]"),
                "missing",
                format!("the counts say {vertex_count}"),
            )
        })?;
        let p = coordinates(&mut text.split_whitespace(), &mut mesh.digits, at_line(line))?;
        mesh.vertices.push(p);
    }
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
        mesh.faces.push(face);
    }
    Ok(mesh)
}

/// Wavefront OBJ: `v x y z` (colours after them ignored) and `f a b c …` (1-based, negative
/// counting back from the last vertex read, `a/t/n` forms taking the first number). Every
/// other statement (`vt`, `vn`, `o`, `g`, `s`, `usemtl`, `mtllib`, `l`) is ignored; the
/// objects and groups of one file are one surface.
fn obj_mesh(text: &str, source: &str) -> Result<RawMesh> {
    let mut mesh = RawMesh::new("obj");
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        let at = || format!("{source}: line {}", i + 1);
        let mut tokens = line.split_whitespace();
        match tokens.next() {
            Some("v") => {
                let p = coordinates(&mut tokens, &mut mesh.digits, at)?;
                mesh.vertices.push(p);
            }
            Some("f") => {
                let mut face = Vec::new();
                for token in tokens {
                    let index: i64 = number(token.split('/').next(), at, "a vertex index")?;
                    let count = mesh.vertices.len();
                    let resolved = match index {
                        i if i > 0 && i as usize <= count => (i - 1) as usize,
                        i if i < 0 && i.unsigned_abs() as usize <= count => count - i.unsigned_abs() as usize,
                        _ => {
                            return Err(NanofoldError::invalid(
                                at(),
                                token,
                                format!("a vertex index from 1 (or back from -1) among the {count} read so far"),
                            ))
                        }
                    };
                    face.push(resolved);
                }
                mesh.faces.push(face);
            }
            _ => {}
        }
        check_counts(source, mesh.vertices.len(), mesh.faces.len())?;
    }
    Ok(mesh)
}

/// A FOLD file with 3D `vertices_coords` and `faces_vertices` (a folded model's faces).
fn fold_mesh(text: &str, source: &str) -> Result<RawMesh> {
    let mut mesh = RawMesh::new("fold");
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
        xyz.iter().for_each(|&x| mesh.digits.json_number(x));
        mesh.vertices.push(point([xyz[0], xyz[1], xyz[2]], at)?);
    }
    for (k, f) in face_lists.iter().enumerate() {
        let face: Option<Vec<usize>> = f
            .as_array()
            .and_then(|a| a.iter().map(|x| x.as_u64().map(|i| i as usize)).collect());
        mesh.faces.push(face.ok_or_else(|| {
            NanofoldError::invalid(
                format!("{source}: faces_vertices[{k}]"),
                f.to_string(),
                "a list of vertex indices",
            )
        })?);
    }
    Ok(mesh)
}

/// STL, binary or ASCII: each facet's three corners, wound counter-clockwise seen from
/// outside (the facet normal written beside them is not used). A file is binary when its
/// size is 84 bytes plus 50 a triangle its count gives (ASCII files start with `solid`, but
/// so do some binary headers).
fn stl_mesh(bytes: &[u8], source: &str) -> Result<RawMesh> {
    let binary = bytes.len() >= 84 && {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        count.checked_mul(50).and_then(|b| b.checked_add(84)) == Some(bytes.len())
    };
    if binary {
        return binary_stl(bytes, source);
    }
    let text = std::str::from_utf8(bytes).map_err(|_| {
        NanofoldError::invalid(
            source,
            format!("{} bytes", bytes.len()),
            "neither binary STL (84 bytes and 50 a triangle, as its count says) nor ASCII STL text",
        )
    })?;
    ascii_stl(text, source)
}

fn binary_stl(bytes: &[u8], source: &str) -> Result<RawMesh> {
    let mut mesh = RawMesh::new("stl (binary)");
    let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
    check_counts(source, 3 * count, count)?;
    for t in 0..count {
        let record = &bytes[84 + 50 * t..84 + 50 * (t + 1)];
        let mut face = Vec::with_capacity(3);
        for corner in 0..3 {
            let at = 12 + 12 * corner;
            let value = |i: usize| {
                f32::from_le_bytes([
                    record[at + 4 * i],
                    record[at + 4 * i + 1],
                    record[at + 4 * i + 2],
                    record[at + 4 * i + 3],
                ])
            };
            let xyz = [value(0), value(1), value(2)];
            xyz.iter().for_each(|&x| mesh.digits.binary_single(x));
            mesh.vertices
                .push(point(xyz.map(f64::from), || format!("{source}: triangle {t}"))?);
            face.push(mesh.vertices.len() - 1);
        }
        mesh.faces.push(face);
    }
    Ok(mesh)
}

fn ascii_stl(text: &str, source: &str) -> Result<RawMesh> {
    let mut mesh = RawMesh::new("stl (ascii)");
    let mut face: Vec<usize> = Vec::new();
    let mut started = false;
    for (i, raw) in text.lines().enumerate() {
        let at = || format!("{source}: line {}", i + 1);
        let mut tokens = raw.split_whitespace();
        match tokens.next() {
            Some("solid") if !started => started = true,
            Some("vertex") => {
                let p = coordinates(&mut tokens, &mut mesh.digits, at)?;
                mesh.vertices.push(p);
                face.push(mesh.vertices.len() - 1);
            }
            Some("endloop") => {
                if face.len() != 3 {
                    return Err(NanofoldError::invalid(
                        at(),
                        format!("a loop of {} vertices", face.len()),
                        "an STL facet has three",
                    ));
                }
                mesh.faces.push(std::mem::take(&mut face));
                check_counts(source, mesh.vertices.len(), mesh.faces.len())?;
            }
            Some("facet" | "outer" | "endfacet" | "endsolid" | "solid") | None => {}
            Some(other) => {
                return Err(NanofoldError::invalid(
                    at(),
                    other,
                    "ASCII STL has solid, facet normal, outer loop, vertex, endloop, endfacet and endsolid",
                ))
            }
        }
    }
    if !started {
        return Err(NanofoldError::invalid(
            source,
            "no `solid` line",
            "ASCII STL starts with `solid`",
        ));
    }
    Ok(mesh)
}

/// PLY, ASCII or binary (read by `ply-rs-bw`): the `vertex` element's `x`, `y`, `z` and the
/// `face` element's `vertex_indices` (or `vertex_index`). An ASCII file's digits are read off
/// its vertex lines; a binary one's precision is its float width.
fn ply_mesh(bytes: &[u8], source: &str) -> Result<RawMesh> {
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::{DefaultElement, Encoding, Property};
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut std::io::Cursor::new(bytes))
        .map_err(|e| NanofoldError::invalid(source, "not PLY", e.to_string()))?;
    let mut mesh = RawMesh::new(match ply.header.encoding {
        Encoding::Ascii => "ply (ascii)",
        _ => "ply (binary)",
    });
    let element = |name: &str| {
        ply.payload.get(name).ok_or_else(|| {
            NanofoldError::invalid(
                format!("{source}: element {name}"),
                "missing",
                "a solid's PLY file has vertex and face elements",
            )
        })
    };
    let (vertices, faces) = (element("vertex")?, element("face")?);
    check_counts(source, vertices.len(), faces.len())?;
    let ascii = matches!(ply.header.encoding, Encoding::Ascii);
    for (k, v) in vertices.iter().enumerate() {
        let at = || format!("{source}: vertex {k}");
        let mut xyz = [0.0f64; 3];
        for (slot, name) in xyz.iter_mut().zip(["x", "y", "z"]) {
            *slot = match v.get(name) {
                Some(Property::Float(x)) => {
                    if ascii {
                        mesh.digits.text(&format!("{x}"));
                        mesh.digits.held_as_single();
                    } else {
                        mesh.digits.binary_single(*x);
                    }
                    f64::from(*x)
                }
                Some(Property::Double(x)) => {
                    if ascii {
                        mesh.digits.json_number(*x);
                    } else {
                        mesh.digits.binary_double(*x);
                    }
                    *x
                }
                Some(Property::Int(x)) => f64::from(*x),
                Some(Property::Short(x)) => f64::from(*x),
                Some(other) => {
                    return Err(NanofoldError::invalid(
                        at(),
                        format!("{name} = {other:?}"),
                        "a coordinate is a float, double or integer",
                    ))
                }
                None => {
                    return Err(NanofoldError::invalid(
                        at(),
                        format!("no {name}"),
                        "a vertex has x, y and z",
                    ))
                }
            };
        }
        mesh.vertices.push(point(xyz, at)?);
    }
    for (k, f) in faces.iter().enumerate() {
        let at = || format!("{source}: face {k}");
        let list = f.get("vertex_indices").or_else(|| f.get("vertex_index"));
        let face: Vec<i64> = match list {
            Some(Property::ListInt(l)) => l.iter().map(|&i| i64::from(i)).collect(),
            Some(Property::ListUInt(l)) => l.iter().map(|&i| i64::from(i)).collect(),
            Some(Property::ListUShort(l)) => l.iter().map(|&i| i64::from(i)).collect(),
            Some(Property::ListShort(l)) => l.iter().map(|&i| i64::from(i)).collect(),
            Some(Property::ListUChar(l)) => l.iter().map(|&i| i64::from(i)).collect(),
            Some(Property::ListChar(l)) => l.iter().map(|&i| i64::from(i)).collect(),
            _ => {
                return Err(NanofoldError::invalid(
                    at(),
                    "no vertex_indices",
                    "a face is a list of integer vertex indices",
                ))
            }
        };
        let face = face
            .into_iter()
            .map(|i| usize::try_from(i).map_err(|_| NanofoldError::invalid(at(), i, "a vertex index is ≥ 0")))
            .collect::<Result<Vec<usize>>>()?;
        mesh.faces.push(face);
    }
    Ok(mesh)
}

/// An OFF file's solid (default options).
pub fn parse_off(text: &str, source: &str) -> Result<Polyhedron> {
    Ok(parse_solid(text.as_bytes(), "off", source, &SolidOptions::default())?.0)
}

/// An OBJ file's solid (default options).
pub fn parse_obj(text: &str, source: &str) -> Result<Polyhedron> {
    Ok(parse_solid(text.as_bytes(), "obj", source, &SolidOptions::default())?.0)
}

/// A FOLD file's solid (default options).
pub fn parse_fold_solid(text: &str, source: &str) -> Result<Polyhedron> {
    Ok(parse_solid(text.as_bytes(), "fold", source, &SolidOptions::default())?.0)
}
