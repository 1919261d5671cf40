//! Output folders written as one: every file of a run goes into a fresh temporary folder
//! beside the target, which then replaces the target by renames. A failed write (a full
//! disk, a killed process) leaves the previous folder as it was and no partial set; two runs
//! into one folder never mix their files (the last to finish wins). Files another command
//! wrote there (`unfold`'s beside `constraints`') are carried over; a folder holding files
//! nanofold did not write is never replaced.

use crate::error::{NanofoldError, Result};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// File names nanofold writes into an output folder; a folder holding anything else is
/// someone else's and is refused.
pub const OUTPUT_FILES: &[&str] = &[
    "trajectory.json",
    "unfold.svg",
    "unfold.fold",
    "fold.fold",
    "folded.fold",
    "fold.svg",
    "fold.html",
    "view.html",
    "unfold.html",
    "response.html",
    "modes.html",
    "constraints.json",
    "constraints.svg",
    "constraints.xml",
    "response.json",
    "response.svg",
    "snapshots.svg",
    "motion.fold",
    "modes.fold",
    "fit.json",
    "fit.csv",
    "fitted.scene.json",
    "fit.svg",
    "nets.json",
    "nets.csv",
    "gallery.svg",
    OWNER_FILE,
];

/// A file of one `nets` run: `net_<rank>.fold` or `net_<rank>.scene.json` (the rank in
/// digits), closing.html, jam.html.
/// They are not in [`OUTPUT_FILES`]: a run never keeps another run's nets.
fn is_net_file(name: &str) -> bool {
    // The study's pages show one run's nets: another run's would mislead.
    if matches!(name, "closing.html" | "jam.html") {
        return true;
    }
    name.strip_prefix("net_")
        .and_then(|rest| rest.strip_suffix(".fold").or_else(|| rest.strip_suffix(".scene.json")))
        .is_some_and(|rank| !rank.is_empty() && rank.bytes().all(|b| b.is_ascii_digit()))
}

/// The file in every output folder that names the input its results are of.
pub const OWNER_FILE: &str = "nanofold.json";

/// Marks temporary and retired folders beside the target: `.{name}.nanofold-{kind}-{pid}-{n}`.
const MARK: &str = ".nanofold-";

static NONCE: AtomicUsize = AtomicUsize::new(0);

fn output_error(path: &Path, source: std::io::Error) -> NanofoldError {
    NanofoldError::Output {
        path: path.display().to_string(),
        source,
    }
}

/// Whether process `pid` is running (Linux's /proc; elsewhere assumed running).
fn running(pid: u32) -> bool {
    let proc = Path::new("/proc");
    !proc.is_dir() || proc.join(pid.to_string()).exists()
}

/// Removes temporary folders of `name` left by runs that were killed mid-write.
fn remove_orphans(parent: &Path, name: &str) {
    let prefix = format!(".{name}{MARK}");
    let Ok(entries) = std::fs::read_dir(parent) else { return };
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let Some(rest) = file_name.to_str().and_then(|n| n.strip_prefix(&prefix)) else {
            continue;
        };
        // rest = "{kind}-{pid}-{n}"
        let pid = rest.split('-').nth(1).and_then(|p| p.parse::<u32>().ok());
        if pid.is_some_and(|pid| pid != std::process::id() && !running(pid)) {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

/// Refuses a target that exists and holds files nanofold did not write.
fn check_target(dir: &Path) -> Result<()> {
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotADirectory => {
            return Err(NanofoldError::invalid(
                dir.display().to_string(),
                "a file",
                "the output folder's path names a file: choose another output folder",
            ))
        }
        Err(e) => return Err(output_error(dir, e)),
    };
    let foreign: Vec<String> = entries
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| !OUTPUT_FILES.contains(&n.as_str()) && !is_net_file(n))
        .take(5)
        .collect();
    if !foreign.is_empty() {
        return Err(NanofoldError::invalid(
            dir.display().to_string(),
            format!("holds {}", foreign.join(", ")),
            "an output folder is replaced as a whole, and this one holds files nanofold did not write: choose another output folder",
        ));
    }
    Ok(())
}

