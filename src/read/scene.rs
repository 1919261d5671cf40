//! Scene files (`*.scene.json`): a strip (`plates`, `hinges`) or a closed chain (a
//! `pattern` FOLD file whose faces are the plates). The loader parses, names the scene after
//! its file when it has no `name`, and loads the pattern; building the scene
//! ([`SceneSpec::build`]) validates it and runs the closed chain's sweep and fit.

use crate::error::{NanofoldError, Result};
use crate::pattern::LoadOptions;
use crate::read::scene_spec::SceneSpec;
use crate::read::scene_spec::{ClosedSpec, NetworkSpec, StripSpec};
use std::path::Path;

/// A scene's name from its file name: `bridge_step.scene.json` → `bridge_step`.
pub fn scene_name(path: &Path) -> String {
    let stem = path.file_name().and_then(|n| n.to_str()).unwrap_or("scene");
    stem.strip_suffix(".scene.json")
        .or_else(|| stem.strip_suffix(".json"))
        .unwrap_or(stem)
        .to_string()
}

/// A scene file as parsed JSON, before it is read into a description: what a fit edits.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneDocument {
    /// The file's JSON.
    pub value: serde_json::Value,
    /// Where it was read from (names it in errors).
    pub source: String,
    /// The scene's name when the file gives none.
    pub fallback_name: String,
    /// The folder its `pattern` path is relative to.
    pub base: std::path::PathBuf,
}

impl SceneDocument {
    /// Reads a scene file's JSON (strictly, within the scene size limit).
    pub fn load(path: &Path) -> Result<SceneDocument> {
        let text = crate::read::input::read_text(path, crate::read::input::MAX_SCENE_BYTES)?;
        let source = path.display().to_string();
        Ok(SceneDocument {
            value: crate::read::input::parse_json(&text, &source)?,
            fallback_name: scene_name(path),
            base: path.parent().unwrap_or(Path::new(".")).to_path_buf(),
            source,
        })
    }

    /// The description this JSON reads as (its pattern loaded).
    pub fn spec(&self) -> Result<SceneSpec> {
        scene_from_value(&self.value, &self.source, &self.fallback_name, &self.base)
    }

    /// The same document with other JSON (a fit's parameters set).
    pub fn with_value(&self, value: serde_json::Value) -> SceneDocument {
        SceneDocument { value, ..self.clone() }
    }
}

/// Loads a scene file; a closed chain's `pattern` is read relative to the scene's folder.
/// Building the scene ([`SceneSpec::build`]) validates it.
///
/// ```
/// use nanofold::prelude::*;
/// let spec = load_scene("patterns/bridge_step.scene.json".as_ref())?;
/// let scene = spec.build()?;
/// assert_eq!(scene.name, "bridge_step");
/// assert_eq!(scene.strip().unwrap().model.dof(), 4);
/// # Ok::<(), NanofoldError>(())
/// ```
pub fn load_scene(path: &Path) -> Result<SceneSpec> {
    let text = crate::read::input::read_text(path, crate::read::input::MAX_SCENE_BYTES)?;
    let base = path.parent().unwrap_or(Path::new("."));
    parse_scene(&text, &path.display().to_string(), &scene_name(path), base)
}

/// Parses scene text; `source` names it in errors, `fallback_name` names the scene when it
/// has no `name`, `base` is the folder a closed chain's pattern path is relative to.
pub fn parse_scene(text: &str, source: &str, fallback_name: &str, base: &Path) -> Result<SceneSpec> {
    scene_from_value(
        &crate::read::input::parse_json(text, source)?,
        source,
        fallback_name,
        base,
    )
}

/// A scene description from parsed JSON (as [`parse_scene`] reads it): a fit changes
/// numbers in the JSON and rebuilds the scene from it.
pub fn scene_from_value(
    value: &serde_json::Value,
    source: &str,
    fallback_name: &str,
    base: &Path,
) -> Result<SceneSpec> {
    if crate::read::is_fold_object(value) || value.get("sector_angles").is_some() {
        return Err(NanofoldError::invalid(
            source,
            "a pattern file",
            "this is a crease pattern, not a scene: unfold it with `unfold`, or name it as a scene's `pattern`",
        ));
    }
    let closed = value.get("pattern").is_some() && value.get("cut_crease").is_some();
    let network = value.get("pattern").is_some() && !closed;
    let mut spec = if network {
        let file: NetworkSpec<String> = crate::read::input::from_value(value)?;
        let loaded = file.with_pattern(|path| {
            let resolved = base.join(&path);
            crate::read::load_crease_pattern(&resolved).map_err(|e| {
                NanofoldError::invalid(
                    "pattern",
                    format!("\"{path}\" ({})", resolved.display()),
                    full_message(&e),
                )
            })
        })?;
        SceneSpec::Network(Box::new(loaded))
    } else if closed {
        let file: ClosedSpec<String> = crate::read::input::from_value(value)?;
        let loaded = file.with_pattern(|path| {
            let resolved = base.join(&path);
            crate::read::load_pattern(&resolved, &LoadOptions::default()).map_err(|e| {
                NanofoldError::invalid(
                    "pattern",
                    format!("\"{path}\" ({})", resolved.display()),
                    full_message(&e),
                )
            })
        })?;
        SceneSpec::Closed(Box::new(loaded))
    } else {
        let file: StripSpec = crate::read::input::from_value(value)?;
        SceneSpec::Strip(file)
    };
    match &mut spec {
        SceneSpec::Strip(s) => {
            s.name.get_or_insert_with(|| fallback_name.to_string());
        }
        SceneSpec::Closed(s) => {
            s.name.get_or_insert_with(|| fallback_name.to_string());
        }
        SceneSpec::Network(s) => {
            s.name.get_or_insert_with(|| fallback_name.to_string());
        }
    }
    Ok(spec)
}

/// An error and its sources, joined.
fn full_message(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(s) = source {
        text += &format!(": {s}");
        source = s.source();
    }
    text
}
