//! The 3D page of a FOLD file behind the door (`view`): an animation's frames, a 3D folded
//! form, or a crease pattern at the state it carries.

use crate::error::Result;
use crate::folding::FoldingModel;
use serde_json::Value;
use std::path::Path;

/// Largest FOLD file `view` reads, bytes (an animation repeats its mesh in every frame).
pub const MAX_VIEW_BYTES: u64 = 128 << 20;

/// The page (view.html) of the FOLD file at `path`: its own frames when it has 3D ones with
/// faces, else its crease pattern folded to the angles it carries.
pub fn view_page(path: &Path) -> Result<String> {
    let origin = path.display().to_string();
    let text = crate::read::input::read_text(path, MAX_VIEW_BYTES)?;
    let value = crate::read::input::parse_json(&text, &origin)?;
    let name = crate::read::pattern_name(path);
    let three_d = |frame: &Value| {
        frame["vertices_coords"].as_array().is_some_and(|v| {
            v.iter()
                .any(|p| p.as_array().is_some_and(|p| p.len() == 3 && p[2].as_f64() != Some(0.0)))
        })
    };
    let has_3d = three_d(&value) || value["file_frames"].as_array().is_some_and(|f| f.iter().any(three_d));
    if has_3d && value.get("faces_vertices").is_some() {
        return crate::plot::page::page_of_fold(&value, &name, &[], None);
    }
    let model = FoldingModel::new(crate::read::crease_pattern_of_value(&value, &name, &origin)?)?;
    let state = model.given_fold_angles();
    crate::plot::page::page_of_states(
        &model,
        &model.pattern.name,
        &[("as read".to_string(), state.as_slice())],
    )
}
