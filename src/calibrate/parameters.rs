//! Free parameters of a fit (`docs/model.md#calibration`): numbers of a scene file named by
//! their place in it (`hinges[3].layers[1].thickness_um`, `materials.Cr.youngs_modulus_gpa`,
//! `hinges[*].target_angle_deg` for every hinge at once), each with bounds.

use crate::error::{NanofoldError, Result};
use crate::read::scene_spec::default_number;
use crate::read::SceneDocument;
use serde_json::Value;

/// A parameter to fit, as the user names it: a path into the scene file and its bounds.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FreeParameter {
    /// The path of a number in the scene file.
    pub path: String,
    /// Lower bound, in the number's own unit.
    pub lower: f64,
    /// Upper bound.
    pub upper: f64,
}

impl FreeParameter {
    /// Reads `PATH=LOWER:UPPER` (the command line's `--free`).
    pub fn parse(text: &str) -> Result<FreeParameter> {
        let invalid = |reason: &str| NanofoldError::invalid("free", text, reason.to_string());
        let (path, bounds) = text
            .split_once('=')
            .ok_or_else(|| invalid("write PATH=LOWER:UPPER, e.g. environment.drag_coefficient=0.5:4"))?;
        let (lower, upper) = bounds
            .split_once(':')
            .ok_or_else(|| invalid("the bounds are LOWER:UPPER"))?;
        let number = |s: &str| {
            s.trim()
                .parse::<f64>()
                .map_err(|_| invalid(&format!("`{}` is not a number", s.trim())))
        };
        Ok(FreeParameter {
            path: path.trim().to_string(),
            lower: number(lower)?,
            upper: number(upper)?,
        })
    }
}

/// One step of a path: an object key, an array index, or every element.
#[derive(Debug, Clone, PartialEq)]
enum Step {
    Key(String),
    Index(usize),
    Every,
}

/// A free parameter resolved in a scene file: where it is, its value there, its bounds and
/// the scale the fit measures it in.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedParameter {
    /// As given.
    pub path: String,
    steps: Vec<Step>,
    /// The scene file's value.
    pub start: f64,
    /// Bounds, in the number's unit.
    pub lower: f64,
    /// Upper bound.
    pub upper: f64,
    /// The fit's unit for it: |start|, or the bounds' span when the start is 0.
    pub scale: f64,
}

/// Resolves every free parameter in `document`: each path must name numbers (all equal,
/// for a `[*]` path), the bounds must be finite, ordered and contain the file's value, and no
/// two parameters may name the same place.
pub fn resolve(document: &SceneDocument, free: &[FreeParameter]) -> Result<Vec<ResolvedParameter>> {
    if free.is_empty() {
        return Err(NanofoldError::invalid(
            "free",
            "[]",
            "name at least one parameter to fit",
        ));
    }
    let mut resolved: Vec<ResolvedParameter> = Vec::with_capacity(free.len());
    for (k, parameter) in free.iter().enumerate() {
        let field = format!("free[{k}]");
        let steps = parse_path(&parameter.path)
            .map_err(|reason| NanofoldError::invalid(format!("{field}.path"), &parameter.path, reason))?;
        let mut values = Vec::new();
        collect(&document.value, &steps, "", &mut values).map_err(|reason| {
            NanofoldError::invalid(
                format!("{field}.path"),
                &parameter.path,
                format!("{reason} in {}", document.source),
            )
        })?;
        let start = values[0];
        if values.iter().any(|&v| v != start) {
            return Err(NanofoldError::invalid(
                format!("{field}.path"),
                &parameter.path,
                format!("the places it names hold different values ({values:?}): one parameter sets them all to one"),
            ));
        }
        let (lower, upper) = (parameter.lower, parameter.upper);
        if !(lower.is_finite() && upper.is_finite() && lower < upper) {
            return Err(NanofoldError::invalid(
                format!("{field}.bounds"),
                format!("{lower}:{upper}"),
                "bounds must be finite with lower < upper",
            ));
        }
        if !(lower..=upper).contains(&start) {
            return Err(NanofoldError::invalid(
                format!("{field}.bounds"),
                format!("{lower}:{upper}"),
                format!("they exclude the scene's value {start} of {}", parameter.path),
            ));
        }
        if let Some(other) = resolved.iter().find(|r| overlaps(&r.steps, &steps)) {
            return Err(NanofoldError::invalid(
                format!("{field}.path"),
                &parameter.path,
                format!("it names a place `{}` already names", other.path),
            ));
        }
        let scale = if start != 0.0 { start.abs() } else { upper - lower };
        resolved.push(ResolvedParameter {
            path: parameter.path.clone(),
            steps,
            start,
            lower,
            upper,
            scale,
        });
    }
    Ok(resolved)
}

