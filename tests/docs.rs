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