/// Writes `files` into `temporary`, then links (or copies) in the other nanofold files of
/// `dir` that this run does not replace.
fn fill(temporary: &Path, dir: &Path, files: &[(&str, &[u8])]) -> std::result::Result<(), (PathBuf, std::io::Error)> {
    for (file, contents) in files {
        std::fs::write(temporary.join(file), contents).map_err(|e| (dir.join(file), e))?;
    }
    for kept in OUTPUT_FILES
        .iter()
        .filter(|name| !files.iter().any(|(f, _)| f == *name))
    {
        let old = dir.join(kept);
        if old.is_file() && std::fs::hard_link(&old, temporary.join(kept)).is_err() {
            std::fs::copy(&old, temporary.join(kept)).map_err(|e| (old.clone(), e))?;
        }
    }
    Ok(())
}

/// `write_folder` for the results of `input`: the folder also gets `OWNER_FILE` naming
/// the input (its canonical path), and a folder that holds another input's results is
/// refused unless `replace_other` (the command line's `--force`).
pub fn write_folder_of(dir: &Path, input: &Path, replace_other: bool, files: &[(&str, &[u8])]) -> Result<()> {
    let input = std::fs::canonicalize(input).unwrap_or_else(|_| input.to_path_buf());
    let shown = input.display().to_string();
    if let Some(other) = owner(dir) {
        if other != shown && !replace_other {
            return Err(NanofoldError::invalid(
                dir.display().to_string(),
                format!("holds the results of {other}"),
                format!("this run is of {shown}: give another output folder (--out DIR), or --force to replace them"),
            ));
        }
    }
    let marker = serde_json::json!({
        "input": shown,
        "written_by": format!("nanofold {}", env!("CARGO_PKG_VERSION")),
    })
    .to_string();
    let mut all: Vec<(&str, &[u8])> = files.to_vec();
    all.push((OWNER_FILE, marker.as_bytes()));
    write_folder(dir, &all)
}

/// The input an output folder's results are of, as its [`OWNER_FILE`] names it.
pub fn owner(dir: &Path) -> Option<String> {
    let text = std::fs::read_to_string(dir.join(OWNER_FILE)).ok()?;
    let value: serde_json::Value = serde_json::from_str(&text).ok()?;
    value.get("input")?.as_str().map(str::to_string)
}