/// The document with every parameter set to `values` (one per parameter, in its unit).
pub fn with_values(document: &SceneDocument, parameters: &[ResolvedParameter], values: &[f64]) -> SceneDocument {
    let mut value = document.value.clone();
    for (parameter, &x) in parameters.iter().zip(values) {
        assign(&mut value, &parameter.steps, x);
    }
    document.with_value(value)
}

fn parse_path(path: &str) -> std::result::Result<Vec<Step>, String> {
    let mut steps = Vec::new();
    for segment in path.split('.') {
        let (key, mut rest) = match segment.find('[') {
            Some(at) => (&segment[..at], &segment[at..]),
            None => (segment, ""),
        };
        if key.is_empty() && (steps.is_empty() || rest.is_empty()) {
            return Err(format!("an empty key in `{segment}`: write a.b[2].c"));
        }
        // `hinges.3.layers` (as Scene.replace in Python writes it) is `hinges[3].layers`.
        match key {
            "" => {}
            "*" => steps.push(Step::Every),
            digits if digits.bytes().all(|b| b.is_ascii_digit()) => steps.push(Step::Index(
                digits.parse().map_err(|_| format!("`{digits}` is not an index"))?,
            )),
            _ => steps.push(Step::Key(key.to_string())),
        }
        while !rest.is_empty() {
            let close = rest
                .find(']')
                .filter(|_| rest.starts_with('['))
                .ok_or_else(|| format!("`{rest}` is not an index [i] or [*]"))?;
            let inside = &rest[1..close];
            steps.push(match inside {
                "*" => Step::Every,
                _ => Step::Index(
                    inside
                        .parse()
                        .map_err(|_| format!("`[{inside}]` is not an index [i] or [*]"))?,
                ),
            });
            rest = &rest[close + 1..];
        }
    }
    Ok(steps)
}

/// Every number the steps reach, or where the path leaves the file; a last key the file
/// leaves out counts with its default, if it has one (`parent`: the key above the object).
fn collect(value: &Value, steps: &[Step], parent: &str, out: &mut Vec<f64>) -> std::result::Result<(), String> {
    let Some((step, rest)) = steps.split_first() else {
        return match value.as_f64() {
            Some(x) => {
                out.push(x);
                Ok(())
            }
            None => Err(format!("it names {value}, not a number")),
        };
    };
    match (step, value) {
        (Step::Key(key), Value::Object(map)) => match map.get(key) {
            Some(inner) => collect(inner, rest, key, out),
            None => match default_number(parent, key).filter(|_| rest.is_empty()) {
                Some(default) => {
                    out.push(default);
                    Ok(())
                }
                None => {
                    let keys: Vec<&str> = map.keys().map(String::as_str).collect();
                    Err(format!("no key `{key}` (there are {})", keys.join(", ")))
                }
            },
        },
        (Step::Index(i), Value::Array(items)) => match items.get(*i) {
            Some(inner) => collect(inner, rest, parent, out),
            None => Err(format!("index [{i}] past the {} entries", items.len())),
        },
        (Step::Every, Value::Array(items)) if !items.is_empty() => {
            items.iter().try_for_each(|inner| collect(inner, rest, parent, out))
        }
        (Step::Key(key), _) => Err(format!("`{key}` is asked of something that is not an object")),
        _ => Err("an index is asked of something that is not a list of entries".to_string()),
    }
}

fn assign(value: &mut Value, steps: &[Step], x: f64) {
    let Some((step, rest)) = steps.split_first() else {
        *value = serde_json::json!(x);
        return;
    };
    match (step, value) {
        (Step::Key(key), Value::Object(map)) => match map.get_mut(key) {
            Some(inner) => assign(inner, rest, x),
            // A number left to its default (resolve checked it has one) is written in.
            None if rest.is_empty() => {
                map.insert(key.clone(), serde_json::json!(x));
            }
            None => {}
        },
        (Step::Index(i), Value::Array(items)) => {
            if let Some(inner) = items.get_mut(*i) {
                assign(inner, rest, x);
            }
        }
        (Step::Every, Value::Array(items)) => items.iter_mut().for_each(|inner| assign(inner, rest, x)),
        _ => {}
    }
}

