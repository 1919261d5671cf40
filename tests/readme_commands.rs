//! Every command README and the user guide show (`cargo run --release -- …` in their `sh`
//! blocks) runs and succeeds, README first, then the guide's chapters in the order of its
//! index, so a newcomer's first hour matches what they say. The MuJoCo line runs when
//! `scripts/test.sh` has installed the client; examples are left to their own runs
//! (work_precision takes half a minute).

use std::process::Command;

/// README, then every chapter the guide's index links to, in its order.
fn documents() -> Vec<(String, String)> {
    let index = std::fs::read_to_string("docs/guide/README.md").unwrap();
    let mut names = vec!["README.md".to_string()];
    for (at, _) in index.match_indices("](") {
        let target: String = index[at + 2..].chars().take_while(|c| *c != ')').collect();
        let file = format!("docs/guide/{target}");
        if !target.contains('/') && target.ends_with(".md") && !names.contains(&file) {
            names.push(file);
        }
    }
    names
        .into_iter()
        .map(|name| {
            let text = std::fs::read_to_string(&name).unwrap_or_else(|e| panic!("{name}: {e}"));
            (name, text)
        })
        .collect()
}

#[test]
fn the_guide_index_names_every_chapter() {
    let listed: Vec<String> = documents().into_iter().skip(1).map(|(name, _)| name).collect();
    for entry in std::fs::read_dir("docs/guide").unwrap() {
        let path = entry.unwrap().path().display().to_string();
        if path.ends_with(".md") && !path.ends_with("README.md") {
            assert!(listed.contains(&path), "{path} is not in the guide's index: {listed:?}");
        }
    }
    assert!(listed.len() >= 10, "{listed:?}");
}

#[test]
fn every_readme_command_succeeds() {
    let documents = documents();
    let readme: String = documents
        .iter()
        .map(|(_, text)| text.as_str())
        .collect::<Vec<_>>()
        .join("\n");
    let mut commands = Vec::new();
    for block in readme.split("```sh\n").skip(1) {
        let block = block.split("```").next().unwrap();
        for line in block.lines() {
            let line = line.split('#').next().unwrap().trim();
            if let Some(args) = line.strip_prefix("cargo run --release -- ") {
                commands.push((
                    line.to_string(),
                    args.split_whitespace().map(String::from).collect::<Vec<_>>(),
                ));
            }
        }
    }
    assert!(commands.len() >= 15, "found {} commands", commands.len());
    for (line, args) in &commands {
        let out = Command::new(env!("CARGO_BIN_EXE_nanofold"))
            .args(args)
            .output()
            .unwrap();
        assert!(out.status.success(), "{line}\n{}", String::from_utf8_lossy(&out.stderr));
    }
    // The MuJoCo client line, with the client the test script installed.
    if let Some(python) = std::env::var_os("NANOFOLD_PYTHON") {
        let line = readme
            .lines()
            .find(|l| l.trim_start().starts_with("target/clients-venv/bin/python"))
            .expect("the guide shows the MuJoCo run");
        let args: Vec<&str> = line.split('#').next().unwrap().split_whitespace().skip(1).collect();
        let out = Command::new(python).args(&args).output().unwrap();
        assert!(out.status.success(), "{line}\n{}", String::from_utf8_lossy(&out.stderr));
    }
}
