//! Keyword arguments (a JSON object from Python) into the library's settings, by the
//! library's own field names and units (radians, fractions); every value is then validated
//! by the library. An unknown keyword is refused by name.

use nanofold::commands::{ConstraintSettings, Degree, Generator, Settings};
use nanofold::dynamics::integrate::Method;
use nanofold::dynamics::simulate::{ModelChoice, SimulationSettings};
use nanofold::pattern::generate::{BirdBaseSpec, MiuraSpec, SquareTwistSpec, WaterbombSpec};
use nanofold::pattern::LoadOptions;
use nanofold::unfold::energy::EnergyKind;
use nanofold::unfold::qp::QpMethod;
use nanofold::{NanofoldError, Result};
use serde_json::{Map, Value};

/// Which command's keywords.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Check,
    Unfold,
    Fold,
}

/// The command's settings with the bindings' own `frames` (fold's FOLD animation).
pub struct CommandSettings {
    pub settings: Settings,
    pub frames: usize,
    /// `drive` by FOLD edge index (made columns once the pattern is known).
    pub drive_edges: Vec<(usize, f64)>,
}

fn object<'v>(value: &'v Value, what: &str) -> Result<&'v Map<String, Value>> {
    value
        .as_object()
        .ok_or_else(|| NanofoldError::invalid(what, value.to_string(), "expected keyword arguments (a JSON object)"))
}

fn number(key: &str, value: &Value) -> Result<f64> {
    value
        .as_f64()
        .ok_or_else(|| NanofoldError::invalid(key, value.to_string(), "expected a number"))
}

fn count(key: &str, value: &Value) -> Result<usize> {
    value
        .as_u64()
        .and_then(|v| usize::try_from(v).ok())
        .ok_or_else(|| NanofoldError::invalid(key, value.to_string(), "expected a whole number ≥ 0"))
}

fn text<'v>(key: &str, value: &'v Value) -> Result<&'v str> {
    value
        .as_str()
        .ok_or_else(|| NanofoldError::invalid(key, value.to_string(), "expected a string"))
}

fn unknown(key: &str, value: &Value, known: &[&str]) -> NanofoldError {
    NanofoldError::invalid(
        key,
        value.to_string(),
        format!("not a setting here; known: {}", known.join(", ")),
    )
}

/// `closure_tol`, `angle_sum_tol`.
pub fn load_options(value: &Value) -> Result<LoadOptions> {
    let mut options = LoadOptions::default();
    for (key, v) in object(value, "options")? {
        match key.as_str() {
            "closure_tol" => options.closure_tol = number(key, v)?,
            "angle_sum_tol" => options.angle_sum_tol = number(key, v)?,
            _ => return Err(unknown(key, v, &["closure_tol", "angle_sum_tol"])),
        }
    }
    options.validate()?;
    Ok(options)
}

const UNFOLD_KEYS: &[&str] = &[
    "energy",
    "p",
    "qp",
    "flat_tol",
    "max_iterations",
    "bending_metric",
    "restarts",
    "seed",
];
const FOLD_KEYS: &[&str] = &["to", "drive", "max_step", "max_steps", "frames"];
const CHECK_KEYS: &[&str] = &["closure_tol"];