/// Whether two paths can name one place.
fn overlaps(a: &[Step], b: &[Step]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| match (x, y) {
            (Step::Every, Step::Index(_) | Step::Every) | (Step::Index(_), Step::Every) => true,
            _ => x == y,
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn document() -> SceneDocument {
        SceneDocument {
            value: serde_json::json!({
                "hinges": [{"target_angle_deg": 90, "layers": [{"thickness_um": 0.2}]},
                           {"target_angle_deg": 90, "layers": [{"thickness_um": 0.1}]}],
                "environment": {"drag_coefficient": 1.28, "drag": true}
            }),
            source: "s.scene.json".into(),
            fallback_name: "s".into(),
            base: ".".into(),
        }
    }

    fn free(path: &str, lower: f64, upper: f64) -> FreeParameter {
        FreeParameter {
            path: path.into(),
            lower,
            upper,
        }
    }

    #[test]
    fn resolves_sets_and_ties() {
        let doc = document();
        let parameters = resolve(
            &doc,
            &[
                free("hinges[*].target_angle_deg", 45.0, 120.0),
                free("hinges[1].layers[0].thickness_um", 0.05, 0.3),
            ],
        )
        .unwrap();
        assert_eq!((parameters[0].start, parameters[1].start), (90.0, 0.1));
        let changed = with_values(&doc, &parameters, &[80.0, 0.15]);
        assert_eq!(changed.value["hinges"][0]["target_angle_deg"], 80.0);
        assert_eq!(changed.value["hinges"][1]["target_angle_deg"], 80.0);
        assert_eq!(changed.value["hinges"][1]["layers"][0]["thickness_um"], 0.15);
        assert_eq!(changed.value["hinges"][0]["layers"][0]["thickness_um"], 0.2);
        // The dotted spelling names the same places.
        let dotted = resolve(&doc, &[free("hinges.1.layers.0.thickness_um", 0.05, 0.3)]).unwrap();
        assert_eq!(dotted[0].start, 0.1);
        assert_eq!(
            FreeParameter::parse("environment.drag_coefficient=0.5:4").unwrap(),
            free("environment.drag_coefficient", 0.5, 4.0)
        );
    }

    #[test]
    fn a_number_left_to_its_default_is_fitted_from_it_and_written_in() {
        let doc = document();
        let parameters = resolve(
            &doc,
            &[
                free("environment.air_density_kg_m3", 0.5, 3.0),
                free("hinges[*].stiffness_scale", 0.1, 10.0),
            ],
        )
        .unwrap();
        assert_eq!((parameters[0].start, parameters[1].start), (1.2, 1.0));
        let changed = with_values(&doc, &parameters, &[1.1, 2.0]);
        assert_eq!(changed.value["environment"]["air_density_kg_m3"], 1.1);
        assert_eq!(changed.value["hinges"][0]["stiffness_scale"], 2.0);
        assert_eq!(changed.value["hinges"][1]["stiffness_scale"], 2.0);
        // A key without a default is still refused, and so is one under a missing object.
        assert!(resolve(&doc, &[free("environment.viscosity", 0.5, 3.0)]).is_err());
        assert!(resolve(&doc, &[free("hinge_defaults.stiffness_scale", 0.5, 3.0)]).is_err());
    }

    #[test]
    fn refuses_by_name() {
        let doc = document();
        let error = |list: &[FreeParameter]| resolve(&doc, list).unwrap_err().to_string();
        assert!(error(&[free("environment.drag_coeficient", 0.5, 4.0)]).contains("no key `drag_coeficient`"));
        assert!(error(&[free("environment.drag_coefficient", 2.0, 4.0)]).contains("exclude the scene's value 1.28"));
        assert!(error(&[free("environment.drag", 0.0, 1.0)]).contains("not a number"));
        assert!(error(&[free("hinges[2].target_angle_deg", 0.0, 100.0)]).contains("index [2]"));
        assert!(error(&[free("hinges[*].layers[0].thickness_um", 0.0, 1.0)]).contains("different values"));
        assert!(error(&[free("environment.drag_coefficient", 4.0, 0.5)]).contains("lower < upper"));
        assert!(error(&[
            free("hinges[*].target_angle_deg", 0.0, 100.0),
            free("hinges[0].target_angle_deg", 0.0, 100.0)
        ])
        .contains("already names"));
        assert!(FreeParameter::parse("environment.drag_coefficient=0.5").is_err());
    }
}
