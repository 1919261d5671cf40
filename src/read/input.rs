//! Reading input files within stated limits: only regular files, at most a stated size,
//! and JSON parsed strictly (a key given twice is an error naming it, not "the last one
//! wins").

use crate::error::{NanofoldError, Result};
use serde::de::{self, DeserializeSeed, MapAccess, SeqAccess, Visitor};
use serde_json::{Map, Value};
use std::fmt;
use std::io::Read;
use std::path::Path;

/// Largest pattern file read, bytes (a single vertex is a few kB; a crease pattern of
/// 20 000 creases about 3 MB).
pub const MAX_PATTERN_BYTES: u64 = 16 << 20;
/// Largest scene file read, bytes.
pub const MAX_SCENE_BYTES: u64 = 1 << 20;

/// The text of a regular file of at most `limit` bytes.
pub fn read_text(path: &Path, limit: u64) -> Result<String> {
    let bytes = read_bytes(path, limit)?;
    String::from_utf8(bytes).map_err(|e| {
        NanofoldError::invalid(
            path.display().to_string(),
            format!("byte {} is not UTF-8", e.utf8_error().valid_up_to()),
            "a text file (UTF-8) was expected",
        )
    })
}

/// The bytes of a regular file of at most `limit` bytes.
pub fn read_bytes(path: &Path, limit: u64) -> Result<Vec<u8>> {
    let io = |source| NanofoldError::Io {
        path: path.display().to_string(),
        source,
    };
    let metadata = std::fs::metadata(path).map_err(io)?;
    if !metadata.is_file() {
        return Err(NanofoldError::invalid(
            path.display().to_string(),
            "not a regular file",
            "give a pattern or scene file (devices, pipes and directories are not read)",
        ));
    }
    if metadata.len() > limit {
        return Err(too_large(path, metadata.len(), limit));
    }
    let file = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::new();
    // The size can change between the check and the read: read at most one byte more.
    file.take(limit + 1).read_to_end(&mut bytes).map_err(io)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(path, bytes.len() as u64, limit));
    }
    Ok(bytes)
}

fn too_large(path: &Path, size: u64, limit: u64) -> NanofoldError {
    NanofoldError::invalid(
        path.display().to_string(),
        format!("{size} bytes"),
        format!("larger than the {limit}-byte limit for this kind of input"),
    )
}

/// Parses JSON text, refusing a key that appears twice in one object; `origin` names the
/// input in errors.
pub fn parse_json(text: &str, origin: &str) -> Result<Value> {
    let mut deserializer = serde_json::Deserializer::from_str(text);
    let value = StrictValue
        .deserialize(&mut deserializer)
        .and_then(|value| deserializer.end().map(|()| value))
        .map_err(|source| NanofoldError::Json {
            path: origin.to_string(),
            source,
        })?;
    Ok(value)
}

/// Deserialises `value` into `T`; a type error names the field by its path in the input
/// (`creases[2].fold_angle`) and shows the value found there.
pub fn from_value<T: serde::de::DeserializeOwned>(value: &Value) -> Result<T> {
    serde_path_to_error::deserialize(value).map_err(|error| {
        let path = error.path().clone();
        let message = error.into_inner().to_string();
        let mut field = path.to_string();
        if field == "." {
            field.clear();
        }
        let join = |parent: &str, key: &str| {
            if parent.is_empty() {
                key.to_string()
            } else {
                format!("{parent}.{key}")
            }
        };
        // serde reports a missing or unknown key at the object that lacks or holds it.
        if let Some(key) = quoted_after(&message, "missing field `") {
            return NanofoldError::missing(join(&field, key));
        }
        if let Some(key) = quoted_after(&message, "unknown field `") {
            let expected = message.split_once(", expected").map_or("", |(_, rest)| rest).trim();
            // Here the path already ends at the key.
            let at = if field == key || field.ends_with(&format!(".{key}")) {
                field.clone()
            } else {
                join(&field, key)
            };
            return NanofoldError::invalid(at, "an unknown key", format!("expected {expected}"));
        }
        let found = lookup(value, &path).map_or_else(String::new, short_json);
        NanofoldError::invalid(
            if field.is_empty() { "(top level)".into() } else { field },
            found,
            message,
        )
    })
}

/// The text between `prefix` and the next backtick of `message`.
fn quoted_after<'m>(message: &'m str, prefix: &str) -> Option<&'m str> {
    let rest = message.strip_prefix(prefix)?;
    rest.split_once('`').map(|(key, _)| key)
}

