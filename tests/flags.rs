//! Every option of every command, handed the numbers a careless user or script hands it.
//!
//! The walk reads the command line's own definition (clap's), so a command or an option
//! added later is walked too, and an option that takes text with numbers inside (`J=DEG`,
//! `A:B`, a shape's sides) must say here how to put a number into it, or the test fails.
//! Each numeric slot gets NaN, ±inf, −1, 0 and 1e308, alone and in the combinations the
//! guides name. The answer must be a clean refusal naming the option, or a valid run:
//! never a panic, a run past 10 s, a null in exit-0 JSON, or NaN or inf taken silently.

#[allow(dead_code, unused_imports)]
#[path = "../src/cli.rs"]
mod cli;
mod common;

use clap::CommandFactory;
use std::any::TypeId;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The values every numeric slot is handed.
const BAD: [&str; 6] = ["NaN", "inf", "-inf", "-1", "0", "1e308"];

/// The longest a run may take, s: a hang past it is a failure.
const TIME_LIMIT: Duration = Duration::from_secs(10);

/// Options whose value may be negative (a signed angle or a direction); every other
/// numeric option must refuse −1 as a negative size, count or tolerance.
const SIGNED: [&str; 6] = [
    "constraints --lock",
    "constraints --range",
    "constraints --check",
    "fold --drive",
    "generate miura --fold-deg",
    "nets --front-deg",
];

/// A cheap valid run of each command (`{out}` is a fresh folder of the test's): the options
/// are added to it, replacing the run's own value of the same option.
fn bases(command: &str) -> Vec<Vec<&'static str>> {
    let single = "patterns/waterbomb.fold";
    let sheet = "patterns/many/miura_4x4_folded.fold";
    match command {
        "unfold" => vec![
            vec!["unfold", single, "--json", "--out", "{out}"],
            vec!["unfold", sheet, "--json", "--out", "{out}"],
        ],
        "check" => vec![vec!["check", single, "--json"], vec!["check", sheet, "--json"]],
        "fold" => vec![vec![
            "fold",
            "patterns/many/miura_4x4.fold",
            "--to",
            "50",
            "--frames",
            "3",
            "--json",
            "--out",
            "{out}",
        ]],
        "view" => vec![vec!["view", sheet, "--out", "{out}"]],
        "generate miura" => vec![vec!["generate", "miura", "--out", "{out}/miura.fold"]],
        "generate square-twist" => vec![vec!["generate", "square-twist", "--out", "{out}/twist.fold"]],
        "generate waterbomb" => vec![vec!["generate", "waterbomb", "--out", "{out}/waterbomb.fold"]],
        "generate bird-base" => vec![vec!["generate", "bird-base", "--out", "{out}/bird.fold"]],
        "constraints" => vec![
            vec![
                "constraints",
                sheet,
                "--drive",
                "4",
                "--samples",
                "21",
                "--json",
                "--out",
                "{out}",
            ],
            vec![
                "constraints",
                "patterns/degree4_generic.fold",
                "--drive",
                "0",
                "--json",
                "--out",
                "{out}",
            ],
            // Three degrees of freedom: the driver and two held creases leave one.
            vec![
                "constraints",
                "patterns/degree6_asymmetric.fold",
                "--drive",
                "0",
                "--lock",
                "2=-60",
                "--lock",
                "3=-82.24906982434894",
                "--range",
                "70:80",
                "--json",
                "--out",
                "{out}",
            ],
        ],
        "simulate" => vec![
            vec![
                "simulate",
                "patterns/bridge_step.scene.json",
                "--json",
                "--out",
                "{out}",
            ],
            vec![
                "simulate",
                "patterns/bridge_ramp.scene.json",
                "--json",
                "--out",
                "{out}",
            ],
        ],
        "fit" => vec![vec![
            "fit",
            "patterns/bridge_step.scene.json",
            "patterns/measurements/bridge_step_measured.csv",
            "--free",
            "environment.drag_coefficient=0.2:5",
            "--max-iterations",
            "3",
            "--json",
            "--out",
            "{out}",
        ]],
        "nets" => vec![vec![
            "nets",
            "tetrahedron",
            "--simulate",
            "1",
            "--fronts",
            "2",
            "--yield-samples",
            "2",
            "--top",
            "1",
            "--json",
            "--out",
            "{out}",
        ]],
        "export mujoco" => vec![vec![
            "export",
            "mujoco",
            "patterns/bridge_step.scene.json",
            "--out",
            "{out}/bridge.xml",
        ]],
        "modes" => vec![vec![
            "modes",
            "patterns/bridge_step.scene.json",
            "--json",
            "--out",
            "{out}",
        ]],
        other => panic!("no valid run of `{other}` to walk its options on: add one to bases()"),
    }
}

