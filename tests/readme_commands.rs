//! Every command README shows (`cargo run --release -- …` in its `sh` blocks) runs and
//! succeeds, in README's order, so a newcomer's first hour matches what README says. The
//! MuJoCo line runs when `scripts/test.sh` has installed the client; examples are left to
//! their own runs (work_precision takes half a minute).

use std::process::Command;

#[test]
fn every_readme_command_succeeds() {
    let readme = std::fs::read_to_string("README.md").unwrap();
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
            .expect("README shows the MuJoCo run");
        let args: Vec<&str> = line.split('#').next().unwrap().split_whitespace().skip(1).collect();
        let out = Command::new(python).args(&args).output().unwrap();
        assert!(out.status.success(), "{line}\n{}", String::from_utf8_lossy(&out.stderr));
    }
}