/// The value at `path` inside `value`, when the path leads to one.
fn lookup<'v>(value: &'v Value, path: &serde_path_to_error::Path) -> Option<&'v Value> {
    use serde_path_to_error::Segment;
    path.iter().try_fold(value, |here, segment| match segment {
        Segment::Seq { index } => here.get(*index),
        Segment::Map { key } => here.get(key.as_str()),
        Segment::Enum { .. } | Segment::Unknown => Some(here),
    })
}

/// A value as compact JSON, cut to 60 characters (by characters, not bytes).
pub fn short_json(value: &Value) -> String {
    let text = value.to_string();
    if text.chars().count() > 60 {
        format!("{}…", text.chars().take(57).collect::<String>())
    } else {
        text
    }
}

/// A `serde_json::Value` deserialiser that errors on duplicate object keys.
struct StrictValue;

impl<'de> DeserializeSeed<'de> for StrictValue {
    type Value = Value;

    fn deserialize<D: de::Deserializer<'de>>(self, deserializer: D) -> std::result::Result<Value, D::Error> {
        deserializer.deserialize_any(StrictVisitor)
    }
}

struct StrictVisitor;

impl<'de> Visitor<'de> for StrictVisitor {
    type Value = Value;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("any JSON value")
    }
    fn visit_bool<E>(self, v: bool) -> std::result::Result<Value, E> {
        Ok(Value::Bool(v))
    }
    fn visit_i64<E>(self, v: i64) -> std::result::Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_u64<E>(self, v: u64) -> std::result::Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_f64<E>(self, v: f64) -> std::result::Result<Value, E> {
        Ok(serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number))
    }
    fn visit_str<E>(self, v: &str) -> std::result::Result<Value, E> {
        Ok(Value::String(v.to_string()))
    }
    fn visit_string<E>(self, v: String) -> std::result::Result<Value, E> {
        Ok(Value::String(v))
    }
    fn visit_unit<E>(self) -> std::result::Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_none<E>(self) -> std::result::Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> std::result::Result<Value, A::Error> {
        let mut items = Vec::new();
        while let Some(item) = seq.next_element_seed(StrictValue)? {
            items.push(item);
        }
        Ok(Value::Array(items))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> std::result::Result<Value, A::Error> {
        let mut object = Map::new();
        while let Some(key) = map.next_key::<String>()? {
            if object.contains_key(&key) {
                return Err(de::Error::custom(format!(
                    "the key `{key}` appears twice in one object"
                )));
            }
            let value = map.next_value_seed(StrictValue)?;
            object.insert(key, value);
        }
        Ok(Value::Object(object))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_key_given_twice_is_refused_by_name() {
        let message =
            crate::error::NanofoldError::to_string(&parse_json(r#"{"a": 1, "b": {"c": 2, "c": 3}}"#, "t").unwrap_err());
        assert!(message.contains("malformed JSON"), "{message}");
        let Err(NanofoldError::Json { source, .. }) = parse_json(r#"{"a": 1, "b": {"c": 2, "c": 3}}"#, "t") else {
            panic!("expected a JSON error")
        };
        assert!(source.to_string().contains("`c` appears twice"), "{source}");
        let value = parse_json(r#"{"a": [1, 2.5, "x", null, true], "b": {"c": -3}}"#, "t").unwrap();
        assert_eq!(value["a"][1], 2.5);
        assert_eq!(value["b"]["c"], -3);
        assert!(parse_json("{} trailing", "t").is_err());
    }

    #[derive(serde::Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Outer {
        inner: Vec<Inner>,
    }
    #[derive(serde::Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Inner {
        angle: f64,
    }

    #[test]
    fn type_errors_name_the_path_and_the_value() {
        let message = |text: &str| {
            from_value::<Outer>(&parse_json(text, "t").unwrap())
                .unwrap_err()
                .to_string()
        };
        let e = message(r#"{"inner": [{"angle": 1}, {"angle": "ten"}]}"#);
        assert!(e.contains("`inner[1].angle`") && e.contains(r#""ten""#), "{e}");
        let e = message(r#"{"inner": [{}]}"#);
        assert!(e.contains("missing key `inner[0].angle`"), "{e}");
        let e = message(r#"{"inner": [], "extra": 1}"#);
        assert!(e.contains("`extra`") && e.contains("inner"), "{e}");
        let long = format!(r#"{{"inner": [{{"angle": "{}"}}]}}"#, "é".repeat(100));
        assert!(message(&long).contains('…'));
    }
}