/// Options that act only beside others (as the guides use them): each is walked alone and
/// with these (an option and its value, or a switch).
fn contexts(option: &str) -> Vec<Vec<(&'static str, Option<&'static str>)>> {
    match option {
        "constraints --tol" => vec![vec![("--degree", Some("auto"))]],
        "unfold --p" | "check --p" => vec![vec![], vec![("--energy", Some("non-separable"))]],
        "unfold --bending-metric" | "check --bending-metric" | "unfold --closure-tol" | "check --closure-tol" => {
            vec![vec![], vec![("--project", None)]]
        }
        "fold --max-step" => vec![vec![], vec![("--drive", Some("4=60"))]],
        "nets --front-deg" | "nets --etch-rate-um-per-min" => vec![vec![], vec![("--fronts", Some("1"))]],
        _ => vec![vec![]],
    }
}

/// How a number goes into an option whose value is text: each template's `{}` takes the
/// value. A text option missing here fails the walk.
fn templates(option: &str) -> Option<Vec<&'static str>> {
    Some(match option {
        "fold --drive" => vec!["4={}"],
        "constraints --lock" => vec!["5={}"],
        "constraints --check" => vec!["1={},0.5"],
        "constraints --degree" => vec!["{}"],
        "constraints --range" => vec!["{}:20", "0:{}"],
        "fit --free" => vec![
            "environment.drag_coefficient={}:5",
            "environment.drag_coefficient=0.2:{}",
        ],
        "fit --noise" => vec!["{}", "hinge_0_deg={}"],
        "nets SHAPE" => vec![
            "box:{}x2x3",
            "box:1x2x{}",
            "prism:{}",
            "prism:6:{}",
            "antiprism:5:{}",
            "pyramid:4:{}",
            "polycube:{},0,0;1,0,0",
        ],
        _ => return None,
    })
}

/// Options that are paths or names, not numbers (checked so that a new text option must be
/// placed on one side or the other).
fn is_text(option: &str) -> bool {
    option.ends_with(" --out")
        || matches!(
            option,
            "unfold PATTERNS" | "check PATTERNS" | "fold PATTERN" | "view FILE" | "constraints PATTERN"
        )
}

/// One run of the walk.
#[derive(Debug, Clone)]
struct Case {
    /// `command --option` (or `command POSITIONAL`).
    option: String,
    /// What the option is named by in a refusal.
    named: String,
    /// The value put in.
    value: String,
    args: Vec<String>,
    /// Whether −1 is a valid value of this option.
    signed: bool,
}

/// The number types an option may parse to.
const NUMBERS: [fn() -> TypeId; 7] = [
    TypeId::of::<f64>,
    TypeId::of::<f32>,
    TypeId::of::<usize>,
    TypeId::of::<u64>,
    TypeId::of::<u32>,
    TypeId::of::<i64>,
    TypeId::of::<i32>,
];

fn numeric(type_id: TypeId) -> bool {
    NUMBERS.iter().any(|t| t() == type_id)
}