/// Writes `files` (name, contents) into `dir` atomically: afterwards `dir` holds exactly
/// these files plus the other nanofold output files it held before.
pub fn write_folder(dir: &Path, files: &[(&str, &[u8])]) -> Result<()> {
    let name = dir
        .file_name()
        .and_then(|n| n.to_str())
        .filter(|n| !n.is_empty() && *n != "." && *n != "..")
        .ok_or_else(|| {
            NanofoldError::invalid(
                dir.display().to_string(),
                "no folder name",
                "the output folder must end in a folder name",
            )
        })?
        .to_string();
    let parent = dir
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
        .to_path_buf();
    std::fs::create_dir_all(&parent).map_err(|e| output_error(&parent, e))?;
    remove_orphans(&parent, &name);
    check_target(dir)?;
    let sibling = |kind: &str| -> PathBuf {
        let n = NONCE.fetch_add(1, Ordering::Relaxed);
        parent.join(format!(".{name}{MARK}{kind}-{}-{n}", std::process::id()))
    };
    let temporary = sibling("tmp");
    std::fs::create_dir(&temporary).map_err(|e| output_error(&temporary, e))?;
    let filled = fill(&temporary, dir, files);
    if let Err((path, e)) = filled {
        let _ = std::fs::remove_dir_all(&temporary);
        return Err(output_error(&path, e));
    }
    // Swap in: the target may be absent, present, or replaced by a concurrent run between
    // the steps; retry a few times, never leaving a mix.
    let mut last_error = None;
    for _ in 0..8 {
        match std::fs::rename(&temporary, dir) {
            Ok(()) => return Ok(()),
            Err(e) => last_error = Some(e),
        }
        // The target exists: retire it, then try again.
        let retired = sibling("old");
        match std::fs::rename(dir, &retired) {
            Ok(()) => {
                let moved_in = std::fs::rename(&temporary, dir);
                let _ = std::fs::remove_dir_all(&retired);
                match moved_in {
                    Ok(()) => return Ok(()),
                    Err(e) => last_error = Some(e),
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
            Err(e) => {
                last_error = Some(e);
                break;
            }
        }
    }
    let _ = std::fs::remove_dir_all(&temporary);
    Err(output_error(
        dir,
        last_error.unwrap_or_else(|| std::io::Error::other("could not replace the folder")),
    ))
}

/// A safe output-folder name from a pattern's or scene's name: one path component, no
/// separators, not `.` or `..`, not empty, not hidden; anything else falls back on
/// `fallback` (the file's own name).
pub fn folder_name(name: &str, fallback: &str) -> String {
    let safe = |n: &str| {
        !n.is_empty()
            && n.len() <= 128
            && !n.starts_with('.')
            && n.chars()
                .all(|c| c.is_alphanumeric() || matches!(c, '_' | '-' | '+' | ' ' | '(' | ')' | ','))
    };
    if safe(name) {
        name.to_string()
    } else if safe(fallback) {
        fallback.to_string()
    } else {
        "output".to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(label: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("nanofold-folder-{label}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn a_folder_is_replaced_whole_and_foreign_folders_are_refused() {
        let root = scratch("whole");
        let dir = root.join("run");
        write_folder(&dir, &[("response.json", b"1"), ("response.svg", b"a")]).unwrap();
        write_folder(&dir, &[("response.json", b"2"), ("response.svg", b"b")]).unwrap();
        write_folder(&dir, &[("constraints.json", b"c")]).unwrap();
        let mut names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, ["constraints.json", "response.json", "response.svg"]);
        assert_eq!(std::fs::read(dir.join("response.json")).unwrap(), b"2");
        assert_eq!(std::fs::read(dir.join("response.svg")).unwrap(), b"b");
        // Nothing left beside it.
        assert_eq!(std::fs::read_dir(&root).unwrap().count(), 1);
        std::fs::write(dir.join("notes.txt"), b"mine").unwrap();
        let error = write_folder(&dir, &[("response.json", b"3")]).unwrap_err().to_string();
        assert!(error.contains("notes.txt"), "{error}");
        assert_eq!(std::fs::read(dir.join("notes.txt")).unwrap(), b"mine");
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn a_failed_write_leaves_the_previous_folder_and_no_temporary() {
        let root = scratch("failed");
        let dir = root.join("run");
        write_folder(&dir, &[("response.json", b"old")]).unwrap();
        // A file name that cannot be created (a path into a missing folder) fails mid-set.
        let error = write_folder(&dir, &[("response.json", b"new"), ("missing/x.svg", b"x")]);
        assert!(error.is_err());
        assert_eq!(std::fs::read(dir.join("response.json")).unwrap(), b"old");
        assert_eq!(
            std::fs::read_dir(&root).unwrap().count(),
            1,
            "a temporary folder was left"
        );
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn concurrent_runs_never_mix_their_files() {
        let root = scratch("concurrent");
        let dir = root.join("run");
        std::thread::scope(|scope| {
            for writer in 0..4u8 {
                let dir = &dir;
                scope.spawn(move || {
                    for _ in 0..25 {
                        let tag = [b'0' + writer];
                        // A write may lose a race for the rename; it must then fail cleanly.
                        let _ = write_folder(dir, &[("response.json", &tag), ("response.svg", &tag)]);
                    }
                });
            }
        });
        let json = std::fs::read(dir.join("response.json")).unwrap();
        let svg = std::fs::read(dir.join("response.svg")).unwrap();
        assert_eq!(json, svg, "files of two runs mixed");
        assert_eq!(std::fs::read_dir(&root).unwrap().count(), 1, "temporaries left");
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn an_orphan_of_a_killed_run_is_removed() {
        let root = scratch("orphan");
        std::fs::create_dir_all(&root).unwrap();
        // A process id that is not running (pid_max is far below it).
        let orphan = root.join(format!(".run{MARK}tmp-4194304999-0"));
        std::fs::create_dir(&orphan).unwrap();
        write_folder(&root.join("run"), &[("response.json", b"1")]).unwrap();
        assert!(!orphan.exists());
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn names_that_would_leave_the_output_folder_fall_back() {
        for bad in ["/abs/path", "../..", "..", "", ".", "a/b", ".hidden", "a\\\\b"] {
            assert_eq!(folder_name(bad, "file_stem"), "file_stem", "{bad:?}");
        }
        assert_eq!(folder_name("corner_cube", "x"), "corner_cube");
        assert_eq!(folder_name("..", ".."), "output");
    }
}
