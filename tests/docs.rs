//! Every `docs/model.md#anchor` the code, the tests, the examples and the READMEs cite is a
//! heading of docs/model.md (GitHub's anchors: the heading in lower case, spaces to
//! hyphens, punctuation dropped).

use std::collections::BTreeSet;
use std::path::Path;

fn anchors() -> BTreeSet<String> {
    std::fs::read_to_string("docs/model.md")
        .unwrap()
        .lines()
        .filter_map(|line| line.strip_prefix("## ").or_else(|| line.strip_prefix("# ")))
        .map(|heading| {
            heading
                .to_lowercase()
                .chars()
                .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-')
                .map(|c| if c == ' ' { '-' } else { c })
                .collect()
        })
        .collect()
}

fn sources(dir: &Path, out: &mut Vec<(String, String)>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs" || e == "md") {
            out.push((path.display().to_string(), std::fs::read_to_string(&path).unwrap()));
        }
    }
}

#[test]
fn every_cited_model_anchor_exists() {
    let known = anchors();
    assert!(known.contains("projected-gradient") && known.len() > 20, "{known:?}");
    let mut files = Vec::new();
    for dir in ["src", "tests", "examples", "benches"] {
        sources(Path::new(dir), &mut files);
    }
    for readme in ["README.md", "patterns/README.md"] {
        files.push((readme.to_string(), std::fs::read_to_string(readme).unwrap()));
    }
    // The guide and the performance page cite the model relative to their folder.
    for file in documents().into_iter().filter(|f| f.starts_with("docs")) {
        let text = std::fs::read_to_string(&file).unwrap();
        files.push((
            file.display().to_string(),
            text.replace("](../model.md#", "](docs/model.md#")
                .replace("](model.md#", "](docs/model.md#"),
        ));
    }
    let mut cited = 0;
    let mut missing = Vec::new();
    for (file, text) in files.iter().filter(|(file, _)| !file.ends_with("docs.rs")) {
        for (i, _) in text.match_indices("docs/model.md#") {
            let anchor: String = text[i + "docs/model.md#".len()..]
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
                .collect();
            cited += 1;
            if !known.contains(&anchor) {
                missing.push(format!("{file}: #{anchor}"));
            }
        }
    }
    assert!(cited > 30, "only {cited} citations found");
    assert!(
        missing.is_empty(),
        "anchors not in docs/model.md:\n{}",
        missing.join("\n")
    );
}

/// GitHub's anchor of a heading: a link keeps its text, then lower case, punctuation but
/// `-` and `_` dropped, spaces to hyphens.
fn slug(heading: &str) -> String {
    let mut text = String::new();
    let mut rest = heading;
    while let Some(open) = rest.find('[') {
        let Some(close) = rest[open..].find("](").map(|c| open + c) else {
            break;
        };
        let Some(end) = rest[close..].find(')').map(|e| close + e) else {
            break;
        };
        text.push_str(&rest[..open]);
        text.push_str(&rest[open + 1..close]);
        rest = &rest[end + 1..];
    }
    text.push_str(rest);
    text.trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// Every heading's anchor in a Markdown file (code blocks skipped).
fn headings(text: &str) -> BTreeSet<String> {
    let mut in_code = false;
    let mut out = BTreeSet::new();
    for line in text.lines() {
        if line.starts_with("```") {
            in_code = !in_code;
        } else if !in_code && line.starts_with('#') {
            let heading = line.trim_start_matches('#');
            if heading.starts_with(' ') {
                out.insert(slug(heading));
            }
        }
    }
    out
}

/// The documents a reader follows: README, the user guide, the performance and thesis pages,
/// the patterns' README.
fn documents() -> Vec<std::path::PathBuf> {
    let mut files: Vec<std::path::PathBuf> = [
        "README.md",
        "docs/performance.md",
        "docs/thesis.md",
        "patterns/README.md",
    ]
    .iter()
    .map(std::path::PathBuf::from)
    .collect();
    for entry in std::fs::read_dir("docs/guide").unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "md") {
            files.push(path);
        }
    }
    files
}

#[test]
fn every_link_between_the_documents_lands() {
    assert_eq!(
        slug("Constraint curves ([model](docs/model.md#constraint-curves))"),
        "constraint-curves-model"
    );
    assert_eq!(
        slug(" Unfolding a vertex: `unfold` and `check`"),
        "unfolding-a-vertex-unfold-and-check"
    );
    let mut checked = 0;
    let mut broken = Vec::new();
    for file in documents() {
        let text = std::fs::read_to_string(&file).unwrap();
        let mut in_code = false;
        for line in text.lines() {
            if line.starts_with("```") {
                in_code = !in_code;
                continue;
            }
            if in_code {
                continue;
            }
            for (at, _) in line.match_indices("](") {
                let target: String = line[at + 2..].chars().take_while(|c| *c != ')' && *c != ' ').collect();
                if target.contains("://") || target.starts_with("mailto:") {
                    continue;
                }
                checked += 1;
                let (path, anchor) = target.split_once('#').unwrap_or((&target, ""));
                let landing = if path.is_empty() {
                    file.clone()
                } else {
                    file.parent().unwrap().join(path)
                };
                if !landing.exists() {
                    broken.push(format!("{}: {target} (no file {})", file.display(), landing.display()));
                    continue;
                }
                if !anchor.is_empty() && landing.extension().is_some_and(|e| e == "md") {
                    let known = headings(&std::fs::read_to_string(&landing).unwrap());
                    if !known.contains(anchor) {
                        broken.push(format!("{}: {target} (no heading #{anchor})", file.display()));
                    }
                }
            }
        }
    }
    assert!(checked > 100, "only {checked} links found");
    assert!(broken.is_empty(), "links that land nowhere:\n{}", broken.join("\n"));
}