/// `check`, `unfold` or `fold` keywords.
pub fn command_settings(value: &Value, kind: Kind) -> Result<CommandSettings> {
    let mut settings = Settings::default();
    let mut frames = 11;
    let mut drive_edges = Vec::new();
    let known: &[&str] = match kind {
        Kind::Check => CHECK_KEYS,
        Kind::Unfold => UNFOLD_KEYS,
        Kind::Fold => FOLD_KEYS,
    };
    for (key, v) in object(value, "settings")? {
        if !known.contains(&key.as_str()) {
            return Err(unknown(key, v, known));
        }
        let u = &mut settings.unfold;
        match key.as_str() {
            "energy" => {
                u.energy = match text(key, v)? {
                    "separable" => EnergyKind::Separable,
                    "non_separable" => EnergyKind::NonSeparable,
                    other => {
                        return Err(NanofoldError::invalid(
                            key,
                            other,
                            "expected \"separable\" or \"non_separable\"",
                        ))
                    }
                }
            }
            "p" => u.p = Some(number(key, v)?),
            "qp" => {
                u.qp = match text(key, v)? {
                    "clarabel" => QpMethod::Clarabel,
                    "direct" => QpMethod::Direct,
                    other => {
                        return Err(NanofoldError::invalid(
                            key,
                            other,
                            "expected \"clarabel\" or \"direct\"",
                        ))
                    }
                }
            }
            "flat_tol" => u.flat_tol = number(key, v)?,
            "max_iterations" => u.max_iterations = count(key, v)?,
            "bending_metric" => u.bending_metric = number(key, v)?,
            "restarts" => u.restarts = count(key, v)?,
            "seed" => u.seed = count(key, v)? as u64,
            "closure_tol" => settings.check.closure_tol = number(key, v)?,
            "to" => settings.fold.drive = nanofold::folding::Drive::Assignment { to: number(key, v)? },
            "drive" => drive_edges = drive(v)?,
            "max_step" => settings.fold.max_step = number(key, v)?.to_radians(),
            "max_steps" => settings.fold.max_steps = count(key, v)?,
            "frames" => {
                frames = count(key, v)?;
                if !(2..=10_000).contains(&frames) {
                    return Err(NanofoldError::invalid(key, frames, "must lie in [2, 10000]"));
                }
            }
            _ => unreachable!("known keys are matched above"),
        }
    }
    settings.unfold.validate()?;
    Ok(CommandSettings {
        settings,
        frames,
        drive_edges,
    })
}

/// `drive`: {FOLD edge index: angle in degrees}, as `fold --drive EDGE=DEG`.
fn drive(value: &Value) -> Result<Vec<(usize, f64)>> {
    let map = object(value, "drive")?;
    map.iter()
        .map(|(edge, angle)| {
            let edge: usize = edge
                .parse()
                .map_err(|_| NanofoldError::invalid("drive", edge, "keys are FOLD edge indices"))?;
            Ok((edge, number("drive", angle)?.to_radians()))
        })
        .collect()
}

/// `constraints` keywords.
pub fn constraint_settings(value: &Value) -> Result<ConstraintSettings> {
    const KNOWN: &[&str] = &["driver", "locks", "free", "degree", "tol", "domain", "samples"];
    let mut settings = ConstraintSettings::default();
    let mut tol = None;
    let mut auto = false;
    for (key, v) in object(value, "settings")? {
        match key.as_str() {
            "driver" => settings.driver = count(key, v)?,
            "locks" => {
                settings.locks = object(v, "locks")?
                    .iter()
                    .map(|(crease, angle)| {
                        let crease: usize = crease
                            .parse()
                            .map_err(|_| NanofoldError::invalid("locks", crease, "keys are crease indices"))?;
                        Ok((crease, number("locks", angle)?))
                    })
                    .collect::<Result<_>>()?
            }
            "free" => {
                settings.free = v
                    .as_array()
                    .ok_or_else(|| NanofoldError::invalid("free", v.to_string(), "expected a list of crease indices"))?
                    .iter()
                    .map(|c| count("free", c))
                    .collect::<Result<_>>()?
            }
            "degree" => match v.as_str() {
                Some("auto") => auto = true,
                _ => settings.degree = Degree::Fixed(count(key, v)?),
            },
            "tol" => tol = Some(number(key, v)?),
            "domain" => {
                let pair = v
                    .as_array()
                    .filter(|a| a.len() == 2)
                    .ok_or_else(|| NanofoldError::invalid("domain", v.to_string(), "expected [a, b] in rad"))?;
                settings.domain = Some([number("domain", &pair[0])?, number("domain", &pair[1])?]);
            }
            "samples" => settings.samples = count(key, v)?,
            _ => return Err(unknown(key, v, KNOWN)),
        }
    }
    match (auto, tol) {
        (true, Some(tol)) => {
            settings.degree = Degree::Auto {
                tol,
                at_most: nanofold::constraints::MAX_DEGREE,
            }
        }
        (true, None) => {
            return Err(NanofoldError::invalid(
                "degree",
                "\"auto\"",
                "needs tol (the largest accepted fit error, rad)",
            ))
        }
        (false, Some(_)) => {
            return Err(NanofoldError::invalid(
                "tol",
                "given",
                "applies only to degree=\"auto\"",
            ))
        }
        (false, None) => {}
    }
    Ok(settings)
}