/// The type an option's value parser gives (clap's AnyValueId compares with a TypeId).
fn value_type(arg: &clap::Arg) -> TypeId {
    let id = arg.get_value_parser().type_id();
    NUMBERS
        .iter()
        .map(|t| t())
        .chain([TypeId::of::<String>(), TypeId::of::<PathBuf>()])
        .find(|&t| id == t)
        .unwrap_or(TypeId::of::<()>())
}

/// `args` with `flag` removed, and the value after it when it takes one.
fn without(args: &[String], flag: &str, takes_value: bool) -> Vec<String> {
    let mut kept = Vec::new();
    let mut skip = false;
    for a in args {
        if skip {
            skip = false;
        } else if a == flag {
            skip = takes_value;
        } else {
            kept.push(a.clone());
        }
    }
    kept
}

/// Every case of the walk: each leaf command's options, by clap's definition.
fn cases() -> Vec<Case> {
    fn leaves(command: &clap::Command, path: Vec<String>, out: &mut Vec<(String, clap::Command)>) {
        let subcommands: Vec<_> = command.get_subcommands().filter(|s| s.get_name() != "help").collect();
        if subcommands.is_empty() {
            out.push((path.join(" "), command.clone()));
        }
        for s in subcommands {
            let mut p = path.clone();
            p.push(s.get_name().to_string());
            leaves(s, p, out);
        }
    }
    let mut commands = Vec::new();
    leaves(&cli::Cli::command(), Vec::new(), &mut commands);
    assert!(commands.len() >= 14, "the walk found {} commands", commands.len());
    let mut cases = Vec::new();
    let mut unplaced = Vec::new();
    for (name, command) in &commands {
        for arg in command.get_arguments() {
            let takes_value = arg.get_action().takes_values();
            if !takes_value || !arg.get_possible_values().is_empty() {
                continue; // a switch, or a choice clap checks against its list
            }
            let (option, flag) = match arg.get_long() {
                Some(long) => (format!("{name} --{long}"), Some(format!("--{long}"))),
                None => (
                    format!(
                        "{name} {}",
                        arg.get_value_names().map_or("?".into(), |v| v[0].to_string())
                    ),
                    None,
                ),
            };
            let t = value_type(arg);
            let slots: Vec<String> = if numeric(t) {
                vec!["{}".to_string()]
            } else if let Some(list) = templates(&option) {
                list.into_iter().map(String::from).collect()
            } else if t == TypeId::of::<PathBuf>() || is_text(&option) {
                continue;
            } else {
                unplaced.push(option.clone());
                continue;
            };
            for base in bases(name) {
                for context in contexts(&option) {
                    for slot in &slots {
                        for bad in BAD {
                            let value = slot.replace("{}", bad);
                            let mut args: Vec<String> = base.iter().map(|s| s.to_string()).collect();
                            // The option's value replaces the run's own (a repeatable one's too:
                            // `fit --free` alone, not beside the run's).
                            if let Some(long) = &flag {
                                args = without(&args, long, true);
                            }
                            for (context_flag, context_value) in &context {
                                args = without(&args, context_flag, context_value.is_some());
                                args.push(context_flag.to_string());
                                args.extend(context_value.map(String::from));
                            }
                            match &flag {
                                Some(long) => {
                                    args.push(long.clone());
                                    args.push(value.clone());
                                }
                                None => {
                                    // The positional in the base's place.
                                    let at = args.iter().position(|a| a == "tetrahedron").expect("a shape");
                                    args[at] = value.clone();
                                }
                            }
                            cases.push(Case {
                                option: option.clone(),
                                // A positional is named by its text in a refusal.
                                named: flag.clone().unwrap_or_else(|| value.clone()),
                                value,
                                args,
                                signed: SIGNED.contains(&option.as_str()),
                            });
                        }
                    }
                }
            }
        }
    }
    assert!(
        unplaced.is_empty(),
        "options that take text are neither templated nor known to be paths: {unplaced:?}"
    );
    cases
}

