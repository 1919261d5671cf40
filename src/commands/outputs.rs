//! Where a command's files go and how they are written, for the front ends: the names of
//! inputs, the default output folder, and writing a command's files as one set (atomically,
//! never over another input's results unless asked).

use std::path::{Path, PathBuf};

pub use crate::read::scene::scene_name;
pub use crate::read::{is_pattern_file, pattern_name};
pub use crate::write::folder::{folder_name, write_folder_of};
pub use crate::write::output::write_atomic;

/// The folder a command writes for an input named `name` (its title) read from `file`:
/// `output/<name>/`, the file's own name where the title cannot name a folder.
pub fn default_output_folder(name: &str, file: &Path) -> PathBuf {
    let file_name = if is_pattern_file(file) {
        pattern_name(file)
    } else {
        scene_name(file)
    };
    PathBuf::from("output").join(folder_name(name, &file_name))
}