/// `simulate` keywords.
pub fn simulation_settings(value: &Value) -> Result<SimulationSettings> {
    const KNOWN: &[&str] = &["model", "method", "rtol", "t_end", "ignore_collisions", "max_steps"];
    let mut settings = SimulationSettings::default();
    for (key, v) in object(value, "settings")? {
        match key.as_str() {
            "model" => {
                settings.model = match text(key, v)? {
                    "auto" => ModelChoice::Auto,
                    "dynamic" => ModelChoice::Dynamic,
                    "quasi_static" => ModelChoice::QuasiStatic,
                    other => {
                        return Err(NanofoldError::invalid(
                            key,
                            other,
                            "expected \"auto\", \"dynamic\" or \"quasi_static\"",
                        ))
                    }
                }
            }
            "method" => {
                settings.method = match text(key, v)? {
                    "auto" => Method::Auto,
                    "bdf" => Method::Bdf,
                    "esdirk34" => Method::Esdirk34,
                    "tr_bdf2" => Method::TrBdf2,
                    "tsit45" => Method::Tsit45,
                    other => {
                        return Err(NanofoldError::invalid(
                            key,
                            other,
                            "expected \"auto\", \"bdf\", \"esdirk34\", \"tr_bdf2\" or \"tsit45\"",
                        ))
                    }
                }
            }
            "rtol" => settings.rtol = number(key, v)?,
            "t_end" => settings.t_end = if v.is_null() { None } else { Some(number(key, v)?) },
            "ignore_collisions" => {
                settings.ignore_collisions = v
                    .as_bool()
                    .ok_or_else(|| NanofoldError::invalid(key, v.to_string(), "expected true or false"))?
            }
            "max_steps" => settings.max_steps = count(key, v)?,
            _ => return Err(unknown(key, v, KNOWN)),
        }
    }
    settings.validate()?;
    Ok(settings)
}

/// A generator by family name and its keywords (lengths in the sheet's units, angles in
/// degrees as `nanofold generate` takes them).
pub fn generator(kind: &str, value: &Value) -> Result<Generator> {
    let map = object(value, "parameters")?;
    let get = |key: &str| map.get(key);
    let known: &[&str] = match kind {
        "miura" => &["rows", "cols", "angle_deg", "width", "slant", "fold_deg"],
        "square_twist" => &["side", "half_sheet", "twist_deg", "flip_pleats"],
        "waterbomb" => &["rows", "cols", "row_height"],
        "bird_base" => &["half_side"],
        other => {
            return Err(NanofoldError::invalid(
                "kind",
                other,
                "expected \"miura\", \"square_twist\", \"waterbomb\" or \"bird_base\"",
            ))
        }
    };
    if let Some((key, v)) = map.iter().find(|(k, _)| !known.contains(&k.as_str())) {
        return Err(unknown(key, v, known));
    }
    let num = |key: &str, default: f64| get(key).map_or(Ok(default), |v| number(key, v));
    let whole = |key: &str, default: usize| get(key).map_or(Ok(default), |v| count(key, v));
    Ok(match kind {
        "miura" => {
            let d = MiuraSpec::default();
            Generator::Miura(MiuraSpec {
                rows: whole("rows", d.rows)?,
                cols: whole("cols", d.cols)?,
                sector_angle: num("angle_deg", d.sector_angle.to_degrees())?.to_radians(),
                width: num("width", d.width)?,
                slant: num("slant", d.slant)?,
                zigzag_fold_angle: num("fold_deg", 0.0)?.to_radians(),
            })
        }
        "square_twist" => {
            let d = SquareTwistSpec::default();
            Generator::SquareTwist(SquareTwistSpec {
                side: num("side", d.side)?,
                half_sheet: num("half_sheet", d.half_sheet)?,
                twist: num("twist_deg", d.twist.to_degrees())?.to_radians(),
                flip_pleats: get("flip_pleats").map_or(Ok(d.flip_pleats), |v| {
                    v.as_bool()
                        .ok_or_else(|| NanofoldError::invalid("flip_pleats", v.to_string(), "expected true or false"))
                })?,
            })
        }
        "waterbomb" => {
            let d = WaterbombSpec::default();
            Generator::Waterbomb(WaterbombSpec {
                rows: whole("rows", d.rows)?,
                cols: whole("cols", d.cols)?,
                row_height: num("row_height", d.row_height)?,
            })
        }
        _ => Generator::BirdBase(BirdBaseSpec {
            half_side: num("half_side", BirdBaseSpec::default().half_side)?,
        }),
    })
}