/// Runs a case; an empty answer is a pass, else what went wrong.
fn run(case: &Case, root: &Path, k: usize) -> Option<String> {
    let out = root.join(format!("case-{k}"));
    let args: Vec<String> = case
        .args
        .iter()
        .map(|a| a.replace("{out}", &out.display().to_string()))
        .collect();
    std::fs::create_dir_all(&out).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_nanofold"))
        .args(&args)
        .arg("--force")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .env("RUST_BACKTRACE", "0")
        .spawn()
        .unwrap();
    // Drain the pipes beside the wait so a large output cannot block the child.
    let drain = |mut pipe: Box<dyn std::io::Read + Send>| {
        std::thread::spawn(move || {
            let mut s = String::new();
            pipe.read_to_string(&mut s).ok();
            s
        })
    };
    let reader = drain(Box::new(child.stdout.take().unwrap()));
    let error_reader = drain(Box::new(child.stderr.take().unwrap()));
    let started = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break Some(status);
        }
        if started.elapsed() > TIME_LIMIT {
            child.kill().ok();
            child.wait().ok();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let (stdout, stderr) = (reader.join().unwrap(), error_reader.join().unwrap());
    std::fs::remove_dir_all(&out).ok();
    let shown = format!("nanofold {}", args.join(" "));
    let Some(status) = status else {
        return Some(format!("{shown}: still running after {TIME_LIMIT:?}"));
    };
    if stderr.contains("panicked") || !matches!(status.code(), Some(0..=2)) {
        return Some(format!(
            "{shown}: {status} {}",
            stderr.lines().take(3).collect::<Vec<_>>().join(" / ")
        ));
    }
    let must_refuse = matches!(case.value_kind(), "nan" | "inf") || (case.value_kind() == "negative" && !case.signed);
    if status.code() == Some(2) {
        if !stderr.contains(&case.named) {
            return Some(format!(
                "{shown}: refused without naming {}: {}",
                case.named,
                stderr.trim()
            ));
        }
        return None;
    }
    if must_refuse {
        return Some(format!(
            "{shown}: exit {status} took {} (NaN, inf or a negative size must be refused)",
            case.value
        ));
    }
    if let Some(json) = stdout
        .lines()
        .next()
        .and_then(|l| serde_json::from_str::<serde_json::Value>(l).ok())
    {
        if let Some(at) = common::null_in(&json, String::new()) {
            return Some(format!("{shown}: exit-0 JSON has null at {at}"));
        }
    }
    None
}

impl Case {
    fn value_kind(&self) -> &'static str {
        let v = self.value.to_ascii_lowercase();
        if v.contains("nan") {
            "nan"
        } else if v.contains("inf") {
            "inf"
        } else if v.contains("-1") && !v.contains("e-1") {
            "negative"
        } else {
            "finite"
        }
    }
}

#[test]
fn every_numeric_option_refuses_nan_inf_and_negative_sizes_by_name_and_never_hangs() {
    let cases = cases();
    let root = std::env::temp_dir().join(format!("nanofold-flags-{}", std::process::id()));
    std::fs::create_dir_all(&root).unwrap();
    let next = Mutex::new(0usize);
    let failures = Mutex::new(Vec::new());
    let workers = std::thread::available_parallelism().map_or(2, |n| n.get()).clamp(2, 8);
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| loop {
                let k = {
                    let mut n = next.lock().unwrap();
                    *n += 1;
                    *n - 1
                };
                let Some(case) = cases.get(k) else { break };
                if let Some(failure) = run(case, &root, k) {
                    failures.lock().unwrap().push(format!("[{}] {failure}", case.option));
                }
            });
        }
    });
    std::fs::remove_dir_all(&root).ok();
    let failures = failures.into_inner().unwrap();
    let options: std::collections::BTreeSet<_> = cases.iter().map(|c| c.option.clone()).collect();
    println!("{} runs over {} options", cases.len(), options.len());
    assert!(
        failures.is_empty(),
        "{} of {} runs failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}
